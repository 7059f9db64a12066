#!/usr/bin/env bash
# Regenerates the package's maps and simulated bags, byte for byte: the maps
# are drawn by code (pf_make_map), each bag comes from a map, a path script
# in bags/ and a seed (pf_simulator). The table below is the only place the
# seeds live; bags/README.md repeats it.
#
#   scripts/make_bags.sh           rewrite maps/ and bags/ in the repository
#   scripts/make_bags.sh --check   regenerate into a temporary folder and compare
#                                  sha256 sums with the committed files; exits 1
#                                  on any mismatch
#
# The tools are (re)built first with scripts/build.sh (its workspace: $PF_WS, or
# the default of scripts/workspace.bash).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
bin=$ws/devel/lib/pf_localization

#     bag       map       seed  simulator options
bags="tracking  building  1
      global    building  2
      kidnap    building  3
      small     small     4
      reverse   building  5     --unsigned-odometry
      crowd     building  6
      sparse    building  7     --scan-period 2
      corridor  corridor  8     --scan-period 2.5"

check=false
case "${1:-}" in
  --check) check=true ;;
  "") ;;
  *) echo "usage: $0 [--check]" >&2; exit 2 ;;
esac

log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! PF_WS=$ws bash "$repo/scripts/build.sh" pf_make_map pf_simulator >"$log" 2>&1; then
  cat "$log" >&2
  echo "make_bags.sh: building the tools failed" >&2
  exit 1
fi

out=$repo
if $check; then
  out=$(mktemp -d)
  trap 'rm -f "$log"; rm -rf "$out"' EXIT
  mkdir -p "$out/maps" "$out/bags"
fi

"$bin/pf_make_map" --out-dir "$out/maps"
while read -r bag map seed options; do
  # shellcheck disable=SC2086  # the options are words
  "$bin/pf_simulator" --map "$out/maps/$map.yaml" --path "$repo/bags/$bag.path" \
    --seed "$seed" --out "$out/bags/$bag.bag" $options
done <<<"$bags"

if $check; then
  status=0
  for f in maps/building.yaml maps/building.pgm maps/small.yaml maps/small.pgm \
           maps/corridor.yaml maps/corridor.pgm \
           $(awk '{print "bags/" $1 ".bag"}' <<<"$bags"); do
    want=$(sha256sum <"$repo/$f" 2>/dev/null | cut -d' ' -f1 || true)
    got=$(sha256sum <"$out/$f" | cut -d' ' -f1)
    if [ "$want" = "$got" ]; then
      echo "ok        $f"
    else
      echo "MISMATCH  $f" >&2
      status=1
    fi
  done
  exit $status
fi
