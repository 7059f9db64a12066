#!/usr/bin/env bash
# Builds the GoogleTest unit tests with AddressSanitizer + UndefinedBehaviorSanitizer
# (CMake option PF_SANITIZE) in their own catkin workspace and runs them.
#
#   bash scripts/sanitize.sh            # workspace ws_asan beside the usual one
#                                       # (scripts/workspace.bash), or $PF_ASAN_WS
#
# Runs the binaries two at a time; prints each one's gtest summary and exits non-zero
# when a test fails or a sanitizer reports anything (memory error, leak, undefined
# behaviour).
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo" asan)
mkdir -p "$ws"
tests=(pf_core_test pf_sim_test pf_ros_test pf_fuzz_replay_test)
start=$(date +%s)

# Compiled by clang (scripts/install_deps.sh installs clang-14 for the fuzzers), which
# compiles these sources instrumented at -O1 in about two thirds of gcc's CPU time
# (docs/contributing.md, "Where the full run's time goes"); gcc when there is no clang-14.
compilers="" compiler="the default compiler"
if [ -x /usr/bin/clang++-14 ] && [ -x /usr/bin/clang-14 ]; then
  # (-Wno-unknown-attributes: clang has no noipa, which only steers gcc's optimiser.)
  compilers="-DCMAKE_C_COMPILER=/usr/bin/clang-14 -DCMAKE_CXX_COMPILER=/usr/bin/clang++-14"
  compilers+=" -DCMAKE_CXX_FLAGS=-Wno-unknown-attributes" compiler=clang-14
fi
echo "sanitize: building ${tests[*]} with PF_SANITIZE=ON by $compiler in $ws"
# -j2: catkin_make's default adds -l2, which on a busy machine compiles one file at a time.
if ! PF_WS=$ws PF_CMAKE_ARGS="-DPF_SANITIZE=ON $compilers" bash "$repo/scripts/build.sh" "${tests[@]}" -j2 \
  >"$ws.build.log" 2>&1; then
  tail -40 "$ws.build.log"
  echo "sanitize: build failed (log: $ws.build.log)" >&2
  exit 2
fi
echo "sanitize: built in $(($(date +%s) - start)) s"

# halt_on_error makes UBSan fatal; detect_leaks is LeakSanitizer (part of ASan).
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:${ASAN_OPTIONS:-}
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1:${UBSAN_OPTIONS:-}
export PATH=/usr/bin:$PATH
# run_one BINARY: one test binary, its output in $ws/BINARY.sanitize.log; prints one line
# (and what went wrong) at once, and exits 1 when a test failed or a sanitizer reported.
run_one() {
  local t=$1 log=$ws/$1.sanitize.log t0 rc summary reports out
  t0=$(date +%s)
  "$ws/devel/lib/pf_localization/$t" >"$log" 2>&1
  rc=$?
  summary=$(grep -E '^\[  (PASSED|FAILED)  \] [0-9]+ test' "$log" | tr '\n' ' ')
  reports=$(grep -cE 'runtime error:|ERROR: (Address|Leak|Undefined)Sanitizer|SUMMARY: (Address|Leak|Undefined)' "$log")
  out="sanitize: $t: exit $rc, ${summary:-no gtest summary}, $reports sanitizer report line(s), $(($(date +%s) - t0)) s"
  if [ "$rc" -ne 0 ] || [ "$reports" -ne 0 ]; then
    out+=$'\n'$(grep -E '^\[  FAILED  \] [A-Za-z]' "$log" | sort -u | sed 's/^/    /')
    out+=$'\n'$(grep -m1 -A25 -E 'runtime error:|ERROR: (Address|Leak|Undefined)Sanitizer' "$log" | sed 's/^/    /')
    out+=$'\n'"    log: $log"
    echo "$out"
    return 1
  fi
  echo "$out"
}
export -f run_one
export ws
# Two at a time (each binary runs its tests on one thread; the machine has two cores).
failed=0
printf '%s\n' "${tests[@]}" | xargs -P 2 -I{} bash -c 'run_one "$1"' _ {} || failed=1
echo "sanitize: $([ $failed -eq 0 ] && echo OK || echo FAILED) in $(($(date +%s) - start)) s"
exit $failed
