#!/usr/bin/env bash
# Installs every build, run and test dependency of pf_localization from Debian 12's
# archive. rosdep cannot reach its database on our machines, so the Debian package
# names are listed here by hand; keep them in step with package.xml.
# Idempotent: packages already present are skipped by apt, and apt-get update runs
# only when a package is actually missing.
set -euo pipefail

packages=(
  # build tools; ccache: every build of the tests after the first reuses its objects
  build-essential cmake catkin catkin-lint python3-catkin-pkg clang-format ccache
  # scripts/make_deb.sh: dpkg-shlibdeps, dpkg-architecture (build-essential pulls it in too)
  dpkg-dev
  # `catkin build` (catkin_tools; Debian calls it catkin-tools, not python3-catkin-tools)
  catkin-tools
  # ROS 1 core, messages and tools
  ros-base-dev libroscpp-dev rosbash python3-roslaunch python3-rostopic python3-rosnode
  python3-rosservice python3-rosparam python3-rosmsg
  libtf2-dev libtf2-ros-dev libtf2-geometry-msgs-dev libtf2-msgs-dev
  libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libstd-srvs-dev libdiagnostic-msgs-dev
  libros-rosgraph-msgs-dev
  librosbag-dev librosbag-storage-dev python3-rosbag
  # msg/PoseHypotheses.msg: message_generation (the C++ and Python generators)
  # and message_runtime; std_msgs for its header
  ros-message-generation ros-message-runtime python3-genmsg python3-gencpp python3-genpy
  libstd-msgs-dev python3-std-msgs
  # dynamic_reconfigure: the C++ server and its headers; the .cfg generator,
  # the Python client (test/rostest/reconfigure_checker.py) and dynparam
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  # libraries of the core
  libeigen3-dev libyaml-cpp-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev librostest-dev python3-rostest python3-rosunit libbenchmark-dev
  # the Python and replay tests (test/python, test/replay), which scripts/test.sh runs with pytest
  python3-pytest
  # test/rostest/odom_topic.test: relay and transform
  topic-tools python3-topic-tools
  # fuzzing (scripts/fuzz.sh): clang with libFuzzer; clang also builds the sanitizer tier (scripts/sanitize.sh)
  clang-14 libclang-rt-14-dev
  python3-std-srvs python3-geometry-msgs python3-nav-msgs python3-sensor-msgs python3-tf2-msgs
  python3-diagnostic-msgs
  python3-tf2-ros
  # evaluation reports
  python3-numpy python3-matplotlib python3-pil python3-yaml
  # pf_tune: Optuna (its parameter-importance plot needs scikit-learn), Dask's distributed
  # scheduler and workers, scipy's distance transform, the progress bar; psutil for its tests
  python3-optuna python3-sklearn python3-distributed python3-scipy python3-tqdm python3-psutil
  # rviz test (scripts/rviz_click_test.sh): rviz under a virtual X server,
  # driven by xdotool, its window found by xwininfo, screenshots by import
  rviz xvfb xdotool x11-utils imagemagick
  # the manual (mkdocs.yml, docs/): scripts/test.sh builds it with --strict
  mkdocs
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install_deps: installing ${#missing[@]} packages: ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
