#!/usr/bin/env bash
# README.md followed as a new user follows it, from a clean build, each step
# checked:
#
#   demo        "Two commands": bash scripts/demo.sh, in a workspace built from
#               nothing (build.sh's default folder, under a cache folder of its
#               own); exit 0 and a report with summary.json and its plots.
#   bag_demo    "Live, with roslaunch and rviz": with that workspace's
#               setup.bash, roslaunch pf_localization bag_demo.launch rviz:=false
#               (headless, on a roscore port of its own): pf_node publishes
#               map -> odom on /tf and pf_status reaches "localized"; then stopped.
#   help TOOL   rosrun pf_localization TOOL --help for every installed tool
#               (the Python tools and the nodes), with no ROS master to be had:
#               exit 0 and a usage text, within 30 s.
#   user_ws     "Building it yourself": a catkin workspace of the user's (its
#               src/ links to the repository; catkin_make; source devel/setup.bash),
#               not scripts/build.sh's, whose cache is out of reach (HOME is
#               empty): rosrun pf_tune (small.bag, 2 trials, 1 worker),
#               benchmark_datasets (the bundled bags) and pf_evaluate must find
#               that workspace's pf_bag_runner and finish.
#
#   bash scripts/readme_walkthrough.sh [--keep] [CHECK ...]
#
# CHECK: demo, bag_demo, help, user_ws (default: all, in that order; bag_demo
# and help use the workspace demo builds, user_ws needs nothing before it).
#
# Prints one "[check] NAME: ok/FAILED" line per check, then "N passed, N
# failed"; exits 1 if any check failed. Everything it makes (the two
# workspaces, logs, outputs) is in one temporary folder, removed at the end
# unless --keep (or a failure) says otherwise; demo.sh writes its report to
# reports/tracking/ as it does for a user. Two builds from scratch: about 9
# minutes on a shared two-core machine (load 4).
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
keep=0 only=()
while [ $# -gt 0 ]; do
  case $1 in
    --keep) keep=1; shift ;;
    -h | --help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    demo | bag_demo | help | user_ws) only+=("$1"); shift ;;
    *) echo "readme_walkthrough: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
wanted() { [ ${#only[@]} -eq 0 ] || [[ " ${only[*]} " == *" $1 "* ]]; }
export PATH=/usr/bin:$PATH
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
# pf_in_space SETUP CMD...: CMD with only that setup.bash loaded (env -i).
# shellcheck source=scripts/space_checks.bash
source "$repo/scripts/space_checks.bash"

tmp=$(mktemp -d /tmp/pf_readme_walkthrough.XXXXXX)
t_start=$(date +%s)
# The scripts' default workspace, but under a cache of our own: a clean build.
unset PF_WS
# ccache's own folder stays where it was (it would follow XDG_CACHE_HOME).
export CCACHE_DIR=${CCACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/ccache}
export XDG_CACHE_HOME=$tmp/cache
ws=$(pf_default_ws "$repo")
export ROS_HOME=$tmp/ros_home ROS_LOG_DIR=$tmp/ros_log
free_port() { /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])'; }
# No master listens here: a tool that needs one fails (or hangs until its timeout).
no_master_port=$(free_port)
export ROS_MASTER_URI=http://localhost:$no_master_port

passed=0 failed=0
check() {  # check NAME COMMAND...: one line per check, as scripts/test.sh prints
  local name=$1; shift
  if "$@"; then echo "[check] $name: ok"; passed=$((passed + 1))
  else echo "[check] $name: FAILED"; failed=$((failed + 1)); fi
}
show_log() { tail -n "${2:-20}" "$1" | sed 's/^/    /'; echo "    (log: $1)"; }

# --- "Two commands" -------------------------------------------------------------
demo() {
  local log=$tmp/demo.log report
  # As a new user's shell runs it: no workspace sourced (a sourced one would
  # put its devel space on the include path, and the build would differ).
  if ! (cd "$repo" && env -i HOME="${HOME:-/tmp}" PATH=/usr/bin:/bin LANG=C.UTF-8 \
      XDG_CACHE_HOME="$XDG_CACHE_HOME" CCACHE_DIR="$CCACHE_DIR" bash scripts/demo.sh) >"$log" 2>&1; then
    show_log "$log"; return 1
  fi
  report=$(sed -n 's/^demo: report in //p' "$log")
  for f in summary.json trajectory.png error.png spread.png cpu.png particles.gif; do
    [ -s "$report/$f" ] || { echo "    no $report/$f"; show_log "$log"; return 1; }
  done
  grep -E '^ +position error' "$log" | sed 's/^ */    /'
  return 0
}

# --- "Live, with roslaunch and rviz" ----------------------------------------------
cat >"$tmp/live_listener.py" <<'EOF'
"""Waits (wall clock) until pf_node has sent map -> odom on /tf and said "localized" on pf_status."""
import sys
import time

import rospy
from diagnostic_msgs.msg import DiagnosticStatus
from tf2_msgs.msg import TFMessage

seen = {'tf': 0, 'states': []}


def on_tf(msg):
    if msg._connection_header.get('callerid') != '/pf_node':
        return
    for t in msg.transforms:
        if t.header.frame_id.lstrip('/') == 'map' and t.child_frame_id.lstrip('/') == 'odom':
            seen['tf'] += 1


def on_status(msg):
    for kv in msg.values:
        if kv.key == 'state' and (not seen['states'] or seen['states'][-1] != kv.value):
            seen['states'].append(kv.value)


rospy.init_node('readme_walkthrough', anonymous=True, disable_signals=True)
rospy.Subscriber('/tf', TFMessage, on_tf)
rospy.Subscriber('/pf_status', DiagnosticStatus, on_status)
deadline = time.time() + float(sys.argv[1])
while time.time() < deadline and not (seen['tf'] and 'localized' in seen['states']):
    time.sleep(0.2)
print('map -> odom from pf_node: %d transform(s); pf_status states: %s'
      % (seen['tf'], ' -> '.join(seen['states']) or 'none'))
sys.exit(0 if seen['tf'] and 'localized' in seen['states'] else 1)
EOF
bag_demo() {
  local setup=$ws/devel/setup.bash log=$tmp/bag_demo.log port pid rc
  [ -f "$setup" ] || { echo "    no $setup"; return 1; }
  port=$(free_port)
  # A simple command run with & is exec'ed: $! is timeout's pid, which passes SIGTERM on.
  ROS_MASTER_URI=http://localhost:$port pf_space_cmd "$setup" timeout -s TERM 300 \
    roslaunch -p "$port" pf_localization bag_demo.launch rviz:=false
  "${PF_SPACE_CMD[@]}" >"$log" 2>&1 &
  pid=$!
  for _ in $(seq 30); do  # roslaunch starts its roscore first
    ROS_MASTER_URI=http://localhost:$port pf_in_space "$setup" rostopic list >/dev/null 2>&1 && break
    sleep 1
  done
  ROS_MASTER_URI=http://localhost:$port pf_in_space "$setup" timeout 150 \
    /usr/bin/python3 "$tmp/live_listener.py" 120 >"$tmp/live_listener.out" 2>&1
  rc=$?
  kill -TERM "$pid" 2>/dev/null
  wait "$pid"
  sed 's/^/    /' "$tmp/live_listener.out" | tail -n 5
  if [ "$rc" -ne 0 ] || grep -qE 'cannot launch|Cannot locate|ERROR' "$log"; then show_log "$log"; return 1; fi
}

# --- rosrun TOOL --help ------------------------------------------------------------
tool_help() {
  local tool=$1 setup=$ws/devel/setup.bash out rc
  [ -f "$setup" ] || { echo "    no $setup"; return 1; }
  out=$(pf_in_space "$setup" timeout 30 rosrun pf_localization "$tool" --help </dev/null 2>&1)
  rc=$?
  if [ "$rc" -ne 0 ] || ! grep -qi 'usage' <<<"$out"; then
    echo "    exit $rc$([ "$rc" -eq 124 ] && echo ' (timed out: waiting for a ROS master?)'):"
    head -n 8 <<<"$out" | sed 's/^/    /'
    return 1
  fi
}

# --- "Building it yourself": the user's own workspace ------------------------------------
user_ws() {
  local home=$tmp/user_home setup share out
  local uws=$home/catkin_ws
  mkdir -p "$uws/src"
  ln -s "$repo" "$uws/src/pf_localization"
  setup=$uws/devel/setup.bash
  # README: cd ~/catkin_ws; catkin_make; source devel/setup.bash. HOME is empty, so
  # scripts/build.sh's cache (~/.cache/pf_localization/...) is out of the tools' reach.
  # (The compiler cache is the test run's, not the empty home's: only the
  # time a clean build takes depends on it.)
  if ! (cd "$uws" && env -i HOME="$home" PATH=/usr/bin:/bin LANG=C.UTF-8 \
      ${CCACHE_DIR:+CCACHE_DIR=$CCACHE_DIR} catkin_make) \
      >"$tmp/user_ws_build.log" 2>&1; then
    show_log "$tmp/user_ws_build.log"; return 1
  fi
  share=$(HOME=$home pf_in_space "$setup" rospack find pf_localization)
  out=$(HOME=$home pf_in_space "$setup" rosrun pf_localization pf_tune --bags "$share/bags/small.bag" \
    --map "$share/maps/small.yaml" --initial-pose 2.5 2.6 0 --trials 2 --workers 1 --no-progress \
    --out "$tmp/tune" 2>&1) || { tail -n 20 <<<"$out" | sed 's/^/    /'; return 1; }
  [ -s "$tmp/tune/best.yaml" ] || { echo "    pf_tune wrote no best.yaml"; return 1; }
  grep '^pf_tune: wrote' <<<"$out" | sed 's/^/    /'
  out=$(HOME=$home pf_in_space "$setup" rosrun pf_localization benchmark_datasets 0 --no-plots \
    --data "$tmp/no_data" --out "$tmp/bench" 2>&1) || { tail -n 20 <<<"$out" | sed 's/^/    /'; return 1; }
  # Every run with this workspace's runner.
  if grep '^== ' <<<"$out" | grep -v " $uws/devel/lib/pf_localization/pf_bag_runner "; then
    echo "    (runs above not with $uws's pf_bag_runner)"; return 1
  fi
  tail -n 1 <<<"$out" | sed 's/^/    /'
  out=$(HOME=$home pf_in_space "$setup" rosrun pf_localization pf_evaluate \
    --traj "$tmp/bench/sim_tracking_default/traj.tum" --bag "$share/bags/tracking.bag" \
    --map "$share/maps/building.yaml" --out "$tmp/eval" 2>&1) || { sed 's/^/    /' <<<"$out"; return 1; }
}

wanted demo && check "demo: bash scripts/demo.sh builds every node and writes the report" demo
wanted bag_demo &&
  check "bag_demo: roslaunch bag_demo.launch rviz:=false: map -> odom on /tf, pf_status localized" bag_demo
if wanted help; then
  for tool in pf_evaluate pf_tune benchmark_datasets compare_scans.py \
              pf_bag_runner map_publisher pf_simulator pf_make_map pf_param_docs pf_node; do
    check "help $tool: rosrun pf_localization $tool --help, no ROS master" tool_help "$tool"
  done
fi
wanted user_ws &&
  check "user_ws: pf_tune, benchmark_datasets, pf_evaluate from a user's catkin_make workspace" user_ws

echo "$passed passed, $failed failed ($(($(date +%s) - t_start)) s)"
if [ "$failed" -eq 0 ] && [ "$keep" -eq 0 ]; then rm -rf "$tmp"; else echo "files in $tmp"; fi
[ "$failed" -eq 0 ]
