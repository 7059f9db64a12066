# Sourced by scripts/test.sh: the checks of the package as catkin and Debian see it,
# of the sources and of the manual, one function each (0: passed). They read $repo
# (the repository) and $ws (the built workspace). The tests of the filter's behaviour,
# with their thresholds, are test files (test/replay for the replays of the bags).
#
# The package as catkin and Debian see it:
#   catkin_lint_clean install_space make_deb (and scripts/space_checks.bash)
# The sources:
#   core_is_ros_free clang_format_clean no_long_functions no_long_files
# The documentation:
#   docs_build (the manual, strict, its links and anchors)

# --- A standard catkin package: lint, the install space, the Debian package ----
catkin_lint_clean() {
  local out
  out=$(catkin_lint -W1 --strict --offline "$repo" 2>&1) && return 0
  echo "$out" | head -n 30
  return 1
}
install_space() {  # catkin_make install; from scratch in the scripts' own workspace
  # (not in a PF_WS of the user's, whose install space may hold other packages)
  case $ws in "$(pf_cache_dir "$repo")"/*) rm -rf "$ws/install" ;; esac
  bash "$repo/scripts/build.sh" install >"$ws/install.log" 2>&1 && return 0
  tail -n 30 "$ws/install.log"
  return 1
}
# Built in $ws/build_deb (kept: the next run recompiles only what changed),
# written to $ws/deb; read, then unpacked with dpkg -x into a temporary root
# and run from there (installing it would need root and change /usr).
make_deb() {
  rm -rf "$ws/deb"
  bash "$repo/scripts/make_deb.sh" --out "$ws/deb" --build-dir "$ws/build_deb" >"$ws/make_deb.log" 2>&1 &&
    return 0
  tail -n 30 "$ws/make_deb.log"
  return 1
}
built_deb() { tail -n 1 "$ws/make_deb.log" 2>/dev/null; }

# --- The sources -----------------------------------------------------------------
core_is_ros_free() {
  ! grep -rnE '#include [<"](ros|tf2|sensor_msgs|nav_msgs|geometry_msgs|rosbag)/' \
    "$repo/include/pf_localization/core" "$repo/src/core" \
    "$repo/include/pf_localization/sim" "$repo/src/sim"
}
clang_format_clean() {
  local out
  out=$(cd "$repo" && git ls-files '*.h' '*.cc' | xargs -r clang-format --dry-run -Werror 2>&1)
  [ -z "$out" ] && return 0
  echo "$out" | head -n 20
  return 1
}
# No source file over 600 lines: one that long holds more than one idea.
no_long_files() {
  (cd "$repo" && git ls-files '*.cc' '*.h' '*.py' '*.sh' '*.bash' 'scripts/*' | sort -u |
    xargs wc -l | awk '$2 != "total" && $1 > 600 {print "over 600 lines:", $2, $1; n++} END {exit n > 0}')
}
no_long_functions() {
  local sources
  mapfile -t sources < <(cd "$repo" && git ls-files 'src/*.cc')
  (cd "$repo" && /usr/bin/python3 scripts/long_functions.py --max 80 "${sources[@]}")
}

# --- The documentation ---------------------------------------------------------
# The manual (mkdocs.yml, docs/) built with warnings as errors into the
# workspace, outside the repository; then every internal link and anchor of
# the built pages and of README.md must resolve (mkdocs 1.4 checks links to
# pages, not anchors). A few seconds.
docs_build() {
  local site="$ws/manual"
  rm -rf "$site"
  (cd "$repo" && mkdocs build --strict --quiet -f mkdocs.yml -d "$site") || return 1
  /usr/bin/python3 "$repo/scripts/check_doc_links.py" "$site" "$repo"
}
