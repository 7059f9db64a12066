#!/usr/bin/env bash
# Fuzzes the ROS-free core with libFuzzer + ASan + UBSan.
#
#   bash scripts/fuzz.sh [SECONDS]     # default 600, split evenly between the targets
#
# Builds test/fuzz/fuzz_core and fuzz_map_loader with clang-14 in their own
# catkin workspace (default ws_fuzz beside the usual one, see
# scripts/workspace.bash, or $PF_FUZZ_WS; only the fuzz targets and
# their instrumented copy of the core are compiled), then runs each target for
# its share of SECONDS, starting from the committed seeds in
# test/fuzz/corpus/<target>/. What a run discovers is kept in
# <fuzz workspace>/fuzz/<target>/corpus, so the next run carries on from there.
# A crash writes crash-*/leak-*/timeout-* into <fuzz workspace>/fuzz/<target>/;
# fuzzing then resumes (at most 5 restarts per target) so one bug does not
# use up the time budget. Prints executions, time, exec/s and crashes per
# target and exits non-zero when anything crashed.
#
# Needs clang-14 and libclang-rt-14-dev (libFuzzer): scripts/install_deps.sh.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
total=${1:-600}
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo" fuzz)
mkdir -p "$ws"
targets=(fuzz_core fuzz_map_loader)

if ! command -v clang++-14 >/dev/null; then
  echo "fuzz: clang++-14 not found: apt-get install clang-14 libclang-rt-14-dev" >&2
  exit 2
fi

echo "fuzz: building ${targets[*]} in $ws"
CC=clang-14 CXX=clang++-14 PF_WS=$ws \
  PF_CMAKE_ARGS="-DPF_BUILD_FUZZERS=ON -DCATKIN_ENABLE_TESTING=OFF" \
  bash "$repo/scripts/build.sh" "${targets[@]}" >"$ws.build.log" 2>&1 ||
  { tail -40 "$ws.build.log"; echo "fuzz: build failed (log: $ws.build.log)" >&2; exit 2; }
bin=$ws/devel/lib/pf_localization

per=$((total / ${#targets[@]}))
[ "$per" -ge 1 ] || per=1
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

summary=()
any_crash=0
for t in "${targets[@]}"; do
  out=$ws/fuzz/$t
  mkdir -p "$out/corpus"
  before=$(ls "$out" | grep -cE '^(crash|leak|timeout|oom)-' || true)
  execs=0
  start=$(date +%s)
  restarts=0
  while :; do
    left=$((per - ($(date +%s) - start)))
    [ "$left" -ge 1 ] || break
    log=$out/run.$restarts.log
    # -timeout: one input taking 10 s is a hang; -rss_limit_mb: an input that
    # makes the core allocate gigabytes is a finding too.
    "$bin/$t" -max_total_time="$left" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
      -print_final_stats=1 -artifact_prefix="$out/" \
      "$out/corpus" "$repo/test/fuzz/corpus/$t" >"$log" 2>&1 && rc=0 || rc=$?
    n=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | awk '{print $2}' | tail -1)
    if [ -z "$n" ]; then  # a crash skips the final stats: take the last progress line
      n=$(grep -oE '^#[0-9]+' "$log" | tail -1 | tr -d '#')
    fi
    execs=$((execs + ${n:-0}))
    [ "$rc" -eq 0 ] && break
    echo "fuzz: $t stopped (exit $rc): $(grep -m1 -E 'ERROR|runtime error|check failed' "$log" || echo 'see log')"
    echo "      log: $log"
    restarts=$((restarts + 1))
    [ "$restarts" -lt 5 ] || break
  done
  secs=$(($(date +%s) - start))
  [ "$secs" -ge 1 ] || secs=1
  after=$(ls "$out" | grep -cE '^(crash|leak|timeout|oom)-' || true)
  crashes=$((after - before))
  [ "$crashes" -eq 0 ] || any_crash=1
  corpus=$(ls "$out/corpus" | wc -l)
  line=$(printf '%-16s %10d execs in %5d s = %7d exec/s, %d crash(es), corpus %d inputs' \
    "$t" "$execs" "$secs" $((execs / secs)) "$crashes" "$corpus")
  echo "fuzz: $line"
  summary+=("$line")
  if [ "$crashes" -gt 0 ]; then
    ls -t "$out" | grep -E '^(crash|leak|timeout|oom)-' | head -"$crashes" | sed "s|^|      $out/|"
  fi
done

echo "fuzz: summary (${total} s total)"
printf '  %s\n' "${summary[@]}"
exit "$any_crash"
