# Sourced by the project's scripts: where the catkin workspaces live, and how
# to load a built one into the current shell.
#
# The repository root is the catkin package, so the scripts build it in a
# workspace made elsewhere, whose src/ holds a symlink back to the repository.
# That workspace must NOT live inside the repository: rosrun (find -L over the
# package folder) and catkin's package crawl would follow the symlink back into
# the package and loop ("File system loop detected", and a second copy of every
# executable). So the default is a cache folder derived from the repository's
# path (one per clone):
#   ${XDG_CACHE_HOME:-$HOME/.cache}/pf_localization/<repo folder name>-<hash of its path>/
#       ws/        scripts/build.sh, demo.sh, test.sh, ...   override: PF_WS
#       ws_asan/   scripts/sanitize.sh                        override: PF_ASAN_WS
#       ws_fuzz/   scripts/fuzz.sh                            override: PF_FUZZ_WS
#       ws_bench/  scripts/benchmark.sh                       override: PF_BENCH_WS
# scripts/benchmark_datasets computes the same path (keep them in step).
#
#   pf_cache_dir REPO               prints that cache folder
#   pf_default_ws REPO [KIND]       prints $PF_WS (or $PF_ASAN_WS, ...) or the default;
#                                   KIND is ws (default), asan, fuzz or bench
#   pf_source_workspace WS NAME     loads WS's devel space (NAME prefixes the error message)
#   pf_free_port                    prints a TCP port for a private ROS master
pf_cache_dir() {
  local real hash
  real=$(cd "$1" && pwd -P) || return 1
  hash=$(printf '%s' "$real" | sha1sum | cut -c1-10)
  printf '%s\n' "${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/pf_localization/$(basename "$real")-$hash"
}

pf_default_ws() {
  local repo=$1 kind=${2:-ws} override
  case $kind in
    ws) override=${PF_WS:-} ;;
    asan) override=${PF_ASAN_WS:-} ;;
    fuzz) override=${PF_FUZZ_WS:-} ;;
    bench) override=${PF_BENCH_WS:-} ;;
    *) echo "pf_default_ws: unknown kind $kind" >&2; return 2 ;;
  esac
  if [ -n "$override" ]; then
    printf '%s\n' "$override"
  elif [ "$kind" = ws ]; then
    printf '%s/ws\n' "$(pf_cache_dir "$repo")"
  else
    printf '%s/ws_%s\n' "$(pf_cache_dir "$repo")" "$kind"
  fi
}

# ROS 1's Python tools need /usr/bin/python3 first on PATH, and catkin's setup
# scripts read unset variables, so nounset is lifted around them.
pf_source_workspace() {
  local ws=$1 name=$2
  export PATH=/usr/bin:$PATH
  if [ ! -f "$ws/devel/setup.bash" ]; then
    echo "$name: no workspace at $ws: build first (bash scripts/build.sh, or set PF_WS)" >&2
    return 2
  fi
  local had_nounset=0
  [[ $- == *u* ]] && had_nounset=1
  set +u
  # shellcheck disable=SC1091
  source "$ws/devel/setup.bash"
  [ "$had_nounset" = 1 ] && set -u
  return 0
}

# A port for a private roscore: one below the kernel's ephemeral range, which
# nothing listens on now. A port drawn from the ephemeral range (bind to port 0,
# or a random number above 32767) can be taken between the draw and roscore's
# start by the XML-RPC server of any ROS node, or by rostest's own master, which
# binds port 0: in a test run that starts dozens of nodes this happens.
# PF_FREE_PORT_RANGE="LOW HIGH" draws from [LOW, HIGH) instead (for its test,
# which holds ports of a range no other script draws from).
pf_free_port() {
  /usr/bin/python3 - <<'PY'
import os, random, socket
if os.environ.get('PF_FREE_PORT_RANGE'):
    first, high = (int(v) for v in os.environ['PF_FREE_PORT_RANGE'].split())
else:
    low = int(open('/proc/sys/net/ipv4/ip_local_port_range').read().split()[0])
    first, high = 20000, low if low > 21000 else 65536  # no range below it: any port will do
for port in random.sample(range(first, high), min(200, high - first)):
    with socket.socket() as s:
        try:
            s.bind(('localhost', port))
        except OSError:
            continue
    print(port)
    break
else:
    raise SystemExit('pf_free_port: no free port in %d-%d' % (first, high - 1))
PY
}
