# Sourced by scripts/test.sh: checks that the package behaves as a catkin
# package should, from the devel space and from the install space. Each
# function is one test; each loads one space in a clean environment (env -i),
# so nothing of the calling shell (another workspace, the devel space when
# the install space is checked) can make it pass.
#
#   pf_in_space SETUP CMD...        runs CMD with only SETUP (a setup.bash) loaded
#   pf_space_cmd SETUP CMD...       the same command line, in the array PF_SPACE_CMD
#   pf_check_rosrun SETUP           rosrun pf_localization pf_evaluate --help, no prompt, no loop
#   pf_check_install_demo WS        roslaunch bag_demo.launch from WS/install: pf_node publishes pf_pose

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

# bag_demo.launch from the install space alone (a private roscore on a random
# port, the bundled bag at 2x, 66 s long): pf_node must publish pf_pose within 60 s.
# SIGTERM stops roslaunch: a background job of a script ignores SIGINT.
pf_check_install_demo() {
  local ws=$1 tmp port launch_pid rc out
  if [ ! -f "$ws/install/setup.bash" ]; then echo "no $ws/install/setup.bash"; return 1; fi
  tmp=$(mktemp -d /tmp/pf_install_demo.XXXXXX)
  port=$((20000 + RANDOM % 20000))
  (
    export ROS_MASTER_URI=http://localhost:$port ROS_HOME=$tmp/home ROS_LOG_DIR=$tmp/log
    # The package found must be the installed one, not a source folder.
    where=$(pf_in_space "$ws/install/setup.bash" rospack find pf_localization)
    if [ "$where" != "$ws/install/share/pf_localization" ]; then
      echo "rospack find pf_localization: '$where', not $ws/install/share/pf_localization"
      exit 1
    fi
    # A simple command run with & is exec'ed: $! is timeout's pid, and timeout
    # passes the signal on to roslaunch.
    pf_space_cmd "$ws/install/setup.bash" timeout -s TERM 150 \
      roslaunch -p "$port" pf_localization bag_demo.launch rate:=2
    "${PF_SPACE_CMD[@]}" >"$tmp/launch.log" 2>&1 &
    launch_pid=$!
    for _ in $(seq 30); do  # roslaunch starts its roscore first
      pf_in_space "$ws/install/setup.bash" rostopic list >/dev/null 2>&1 && break
      sleep 1
    done
    out=$(pf_in_space "$ws/install/setup.bash" timeout 60 rostopic echo -n 3 /pf_pose 2>&1)
    rc=$?
    kill -TERM "$launch_pid" 2>/dev/null
    wait "$launch_pid"
    n=$(grep -c '^header:' <<<"$out")
    if [ "$rc" -ne 0 ] || [ "$n" -lt 3 ] || grep -qE 'ERROR|cannot launch|not found' "$tmp/launch.log"; then
      echo "rostopic echo -n 3 /pf_pose: exit $rc, $n message(s)"
      tail -n 30 "$tmp/launch.log"
      echo "(logs in $tmp)"
      exit 1
    fi
    echo "bag_demo.launch from $ws/install: $n pf_pose messages, e.g. x=$(grep -m1 -A1 'position:' <<<"$out" | sed -nE 's/.*x: //p')"
  )
  rc=$?
  [ "$rc" -eq 0 ] && rm -rf "$tmp"
  return "$rc"
}
