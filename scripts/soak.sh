#!/usr/bin/env bash
# Long-run check of pf_node: memory must not grow and updates must keep coming.
#
#   bash scripts/soak.sh [SIM_SECONDS]        # default 3600 s of simulated time
#
# Starts a private roscore (a free port, its own ROS_LOG_DIR), then
# `roslaunch pf_localization localization.launch` (map_publisher + pf_node,
# use_sim_time) with the bag's map and start pose, and plays the bag with
# `rosbag play --clock --loop -r RATE` until SIM_SECONDS of simulated time
# have passed (time that runs backwards when the bag loops is not counted).
# pf_node's resident memory (VmRSS) is sampled every second and printed every
# 10 s of wall time, with the number of pf_pose messages so far.
#
# Passes (exit 0) when pf_node is still alive at the end, pf_pose messages
# still arrived during the last tenth of the run, and the final RSS is
# within 5 % of the RSS at 300 s of simulated time. Prints pf_node's
# warnings, grouped, at the end.
#
# Environment: PF_WS (workspace with pf_node built; default: scripts/build.sh's),
# PF_SOAK_BAG, PF_SOAK_MAP, PF_SOAK_POSE ("x y yaw"; default: bags/<bag>.start
# if present, else the bundled tracking bag's start pose from bags/README.md),
# PF_SOAK_RATE (default 20), PF_SOAK_ARGS (extra roslaunch arguments),
# PF_SOAK_KEEP=1 to keep the log folder.
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
sim_seconds=${1:-3600}
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
bag=${PF_SOAK_BAG:-$repo/bags/tracking.bag}
map=${PF_SOAK_MAP:-$repo/maps/building.yaml}
rate=${PF_SOAK_RATE:-20}
if [ -n "${PF_SOAK_POSE:-}" ]; then
  pose=$PF_SOAK_POSE
elif [ -f "${bag%.bag}.start" ]; then
  pose=$(grep -v '^#' "${bag%.bag}.start" | head -1)
else
  pose="1.5 7.6 0"  # tracking.bag, bags/README.md
fi
read -r px py pa <<<"$pose"
mark=300  # s of simulated time at which the reference RSS is taken

export PATH=/usr/bin:$PATH
pf_source_workspace "$ws" soak || exit 2

tmp=$(mktemp -d /tmp/pf_soak.XXXXXX)
port=$(pf_free_port) || exit 2
export ROS_MASTER_URI=http://localhost:$port
export ROS_LOG_DIR=$tmp/log ROS_HOME=$tmp/home
echo "soak: bag $bag (rate x$rate, looped), map $map, start ($px, $py, $pa)"
echo "soak: $sim_seconds s of simulated time; roscore on port $port; logs in $tmp"

pids=()
cleanup() {
  # Only what this script started, newest first, by pid.
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -INT "${pids[i]}" 2>/dev/null; done
  sleep 3
  for ((i = ${#pids[@]} - 1; i >= 0; i--)); do kill -KILL "${pids[i]}" 2>/dev/null; done
  wait 2>/dev/null
  [ "${PF_SOAK_KEEP:-0}" = 1 ] || [ "${keep_logs:-0}" = 1 ] || rm -rf "$tmp"
}
trap cleanup EXIT

roscore -p "$port" >"$tmp/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do rosparam list >/dev/null 2>&1 && break; sleep 0.2; done
rosparam set /use_sim_time true

# shellcheck disable=SC2086
roslaunch --wait pf_localization localization.launch map:="$map" use_sim_time:=true \
  initial_pose_x:="$px" initial_pose_y:="$py" initial_pose_a:="$pa" ${PF_SOAK_ARGS:-} \
  >"$tmp/launch.log" 2>&1 &
launch_pid=$!
pids+=($launch_pid)

# pf_node's pid: the launch's child running the pf_node binary.
node_pid=""
for _ in $(seq 100); do
  node_pid=$(ps --ppid "$launch_pid" -o pid=,args= | awk '$2 ~ /\/pf_node$/ {print $1}' | head -1)
  [ -n "$node_pid" ] && break
  sleep 0.2
done
if [ -z "$node_pid" ]; then
  keep_logs=1
  echo "soak: pf_node did not start; launch log:" >&2
  tail -30 "$tmp/launch.log" >&2
  exit 1
fi

# Counts simulated time (forward steps of /clock only) and pf_pose messages.
cat >"$tmp/monitor.py" <<'EOF'
import sys, rospy
from rosgraph_msgs.msg import Clock
from geometry_msgs.msg import PoseWithCovarianceStamped
state = {"last": None, "sim": 0.0, "poses": 0, "jumps": 0}
def on_clock(m):
    t = m.clock.to_sec()
    if state["last"] is not None:
        d = t - state["last"]
        if d > 0: state["sim"] += d
        elif d < 0: state["jumps"] += 1
    state["last"] = t
def on_pose(_):
    state["poses"] += 1
rospy.init_node("soak_monitor", disable_signals=True)
rospy.Subscriber("/clock", Clock, on_clock, queue_size=100)
rospy.Subscriber("/pf_pose", PoseWithCovarianceStamped, on_pose, queue_size=100)
out = sys.argv[1]
while True:
    with open(out + ".tmp", "w") as f:
        f.write("%.1f %d %d\n" % (state["sim"], state["poses"], state["jumps"]))
    import os; os.replace(out + ".tmp", out)
    rospy.rostime.wallsleep(0.5)
EOF
/usr/bin/python3 "$tmp/monitor.py" "$tmp/progress" >"$tmp/monitor.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -f "$tmp/progress" ] && break; sleep 0.2; done
sleep 2  # the map, pf_node's subscriptions

rosbag play --clock --loop -q -r "$rate" "$bag" >"$tmp/play.log" 2>&1 &
play_pid=$!
pids+=($play_pid)

# VmRSS, then its anonymous (heap, stacks) and file-backed (code, mapped
# files) parts, in kB, from one read of the status file; nothing once the
# process is gone.
rss() {
  awk '/^VmRSS/ {r = $2} /^RssAnon/ {a = $2} /^RssFile/ {f = $2}
       END {if (r != "") print r, a + 0, f + 0}' "/proc/$1/status" 2>/dev/null
}
start=$(date +%s)
rss_mark=""
died=0
last_print=0
samples=$tmp/samples.txt
: >"$samples"
printf 'soak: %6s %8s %10s %10s %10s %8s %6s\n' wall_s sim_s rss_kB anon_kB file_kB pf_pose loops
while :; do
  sleep 1
  now=$(($(date +%s) - start))
  read -r sim poses jumps <"$tmp/progress" 2>/dev/null || continue
  read -r r anon file <<<"$(rss "$node_pid")"
  if [ -z "$r" ]; then
    died=1
    echo "soak: pf_node (pid $node_pid) died at ${sim} s of simulated time"
    break
  fi
  echo "$now $sim $r $poses $jumps $anon $file" >>"$samples"
  if [ -z "$rss_mark" ] && awk -v s="$sim" -v m="$mark" 'BEGIN {exit !(s >= m)}'; then
    rss_mark=$r
    cp "/proc/$node_pid/smaps" "$tmp/smaps.mark" 2>/dev/null
  fi
  if [ $((now - last_print)) -ge 10 ]; then
    printf 'soak: %6d %8.0f %10d %10d %10d %8d %6d\n' "$now" "$sim" "$r" "$anon" "$file" "$poses" "$jumps"
    last_print=$now
  fi
  awk -v s="$sim" -v e="$sim_seconds" 'BEGIN {exit !(s >= e)}' && break
  if ! kill -0 "$play_pid" 2>/dev/null; then
    echo "soak: rosbag play exited early"
    break
  fi
done

read -r sim_end poses_end jumps_end <"$tmp/progress"
cp "/proc/$node_pid/smaps" "$tmp/smaps.end" 2>/dev/null
rss_end=$(tail -1 "$samples" | awk '{print $3}')
wall=$(($(date +%s) - start))
# pf_pose messages in the last tenth of the simulated time.
recent=$(awk -v e="$sim_end" '$2 >= 0.9 * e {if (first == "") first = $4; last = $4}
  END {print (last == "" ? 0 : last - first)}' "$samples")

echo "soak: ---"
echo "soak: $sim_end s simulated in $wall s wall; the bag looped $jumps_end times"
echo "soak: pf_pose messages: $poses_end in total, $recent in the last tenth of the run"
echo "soak: pf_node RSS: ${rss_mark:-n/a} kB at ${mark} s simulated, ${rss_end:-n/a} kB at the end"
# Every scan pf_node could not use is logged, or counted on the next line of
# its kind ("N more like it"): their sum is the number of scans dropped.
drop_lines=$(sed -E 's/\x1b\[[0-9;]*m//g' "$tmp/launch.log" | grep -aE 'pf_node: scan (dropped|not used|ignored)')
dropped=$(( $(printf '%s\n' "$drop_lines" | grep -c . || true) +
  $(printf '%s\n' "$drop_lines" | grep -oE '\([0-9]+ more like it' | tr -dc '0-9\n' | awk '{s += $1} END {print s + 0}') ))
echo "soak: scans pf_node dropped and said so: $dropped"
echo "soak: pf_node warnings and errors (count, first text):"
sed -E 's/\x1b\[[0-9;]*m//g' "$tmp/launch.log" | grep -aoE '\[ *(WARN|ERROR|FATAL)\].*' |
  sed -E 's/\[[0-9.]+(, [0-9.]+)?\]: //' |
  sed -E 's/t=[0-9.]+/t=.../; s/[0-9]+\.[0-9]+/N/g' | sort | uniq -c | sort -rn | head -15 |
  sed 's/^/  /'

ok=1
if [ "$died" = 1 ] || ! kill -0 "$node_pid" 2>/dev/null; then
  echo "soak: FAIL: pf_node died"; ok=0
  keep_logs=1
  tail -20 "$tmp/launch.log"
fi
if [ -z "$rss_mark" ] || [ -z "$rss_end" ]; then
  echo "soak: FAIL: the run did not reach ${mark} s of simulated time"; ok=0
else
  pct=$(awk -v a="$rss_mark" -v b="$rss_end" 'BEGIN {printf "%.1f", 100 * (b - a) / a}')
  if awk -v p="$pct" 'BEGIN {exit !(p <= 5 && p >= -5)}'; then
    echo "soak: RSS at the end is within 5 % of the ${mark} s value ($pct %)"
  else
    echo "soak: FAIL: RSS at the end is $pct % off the ${mark} s value"; ok=0
  fi
fi
if [ "$recent" -le 0 ]; then
  echo "soak: FAIL: no pf_pose message in the last tenth of the run"; ok=0
fi
if [ "$ok" = 1 ]; then echo "soak: PASS"; else keep_logs=1; echo "soak: logs kept in $tmp"; fi
[ "$ok" = 1 ]
