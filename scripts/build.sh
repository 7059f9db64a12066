#!/usr/bin/env bash
# Builds the package with catkin_make in a catkin workspace outside the
# repository (see scripts/workspace.bash): by default
# ~/.cache/pf_localization/<clone>-<hash>/ws, or $PF_WS. The workspace's src/
# holds a symlink back to the repository, which is the package.
# PF_WS may also name the catkin_make workspace the repository already sits in
# (e.g. PF_WS=~/catkin_ws for ~/catkin_ws/src/pf_localization); it is then
# built as it is, other packages included.
# Extra arguments go to catkin_make (e.g. a target, run_tests, or install).
#   bash scripts/build.sh --where      prints the workspace and builds nothing, e.g.
#   source "$(bash scripts/build.sh --where)/devel/setup.bash"
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
if [ "${1:-}" = --where ]; then
  printf '%s\n' "$ws"
  exit 0
fi

# Workspaces inside the package were the old layout (.ws, .ws_asan, ...): their
# src/ links back to the package, so rosrun and catkin loop through them.
for old in .ws .ws_asan .ws_fuzz .ws_bench; do
  if [ -L "$repo/$old/src/pf_localization" ]; then
    echo "build: warning: $repo/$old is an old workspace inside the package; rosrun and catkin" \
      "loop through it: delete it (rm -rf '$repo/$old')" >&2
  fi
done

repo_real=$(cd "$repo" && pwd -P)
case "$(realpath -m "$ws")/" in
  "$repo_real"/*)
    echo "build: the workspace $ws is inside the package: rosrun and catkin would loop" \
      "through its src/ link; pick a folder outside $repo (PF_WS)" >&2
    exit 2 ;;
esac
mkdir -p "$ws/src"
ws=$(cd "$ws" && pwd)
if [ -d "$ws/.catkin_tools" ]; then
  echo "build: $ws is a \`catkin build\` workspace; these scripts use catkin_make." \
    "Build it with \`catkin build pf_localization\` yourself, or leave PF_WS unset" >&2
  exit 2
fi
link=$ws/src/pf_localization
if [ -e "$link" ] || [ -L "$link" ]; then
  if [ "$(cd "$link" 2>/dev/null && pwd -P)" != "$repo_real" ]; then
    echo "build: $link exists and is not this repository ($repo); remove it or pick another PF_WS" >&2
    exit 2
  fi
else
  ln -s "$repo" "$link"
fi
cd "$ws"
# ROS 1 on Debian is Python code for /usr/bin/python3; a python3 earlier on
# PATH (pyenv, a venv) lacks its modules, so the system one goes first.
export PATH=/usr/bin:$PATH
catkin_make -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 ${PF_CMAKE_ARGS:-} "$@"
