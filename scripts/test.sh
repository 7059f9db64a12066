#!/usr/bin/env bash
# The project's tests, in two tiers. This script only builds and schedules them: what each
# test asserts, and its thresholds, live in the test files (test/core, test/sim,
# test/ros_unit, test/fuzz: GoogleTest; test/rostest: rostest; test/python, test/replay:
# pytest); the few checks of the sources and of the package as catkin and Debian see it
# are the functions of scripts/test_checks.bash and scripts/space_checks.bash.
#
#   bash scripts/test.sh           every test: what .ci/run runs, and what a change must pass
#   bash scripts/test.sh --quick   the edit-test loop: build what changed, then the unit tests
#                                  (GoogleTest, test/python) and the source checks; no bag
#                                  replay, no second build
#
# Both install the dependencies (scripts/install_deps.sh; nothing when they are there)
# and build the package and its test binaries on both cores, through ccache
# (CMakeLists.txt, PF_CCACHE). --quick then runs its checks two at a time. The full
# run runs, on two lanes:
#   - side by side at normal priority, PF_TEST_JOBS at a time (default 6): the README
#     walked through (scripts/readme_walkthrough.sh: its clean builds come from
#     ccache), the Python tests, the GoogleTest binaries, the source checks, the
#     rostests (each starts its own master on a free port and mostly waits for its
#     bag's clock: about 0.15 of a core each; the longest first, by the last run's
#     times) and the rviz click test; then, one at a time, the rostests that bound
#     time on the wall clock; then the install space and its demo;
#   - two at a time at the lowest priority (nice 19), so that the rostests' clocks keep
#     their pace: the unit tests built and run under ASan + UBSan (scripts/sanitize.sh,
#     the longest), the Debian package (scripts/make_deb.sh) and the replays of
#     test/replay, whose figures do not depend on the machine's load (pf_bag_runner is
#     deterministic for a seed).
#
# Every check's output goes to a log in <workspace>/test_logs/ (its tail is shown when
# it fails); each prints one line with its time, <workspace>/test_times keeps each one's
# wall and CPU seconds, and the end lists the ten slowest, each failed case with the
# start of its message, the machine, the total, and last one line "N passed, N failed":
# every GoogleTest case, every rostest's test node, every pytest case and every other
# check count one. Exits non-zero when anything failed or nothing
# ran; the full run also fails when it took longer than PF_TEST_BUDGET_S (1500 s).
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
quick=0
case "${1:-}" in
  --quick) quick=1 ;;
  "") ;;
  -h | --help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
  *) echo "test.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
esac
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
# shellcheck source=scripts/space_checks.bash
source "$repo/scripts/space_checks.bash"
# shellcheck source=scripts/test_checks.bash
source "$repo/scripts/test_checks.bash"
ws=$(pf_default_ws "$repo")
export PATH=/usr/bin:$PATH
# One compiler cache for every build of the run, wherever XDG_CACHE_HOME points later.
export CCACHE_DIR=${CCACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/ccache}
cd "$repo" || exit 1
start=$EPOCHREALTIME
budget=${PF_TEST_BUDGET_S:-1500}
jobs=${PF_TEST_JOBS:-6}

bash scripts/install_deps.sh || { echo "install failed"; echo "0 passed, 1 failed"; exit 1; }
mkdir -p "$ws"
logs=$ws/test_logs
results=$ws/build/test_results
rm -rf "$logs" "$results"
mkdir -p "$logs"
# The workspace for the tools and tests this run starts (test/replay, benchmark_datasets).
export PF_WS=$ws

# cpu_seconds: sets CPU_S to the CPU time (user + system, s) of this shell's finished
# children, from `times` (which must run in this shell: a pipe or $(...) would ask a
# fresh subshell, whose children have used nothing yet).
cpu_seconds() {
  local f=$logs/cpu_$BASHPID user sys
  times >"$f"
  { read -r _ _; read -r user sys; } <"$f"
  rm -f "$f"
  CPU_S=$(awk -v u="$user" -v s="$sys" \
    'function sec(x, p) { split(x, p, /[ms]/); return p[1] * 60 + p[2] } BEGIN { printf "%.0f", sec(u) + sec(s) }')
}

if ! bash scripts/build.sh all tests -j2 >"$logs/build.log" 2>&1; then
  tail -n 40 "$logs/build.log"
  echo "build failed (log: $logs/build.log)"; echo "0 passed, 1 failed"; exit 1
fi
cpu_seconds
echo "built in $(awk -v a="$start" -v b="$EPOCHREALTIME" 'BEGIN {printf "%.0f", b - a}') s ($CPU_S s of CPU)"
mkdir -p "$results/pf_localization"
pf_source_workspace "$ws" test || { echo "0 passed, 1 failed"; exit 1; }

# --- Jobs ----------------------------------------------------------------------------
# job KIND NAME COMMAND...: runs COMMAND with its output in $logs/KIND_NAME.log and
# appends "KIND NAME EXIT SECONDS CPU_SECONDS" to $logs/times. KIND check: COMMAND's
# exit status is the verdict (one test); for the others (gtest, rostest, pytest) their
# cases are counted from their result files.
job() {
  local kind=$1 name=$2 t0=$EPOCHREALTIME rc secs log cpu
  shift 2
  log=$logs/${kind}_${name//[^A-Za-z0-9_.-]/_}.log
  cpu=$( ("$@" </dev/null >"$log" 2>&1; rc=$?; cpu_seconds; echo "$CPU_S"; exit "$rc") )
  rc=$?
  secs=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN {printf "%.1f", b - a}')
  printf '%s\t%s\t%d\t%s\t%s\n' "$kind" "$name" "$rc" "$secs" "$cpu" >>"$logs/times"
  if [ "$rc" -eq 0 ]; then
    printf '[%s] %s: ok (%s s)\n' "$kind" "$name" "$secs"
  else
    printf '[%s] %s: FAILED (%s s; log: %s)\n' "$kind" "$name" "$secs" "$log"
    tail -n 15 "$log" | sed 's/^/    /'
  fi
  return "$rc"
}

# Jobs queued with `queue KIND NAME COMMAND...` run by run_queue N, N at a time,
# in the order queued. KIND group: COMMAND runs jobs of its own (it is not one).
queued=()
queue() { queued+=("$(printf '%q ' "$@")"); }
run_queue() {
  local n=$1 spec pid finished
  local -a running=() still words
  for spec in "${queued[@]}"; do
    while [ ${#running[@]} -ge "$n" ]; do
      wait -n -p finished "${running[@]}"
      still=()
      for pid in "${running[@]}"; do [ "$pid" = "$finished" ] || still+=("$pid"); done
      running=("${still[@]}")
    done
    eval "words=($spec)"
    if [ "${words[0]}" = group ]; then "${words[@]:2}" & else job "${words[@]}" & fi
    running+=("$!")
  done
  for pid in "${running[@]}"; do wait "$pid"; done
  queued=()
}

# gtest BINARY: one GoogleTest binary, its cases in gtest-BINARY.xml, run
# as catkin's run_tests target runs it (run_tests.py writes a failure when
# the binary left no result file); one that hangs is stopped after 10 minutes.
gtest() {
  local xml=$results/pf_localization/gtest-$1.xml
  /usr/bin/python3 /usr/share/catkin/cmake/test/run_tests.py "$xml" \
    "timeout -k 10 600 $ws/devel/lib/pf_localization/$1 --gtest_output=xml:$xml" --return-code
}
# pytest_run NAME DIR PYTEST_ARGS...: the pytest tests of DIR (test_*.py, unittest's
# classes among them), each case one test, in pytest-NAME.xml; a run that ends without
# its verdicts (exit 2-5: interrupted, an internal or usage error, nothing collected)
# adds a failure of its own. No cache or bytecode is written into the repository.
pytest_run() {
  local name=$1 dir=$2 xml=$results/pf_localization/pytest-$1.xml rc
  shift 2
  PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -m pytest -p no:cacheprovider -v -rfE \
    --junitxml="$xml" "$@" "$dir"
  rc=$?
  if [ "$rc" -gt 1 ]; then
    printf '<testsuite><testcase classname="pytest" name="%s"><failure message="pytest exited %d"/></testcase></testsuite>\n' \
      "$dir" "$rc" >"$results/pf_localization/pytest-$name-exit.xml"
  fi
  return "$rc"
}
# rostest FILE ARGS...: one rostest as catkin's run_tests target runs it (run_tests.py
# writes a failure when the test left no result file). Each has a ROS_HOME of its own:
# pf_node saves the layer of the map's changes there (map_changes_file), which another
# test on the same map, running beside it or after it, must not restore. The logs stay
# where they were.
rostest_run() {
  local file=$1 name
  shift
  name=test_rostest_$(basename "$file" .test)
  mkdir -p "$logs/ros_home/$name"
  ROS_LOG_DIR=${ROS_LOG_DIR:-${ROS_HOME:-$HOME/.ros}/log} ROS_HOME=$logs/ros_home/$name \
    /usr/bin/python3 /usr/share/catkin/cmake/test/run_tests.py \
    "$results/pf_localization/rostest-$name.xml" \
    "/usr/bin/python3 /usr/bin/rostest --pkgdir=$ws/src/pf_localization --package=pf_localization \
--results-filename $name.xml --results-base-dir $results $ws/src/pf_localization/$file $*"
}

queue_unit_tier() {  # the unit tests and the source checks
  local t
  queue pytest "the Python package's tests (test/python)" pytest_run python test/python
  for t in pf_core_test pf_sim_test pf_ros_test pf_fuzz_replay_test; do queue gtest "$t" gtest "$t"; done
  queue check "catkin_lint -W1 clean" catkin_lint_clean
  queue check "the core and the simulator include no ROS header" core_is_ros_free
  queue check "no function in src/ longer than 80 lines" no_long_functions
  queue check "no source file longer than 600 lines" no_long_files
  queue check "clang-format clean" clang_format_clean
  queue check "the manual builds (mkdocs --strict), its links and anchors resolve" docs_build
  queue check "every code name the manual gives in backticks exists in the code" \
    /usr/bin/python3 "$repo/scripts/check_doc_names.py" "$repo"
  queue check "each file is named after its main type, or holds free functions" \
    /usr/bin/python3 "$repo/scripts/check_file_names.py" "$repo"
}

# The Debian package, then what is checked of it.
deb_checks() {
  job check "make_deb.sh builds ros-pf-localization_VERSION_ARCH.deb" make_deb || return 1
  job check "the .deb: fields, files under /usr, Depends cover its libraries and nodes" \
    pf_check_deb "$(built_deb)" package.xml
  job check "bag_demo.launch from the .deb unpacked with dpkg -x: pf_node publishes pf_pose" \
    pf_check_deb_demo "$(built_deb)"
}

# The low-priority lane: what needs a core for long but no clock, two at a time, the
# sanitizer build (the longest) first.
background_lane() {
  [ "${PF_SKIP_SANITIZE:-0}" = 1 ] ||
    queue check "unit tests under ASan + UBSan (scripts/sanitize.sh)" bash scripts/sanitize.sh
  queue group "the Debian package" deb_checks
  queue pytest "replays of the bundled bags and the real recordings (test/replay)" \
    pytest_run replay test/replay -s
  run_queue 2
}

# The rostests, the longest first when an earlier run left their times.
rostests_by_length() {
  local file args secs
  local previous=$ws/test_times
  while read -r file args; do
    [ -n "$file" ] || continue
    secs=$(awk -F'\t' -v n="$(basename "$file" .test)" '$1 == "rostest" && $2 == n {print $4}' \
      "$previous" 2>/dev/null | tail -n 1)
    printf '%s\t%s\t%s\n' "${secs:-0}" "$file" "$args"
  done <"$ws/build/pf_localization/rostests.txt" | sort -t$'\t' -k1,1nr | cut -f2-
}

# The rostests that bound time on the wall clock (update time, the gap between
# map -> odom messages, CPU under a hog, a track read through tf relayed by Python
# nodes, a 3D lidar's clouds reduced at 4x, whose 6 cm bound needs the node to
# take most of them): run one at a time after the others, when only the
# low-priority lane shares the machine, since five neighbours on two cores are
# not the load they were written for.
timed_rostests="max_update_time overload overload_4x cpu_hog odom_topic map_swap floors cloud"

full_tier() {
  local file args
  (renice -n 19 -p "$BASHPID" >/dev/null && background_lane) &
  local background=$!
  # The longest first: the walkthrough and the Python tests (each about 2 minutes).
  queue check "the README, step by step (scripts/readme_walkthrough.sh)" bash scripts/readme_walkthrough.sh
  queue_unit_tier
  local -a alone=()
  while IFS=$'\t' read -r file args; do
    if [[ " $timed_rostests " == *" $(basename "$file" .test) "* ]]; then
      alone+=("$file${args:+ $args}")
      continue
    fi
    # shellcheck disable=SC2086  # the arguments are words
    queue rostest "$(basename "$file" .test)" rostest_run "$file" $args
  done < <(rostests_by_length)
  queue check "rviz: 2D Pose Estimate clicked re-initialises pf_node (scripts/rviz_click_test.sh)" \
    bash scripts/rviz_click_test.sh --out "$ws/rviz_click_test"
  run_queue "$jobs"
  for file in "${alone[@]}"; do
    # shellcheck disable=SC2086  # the arguments are words
    queue rostest "$(basename "${file%% *}" .test)" rostest_run $file
  done
  run_queue 1
  job check "rosrun pf_evaluate from the devel space: no prompt, no loop" pf_check_rosrun "$ws/devel/setup.bash"
  if job check "catkin_make install" install_space; then
    job check "rosrun pf_evaluate from the install space: no prompt, no loop" pf_check_rosrun "$ws/install/setup.bash"
    job check "no rostest checker node in the install space" pf_check_no_test_nodes "$ws/install/lib/pf_localization"
    job check "bag_demo.launch from the install space alone: pf_node publishes pf_pose" pf_check_install_demo "$ws"
  fi
  wait "$background"
}

if [ "$quick" -eq 1 ]; then
  export PF_TEST_TIER=quick
  queue_unit_tier
  run_queue 2
else
  full_tier
fi

# --- The verdict -----------------------------------------------------------------------
total=$(awk -v a="$start" -v b="$EPOCHREALTIME" 'BEGIN {printf "%.0f", b - a}')
if [ "$quick" -eq 0 ]; then
  job check "the whole run within its budget of $budget s (it took $total s)" test "$total" -le "$budget"
  cp "$logs/times" "$ws/test_times"
fi
echo "the ten slowest (wall s, CPU s):"
sort -t$'\t' -k4,4nr "$logs/times" | head -n 10 |
  awk -F'\t' '{printf "  %7.1f %6s  %s %s\n", $4, $5, $1, $2}'
read -r ok bad < <(/usr/bin/python3 scripts/count_test_results.py "$results")
checks_ok=$(awk -F'\t' '$1 == "check" && $3 == 0' "$logs/times" | wc -l)
checks_bad=$(awk -F'\t' '$1 == "check" && $3 != 0' "$logs/times" | wc -l)
passed=$((${ok:-0} + checks_ok))
failed=$((${bad:-1} + checks_bad))
[ "${ok:-0}" -eq 0 ] && { echo "no gtest or rostest result found"; failed=$((failed + 1)); }
cpu_seconds
# The machine, for figures and failures read from a run elsewhere (CI's).
echo "machine: $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n 1), $(nproc) cores," \
  "$(grep -ow 'avx2\|fma\|avx512f' /proc/cpuinfo | sort -u | tr '\n' ' ')"
echo "$total s in all, $CPU_S s of CPU"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
