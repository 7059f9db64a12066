# Sourced by scripts/test.sh: checks that the package behaves as a catkin
# package should, from the devel space and from the install space. Each
# function is one test; each loads one space in a clean environment (env -i),
# so nothing of the calling shell (another workspace, the devel space when
# the install space is checked) can make it pass.
#
#   pf_in_space SETUP CMD...        runs CMD with only SETUP (a setup.bash) loaded
#   pf_space_cmd SETUP CMD...       the same command line, in the array PF_SPACE_CMD
#   pf_check_rosrun SETUP           rosrun pf_localization pf_evaluate --help, no prompt, no loop
#   pf_check_install_demo WS        roslaunch bag_demo.launch from WS/install: pf_node publishes pf_pose,
#                                   and pf_hypotheses as rostopic reads it (the generated message)
#   pf_check_demo SETUP SHARE       the same from any space; SHARE: where pf_localization must be found
#   pf_check_deb DEB PACKAGE_XML    the .deb of scripts/make_deb.sh: fields, files under /usr, Depends,
#                                   no test node
#   pf_check_no_test_nodes LIBEXEC  no rostest checker node (test/rostest/*.py) in LIBEXEC
#   pf_check_deb_demo DEB           bag_demo.launch from DEB unpacked with dpkg -x into a temporary root

pf_space_cmd() {  # sets PF_SPACE_CMD to the command line of pf_in_space SETUP CMD...
  local setup=$1; shift
  PF_SPACE_CMD=(env -i HOME="${HOME:-/tmp}" PATH=/usr/bin:/bin LANG=C.UTF-8
    ${ROS_MASTER_URI:+ROS_MASTER_URI=$ROS_MASTER_URI} ${ROS_HOME:+ROS_HOME=$ROS_HOME}
    ${ROS_LOG_DIR:+ROS_LOG_DIR=$ROS_LOG_DIR}
    bash -c 'setup=$1; shift; cmd=("$@"); set --; source "$setup" || exit 2; exec "${cmd[@]}"'
    pf_in_space "$setup" "$@")
}
pf_in_space() {
  pf_space_cmd "$@"
  "${PF_SPACE_CMD[@]}"
}
# (catkin's setup.bash reads the positional parameters as its own options:
# they are cleared before it is sourced.)

# rosrun searches the package folder with find -L: a link back into the package
# (a workspace inside it) shows as "File system loop detected", and a second
# copy of pf_evaluate as an interactive "non-unique executable" prompt, which
# reads stdin (</dev/null: it gets nothing and rosrun fails).
pf_check_rosrun() {
  local setup=$1 out rc
  if [ ! -f "$setup" ]; then echo "no $setup"; return 1; fi
  out=$(pf_in_space "$setup" rosrun pf_localization pf_evaluate --help </dev/null 2>&1)
  rc=$?
  if [ "$rc" -ne 0 ] || grep -qiE 'loop|non-unique|\[rosrun\]|warn' <<<"$out" ||
     ! grep -q '^usage: pf_evaluate' <<<"$out"; then
    echo "$out" | head -n 20
    echo "rosrun pf_localization pf_evaluate --help from $setup: exit $rc"
    return 1
  fi
}

# bag_demo.launch from the install space alone (a private roscore on a free
# port, the bundled bag at 2x, 66 s long): pf_node must publish pf_pose within 60 s,
# and pf_hypotheses (latched), which rostopic must read with the space's own
# generated Python message.
# SIGTERM stops roslaunch: a background job of a script ignores SIGINT.
pf_check_install_demo() {
  pf_check_demo "$1/install/setup.bash" "$1/install/share/pf_localization"
}
pf_check_demo() {
  local setup=$1 share=$2 tmp port launch_pid rc out hyp
  if [ ! -f "$setup" ]; then echo "no $setup"; return 1; fi
  tmp=$(mktemp -d /tmp/pf_install_demo.XXXXXX)
  port=$(pf_free_port) || return 1
  (
    export ROS_MASTER_URI=http://localhost:$port ROS_HOME=$tmp/home ROS_LOG_DIR=$tmp/log
    # The package found must be the installed one, not a source folder.
    where=$(pf_in_space "$setup" rospack find pf_localization)
    if [ "$where" != "$share" ]; then
      echo "rospack find pf_localization: '$where', not $share"
      exit 1
    fi
    # A simple command run with & is exec'ed: $! is timeout's pid, and timeout
    # passes the signal on to roslaunch.
    pf_space_cmd "$setup" timeout -s TERM 150 \
      roslaunch -p "$port" pf_localization bag_demo.launch rate:=2
    "${PF_SPACE_CMD[@]}" >"$tmp/launch.log" 2>&1 &
    launch_pid=$!
    for _ in $(seq 30); do  # roslaunch starts its roscore first
      pf_in_space "$setup" rostopic list >/dev/null 2>&1 && break
      sleep 1
    done
    out=$(pf_in_space "$setup" timeout 60 rostopic echo -n 3 /pf_pose 2>&1)
    rc=$?
    hyp=$(pf_in_space "$setup" timeout 20 rostopic echo -n 1 /pf_hypotheses 2>&1)
    kill -TERM "$launch_pid" 2>/dev/null
    wait "$launch_pid"
    n=$(grep -c '^header:' <<<"$out")
    if [ "$rc" -ne 0 ] || [ "$n" -lt 3 ] || grep -qE 'ERROR|cannot launch|not found' "$tmp/launch.log"; then
      echo "rostopic echo -n 3 /pf_pose: exit $rc, $n message(s)"
      tail -n 30 "$tmp/launch.log"
      echo "(logs in $tmp)"
      exit 1
    fi
    if ! grep -qE '^count: [1-9]' <<<"$hyp"; then
      echo "rostopic echo -n 1 /pf_hypotheses: no hypothesis read:"
      head -n 20 <<<"$hyp"
      echo "(logs in $tmp)"
      exit 1
    fi
    echo "bag_demo.launch from $(dirname "$setup"): $n pf_pose messages, e.g. x=$(grep -m1 -A1 'position:' <<<"$out" | sed -nE 's/.*x: //p'); pf_hypotheses $(grep -m1 '^count:' <<<"$hyp")"
  )
  rc=$?
  [ "$rc" -eq 0 ] && rm -rf "$tmp"
  return "$rc"
}

# The .deb of scripts/make_deb.sh, read without installing it: its name and
# fields (version: package.xml's; architecture: dpkg's), every file under /usr
# in Debian's ROS layout and no workspace file, no RPATH, and Depends that
# cover what it runs: the package of every library a binary links (besides its
# own), of roslaunch, and of every node bag_demo.launch starts.
# The rostests' checker nodes (test/rostest/*.py) stay in the source tree:
# roslaunch finds them there, and a robot has no use for them.
pf_check_no_test_nodes() {
  local libexec=$1 node bad=0
  if [ ! -d "$libexec" ]; then echo "no $libexec"; return 1; fi
  for node in "$(dirname "${BASH_SOURCE[0]}")"/../test/rostest/*.py; do
    node=$(basename "$node" .py)
    for f in "$libexec/$node" "$libexec/$node.py"; do
      if [ -e "$f" ]; then echo "test node installed: $f (a leftover of an older install? remove it)"; bad=1; fi
    done
  done
  return "$bad"
}

pf_check_deb() {
  local deb=$1 package_xml=$2 version arch multiarch root depends bad=0 f lib path owner p
  if [ ! -f "$deb" ]; then echo "no .deb: $deb"; return 1; fi
  version=$(sed -n 's:.*<version>\(.*\)</version>.*:\1:p' "$package_xml")
  arch=$(dpkg --print-architecture)
  multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH)
  if [ "$(basename "$deb")" != "ros-pf-localization_${version}_${arch}.deb" ]; then
    echo "file name $(basename "$deb"), not ros-pf-localization_${version}_${arch}.deb"; bad=1
  fi
  for f in Package:ros-pf-localization "Version:$version" "Architecture:$arch"; do
    if [ "$(dpkg-deb -f "$deb" "${f%%:*}")" != "${f#*:}" ]; then
      echo "${f%%:*}: '$(dpkg-deb -f "$deb" "${f%%:*}")', not '${f#*:}'"; bad=1
    fi
  done
  # Depends as package names, one a line (versions and alternatives dropped).
  depends=$(dpkg-deb -f "$deb" Depends | sed -E 's/[,|]/\n/g' | sed -E 's/\(.*\)//; s/:any//; s/ //g' | sed '/^$/d' | sort -u)
  # python3-genpy: pf_hypotheses' generated Python module imports it.
  for p in python3-roslaunch python3-rosbag libroscpp4d python3-genpy; do
    grep -qx "$p" <<<"$depends" || { echo "Depends lacks $p: $(dpkg-deb -f "$deb" Depends)"; bad=1; }
  done
  if grep -E -- '-dev$' <<<"$depends"; then echo "Depends names -dev packages (above)"; bad=1; fi
  # Every package named exists: installed here, or else known to apt.
  local known
  known=$(dpkg-query -W -f '${Package}\n' 2>/dev/null)
  for p in $depends $(dpkg-deb -f "$deb" Recommends Suggests | sed -E 's/^[A-Za-z]+: //; s/\([^)]*\)//g; s/[,|]/ /g'); do
    grep -qx "$p" <<<"$known" || apt-cache show --no-all-versions "$p" >/dev/null 2>&1 ||
      { echo "dependency $p is unknown to apt"; bad=1; }
  done

  # Files: all under /usr, in Debian's layout.
  local listing
  listing=$(dpkg-deb --fsys-tarfile "$deb" | tar -t | sed 's:^\./::; s:/$::' | sed '/^$/d')
  if grep -vE '^usr(/|$)' <<<"$listing"; then echo "files outside /usr (above)"; bad=1; fi
  if grep -E '(^|/)(setup\.(ba|z)?sh|local_setup\..*|_setup_util\.py|env\.sh|\.catkin|\.rosinstall)$' <<<"$listing"; then
    echo "workspace files in the package (above)"; bad=1
  fi
  for f in usr/share/pf_localization/package.xml usr/share/pf_localization/launch/bag_demo.launch \
           usr/share/pf_localization/config/pf.yaml usr/share/pf_localization/maps/building.yaml \
           usr/share/pf_localization/bags/tracking.bag usr/share/pf_localization/rviz/pf.rviz \
           usr/lib/pf_localization/pf_node usr/lib/pf_localization/map_publisher \
           usr/lib/pf_localization/pf_evaluate "usr/lib/$multiarch/libpf_core.so" \
           usr/share/pf_localization/msg/PoseHypotheses.msg usr/include/pf_localization/PoseHypotheses.h \
           usr/lib/python3/dist-packages/pf_localization/msg/_PoseHypotheses.py \
           usr/share/doc/ros-pf-localization/copyright; do
    grep -qx "$f" <<<"$listing" || { echo "missing /$f"; bad=1; }
  done
  if grep -E '^usr/lib/pf_localization/[^/]*(_checker|cpu_hog)[^/]*$' <<<"$listing"; then
    echo "rostest checker nodes in the package (above)"; bad=1
  fi

  # Libraries and nodes: each one's Debian package must be in Depends.
  root=$(mktemp -d /tmp/pf_deb_check.XXXXXX)
  dpkg-deb -x "$deb" "$root"
  # ELF file, library it needs, where it resolves (ldd); then one dpkg -S for all.
  local elves=0 needs="" ldd_out
  while IFS= read -r -d '' f; do
    [ "$(head -c 4 "$f" | od -An -c | tr -d ' ')" = '177ELF' ] || continue
    elves=$((elves + 1))
    if readelf -d "$f" | grep -qE '\((RPATH|RUNPATH)\)'; then echo "${f#"$root"} has an RPATH"; bad=1; fi
    ldd_out=$(LD_LIBRARY_PATH=$root/usr/lib/$multiarch ldd "$f")
    for lib in $(readelf -d "$f" | sed -nE 's/.*\(NEEDED\).*\[(.*)\]/\1/p'); do
      # "libx.so.1 => /path (0x...)", or the loader's "/lib64/ld-linux-x86-64.so.2 (0x...)"
      path=$(awk -v l="$lib" '($1 == l && $2 == "=>") {print $3; exit}
                              (index($1, "/") && substr($1, length($1) - length(l)) == "/" l) {print $1; exit}' <<<"$ldd_out")
      case $path in
        "") echo "${f#"$root"}: $lib not found"; bad=1 ;;
        "$root"/*) ;;  # one of its own
        *) needs+="${f#"$root"} $lib $(realpath "$path")"$'\n' ;;
      esac
    done
  done < <(find "$root" -type f -print0)
  # dpkg knows a library under the path its package ships it at: /lib or /usr/lib
  # (Debian 12 merges /lib into /usr/lib).
  local -A owner_of=()
  local line
  while IFS= read -r line; do
    owner=${line%%:*}
    path=${line#*: }
    owner_of[${path#/usr}]=$owner
  done < <(awk 'NF == 3 {print $3; print "/usr" $3; sub("^/usr", "", $3); print $3}' <<<"$needs" |
           sort -u | xargs -r dpkg -S 2>/dev/null | grep -v '^diversion')
  while read -r f lib path; do
    [ -n "$f" ] || continue
    owner=${owner_of[${path#/usr}]:-}
    if [ -z "$owner" ]; then echo "$f: no Debian package owns $path ($lib)"; bad=1
    elif ! grep -qx "$owner" <<<"$depends"; then
      echo "$f links $lib of $owner, which Depends lacks"; bad=1
    fi
  done <<<"$needs"
  [ "$elves" -gt 0 ] || { echo "no ELF file in the package"; bad=1; }
  local node_pkg node_type
  while read -r node_pkg node_type; do
    [ "$node_pkg" = pf_localization ] && continue
    path=$(env -i PATH=/usr/bin:/bin catkin_find --libexec "$node_pkg" 2>/dev/null | head -n 1)/$node_type
    owner=$(dpkg -S "$path" 2>/dev/null) || true
    owner=${owner%%:*}
    if [ -z "$owner" ] || ! grep -qx "$owner" <<<"$depends"; then
      echo "bag_demo.launch runs $node_pkg/$node_type ($path, package '${owner:-none}'), which Depends lacks"; bad=1
    fi
  done < <(cat "$root"/usr/share/pf_localization/launch/{bag_demo,localization}.launch |
           grep -E '<node ' | grep -vE ' (if|unless)=' |
           sed -nE 's/.*pkg="([^"]+)".*type="([^"]+)".*/\1 \2/p')
  owner=$(dpkg -S /usr/bin/roslaunch 2>/dev/null) || true
  grep -qx "${owner%%:*}" <<<"$depends" || { echo "Depends lacks roslaunch's package (${owner%%:*})"; bad=1; }
  rm -rf "$root"
  [ "$bad" -eq 0 ] && echo "$(basename "$deb"): $(grep -c . <<<"$listing") paths under /usr, $elves ELF files, Depends: $(tr '\n' ' ' <<<"$depends")"
  return "$bad"
}

# bag_demo.launch from the .deb unpacked with dpkg -x into a temporary root
# (what apt would put in /usr, without touching /usr). The root stands in for
# /usr through the variables Debian's ROS searches first: ROS_PACKAGE_PATH
# (rospack), CMAKE_PREFIX_PATH plus a .catkin marker (catkin_find, hence
# roslaunch's node lookup, which falls back to /usr), LD_LIBRARY_PATH and
# PYTHONPATH. The nodes must be the root's, not a build's or an installed copy's.
pf_check_deb_demo() {
  local deb=$1 root multiarch node rc
  if [ ! -f "$deb" ]; then echo "no .deb: $deb"; return 1; fi
  multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH)
  root=$(mktemp -d /tmp/pf_deb_root.XXXXXX)
  dpkg-deb -x "$deb" "$root"
  touch "$root/usr/.catkin"
  cat >"$root/setup.bash" <<SETUP
export CMAKE_PREFIX_PATH=$root/usr
export ROS_PACKAGE_PATH=$root/usr/share:/usr/share
export LD_LIBRARY_PATH=$root/usr/lib/$multiarch
export PYTHONPATH=$root/usr/lib/python3/dist-packages
SETUP
  node=$(pf_in_space "$root/setup.bash" /usr/bin/python3 -c \
    'import roslib.packages as p; print(p.find_node("pf_localization", "pf_node")[0])' 2>&1)
  if [ "$node" != "$root/usr/lib/pf_localization/pf_node" ]; then
    echo "roslaunch would run pf_node from '$node', not $root/usr/lib/pf_localization/pf_node"
    rm -rf "$root"
    return 1
  fi
  pf_check_demo "$root/setup.bash" "$root/usr/share/pf_localization"
  rc=$?
  rm -rf "$root"
  return "$rc"
}
