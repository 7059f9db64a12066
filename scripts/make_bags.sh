#!/usr/bin/env bash
# Regenerates the package's maps and simulated bags, byte for byte: the maps
# are drawn by code (pf_make_map), each bag comes from a map, a path script
# in bags/ and a seed (pf_simulator), and for some a changes file in bags/
# (pf_simulator --changes: the world differs from the map), whose true change
# mask is written beside it (bags/NAME_mask.yaml and .pgm) and checked like the
# bags. The tables below are the only place the seeds live; bags/README.md
# repeats them.
#
#   scripts/make_bags.sh           rewrite maps/ and bags/ in the repository
#   scripts/make_bags.sh --check   regenerate into a temporary folder and compare
#                                  sha256 sums with the committed files; exits 1
#                                  on any mismatch
#   scripts/make_bags.sh --generated BAG BIN_DIR OUT
#                                  write one generated bag (below) with the
#                                  pf_simulator in BIN_DIR, building nothing: what
#                                  the build runs (CMakeLists.txt, pf_cloud_bag)
#
# Generated bags are too big to commit (cloud.bag: ~30 MB of point clouds): the
# build writes them into the devel space, and the repository keeps only their
# sha256 (bags/BAG.bag.sha256), which the first two forms rewrite or check.
#
# The tools are (re)built first with scripts/build.sh (its workspace: $PF_WS, or
# the default of scripts/workspace.bash).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
bin=$ws/devel/lib/pf_localization

#     bag                map       seed  simulator options
bags="tracking           building  1
      global             building  2
      kidnap             building  3
      small              small     4
      reverse            building  5     --unsigned-odometry
      crowd              building  6
      sparse             building  7     --scan-period 2
      corridor           corridor  8     --scan-period 2.5
      two_lidar          building  9     --rig amr
      two_lidar_covered  building  9     --rig amr --block front:30:42
      warehouse_tracking warehouse 11    --rig warehouse --scan-period 0.2
      warehouse_global   warehouse 12    --rig warehouse --scan-period 0.2
      warehouse_kidnap   warehouse 13    --rig warehouse --scan-period 0.2
      changed_10         building  14
      changed_20         building  15
      changed_30         building  16
      crowd_changed      building  17
      warehouse_changed  warehouse 18    --rig warehouse --scan-period 0.2
      floors             building_floors 19"
# The bags' path scripts are bags/BAG.path, but for these, which share one.
path_of() {
  case "$1" in
    two_lidar_covered) echo two_lidar ;;
    changed_10 | changed_20 | changed_30) echo tracking ;;
    crowd_changed) echo crowd ;;
    warehouse_changed) echo warehouse_tracking ;;
    *) echo "$1" ;;
  esac
}
# The bags whose world differs from their map: their changes file is
# bags/NAME.changes, NAME as this prints it (nothing: the world is the map).
changes_of() {
  case "$1" in
    changed_10 | changed_20 | changed_30 | warehouse_changed) echo "$1" ;;
    crowd_changed) echo changed_20 ;;
  esac
}
#          bag    map       seed  simulator options
generated="cloud  building  10    --rig cloud --scan-period 0.4"

# simulate BIN MAPS_DIR OUT_DIR BAG MAP SEED OPTIONS...: a bag with changes
# also writes its changes' mask into OUT_DIR.
simulate() {
  local bin=$1 maps=$2 outdir=$3 bag=$4 map=$5 seed=$6 changes
  shift 6
  changes=$(changes_of "$bag")
  if [ -n "$changes" ]; then
    set -- "$@" --changes "$repo/bags/$changes.changes" \
      --change-mask "$outdir/${changes}_mask.yaml"
  fi
  "$bin/pf_simulator" --map "$maps/$map.yaml" --path "$repo/bags/$(path_of "$bag").path" \
    --seed "$seed" --out "$outdir/$bag.bag" "$@"
}

check=false
case "${1:-}" in
  --check) check=true ;;
  --generated)
    [ $# -eq 4 ] || { echo "usage: $0 --generated BAG BIN_DIR OUT" >&2; exit 2; }
    row=$(awk -v b="$2" '$1 == b' <<<"$generated")
    [ -n "$row" ] || { echo "make_bags.sh: no generated bag '$2'" >&2; exit 2; }
    read -r bag map seed options <<<"$row"
    tmp=$(mktemp -d)
    trap 'rm -rf "$tmp"' EXIT
    # shellcheck disable=SC2086  # the options are words
    simulate "$3" "$repo/maps" "$tmp" "$bag" "$map" "$seed" $options >/dev/null
    mkdir -p "$(dirname "$4")"
    mv "$tmp/$bag.bag" "$4"
    exit 0 ;;
  "") ;;
  *) echo "usage: $0 [--check | --generated BAG BIN_DIR OUT]" >&2; exit 2 ;;
esac

log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! PF_WS=$ws bash "$repo/scripts/build.sh" pf_make_map pf_simulator >"$log" 2>&1; then
  cat "$log" >&2
  echo "make_bags.sh: building the tools failed" >&2
  exit 1
fi

out=$repo
gen=$(mktemp -d)
trap 'rm -f "$log"; rm -rf "$gen"' EXIT
if $check; then
  out=$(mktemp -d)
  trap 'rm -f "$log"; rm -rf "$out" "$gen"' EXIT
  mkdir -p "$out/maps" "$out/bags"
fi

"$bin/pf_make_map" --out-dir "$out/maps"
while read -r bag map seed options; do
  # shellcheck disable=SC2086  # the options are words
  simulate "$bin" "$out/maps" "$out/bags" "$bag" "$map" "$seed" $options
done <<<"$bags"
while read -r bag map seed options; do
  # shellcheck disable=SC2086  # the options are words
  simulate "$bin" "$out/maps" "$gen" "$bag" "$map" "$seed" $options
  sha256sum <"$gen/$bag.bag" | cut -d' ' -f1 >"$gen/$bag.bag.sha256"
  $check || cp "$gen/$bag.bag.sha256" "$repo/bags/$bag.bag.sha256"
done <<<"$generated"

if $check; then
  status=0
  for f in maps/building.yaml maps/building.pgm maps/small.yaml maps/small.pgm \
           maps/corridor.yaml maps/corridor.pgm maps/warehouse.yaml maps/warehouse.pgm \
           maps/building_upper.yaml maps/building_upper.pgm maps/building_floors.yaml \
           $(awk '{print "bags/" $1 ".bag"}' <<<"$bags") \
           $(while read -r bag _; do changes_of "$bag"; done <<<"$bags" | sort -u |
               awk '{print "bags/" $1 "_mask.yaml bags/" $1 "_mask.pgm"}'); do
    want=$(sha256sum <"$repo/$f" 2>/dev/null | cut -d' ' -f1 || true)
    got=$(sha256sum <"$out/$f" | cut -d' ' -f1)
    if [ "$want" = "$got" ]; then
      echo "ok        $f"
    else
      echo "MISMATCH  $f" >&2
      status=1
    fi
  done
  while read -r bag _; do
    f=bags/$bag.bag.sha256
    if [ "$(cat "$repo/$f" 2>/dev/null || true)" = "$(cat "$gen/$bag.bag.sha256")" ]; then
      echo "ok        bags/$bag.bag (generated; $f)"
    else
      echo "MISMATCH  bags/$bag.bag (generated; $f)" >&2
      status=1
    fi
  done <<<"$generated"
  exit $status
fi
