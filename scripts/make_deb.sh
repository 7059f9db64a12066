#!/usr/bin/env bash
# Builds a Debian package of pf_localization laid out like Debian's own ROS 1
# packages (installed under /usr, found by rospack/roslaunch without sourcing
# anything):
#   /usr/lib/pf_localization/        the nodes and Python tools (catkin's libexec)
#   /usr/lib/<multiarch>/            libpf_core.so, libpf_ros.so, libpf_sim.so; cmake/, pkgconfig/
#   /usr/share/pf_localization/      package.xml, launch, config, maps, bags, rviz, msg
#   /usr/include/pf_localization/    the headers (PoseHypotheses.h: pf_hypotheses' message)
#   /usr/lib/python3/dist-packages/pf_localization/   the dynamic_reconfigure client module, msg/
#   /usr/share/doc/ros-pf-localization/               copyright, changelog
# As Debian builds its ROS packages: the package alone, with cmake and
# Debian's catkin, CMAKE_INSTALL_PREFIX=/usr (catkin then installs in Debian's
# layout and no setup.bash), installed with DESTDIR into a staging tree.
#
#   bash scripts/make_deb.sh [--out DIR] [--build-dir DIR] [-j N]
#     --out DIR        where ros-pf-localization_VERSION_ARCH.deb goes
#                      (default: the scripts' workspace, `bash scripts/build.sh --where`)
#     --build-dir DIR  the cmake build folder, kept for the next run (default:
#                      <workspace>/build_deb); must be outside the repository
#     -j N             parallel compile jobs (default 2)
# Prints the .deb's path on its last line.
#
# Version: package.xml's. Architecture: dpkg --print-architecture.
# Depends: the Debian packages of the shared libraries the binaries link
# (dpkg-shlibdeps) and the run-time packages below, mapped from package.xml's
# run dependencies (the script stops on one it does not know).
# Install: sudo apt-get install ./ros-pf-localization_*.deb
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd -P)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
export PATH=/usr/bin:/bin:$PATH LC_ALL=C.UTF-8

die() { echo "make_deb: $*" >&2; exit 2; }

ws=$(pf_default_ws "$repo")
out=$ws
build=
jobs=2
while [ $# -gt 0 ]; do
  case $1 in
    --out) [ $# -ge 2 ] || die "--out needs a folder"; out=$2; shift 2 ;;
    --build-dir) [ $# -ge 2 ] || die "--build-dir needs a folder"; build=$2; shift 2 ;;
    -j) [ $# -ge 2 ] || die "-j needs a number"; jobs=$2; shift 2 ;;
    -j[0-9]*) jobs=${1#-j}; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
done
[[ $jobs =~ ^[1-9][0-9]*$ ]] || die "-j wants a positive number, not '$jobs'"
build=${build:-$ws/build_deb}
case "$(realpath -m "$build")/" in
  "$repo"/*) die "the build folder $build is inside the repository; pick one outside $repo (--build-dir)" ;;
esac

for tool in cmake make dpkg-deb dpkg-shlibdeps dpkg-architecture strip readelf /usr/bin/python3; do
  command -v "$tool" >/dev/null || die "$tool is missing: sudo bash scripts/install_deps.sh (dpkg-dev, cmake, binutils)"
done

# --- What package.xml says ----------------------------------------------------
# name, version, maintainer, license, description, then one run dependency a line
# (<depend> and <exec_depend>, which catkin_pkg lists as exec_depends).
meta_out=$(/usr/bin/python3 - "$repo/package.xml" <<'EOF'
import sys, textwrap
from catkin_pkg.package import parse_package
p = parse_package(sys.argv[1])
m = p.maintainers[0]
print(p.name)
print(p.version)
print('%s <%s>' % (m.name, m.email))
print(' and '.join(p.licenses))
desc = ' '.join(p.description.split())
print(' ' + '\n '.join(textwrap.wrap(desc, 76)).replace('\n', '\\n'))
for d in sorted({d.name for d in p.exec_depends}):
    print(d)
EOF
) || die "cannot read $repo/package.xml (python3-catkin-pkg installed?)"
mapfile -t meta <<<"$meta_out"
name=${meta[0]} version=${meta[1]} maintainer=${meta[2]} license=${meta[3]} longdesc=${meta[4]}
rundeps=("${meta[@]:5}")
[ "$name" = pf_localization ] || die "package.xml names '$name', not pf_localization"
[[ $version =~ ^[0-9]+\.[0-9]+\.[0-9]+$ ]] || die "package.xml's version '$version' is not X.Y.Z"
deb_name=ros-${name//_/-}
arch=$(dpkg --print-architecture)
multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null)

# package.xml's run dependencies as Debian packages. Those whose C++ library
# the binaries link come from dpkg-shlibdeps; message packages and header-only
# libraries are compiled in and need nothing at run time.
depends=(python3 python3-roslaunch python3-rosbag python3-numpy python3-yaml)
recommends=(rosbash python3-matplotlib python3-pil python3-dynamic-reconfigure rviz)
suggests=(python3-rostopic)
for d in "${rundeps[@]}"; do
  case $d in
    # linked C++ libraries: dpkg-shlibdeps
    roscpp|rosbag|message_filters|tf2|tf2_ros|dynamic_reconfigure|yaml-cpp) ;;
    # messages and services, tf2_geometry_msgs, Eigen: headers, compiled in
    tf2_msgs|sensor_msgs|nav_msgs|geometry_msgs|std_msgs|std_srvs|diagnostic_msgs|rosgraph_msgs|tf2_geometry_msgs|eigen) ;;
    # pf_hypotheses' message: compiled into pf_node; its generated Python
    # module (rostopic echo, a Python client) imports genpy and the message
    # packages it is built from
    message_runtime) depends+=(python3-genpy python3-std-msgs python3-geometry-msgs) ;;
    roslaunch) ;;          # python3-roslaunch (above)
    python3-numpy|python3-yaml) ;;  # above
    # pf_tune only (Optuna, Dask, its plots and progress bar): suggested, not
    # forced on a robot that only localizes
    python3-optuna|python3-distributed|python3-sklearn|python3-scipy|python3-tqdm) suggests+=("$d") ;;
    python3-matplotlib) ;; # pf_evaluate's plots only: recommended
    rviz) ;;               # bag_demo.launch rviz:=true only: recommended (Qt, OGRE)
    *) die "package.xml's run dependency '$d' has no Debian package in scripts/make_deb.sh: add it to the table" ;;
  esac
done
# rosbag play (bag_demo.launch) and pf_evaluate's bag reader: python3-rosbag (above).
# The generated dynamic_reconfigure client module: python3-dynamic-reconfigure.
# (The rostests and their checker nodes stay in the source tree: no python3-rostest.)
known=$(dpkg-query -W -f '${Package}\n' 2>/dev/null)
for p in "${depends[@]}" "${recommends[@]}" "${suggests[@]}"; do
  grep -qx "$p" <<<"$known" || apt-cache show --no-all-versions "$p" >/dev/null 2>&1 ||
    die "the Debian package $p (a dependency of $deb_name) is unknown to apt here"
done

# --- Build and install into a staging tree -------------------------------------
tmp=$(mktemp -d "${TMPDIR:-/tmp}/pf_make_deb.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
# debhelper's layout (dpkg-shlibdeps expects it): debian/control, debian/PACKAGE/.
stage=$tmp/src/debian/$deb_name
mkdir -p "$build" "$stage"
echo "make_deb: building $name $version in $build" >&2
# A clean environment: a sourced workspace (CMAKE_PREFIX_PATH, ROS_PACKAGE_PATH,
# PYTHONPATH) must not leak into a package built against /usr.
clean_env=(env -i HOME="${HOME:-/tmp}" PATH=/usr/bin:/bin LANG=C.UTF-8 ${CCACHE_DIR:+CCACHE_DIR=$CCACHE_DIR})
# Laid out as a catkin workspace is (src/pf_localization, build/pf_localization,
# devel/), so that ccache finds the objects a workspace compiled
# (CMakeLists.txt, PF_CCACHE): the compile lines are the same relative to $build.
mkdir -p "$build/src" "$build/build/$name"
ln -sfn "$repo" "$build/src/$name"
"${clean_env[@]}" cmake -S "$build/src/$name" -B "$build/build/$name" \
  -DCMAKE_INSTALL_PREFIX=/usr -DCMAKE_BUILD_TYPE=Release -DCATKIN_DEVEL_PREFIX="$build/devel" \
  -DCATKIN_BUILD_BINARY_PACKAGE=ON -DCATKIN_ENABLE_TESTING=OFF \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 >"$build/make_deb_cmake.log" 2>&1 ||
  { tail -n 30 "$build/make_deb_cmake.log" >&2; die "cmake failed (log: $build/make_deb_cmake.log)"; }
"${clean_env[@]}" make -C "$build/build/$name" -j"$jobs" >"$build/make_deb_build.log" 2>&1 ||
  { grep -E 'error|Error' "$build/make_deb_build.log" | head -n 20 >&2; die "build failed (log: $build/make_deb_build.log)"; }
"${clean_env[@]}" DESTDIR="$stage" make -C "$build/build/$name" install >"$build/make_deb_install.log" 2>&1 ||
  { tail -n 20 "$build/make_deb_install.log" >&2; die "make install failed (log: $build/make_deb_install.log)"; }

# Everything under /usr, and no workspace files (setup.bash, .catkin, ...): a
# Debian package is found by the default search paths, not sourced.
stray=$(cd "$stage" && find . -mindepth 1 -maxdepth 1 ! -name usr)
[ -z "$stray" ] || die "make install put files outside /usr: $stray"
stray=$(cd "$stage/usr" && find . -maxdepth 1 -type f)
[ -z "$stray" ] || die "make install put workspace files in /usr: $stray"
[ -f "$stage/usr/share/$name/package.xml" ] || die "no /usr/share/$name/package.xml in the staging tree"
[ -x "$stage/usr/lib/$name/pf_node" ] || die "no /usr/lib/$name/pf_node in the staging tree"
[ -e "$stage/usr/lib/$multiarch/libpf_core.so" ] || die "no /usr/lib/$multiarch/libpf_core.so in the staging tree"

# As dh_strip and dh_python3 do: binaries stripped, no byte-code.
find "$stage" -name __pycache__ -prune -exec rm -rf {} +
find "$stage" -name '*.pyc' -delete
elves=()
while IFS= read -r -d '' f; do
  if [ "$(head -c 4 "$f" | od -An -c | tr -d ' ')" = '177ELF' ]; then elves+=("$f"); fi
done < <(find "$stage" -type f -print0)
[ ${#elves[@]} -gt 0 ] || die "no ELF file in the staging tree"
for f in "${elves[@]}"; do
  strip --strip-unneeded --remove-section=.comment --remove-section=.note "$f"
  if readelf -d "$f" | grep -qE '\((RPATH|RUNPATH)\)'; then
    die "$f keeps an RPATH: $(readelf -d "$f" | grep -E 'R(UN)?PATH')"
  fi
done

doc=$stage/usr/share/doc/$deb_name
mkdir -p "$doc"
commit=$(git -C "$repo" rev-parse --short HEAD 2>/dev/null || echo unknown)
cat >"$doc/copyright" <<EOF
Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/
Upstream-Name: $name
Upstream-Contact: $maintainer

Files: *
Copyright: the $name developers
License: $license
 See /usr/share/common-licenses/BSD for the BSD license.
EOF
printf '%s (%s) unstable; urgency=medium\n\n  * Built from git %s by scripts/make_deb.sh.\n\n -- %s  %s\n' \
  "$deb_name" "$version" "$commit" "$maintainer" "$(date -R)" | gzip -9n >"$doc/changelog.Debian.gz"

# --- Control file -----------------------------------------------------------------
# dpkg-shlibdeps wants a debian/control; our own libraries are found in the
# staging tree (-S) and so bring no dependency. It warns that their names
# (libpf_core.so: catkin's, unversioned) carry no version: they are private
# to this package, nothing else links them through a shlibs file.
# (DEBIAN/ marks the staging tree as the package's root.)
mkdir -p "$stage/DEBIAN"
printf 'Source: %s\n\nPackage: %s\nArchitecture: any\n' "$deb_name" "$deb_name" >"$tmp/src/debian/control"
shlibs=$(cd "$tmp/src" && dpkg-shlibdeps -O -S"$stage" -l"$stage/usr/lib/$multiarch" "${elves[@]#"$tmp/src/"}" 2>"$tmp/shlibdeps.err") ||
  { cat "$tmp/shlibdeps.err" >&2; die "dpkg-shlibdeps failed"; }
grep -vE "is not used by the|extract name and version from library name 'libpf_" "$tmp/shlibdeps.err" >&2 || true
shlibs=${shlibs#shlibs:Depends=}
[ -n "$shlibs" ] || die "dpkg-shlibdeps found no shared library dependency"
join() { local IFS=,; local s="$*"; printf '%s' "${s//,/, }"; }

cat >"$stage/DEBIAN/control" <<EOF
Package: $deb_name
Version: $version
Architecture: $arch
Maintainer: $maintainer
Installed-Size: $(du -sk "$stage/usr" | cut -f1)
Depends: $shlibs, $(join "${depends[@]}")
Recommends: $(join "${recommends[@]}")
Suggests: $(join "${suggests[@]}")
Section: science
Priority: optional
Description: ROS 1 particle-filter (Monte Carlo) localization on a known map
$longdesc
 .
 Installed like Debian's own ROS packages: \`roslaunch pf_localization
 bag_demo.launch\` runs the bundled bag without sourcing anything.
EOF
sed -i 's/\\n/\n/g' "$stage/DEBIAN/control"
(cd "$stage" && find usr -type f -print0 | sort -z | xargs -0 md5sum) >"$stage/DEBIAN/md5sums"
# Shared libraries in /usr/lib/<multiarch>: refresh ld.so's cache (as dh_makeshlibs does).
echo 'activate-noawait ldconfig' >"$stage/DEBIAN/triggers"
# Debian's modes: nothing group- or world-writable.
chmod -R go-w "$stage"
find "$stage" -type d -exec chmod 755 {} +

mkdir -p "$out"
deb=$(cd "$out" && pwd)/${deb_name}_${version}_${arch}.deb
dpkg-deb --root-owner-group -Zxz --build "$stage" "$deb" >/dev/null
echo "make_deb: $(du -h "$deb" | cut -f1) Depends: $(dpkg-deb -f "$deb" Depends)" >&2
echo "$deb"
