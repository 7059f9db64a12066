#!/usr/bin/env bash
# Builds and runs the Google Benchmark suite (bench/filter_benchmark.cc) in its
# own workspace (ws_bench beside the usual one, see scripts/workspace.bash, or
# $PF_BENCH_WS) with -DPF_BUILD_BENCHMARKS=ON, and
# prints the median of repeated runs. Arguments go to the benchmark binary,
# e.g. --benchmark_filter=FullUpdate. Not part of the tests: timings depend on
# the machine and on what else runs on it.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo" bench)
mkdir -p "$ws"
PF_WS=$ws PF_CMAKE_ARGS="-DPF_BUILD_BENCHMARKS=ON -DCATKIN_ENABLE_TESTING=OFF" \
  bash "$repo/scripts/build.sh" pf_benchmarks >"$ws.build.log" 2>&1 ||
  { tail -30 "$ws.build.log"; echo "benchmark: build failed (log: $ws.build.log)" >&2; exit 2; }
"$ws/devel/lib/pf_localization/pf_benchmarks" --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true "$@" 2>&1 | grep -E "^Benchmark|^---|_median"
