#!/usr/bin/env bash
# Builds the package in a catkin workspace made around the repository.
# The repository root is the package, so the workspace lives in an ignored
# folder (.ws by default, or $PF_WS) whose src/ holds a symlink back to it.
# Extra arguments go to catkin_make (e.g. a target, or run_tests).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${PF_WS:-$repo/.ws}
mkdir -p "$ws/src"
[ -L "$ws/src/pf_localization" ] || ln -s "$repo" "$ws/src/pf_localization"
cd "$ws"
# ROS 1 on Debian is Python code for /usr/bin/python3; a python3 earlier on
# PATH (pyenv, a venv) lacks its modules, so the system one goes first.
export PATH=/usr/bin:$PATH
catkin_make -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 ${PF_CMAKE_ARGS:-} "$@"
