#!/usr/bin/env bash
# The main job: installs the dependencies, builds the package (every node), localizes the
# robot of a bag with pf_bag_runner (as fast as the CPU allows) and writes an
# evaluation report with pf_evaluate.
#
#   bash scripts/demo.sh                       # the bundled tracking bag
#   bash scripts/demo.sh --bag B.bag --map M.yaml [--initial-pose X Y YAW] [runner options...]
#
# Without --bag it runs on bags/tracking.bag and maps/building.yaml from the
# bag's known start pose. Reports go to reports/<bag name>/ (override: --report DIR).
# A bag with /ground_truth is judged against it; one without (most bags of a
# real robot) gets the report of what the filter itself knows: the share of
# the beams that fit the map, the verdict over time, the covariance's size and
# the scans drawn at the estimate (docs/getting-started.md).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
export PATH=/usr/bin:$PATH

bag="" map="" report="" runner_args=() scan_topics=()
while [ $# -gt 0 ]; do
  case $1 in
    --bag) bag=$2; shift 2 ;;
    --map) map=$2; shift 2 ;;
    --report) report=$2; shift 2 ;;
    # The runner's, and pf_evaluate's too: the scans it draws at the estimate.
    --scan-topic) runner_args+=("$1" "$2"); scan_topics+=(--scan-topic "$2"); shift 2 ;;
    *) runner_args+=("$1"); shift ;;
  esac
done
if [ -z "$bag" ]; then
  bag=$repo/bags/tracking.bag
  map=$repo/maps/building.yaml
  # The bundled bag's start pose, from the `start` line of its path script
  # (bags/README.md); the filter is told nothing else.
  read -r x y yaw < <(awk '$1 == "start" {print $2, $3, $4; exit}' "$repo/bags/tracking.path")
  runner_args+=(--initial-pose "$x" "$y" "$yaw")
fi
[ -n "$map" ] || { echo "demo: --map is required with --bag" >&2; exit 2; }
bag=$(realpath "$bag"); map=$(realpath "$map")
report=${report:-$repo/reports/$(basename "$bag" .bag)}

bash "$repo/scripts/install_deps.sh"
# Every node, not just the runner: the README's next step is bag_demo.launch
# (pf_node, map_publisher), and rosrun reaches pf_simulator and pf_make_map.
bash "$repo/scripts/build.sh" >/dev/null
mkdir -p "$report"

echo "demo: localizing $bag on $map"
rm -f "$report/changes.yaml" "$report/changes.pgm"
"$ws/devel/lib/pf_localization/pf_bag_runner" --bag "$bag" --map "$map" \
  --out "$report/trajectory.tum" --log "$report/updates.csv" \
  --particles-out "$report/particles.csv" --covariance "$report/covariance.csv" \
  --changes "$report/changes.yaml" "${runner_args[@]}"
changes=()
[ -f "$report/changes.yaml" ] && changes=(--changes "$report/changes.yaml")
/usr/bin/python3 "$repo/scripts/pf_evaluate" --traj "$report/trajectory.tum" --bag "$bag" \
  --map "$map" --log "$report/updates.csv" --particles "$report/particles.csv" \
  --cov "$report/covariance.csv" "${changes[@]}" "${scan_topics[@]}" --out "$report"
echo "demo: report in $report"
