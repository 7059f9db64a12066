#!/usr/bin/env bash
# Measures the filter on the bags whose world differs from their map
# (bags/README.md, "Worlds that differ from their maps"): pf_bag_runner with
# its defaults from each bag's start pose, for seeds 1..N, and pf_evaluate on
# each run, as scripts/test.sh's bag_run does. Prints one line per bag, over
# the seeds: the ATE RMSE (min-max), the largest position error after the
# first 10 s (min-max), the confidently wrong updates (all seeds together)
# and the seeds lost (ATE RMSE over 0.5 m); and the layer of the map's
# changes the runner learned (pf_bag_runner --changes): against the bag's
# true change mask its precision and recall (the lowest over the seeds), in
# the world as mapped the share of the cells seen it marks (the highest). The
# same tours in the world as mapped (tracking, crowd, warehouse_tracking) come
# first, for comparison. DIR/summary.json holds the same figures.
#
#   scripts/changed_worlds.sh [--seeds N] [--out DIR] [BAG...]
#       N: seeds 1..N (default 16); DIR: where the runs go (default: the
#       workspace's changed_worlds/, DIR/BAG/seedS/); BAG: some of the bags
#       below by name (default: all)
#
# pf_bag_runner is (re)built first with scripts/build.sh.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
cd "$repo"
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
lib=$ws/devel/lib/pf_localization

#     bag                map        true change mask        start pose
bags="tracking           building   -                       1.5 7.6 0
      changed_10         building   changed_10_mask         1.5 7.6 0
      changed_20         building   changed_20_mask         1.5 7.6 0
      changed_30         building   changed_30_mask         1.5 7.6 0
      crowd              building   -                       1.5 7.6 0
      crowd_changed      building   changed_20_mask         1.5 7.6 0
      warehouse_tracking warehouse  -                       5.0 6.0 1.5707963
      warehouse_changed  warehouse  warehouse_changed_mask  5.0 6.0 1.5707963"

seeds=16
out=$ws/changed_worlds
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) seeds=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h | --help) sed -n '2,17p' "$0"; exit 0 ;;
    -*) echo "changed_worlds.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
if [ $# -gt 0 ]; then
  bags=$(for b in "$@"; do
    awk -v b="$b" '$1 == b' <<<"$bags" | grep . ||
      { echo "changed_worlds.sh: no bag '$b'" >&2; exit 2; }
  done)
fi

log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! PF_WS=$ws bash scripts/build.sh pf_bag_runner >"$log" 2>&1; then
  cat "$log" >&2
  echo "changed_worlds.sh: building pf_bag_runner failed" >&2
  exit 1
fi

# run DIR BAG MAP MASK SEED X Y YAW: one run and its evaluation into DIR
# (MASK: the true change mask's YAML, or - for none).
run() {
  local dir=$1 bag=$2 map=$3 mask=$4 seed=$5
  local -a score=()
  [ "$mask" = - ] || score=(--change-mask "$mask")
  shift 5
  rm -rf "$dir" && mkdir -p "$dir"
  "$lib/pf_bag_runner" --bag "$bag" --map "$map" --seed "$seed" --initial-pose "$@" \
    --out "$dir/traj.tum" --log "$dir/updates.csv" --hypotheses "$dir/hypotheses.csv" \
    --covariance "$dir/cov.csv" --changes "$dir/changes.yaml" --quiet >"$dir/runner.log" 2>&1 ||
    { tail -n 5 "$dir/runner.log" >&2; return 1; }
  /usr/bin/python3 "$lib/pf_evaluate" --traj "$dir/traj.tum" --bag "$bag" --map "$map" \
    --log "$dir/updates.csv" --hypotheses "$dir/hypotheses.csv" --cov "$dir/cov.csv" \
    --changes "$dir/changes.yaml" "${score[@]}" \
    --max-gap 0.5 --out "$dir/eval" --no-plots >"$dir/eval.log" 2>&1 ||
    { tail -n 5 "$dir/eval.log" >&2; return 1; }
}

while read -r bag map mask x y yaw; do
  [ "$mask" = - ] || mask=bags/$mask.yaml
  for seed in $(seq 1 "$seeds"); do
    run "$out/$bag/seed$seed" "bags/$bag.bag" "maps/$map.yaml" "$mask" "$seed" "$x" "$y" "$yaw"
  done
done <<<"$bags"

# shellcheck disable=SC2046  # the bags' names are words
/usr/bin/python3 - "$repo/src" "$out" "$seeds" $(awk '{print $1}' <<<"$bags") <<'PY'
import json, os, sys
sys.path.insert(0, sys.argv[1])
import numpy as np
from pf_localization import evaluate as ev

out, seeds, bags = sys.argv[2], int(sys.argv[3]), sys.argv[4:]
LOST_M = 0.5
print('%-18s %5s  %-13s  %-16s  %-9s  %-4s  %s' % ('bag', 'seeds', 'ATE RMSE m', 'max after 10 s m',
                                                  'conf.wrong', 'lost', 'map changes'))
table = {}
for bag in bags:
    ref = ev.read_bag_reference(os.path.join('bags', bag + '.bag'))
    rmse, late, wrong, changes = [], [], 0, []
    for s in range(1, seeds + 1):
        d = os.path.join(out, bag, 'seed%d' % s)
        summary = json.load(open(os.path.join(d, 'eval', 'summary.json')))
        _, match = ev.evaluate(ev.read_tum(os.path.join(d, 'traj.tum')), ref, max_gap=0.5)
        after = match['t'] - match['t0'] >= ev.SETTLE_S
        rmse.append(summary['ate_rmse_m'])
        late.append(float(np.max(match['pos_err'][after])))
        wrong += summary.get('confidently_wrong_updates', 0)
        changes.append(summary['map_changes'])
    row = dict(seeds=seeds, ate_rmse_m=[min(rmse), max(rmse)], max_after_10s_m=[min(late), max(late)],
               confidently_wrong=wrong, lost=sum(r > LOST_M for r in rmse),
               changed_share_max=max(c['changed_share_of_seen'] for c in changes))
    if 'recall' in changes[0]:
        row['precision_min'] = min(c['precision'] or 0.0 for c in changes)
        row['recall_min'] = min(c['recall'] or 0.0 for c in changes)
        layer = 'precision >= %.3f, recall >= %.3f' % (row['precision_min'], row['recall_min'])
    else:
        layer = '%.2f %% of the cells seen, at most' % (100 * row['changed_share_max'])
    table[bag] = row
    print('%-18s %5d  %.3f-%.3f    %.3f-%.3f      %-9d  %-4d  %s' % (
        bag, seeds, min(rmse), max(rmse), min(late), max(late), wrong, row['lost'], layer))
with open(os.path.join(out, 'summary.json'), 'w') as f:
    json.dump(table, f, indent=1)
PY
