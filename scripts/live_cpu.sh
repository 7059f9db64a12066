#!/usr/bin/env bash
# Issue 17's live measurement: whole-process CPU seconds of pf_node on a real
# bag, next to the floor of its messages alone (bench/plumbing_floor_node.cc:
# tf and scans in, map -> odom and a pose out per scan, nothing else).
#
# neato_ac109_1 from ../shared/data, replayed by ../shared/tools/run_localizer.sh
# on the wall clock (WALL=1: under simulated time every roscpp node polls
# /clock at 1 kHz) at 2x, 60 beams, an update on every scan, /particlecloud
# not subscribed. Each round runs, in turn: the floor, pf_node with the
# defaults (KLD, particles:=5000) and pf_node with 5000 fixed particles.
# Prints a line per run (CPU s, and ATE RMSE m for pf_node) and the medians.
# Builds in the benchmark workspace (scripts/benchmark.sh's). Not a test: the
# figures depend on the machine and on what else runs on it.
#
#   bash scripts/live_cpu.sh [ROUNDS]  (default 3; about 4 minutes a round)
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
rounds=${1:-3}
shared=$(cd "$repo/.." && pwd)/shared
data=$shared/data/neato_ac109_1
if [ ! -f "$data/ac109_1.bag" ] || [ ! -x "$shared/tools/run_localizer.sh" ]; then
  echo "live_cpu: skipped: needs $data/ac109_1.bag and $shared/tools/run_localizer.sh"
  exit 0
fi
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo" bench)
mkdir -p "$ws"
PF_WS=$ws PF_CMAKE_ARGS="-DPF_BUILD_BENCHMARKS=ON -DCATKIN_ENABLE_TESTING=OFF" \
  bash "$repo/scripts/build.sh" pf_node map_publisher pf_plumbing_floor >"$ws.build.log" 2>&1 ||
  { tail -30 "$ws.build.log"; echo "live_cpu: build failed (log: $ws.build.log)" >&2; exit 2; }
export PATH=/usr/bin:$PATH
set +u  # ROS's setup scripts read unset variables
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u
out=$(mktemp -d /tmp/live_cpu.XXXXXX)
launch="roslaunch pf_localization localization.launch map:=\$MAP_YAML use_sim_time:=false \
initial_pose_x:=3.972 initial_pose_y:=-0.090 initial_pose_a:=2.904 \
update_min_d:=0 update_min_a:=0 max_beams:=60"

# run NAME PROCESS COMMAND: one replay; prints NAME, the CPU of PROCESS and the ATE.
run() {
  local name=$1 process=$2 command=$3 dir=$out/$1.$r cpu ate=""
  WALL=1 "$shared/tools/run_localizer.sh" "$dir" "$data/ac109_1.yaml" "$data/ac109_1.bag" 2 -- \
    bash -c "$command" >"$dir.log" 2>&1
  cpu=$(awk -v p="$process" '$1 == p {print $2}' "$dir/cpu_procs.txt")
  if [ "$process" = pf_node ]; then
    ate=$(/usr/bin/python3 "$shared/tools/ate.py" "$dir/out.bag" 2>/dev/null |
      /usr/bin/python3 -c "import json, sys; print('ATE %.4f m' % json.load(sys.stdin)['ate_rmse_m'])" ||
      echo "ATE ?")
  fi
  echo "$name ${cpu:-?} s $ate"
}

for r in $(seq "$rounds"); do
  run floor pf_plumbing_flo "exec rosrun pf_localization pf_plumbing_floor"
  run kld pf_node "exec $launch particles:=5000"
  run fixed5000 pf_node "exec $launch particles:=5000 min_particles:=5000"
done | tee "$out/runs.txt"
echo "medians over $rounds rounds (CPU s):"
for name in floor kld fixed5000; do
  awk -v n=$name '$1 == n {print $2}' "$out/runs.txt" | sort -n |
    awk -v n=$name '{v[NR] = $1} END {m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2; printf "  %-10s %.2f\n", n, m}'
done
echo "runs in $out"
