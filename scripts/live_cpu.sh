#!/usr/bin/env bash
# pf_node's live CPU on a real bag, next to what it cannot go below: the
# floor of its messages alone (bench/plumbing_floor_node.cc: tf and scans
# in, map -> odom and a pose out per scan, nothing else) and the same
# filter's work without ROS (pf_bag_runner, the same bag, particles and
# beams, an update on every scan, at the same pace).
#
# neato_ac109_1 from ../shared/data, replayed by ../shared/tools/run_localizer.sh
# in two modes: "wall" (WALL=1, the bag on the wall clock at 2x, as on a
# robot) and "sim" (simulated time, `rosbag play --clock` at 10x, as in a
# replay harness). 60 beams, an update on every scan, /particlecloud not
# subscribed. The runs of a round, each in each mode, in turn:
#   floor      pf_plumbing_floor
#   p10        pf_node with 10 fixed particles: its cost beyond the floor is fixed cost
#   kld        pf_node with the defaults (KLD, particles:=5000)
#   fixed5000  pf_node with 5000 fixed particles
#   runner_p10, runner_kld, runner_fixed5000  pf_bag_runner on the same bag
#              with the same particles, at the replay's pace: the filter's own
#              work (its updates and the map's set-up)
#   runner_fixed500, runner_fixed2000, runner_fixed10000  the same with 500,
#              2 000 and 10 000 fixed particles: how that work grows
# Prints a line per run: whole-process CPU s, the ATE RMSE for pf_node, and
# the CPU of each thread (pf_* are pf_node's own, named; main is the main
# spinner; the unnamed others are roscpp's: the poll thread is the busiest),
# then the medians and each pf_node run's cost above the floor (and above
# the floor plus the filter's own work). Not a test: the
# figures depend on the machine and on what else runs on it.
#
#   bash scripts/live_cpu.sh [ROUNDS]   (default 3; about 12 minutes a round)
# Environment: LIVE_CPU_MODES ("wall sim"), LIVE_CPU_RUNS (the run names
# above, default all), LIVE_CPU_WS (a built workspace to use as it is,
# instead of building the benchmark workspace), LIVE_CPU_OUT (output folder).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
rounds=${1:-3}
modes=${LIVE_CPU_MODES:-wall sim}
fixed_counts="500 2000 5000 10000"  # the runner_fixedN runs' particles
# shellcheck disable=SC2086 # the counts are words
runs=${LIVE_CPU_RUNS:-floor p10 kld fixed5000 runner_p10 runner_kld $(printf 'runner_fixed%s ' $fixed_counts)}
shared=$(cd "$repo/.." && pwd)/shared
data=$shared/data/neato_ac109_1
if [ ! -f "$data/ac109_1.bag" ] || [ ! -x "$shared/tools/run_localizer.sh" ]; then
  echo "live_cpu: skipped: needs $data/ac109_1.bag and $shared/tools/run_localizer.sh"
  exit 0
fi
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
if [ -n "${LIVE_CPU_WS:-}" ]; then
  ws=$LIVE_CPU_WS
else
  ws=$(pf_default_ws "$repo" bench)
  mkdir -p "$ws"
  PF_WS=$ws PF_CMAKE_ARGS="-DPF_BUILD_BENCHMARKS=ON -DCATKIN_ENABLE_TESTING=OFF" \
    bash "$repo/scripts/build.sh" pf_node map_publisher pf_plumbing_floor pf_bag_runner \
    >"$ws.build.log" 2>&1 ||
    { tail -30 "$ws.build.log"; echo "live_cpu: build failed (log: $ws.build.log)" >&2; exit 2; }
fi
export PATH=/usr/bin:$PATH
set +u  # ROS's setup scripts read unset variables
# shellcheck disable=SC1091
source "$ws/devel/setup.bash"
set -u
out=${LIVE_CPU_OUT:-$(mktemp -d /tmp/live_cpu.XXXXXX)}
mkdir -p "$out"
pose="initial_pose_x:=3.972 initial_pose_y:=-0.090 initial_pose_a:=2.904"
every_scan="update_min_d:=0 update_min_a:=0 max_beams:=60"

# threads PROCESS FILE: until PROCESS (its name in /proc, run from the
# workspace: other processes of the same name may run) has come and gone,
# writes the CPU seconds of each of its threads to FILE, twice a second.
threads() {
  /usr/bin/python3 - "$1" "$2" "$(cd "$ws" && pwd -P)" <<'EOF'
import os, sys, time
name, path, ws = sys.argv[1], sys.argv[2], sys.argv[3]
tick = os.sysconf('SC_CLK_TCK')
def started(p):  # clock ticks after boot
    stat = open('/proc/%s/stat' % p).read()
    return int(stat[stat.rindex(')') + 2:].split()[19])
me = started('self')
def find():  # one started after this sampler (not one left over from elsewhere)
    for p in os.listdir('/proc'):
        try:
            if (p.isdigit() and open('/proc/%s/comm' % p).read().strip() == name and
                    os.path.realpath('/proc/%s/exe' % p).startswith(ws + '/') and
                    started(p) >= me):
                return p
        except (OSError, ValueError):
            pass
seen, start, cpu = None, time.time(), {}  # cpu: tid -> [label, s], every thread ever seen
while time.time() - start < 300:
    pid = seen or find()
    if pid:
        seen = pid
        try:
            tids = os.listdir('/proc/%s/task' % pid)
        except OSError:
            break  # gone: the last figures stay
        for tid in tids:
            try:
                stat = open('/proc/%s/task/%s/stat' % (pid, tid)).read()
            except OSError:
                continue  # a thread that just ended keeps its last figure
            comm = stat[stat.index('(') + 1:stat.rindex(')')]
            f = stat[stat.rindex(')') + 2:].split()
            label = 'main' if tid == pid else ('ros' if comm == name else comm)
            cpu[tid] = [label, (int(f[11]) + int(f[12])) / tick]
        with open(path, 'w') as out:
            out.write(' '.join('%s %.2f' % tuple(cpu[t]) for t in sorted(cpu, key=int)) + '\n')
    time.sleep(0.5)
EOF
}

# replay MODE NAME PROCESS COMMAND: one replay; prints MODE NAME, the CPU of
# PROCESS, the ATE and the threads.
replay() {
  local mode=$1 name=$2 process=$3 command=$4 dir=$out/$1.$2.$r cpu ate="" wall=1 rate=2
  if [ "$mode" = sim ]; then
    wall=0 rate=10 command=${command//use_sim_time:=false/use_sim_time:=true}
  fi
  threads "$process" "$dir.threads" &
  local sampler=$!
  WALL=$wall "$shared/tools/run_localizer.sh" "$dir" "$data/ac109_1.yaml" "$data/ac109_1.bag" \
    "$rate" -- bash -c "$command" >"$dir.log" 2>&1
  # It ends by itself once the process is gone; one that never found it is stopped.
  for _ in 1 2 3 4; do kill -0 "$sampler" 2>/dev/null && sleep 0.5; done
  kill "$sampler" 2>/dev/null || true
  wait "$sampler" 2>/dev/null || true
  cpu=$(awk -v p="$process" '$1 == p {print $2}' "$dir/cpu_procs.txt")
  if [ "$process" = pf_node ]; then
    ate=$(/usr/bin/python3 "$shared/tools/ate.py" "$dir/out.bag" 2>/dev/null |
      /usr/bin/python3 -c "import json, sys; print('ATE %.4f m' % json.load(sys.stdin)['ate_rmse_m'])" ||
      echo "ATE ?")
  fi
  echo "$mode $name ${cpu:-?} s $ate | threads: $(cat "$dir.threads" 2>/dev/null)"
}

# runner NAME PARAMS...: pf_bag_runner on the bag with these parameters, in
# each mode at that mode's pace (--pace: the scans come as in the replay, so
# the caches are as cold at each update as pf_node's are; back to back, the
# same updates cost a half to a third of that on a virtual machine). Prints
# the filter's own work: the CPU of its updates plus the map's set-up, as
# the runner measures them (reading the bag stands for the messages, which
# are the floor's part), then the runner's whole-process CPU for reference.
runner() {
  local name=$1 dir mode rate cpu work
  shift
  for mode in $modes; do
    dir=$out/runner.$mode.$name.$r rate=2
    [ "$mode" = sim ] && rate=10
    mkdir -p "$dir"
    printf '%s\n' "update_min_d: 0" "update_min_a: 0" "$@" >"$dir/params.yaml"
    # The executable itself: rosrun would add its own start-up (a Python look-up).
    cpu=$(/usr/bin/python3 - "$dir" "$data" "$ws/devel/lib/pf_localization/pf_bag_runner" "$rate" <<'EOF'
import resource, subprocess, sys
d, data, runner, rate = sys.argv[1:5]
with open(d + '/runner.log', 'w') as log:
    subprocess.run([runner, '--bag', data + '/ac109_1.bag',
                    '--map', data + '/ac109_1.yaml', '--out', d + '/traj.tum', '--quiet',
                    '--initial-pose', '3.972', '-0.090', '2.904', '--max-beams', '60',
                    '--params', d + '/params.yaml', '--pace', rate],
                   stdout=log, stderr=log, check=True)
u = resource.getrusage(resource.RUSAGE_CHILDREN)
print('%.2f' % (u.ru_utime + u.ru_stime))
EOF
    )
    work=$(awk '/filter updates.*; CPU/ {for (i = 1; i <= NF; ++i) if ($i == "CPU") u = $(i + 1)}
                /map set-up CPU/ {s = $(NF - 1)}
                END {if (u != "" && s != "") printf "%.2f", u + s}' "$dir/runner.log")
    echo "$mode $name ${work:-?} s work | process $cpu s"
  done
}

has() { case " $runs " in *" $1 "*) return 0 ;; esac; return 1; }
launch="roslaunch pf_localization localization.launch map:=\$MAP_YAML use_sim_time:=false $pose $every_scan"
for r in $(seq "$rounds"); do
  for mode in $modes; do
    if has floor; then replay "$mode" floor pf_plumbing_flo "exec rosrun pf_localization pf_plumbing_floor"; fi
    if has p10; then replay "$mode" p10 pf_node "exec $launch particles:=10 min_particles:=10"; fi
    if has kld; then replay "$mode" kld pf_node "exec $launch particles:=5000"; fi
    if has fixed5000; then replay "$mode" fixed5000 pf_node "exec $launch particles:=5000 min_particles:=5000"; fi
  done
  if has runner_p10; then runner runner_p10 "max_particles: 10" "min_particles: 10"; fi
  if has runner_kld; then runner runner_kld "max_particles: 5000"; fi
  for n in $fixed_counts; do
    if has "runner_fixed$n"; then runner "runner_fixed$n" "max_particles: $n" "min_particles: $n"; fi
  done
done | tee "$out/runs.txt"

median() {
  awk -v m="$1" -v n="$2" '$1 == m && $2 == n && $3 != "?" {print $3}' "$out/runs.txt" | sort -n |
    awk '{v[NR] = $1} END {if (NR) printf "%.2f", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'
}
echo "medians over $rounds rounds (CPU s), and pf_node above the floor (+ the filter's own work):"
for mode in $modes; do
  floor=$(median "$mode" floor)
  for name in floor p10 kld fixed5000; do
    m=$(median "$mode" $name)
    [ -n "$m" ] || continue
    line=$(printf '  %-5s %-10s %5s s' "$mode" $name "$m")
    if [ -n "$floor" ] && [ $name != floor ]; then
      work=$(median "$mode" runner_$name)
      line+=$(awk -v m="$m" -v f="$floor" -v w="${work:-0}" 'BEGIN {
        printf "   above the floor %+.0f %%; floor + filter work %.2f s: %+.0f %%",
          100 * (m / f - 1), f + w, 100 * (m / (f + w) - 1)}')
    fi
    echo "$line"
  done
done
echo "the filter's own work at the replay's pace, fixed particles (pf_bag_runner, CPU s):"
for mode in $modes; do
  line=$(printf '  %-5s' "$mode")
  for n in $fixed_counts; do
    m=$(median "$mode" "runner_fixed$n")
    if [ -n "$m" ]; then line+=$(printf "   %5d: %s s" "$n" "$m"); fi
  done
  echo "$line"
done
echo "runs in $out"
