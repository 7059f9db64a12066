# Sourced by the project's scripts: loads a built catkin workspace into the
# current shell. ROS 1's Python tools need /usr/bin/python3 first on PATH, and
# catkin's setup scripts read unset variables, so nounset is lifted around them.
#   pf_source_workspace WS NAME     (NAME prefixes the error message)
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
