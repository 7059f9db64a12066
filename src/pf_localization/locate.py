"""Where the Python tools find pf_localization's other parts: pf_bag_runner and the package's
files (bags/, maps/, config/).

A tool is started by its command (sys.argv[0]), which says where it was run from:
  - DEVEL_OR_INSTALL/lib/pf_localization/NAME (rosrun, or that path): pf_bag_runner is the one
    beside it, built in the same space; failing that, the first lib/pf_localization/pf_bag_runner
    of the ROS environment's workspaces (CMAKE_PREFIX_PATH, as catkin_find --libexec searches).
    The package's files are where ROS finds the package (rospack: the source folder for a devel
    space, share/pf_localization for an install space).
  - the repository's scripts/NAME: the repository is the package. pf_bag_runner comes from $PF_WS
    if set, else from the sourced ROS environment when ROS finds this repository as
    pf_localization (a devel space built from it), else from scripts/build.sh's own workspace
    (its cache folder: scripts/workspace.bash). Only this case ever looks in that cache.
"""
import hashlib
import os

PACKAGE = 'pf_localization'
RUNNER = 'pf_bag_runner'


class NotFound(Exception):
    """pf_bag_runner is nowhere the tool looked; the message says where it looked."""


def _executable(path):
    return os.path.isfile(path) and os.access(path, os.X_OK)


def _command(command):
    import sys
    return os.path.realpath(command if command is not None else sys.argv[0])


def repository(command=None):
    """The repository's root if `command` (default sys.argv[0]) is its scripts/NAME, else None."""
    scripts = os.path.dirname(_command(command))
    root = os.path.dirname(scripts)
    if os.path.basename(scripts) == 'scripts' and os.path.isfile(os.path.join(root, 'package.xml')) \
            and os.path.isfile(os.path.join(root, 'src', PACKAGE, '__init__.py')):
        return root
    return None


def default_workspace(repo):
    """scripts/build.sh's workspace when PF_WS is not set: pf_cache_dir in scripts/workspace.bash."""
    real = os.path.realpath(repo)
    cache = os.environ.get('XDG_CACHE_HOME') or os.path.join(os.environ.get('HOME') or '/tmp', '.cache')
    digest = hashlib.sha1(real.encode()).hexdigest()[:10]
    return os.path.join(cache, PACKAGE, '%s-%s' % (os.path.basename(real), digest), 'ws')


def ros_package_path():
    """The folder ROS finds pf_localization in (rospack, over ROS_PACKAGE_PATH), or None."""
    try:
        import rospkg
        return rospkg.RosPack().get_path(PACKAGE)
    except Exception:  # no rospkg, no ROS environment, or the package is not in it
        return None


def _environment_runners():
    prefixes = [p for p in os.environ.get('CMAKE_PREFIX_PATH', '').split(os.pathsep) if p]
    return [os.path.join(p, 'lib', PACKAGE, RUNNER) for p in prefixes]


def find_runner(command=None):
    """pf_bag_runner's path for the tool started as `command` (default sys.argv[0]); raises
    NotFound, naming every place looked at, when there is none."""
    cmd = _command(command)
    repo = repository(cmd)
    looked = []
    if repo is None:
        candidates = [os.path.join(os.path.dirname(cmd), RUNNER)] + _environment_runners()
    elif os.environ.get('PF_WS'):
        candidates = [os.path.join(os.environ['PF_WS'], 'devel', 'lib', PACKAGE, RUNNER)]
    else:
        ros = ros_package_path()
        mine = ros is not None and os.path.realpath(ros) == os.path.realpath(repo)
        candidates = (_environment_runners() if mine else []) + \
            [os.path.join(default_workspace(repo), 'devel', 'lib', PACKAGE, RUNNER)]
    for c in candidates:
        if _executable(c):
            return c
        looked.append(c)
    if repo is None:
        hint = 'build the package in this workspace (catkin_make) and source its setup.bash'
    else:
        hint = 'build it with scripts/build.sh (or set PF_WS to the workspace)'
    raise NotFound('%s not found (looked at %s): %s' % (RUNNER, ', '.join(looked) or 'nothing', hint))


def package_dir(command=None):
    """The package's folder (bags/, maps/, config/): the repository, or where ROS finds the
    package, or share/pf_localization beside the command's lib/pf_localization; None if none."""
    cmd = _command(command)
    repo = repository(cmd)
    if repo is not None:
        return repo
    ros = ros_package_path()
    if ros is not None:
        return ros
    share = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(cmd))), 'share', PACKAGE)
    return share if os.path.isfile(os.path.join(share, 'package.xml')) else None


def shared_data(package):
    """The real recordings' default folder, beside a source checkout (../shared/data, from where
    the checkout really is: a workspace's src/ may hold a link to it), or None for an install
    space's share folder."""
    if package is None or not os.path.isfile(os.path.join(package, 'CMakeLists.txt')):
        return None
    return os.path.join(os.path.dirname(os.path.realpath(package)), 'shared', 'data')
