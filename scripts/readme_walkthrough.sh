#!/usr/bin/env bash
# README.md followed as a new user follows it, from a clean build, each step
# checked. The commands are read from the README's own code blocks (a line
# that starts as below, with its continuation lines) and run as written, in
# the repository, in a shell with nothing sourced; a check fails when the
# README no longer has its command.
#
#   demo        "Two commands": `bash scripts/demo.sh`, in a workspace built
#               from nothing (build.sh's default folder, under a cache folder
#               of its own); exit 0 and a report with summary.json and its
#               plots. (`bash scripts/test.sh`, the other command, is what
#               runs this walkthrough.)
#   own_bag     "Localizing a bag of your own": its `bash scripts/demo.sh
#               --bag ...` commands; exit 0 and a summary.json each. The
#               real robot's bag without a reference (../shared/data, skipped
#               with a message when absent): fit.png, scans.png and a
#               verdict of localized, as the README says.
#   bag_demo    "Live, with roslaunch and rviz": `export PATH=...`, `source
#               "$(bash scripts/build.sh --where)/devel/setup.bash"` and
#               `roslaunch pf_localization bag_demo.launch` with rviz:=false
#               (the README's variant without a display), on a roscore port of
#               its own: pf_node publishes map -> odom on /tf and pf_status
#               reaches "localized"; then stopped.
#   live        the same section's `roslaunch pf_localization
#               localization.launch ...`, then its `rosbag play --clock ...`
#               as from a second shell: the same two conditions.
#   manual      "Read on": `mkdocs build --strict -d /tmp/pf_manual`; exit 0
#               and an index.html.
#   help TOOL   rosrun pf_localization TOOL --help for every installed tool
#               (the Python tools and the nodes), with no ROS master to be had:
#               exit 0 and a usage text, within 30 s (docs/tools.md).
#   user_ws     docs/getting-started.md, "Building it yourself": a catkin
#               workspace of the user's (its src/ links to the repository;
#               catkin_make; source devel/setup.bash), not scripts/build.sh's,
#               whose cache is out of reach (HOME is empty): rosrun pf_tune
#               (small.bag, 2 trials, 1 worker), benchmark_datasets (the
#               bundled bags) and pf_evaluate must find that workspace's
#               pf_bag_runner and finish.
#
#   bash scripts/readme_walkthrough.sh [--keep] [CHECK ...]
#
# CHECK: demo, own_bag, bag_demo, live, manual, help, user_ws (default: all,
# in that order; own_bag, bag_demo, live and help use the workspace demo
# builds, manual and user_ws need nothing before them).
#
# Prints one "[check] NAME: ok/FAILED" line per check, then "N passed, N
# failed"; exits 1 if any check failed. Everything it makes (the two
# workspaces, logs, outputs) is in one temporary folder, removed at the end
# unless --keep (or a failure) says otherwise; demo.sh writes its reports to
# reports/ as it does for a user, and the manual goes to /tmp/pf_manual, as
# the README says. Two builds from scratch: about 10 minutes on a shared
# two-core machine (load 4).
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
keep=0 only=()
while [ $# -gt 0 ]; do
  case $1 in
    --keep) keep=1; shift ;;
    -h | --help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    demo | own_bag | bag_demo | live | manual | help | user_ws) only+=("$1"); shift ;;
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
# No master listens here: a tool that needs one fails (or hangs until its timeout).
no_master_port=$(pf_free_port)
export ROS_MASTER_URI=http://localhost:$no_master_port

passed=0 failed=0
check() {  # check NAME COMMAND...: one line per check, as scripts/test.sh prints
  local name=$1; shift
  if "$@"; then echo "[check] $name: ok"; passed=$((passed + 1))
  else echo "[check] $name: FAILED"; failed=$((failed + 1)); fi
}
show_log() { tail -n "${2:-20}" "$1" | sed 's/^/    /'; echo "    (log: $1)"; }

# readme_cmd PREFIX: the README's command (in a ```bash block) whose first line
# starts with PREFIX, its continuation lines joined; nothing and status 1 if
# the README has none.
readme_cmd() {
  /usr/bin/python3 - "$repo/README.md" "$1" <<'PY'
import re, sys
text, prefix = open(sys.argv[1]).read(), sys.argv[2]
for block in re.findall(r'```bash\n(.*?)```', text, re.S):
    lines = block.split('\n')
    for i, line in enumerate(lines):
        if line.startswith(prefix):
            cmd = [line]
            while cmd[-1].rstrip().endswith('\\') and i + 1 < len(lines):
                i += 1
                cmd.append(lines[i])
            print('\n'.join(cmd))
            sys.exit(0)
print('    README.md has no command starting with: %s' % prefix, file=sys.stderr)
sys.exit(1)
PY
}
# as_user CMD: CMD (a shell command line) in the repository, as a new user's
# shell runs it: nothing sourced, only the walkthrough's cache, ROS home and
# master port set.
as_user() {
  (cd "$repo" && env -i HOME="${HOME:-/tmp}" PATH=/usr/bin:/bin LANG=C.UTF-8 \
    XDG_CACHE_HOME="$XDG_CACHE_HOME" CCACHE_DIR="$CCACHE_DIR" ROS_HOME="$ROS_HOME" \
    ROS_LOG_DIR="$ROS_LOG_DIR" ROS_MASTER_URI="$ROS_MASTER_URI" bash -c "$1")
}

# --- "Two commands" -------------------------------------------------------------
demo() {
  local log=$tmp/demo.log report cmd
  cmd=$(readme_cmd 'bash scripts/demo.sh    #') || return 1
  # As a new user's shell runs it: no workspace sourced (a sourced one would
  # put its devel space on the include path, and the build would differ).
  if ! as_user "$cmd" >"$log" 2>&1; then
    show_log "$log"; return 1
  fi
  report=$(sed -n 's/^demo: report in //p' "$log")
  for f in summary.json trajectory.png error.png spread.png cpu.png particles.gif; do
    [ -s "$report/$f" ] || { echo "    no $report/$f"; show_log "$log"; return 1; }
  done
  grep -E '^ +position error' "$log" | sed 's/^ */    /'
  return 0
}

# --- "Localizing a bag of your own" -----------------------------------------------
own_bag() {
  local prefix cmd log report n=0
  local real=../shared/data/comprobo_mac_first_floor_take_2
  for prefix in 'bash scripts/demo.sh --bag bags/crowd.bag' 'bash scripts/demo.sh --bag bags/two_lidar.bag' \
    "bash scripts/demo.sh --bag $real/"; do
    n=$((n + 1))
    log=$tmp/own_bag_$n.log
    cmd=$(readme_cmd "$prefix") || return 1
    if [ "$prefix" = "bash scripts/demo.sh --bag $real/" ] && [ ! -d "$repo/$real" ]; then
      echo "    $real is not beside the repository: its example skipped"
      continue
    fi
    as_user "$cmd" >"$log" 2>&1 || { show_log "$log"; return 1; }
    report=$(sed -n 's/^demo: report in //p' "$log")
    [ -s "$report/summary.json" ] || { echo "    no $report/summary.json"; show_log "$log"; return 1; }
    if grep -q '^pf_evaluate: no reference' "$log"; then
      # Without a reference: what the filter itself knows, with its pictures.
      for f in fit.png scans.png trajectory.png; do
        [ -s "$report/$f" ] || { echo "    no $report/$f"; show_log "$log"; return 1; }
      done
      echo "    $(head -n 1 <<<"$cmd" | cut -c1-70)...:"
      grep -E '^ +(beams fit|verdict):' "$log" | sed 's/^ */      /'
      # The README says it was localized (at every update but the first).
      grep -qE '^ +verdict: +localized' "$log" || { echo "    not localized"; return 1; }
    else
      echo "    $(head -n 1 <<<"$cmd" | cut -c1-70)...: $(grep -E '^ +position error' "$log" | sed 's/^ *//')"
    fi
  done
}

# --- "Read on": the manual -----------------------------------------------------------
manual() {
  local cmd log=$tmp/manual.log
  cmd=$(readme_cmd 'mkdocs build --strict') || return 1
  as_user "$cmd" >"$log" 2>&1 || { show_log "$log"; return 1; }
  [ -s /tmp/pf_manual/index.html ] || { echo "    no /tmp/pf_manual/index.html"; show_log "$log"; return 1; }
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
# user_session FILE: the shell script FILE run as as_user runs a command, in a
# session of its own (setsid, exec'ed: $! of `user_session FILE &` is the
# session's id, and kill -- -ID stops everything in it).
user_session() {
  local file=$1
  cd "$repo" && exec setsid env -i HOME="${HOME:-/tmp}" PATH=/usr/bin:/bin LANG=C.UTF-8 \
    XDG_CACHE_HOME="$XDG_CACHE_HOME" CCACHE_DIR="$CCACHE_DIR" ROS_HOME="$ROS_HOME" \
    ROS_LOG_DIR="$ROS_LOG_DIR" ROS_MASTER_URI="$ROS_MASTER_URI" bash "$file"
}

# live_run NAME LAUNCH [PLAY]: the README's `export PATH`, `source ...setup.bash`
# and LAUNCH (a roslaunch command line) in a session of their own, on a free
# master port (roslaunch starts its roscore on ROS_MASTER_URI's port); then
# PLAY (a rosbag play command line), as from a second shell with the same
# setup.bash; pf_node must send map -> odom and say "localized" within 120 s.
# Both are stopped after.
live_run() {
  local name=$1 launch=$2 play=${3:-} log=$tmp/$1.log port pid play_pid rc prelude setup=$ws/devel/setup.bash
  [ -f "$setup" ] || { echo "    no $setup"; return 1; }
  prelude="$(readme_cmd 'export PATH=/usr/bin:$PATH')"$'\n'"$(readme_cmd 'source "$(bash scripts/build.sh --where)')" ||
    return 1
  port=$(pf_free_port)
  printf '%s\nexec timeout -s TERM 300 %s\n' "$prelude" "$launch" >"$tmp/$name.sh"
  ROS_MASTER_URI=http://localhost:$port user_session "$tmp/$name.sh" >"$log" 2>&1 &
  pid=$!
  for _ in $(seq 30); do  # roslaunch starts its roscore first
    ROS_MASTER_URI=http://localhost:$port pf_in_space "$setup" rostopic list >/dev/null 2>&1 && break
    sleep 1
  done
  if [ -n "$play" ]; then
    printf '%s\nexec timeout -s TERM 200 %s\n' "$prelude" "$play" >"$tmp/${name}_play.sh"
    ROS_MASTER_URI=http://localhost:$port user_session "$tmp/${name}_play.sh" >"$tmp/${name}_play.log" 2>&1 &
    play_pid=$!
  fi
  ROS_MASTER_URI=http://localhost:$port pf_in_space "$setup" timeout 150 \
    /usr/bin/python3 "$tmp/live_listener.py" 120 >"$tmp/${name}_listener.out" 2>&1
  rc=$?
  [ -n "${play_pid:-}" ] && { kill -TERM -- "-$play_pid" 2>/dev/null; wait "$play_pid"; }
  kill -TERM -- "-$pid" 2>/dev/null
  wait "$pid"
  sed 's/^/    /' "$tmp/${name}_listener.out" | tail -n 5
  if [ "$rc" -ne 0 ] || grep -qE 'cannot launch|Cannot locate|ERROR' "$log"; then show_log "$log"; return 1; fi
}

bag_demo() {
  local launch
  launch=$(readme_cmd 'roslaunch pf_localization bag_demo.launch') || return 1
  # The README's rviz:=true needs a display; its variant without one:
  live_run bag_demo "${launch/rviz:=true/rviz:=false}"
}

live() {
  local launch play
  launch=$(readme_cmd 'roslaunch pf_localization localization.launch') || return 1
  play=$(readme_cmd 'rosbag play --clock') || return 1
  live_run live "$launch" "$play"
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
wanted own_bag && check "own_bag: the README's demo.sh --bag commands write their reports, with a reference or without" own_bag
wanted bag_demo &&
  check "bag_demo: roslaunch bag_demo.launch rviz:=false: map -> odom on /tf, pf_status localized" bag_demo
wanted live &&
  check "live: roslaunch localization.launch and rosbag play --clock: map -> odom on /tf, pf_status localized" live
wanted manual && check "manual: mkdocs build --strict -d /tmp/pf_manual" manual
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
