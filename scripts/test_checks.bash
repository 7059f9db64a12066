# Sourced by scripts/test.sh: its checks, one function each (0: passed). They
# read $repo (the repository) and $ws (the built workspace).
#
# Replays of the bundled bags and the real recordings with pf_bag_runner
# (deterministic for a seed, so a loaded machine changes no figure):
#   warehouse_global warehouse_global_default warehouse_kidnap
#   corridor_small_budget close_updates changed_worlds_check real_recordings
# The package as catkin and Debian see it:
#   catkin_lint_clean install_space make_deb
# The sources:
#   core_is_ros_free clang_format_clean no_long_functions
# The documentation:
#   docs_build (the manual, strict, its links and anchors)
#   results_tables_current (README's and docs/results.md's tables against a fresh benchmark run)
# The Python unit tests: python_unit_tests (writes "PASSED FAILED" to $1).

# --- Replays of the bundled bags with pf_bag_runner (deterministic for a seed) ---
# bag_run DIR BAG MAP MAX_GAP RUNNER_ARGS...: pf_bag_runner on BAG and MAP
# into DIR (deterministic for a seed), then pf_evaluate into DIR/eval (a
# reference pose matched within MAX_GAP s), with the published covariance's
# honesty.
bag_run() {
  local dir=$1 bag=$2 map=$3 max_gap=$4 lib="$ws/devel/lib/pf_localization"
  shift 4
  rm -rf "$dir" && mkdir -p "$dir"
  "$lib/pf_bag_runner" --bag "$bag" --map "$map" "$@" --out "$dir/traj.tum" \
    --log "$dir/updates.csv" --hypotheses "$dir/hypotheses.csv" --covariance "$dir/cov.csv" \
    --quiet >"$dir/runner.log" 2>&1 ||
    { tail -n 5 "$dir/runner.log"; return 1; }
  /usr/bin/python3 "$lib/pf_evaluate" --traj "$dir/traj.tum" --bag "$bag" --map "$map" \
    --log "$dir/updates.csv" --hypotheses "$dir/hypotheses.csv" --cov "$dir/cov.csv" \
    --max-gap "$max_gap" --out "$dir/eval" --no-plots >"$dir/eval.log" 2>&1 ||
    { tail -n 5 "$dir/eval.log"; return 1; }
}

# warehouse_run DIR BAG RUNNER_ARGS...: bag_run on maps/warehouse.yaml.
warehouse_run() {
  local dir=$1 bag=$2
  shift 2
  bag_run "$dir" "$bag" maps/warehouse.yaml 0.5 "$@"
}

# warehouse_seeds DIR BAG RUNNER_ARGS...: warehouse_run for seeds 1-10, into
# DIR/seed1 ... DIR/seed10.
warehouse_seeds() {
  local dir=$1 bag=$2 seed
  shift 2
  for seed in 1 2 3 4 5 6 7 8 9 10; do
    warehouse_run "$dir/seed$seed" "$bag" --seed $seed "$@" || return 1
  done
}

# Global localization with a million particles (seed 2): never "localized" at
# the wrong place, and the true place among the published hypotheses (within
# 1 m of one's mean or inside its 95 % ellipse) in every update. Without
# GlobalSearch (the smoothed likelihood, then the settling), seed 1: 57
# updates confidently wrong, the truth listed in 59 %; with 32 hypotheses
# listed instead of 64, seed 2 misses it in 2 updates. About 10 s.
warehouse_global() {
  local out="$ws/warehouse_global"
  warehouse_run "$out" bags/warehouse_global.bag --seed 2 --particles 1000000 || return 1
  /usr/bin/python3 - "$out/eval/summary.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
wrong, share = d['confidently_wrong_updates'], d['hypotheses']['contain_truth_share']
print('warehouse_global.bag, 1 000 000 particles, seed 2: %d updates confidently wrong, '
      'the truth among the hypotheses in %.1f %% of %d' % (wrong, 100 * share, d['hypotheses']['updates']))
# Every update: with 32 listed (before 64), seed 2 left the truth off in 2.
sys.exit(0 if wrong == 0 and share == 1.0 else 1)
PY
}

# The same at the default budget (50 000), seeds 1-10: never "localized" at
# the wrong place; the true place among the hypotheses in at least 99.9 %
# of the updates (one miss in 2 500); and "localized" (so, at the right
# place) within 10 s of the first scan that tells the aisles apart (34.1 s,
# README), by 44.1 s. Such a cloud may hold the true aisle only a rack bay
# or two from the truth: with the look-alikes of the estimate alone listed,
# not those of every place the cloud holds, seeds 2, 4 and 8 left the truth
# off in 10 updates between 0.9 and 1.7 s (99.6 %). While the fit had to be
# below the usual one too before a better look-alike got a copy of the
# cloud, seeds 4 and 8 were localized only at 45.9 and 44.3 s. And the
# published covariance covers the look-alikes until a scan tells the place
# apart (ConfidenceTracker::coverLookAlikes), and the map's error once it is
# told apart (ScanRefiner::mapErrorCovariance): each seed has 85-99 % of the
# reference poses inside its 95 % ellipse (90.4-93.4 % today) and a NEES
# mean of at most 5 (2.2-2.8). While it was one aisle's, 33-77 % and up to
# 8e5 (7 seeds over 3e4), the cloud alone in a wrong twin aisle saying 1 cm;
# without the map's error, 72-77 %, the simulator's walls half a cell nearer
# than the map's and the fit saying 1 cm. About 30 s.
warehouse_global_default() {
  local out="$ws/warehouse_global_default"
  warehouse_seeds "$out" bags/warehouse_global.bag || return 1
  /usr/bin/python3 - "$out" <<'PY'
import csv, json, sys
runs = [json.load(open('%s/seed%d/eval/summary.json' % (sys.argv[1], s))) for s in range(1, 11)]
def localized_at(seed, start):
    for row in csv.DictReader(open('%s/seed%d/updates.csv' % (sys.argv[1], seed))):
        if row['state'] == 'localized':
            return float(row['t']) - start
    return float('inf')
BY = 44.1  # s: 10 s after the first scan that tells the aisles apart
localized = [localized_at(s + 1, d['reference_start_s']) for s, d in enumerate(runs)]
wrong = sum(d['confidently_wrong_updates'] for d in runs)
updates = sum(d['hypotheses']['updates'] for d in runs)
listed = sum(d['hypotheses']['contain_truth_share'] * d['hypotheses']['updates'] for d in runs)
misses = ['seed %d at %s s' % (s + 1, ', '.join('%.2f' % t for t in d['hypotheses']['misses_s']))
          for s, d in enumerate(runs) if d['hypotheses']['misses_s']]
inside = [d['covariance']['inside_95_percent'] for d in runs]
nees = [d['covariance']['nees_mean'] for d in runs]
print('warehouse_global.bag, 50 000 particles, seeds 1-10: %d updates confidently wrong, the truth '
      'among the hypotheses in %.2f %% of %d (missed: %s), localized at %s s (bound %.1f s); '
      'inside the published 95 %% ellipse %.1f-%.1f %% (bounds 85-99), NEES mean %.2f-%.2f (bound 5)'
      % (wrong, 100 * listed / updates, updates, '; '.join(misses) or 'none',
         ', '.join('%.1f' % t for t in localized), BY, min(inside), max(inside), min(nees), max(nees)))
sys.exit(0 if wrong == 0 and listed >= 0.999 * updates and max(localized) <= BY
         and min(inside) >= 85 and max(inside) <= 99 and max(nees) <= 5 else 1)
PY
}

# Kidnapped into the twin aisle: the default budget, seeds 1-10, never
# "localized" wrong, and back within 0.3 m for good by 84.5 s, 10 s after the
# scans first fit the twin clearly better (74.5 s, docs/design.md, "Look-alike
# places"). With each look-alike given a share of the survivors instead of a
# copy of them, seed 8 lost the twin on the next scan and was back only at
# 87.5 s. About 20 s.
warehouse_kidnap() {
  local out="$ws/warehouse_kidnap"
  warehouse_seeds "$out" bags/warehouse_kidnap.bag --initial-pose 5.0 6.0 1.5707963 || return 1
  /usr/bin/python3 - "$out" <<'PY'
import json, sys
runs = [json.load(open('%s/seed%d/eval/summary.json' % (sys.argv[1], s))) for s in range(1, 11)]
back = [d['convergence_time_s'] for d in runs]
wrong = sum(d['confidently_wrong_updates'] for d in runs)
print('warehouse_kidnap.bag, seeds 1-10: back within 0.3 m for good at %s s (bound 84.5 s); '
      '%d updates confidently wrong' % (', '.join('%.1f' % b if b is not None else 'never' for b in back), wrong))
sys.exit(0 if wrong == 0 and all(b is not None and b <= 84.5 for b in back) else 1)
PY
}

# --- The corridor bag's scans 2.5 s apart -------------------------------------
# At a 5000-particle budget, seeds 1-10: within the corridor's bounds
# (RMSE 0.05 m, max 0.15 m) on every seed. While a step's motion noise grew
# with its square (odometry_motion_model.h), a 1.9 m step turned the
# direction of travel by 0.84 rad, the cloud fell 3.6 m behind the robot in
# the featureless stretch, and seeds 4 and 6 published a pose 1.8 and 1.2 m
# off where it ends. About 10 s.
corridor_small_budget() {
  local out="$ws/corridor_5000" seed
  for seed in 1 2 3 4 5 6 7 8 9 10; do
    bag_run "$out/seed$seed" bags/corridor.bag maps/corridor.yaml 0.1 \
      --initial-pose 2.5 3.95 0.0 --particles 5000 --seed $seed || return 1
  done
  /usr/bin/python3 - "$out" <<'PY'
import json, sys
runs = [json.load(open('%s/seed%d/eval/summary.json' % (sys.argv[1], s))) for s in range(1, 11)]
rmse, worst = [d['ate_rmse_m'] for d in runs], [d['max_m'] for d in runs]
print('corridor.bag, 5000 particles, seeds 1-10: ATE RMSE %.3f-%.3f m (bound 0.05), max %.3f-%.3f m '
      '(bound 0.15)' % (min(rmse), max(rmse), min(worst), max(worst)))
sys.exit(0 if max(rmse) <= 0.05 and max(worst) <= 0.15 else 1)
PY
}

# --- The runner at a replay's pace --------------------------------------------
# pf_bag_runner --pace (scripts/live_cpu.sh: the filter's work at pf_node's
# rhythm) only waits between scans: tracking.bag at 20 times its pace gives
# the trajectory of the run back to back, byte for byte, and takes its
# duration divided by 20 (6.6 s). About 8 s.
paced_runner_same() {
  local out="$ws/paced_runner" lib="$ws/devel/lib/pf_localization" pace start took
  rm -rf "$out" && mkdir -p "$out"
  for pace in none 20; do
    start=$(date +%s.%N)
    "$lib/pf_bag_runner" --bag bags/tracking.bag --map maps/building.yaml \
      --initial-pose 1.5 7.6 0.0 --out "$out/$pace.tum" --quiet \
      $([ $pace = none ] || echo --pace $pace) >"$out/$pace.log" 2>&1 ||
      { tail -n 5 "$out/$pace.log"; return 1; }
    took=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.1f", b - a}')
  done
  echo "tracking.bag at --pace 20: $took s (bag 131.6 s / 20 = 6.6 s)"
  cmp "$out/none.tum" "$out/20.tum" || return 1
  awk -v t="$took" 'BEGIN {exit !(t >= 6.5 && t < 20)}'
}

# --- Updates closer together than the defaults -------------------------------
# crowd.bag with an amcl configuration's update_min_d 0.05 m and update_min_a
# 0.1 rad, seeds 1-16: never "localized" more than 1 m off, and at least 15
# of the 16 tracked as with the defaults (RMSE within 0.03 m, max within
# 0.15 m; seed 2 jumps and comes back, "uncertain" meanwhile). While the
# filter's evidence, motion noise, fault tracking and recovery counted
# updates instead of views (view_share.h), every seed jumped 9-16 m to a place
# that fits the scans people hide (ATE 3.6-5.9 m); while the scans of a
# suspect odometry counted whole views, 5 of the 16 did (383 updates
# confidently wrong). About 20 s.
close_updates() {
  local out="$ws/close_updates" seed
  mkdir -p "$out"
  printf 'update_min_d: 0.05\nupdate_min_a: 0.1\n' >"$out/params.yaml"
  for seed in $(seq 1 16); do
    bag_run "$out/seed$seed" bags/crowd.bag maps/building.yaml 0.5 \
      --initial-pose 1.5 7.6 0.0 --params "$out/params.yaml" --seed $seed || return 1
  done
  /usr/bin/python3 - "$out" <<'PY'
import json, sys
runs = [json.load(open('%s/seed%d/eval/summary.json' % (sys.argv[1], s))) for s in range(1, 17)]
tracked = [s for s, d in enumerate(runs, 1) if d['ate_rmse_m'] <= 0.03 and d['max_m'] <= 0.15]
off = ['seed %d: %.3f m, max %.1f m' % (s, d['ate_rmse_m'], d['max_m'])
       for s, d in enumerate(runs, 1) if s not in tracked]
wrong = sum(d['confidently_wrong_updates'] for d in runs)
print('crowd.bag, update_min_d 0.05 m, update_min_a 0.1 rad, seeds 1-16: %d tracked within 0.03 m '
      'RMSE and 0.15 m max (bound 15)%s; %d updates confidently wrong (bound 0)'
      % (len(tracked), ' (off: %s)' % '; '.join(off) if off else '', wrong))
sys.exit(0 if len(tracked) >= 15 and wrong == 0 else 1)
PY
}

# --- Worlds that no longer match their maps ------------------------------------
# scripts/changed_worlds.sh, seeds 1-8: on each changed-world bag and the same
# tours as mapped, the ATE RMSE and the largest error after the first 10 s
# within their bounds on every seed, never "localized" more than 1 m off, no
# seed lost; the layer of the map's changes (pf_bag_runner --changes) against
# the bag's true change mask at least as precise and complete as the bounds
# (a marked cell within one cell of a true change of its kind), and on the
# tours as mapped marking at most 1 % of the cells seen. The bounds hold the
# figures of 16 seeds with a few millimetres to spare (docs/design.md, "A map
# out of date is not a wrong pose"). Before beams that see changes were told
# from a wrong pose, crowd_changed was lost on every seed (2.5-7.6 m) and
# changed_30 on some (up to 5.2 m). About 70 s.
changed_worlds_check() {
  local out="$ws/changed_worlds_check"
  bash scripts/changed_worlds.sh --seeds 8 --out "$out" || return 1
  /usr/bin/python3 - "$out/summary.json" <<'PY'
import json, sys
# bag: ATE RMSE, max after 10 s (m), and the layer: (precision, recall) against the mask, or the
# largest share of the cells seen marked on a tour as mapped.
BOUNDS = {'tracking': (0.02, 0.06, 0.01), 'changed_10': (0.025, 0.1, (0.95, 0.9)),
          'changed_20': (0.03, 0.1, (0.95, 0.9)), 'changed_30': (0.05, 0.25, (0.95, 0.9)),
          'crowd': (0.02, 0.12, 0.01), 'crowd_changed': (0.03, 0.15, (0.9, 0.85)),
          'warehouse_tracking': (0.02, 0.2, 0.01), 'warehouse_changed': (0.025, 0.2, (0.95, 0.95))}
table = json.load(open(sys.argv[1]))
ok = True
for bag, (rmse, late, layer) in BOUNDS.items():
    r = table[bag]
    good = (r['ate_rmse_m'][1] <= rmse and r['max_after_10s_m'][1] <= late
            and r['confidently_wrong'] == 0 and r['lost'] == 0)
    text = '%s: ATE %.3f m (bound %.3f), max after 10 s %.3f m (bound %.2f), %d confidently wrong' % (
        bag, r['ate_rmse_m'][1], rmse, r['max_after_10s_m'][1], late, r['confidently_wrong'])
    if isinstance(layer, tuple):
        good = good and r['precision_min'] >= layer[0] and r['recall_min'] >= layer[1]
        text += ', changes precision %.3f (bound %.2f), recall %.3f (bound %.2f)' % (
            r['precision_min'], layer[0], r['recall_min'], layer[1])
    else:
        good = good and r['changed_share_max'] <= layer
        text += ', %.2f %% of the cells seen marked changed (bound %.0f %%)' % (
            100 * r['changed_share_max'], 100 * layer)
    print(text + ': ' + ('ok' if good else 'FAILED'))
    ok = ok and good
sys.exit(0 if ok else 1)
PY
}

# --- The real recordings of ../shared/data ------------------------------------
# scripts/benchmark_datasets on every recording there with a reference, with
# the defaults (seed 1: each run is the same every time), held to these
# bounds: Intel <= 0.035 m, fr079 <= 0.065 m, AC109 <= 0.065 m after the
# best rigid fit (its AprilTags are turned 3 deg from the map) and no worse
# than 0.13 m raw; never more than 0.5 m off (every pose of all three); never "localized" more
# than 1 m off; where the reference's
# noise is known well enough to judge it (not AC109, where 100 % of the tags
# fall inside: docs/design.md, "An honest covariance"), 85-99 % of the
# reference inside the published 95 % ellipse; the layer of the map's changes
# marking at most 1 % of the cells seen (their maps are the world as it was
# recorded). The figures the defaults reach are printed. Without the
# recordings this fails: CI always has them. About 3 s.
real_recordings() {
  local out="$ws/real_recordings"
  rm -rf "$out" && mkdir -p "$out"
  PF_WS="$ws" /usr/bin/python3 scripts/benchmark_datasets 0 --no-bundled --no-plots --out "$out" \
    >"$out/benchmark.log" 2>&1 || { tail -n 5 "$out/benchmark.log"; return 1; }
  /usr/bin/python3 - "$out" <<'PY'
import json, os, re, sys
# name: (ATE RMSE bound, the same after the best rigid fit, whether the
# published covariance is judged), metres.
MAX_CHANGED_PERCENT = 1.0  # of the cells seen, marked changed on a map of the world as recorded
bounds = {'intel_lab': (0.035, None, True), 'fr079': (0.065, None, True),
          'neato_ac109_1': (0.13, 0.065, False)}
MAX_ERROR = 0.5  # m, of any pose
ok = True
for name, (raw, aligned, judge_cov) in sorted(bounds.items()):
    path = os.path.join(sys.argv[1], name + '_default', 'eval', 'summary.json')
    if not os.path.exists(path):
        print('%s: no result (is ../shared/data/%s there?)' % (name, name))
        ok = False
        continue
    d = json.load(open(path))
    inside = d['covariance']['inside_95_percent']
    # pf_bag_runner's summary: "map changes: N cells seen from U updates, A added, R removed (P %)"
    runner_log = open(os.path.join(sys.argv[1], name + '_default', 'runner.log')).read()
    changed = re.search(r'map changes: .*\(([0-9.]+) %\)', runner_log)
    changed = float(changed.group(1)) if changed else float('inf')
    good = (d['ate_rmse_m'] <= raw and (aligned is None or d['ate_aligned_rmse_m'] <= aligned)
            and d['max_m'] <= MAX_ERROR and d['confidently_wrong_updates'] == 0
            and (not judge_cov or 85.0 <= inside <= 99.0) and changed <= MAX_CHANGED_PERCENT)
    print('%s: ATE %.3f m (bound %.3f), after the rigid fit %.3f m%s, max %.2f m (bound %.1f), '
          '%d updates confidently wrong, %.1f %% inside the 95 %% ellipse%s, %.2f %% of the cells '
          'seen marked changed (bound %.0f %%): %s'
          % (name, d['ate_rmse_m'], raw, d['ate_aligned_rmse_m'],
             ' (bound %.3f)' % aligned if aligned else '', d['max_m'], MAX_ERROR,
             d['confidently_wrong_updates'], inside,
             ' (85-99)' if judge_cov else ' (not judged)', changed, MAX_CHANGED_PERCENT,
             'ok' if good else 'FAILED'))
    ok = ok and good
sys.exit(0 if ok else 1)
PY
}

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

# The results tables of README.md and docs/results.md are scripts/results_tables.py's
# output from one run of `scripts/benchmark_datasets 0 5000`; pf_bag_runner is
# deterministic for a seed, so a fresh run must give the same accuracy figures
# (the CPU column is the machine's, not compared). Recordings of ../shared/data
# that are absent are not compared. About 15 s on two idle cores.
results_tables_current() {
  local out="$ws/results_tables"
  rm -rf "$out" && mkdir -p "$out"
  PF_WS="$ws" /usr/bin/python3 "$repo/scripts/results_tables.py" --check --keep "$out"
}

# --- Python unit tests (pf_evaluate's metrics, pf_tune, locate) -----------------
# python_unit_tests COUNTS: runs them (with PF_TEST_TIER=quick, not those that
# replay bags); writes "PASSED FAILED" to COUNTS, the skipped ones in neither.
python_unit_tests() {
  local out ran bad skipped
  out=$(cd "$repo" && /usr/bin/python3 -m unittest discover -s test/python -p 'test_*.py' 2>&1)
  echo "$out" | tail -n 5
  ran=$(echo "$out" | sed -nE 's/^Ran ([0-9]+) tests?.*/\1/p')
  bad=$(echo "$out" | sed -nE 's/^FAILED \((.*)\)/\1/p' | grep -oE '(failures|errors)=[0-9]+' |
    grep -oE '[0-9]+' | awk '{s += $1} END {print s + 0}')
  skipped=$(echo "$out" | grep -oE 'skipped=[0-9]+' | grep -oE '[0-9]+' | tail -n 1)
  if [ -z "$ran" ]; then echo "0 1" >"$1"; return 1; fi
  echo "$((ran - bad - ${skipped:-0})) $bad" >"$1"
  [ "$bad" -eq 0 ]
}
