#!/usr/bin/python3
"""Tests of pf_localization.locate: which pf_bag_runner and package folder a tool uses, by where
it was started from (a devel or install space's lib/pf_localization/, or the repository's scripts/).

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs nothing built: the spaces are fakes in a temporary folder.
"""
import os
import shutil
import sys
import tempfile
import unittest
from unittest import mock

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
sys.path.insert(0, os.path.join(REPO, 'src'))
from pf_localization import locate  # noqa: E402


def executable(path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w') as f:
        f.write('#!/bin/sh\n')
    os.chmod(path, 0o755)
    return path


class LocateTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='pf_locate_test_')
        # A cache with a runner in it, where scripts/build.sh would have put one for this repository:
        # only a tool run from the repository's scripts/ may use it.
        self.env = {'HOME': self.tmp, 'XDG_CACHE_HOME': os.path.join(self.tmp, 'cache'), 'PATH': '/usr/bin',
                    'ROS_PACKAGE_PATH': '', 'CMAKE_PREFIX_PATH': ''}
        with mock.patch.dict(os.environ, self.env, clear=True):
            self.cached = executable(os.path.join(locate.default_workspace(REPO), 'devel', 'lib',
                                                  'pf_localization', 'pf_bag_runner'))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def env_with(self, **kw):
        env = dict(self.env)
        env.update(kw)
        return mock.patch.dict(os.environ, env, clear=True)

    def test_an_installed_tool_uses_the_runner_beside_it_not_the_scripts_cache(self):
        lib = os.path.join(self.tmp, 'ws', 'install', 'lib', 'pf_localization')
        tool, runner = os.path.join(lib, 'pf_tune'), executable(os.path.join(lib, 'pf_bag_runner'))
        executable(tool)
        with self.env_with(PF_WS=os.path.join(self.tmp, 'elsewhere')):
            self.assertIsNone(locate.repository(tool))
            self.assertEqual(locate.find_runner(tool), runner)

    def test_an_installed_tool_without_a_runner_beside_it_takes_the_ros_environments(self):
        tool = executable(os.path.join(self.tmp, 'other', 'lib', 'pf_localization', 'benchmark_datasets'))
        prefix = os.path.join(self.tmp, 'ws', 'devel')
        runner = executable(os.path.join(prefix, 'lib', 'pf_localization', 'pf_bag_runner'))
        with self.env_with(CMAKE_PREFIX_PATH=os.pathsep.join([os.path.join(self.tmp, 'none'), prefix])):
            self.assertEqual(locate.find_runner(tool), runner)
        with self.env_with():
            with self.assertRaises(locate.NotFound) as cm:
                locate.find_runner(tool)
        message = str(cm.exception)
        self.assertIn(os.path.join(os.path.dirname(tool), 'pf_bag_runner'), message)
        self.assertNotIn(self.cached, message)  # never the scripts' cache
        self.assertIn('catkin_make', message)

    def test_the_repositorys_scripts_use_pf_ws_else_build_shs_cache(self):
        tool = os.path.join(REPO, 'scripts', 'pf_tune')
        self.assertEqual(locate.repository(tool), REPO)
        self.assertEqual(locate.package_dir(tool), REPO)
        with self.env_with():
            self.assertEqual(locate.find_runner(tool), self.cached)
        ws = os.path.join(self.tmp, 'my_ws')
        with self.env_with(PF_WS=ws):
            with self.assertRaises(locate.NotFound) as cm:
                locate.find_runner(tool)
            self.assertIn(os.path.join(ws, 'devel', 'lib', 'pf_localization', 'pf_bag_runner'), str(cm.exception))
            mine = executable(os.path.join(ws, 'devel', 'lib', 'pf_localization', 'pf_bag_runner'))
            self.assertEqual(locate.find_runner(tool), mine)

    def test_an_installed_tools_package_folder_is_its_share_folder(self):
        prefix = os.path.join(self.tmp, 'install')
        tool = executable(os.path.join(prefix, 'lib', 'pf_localization', 'pf_tune'))
        share = os.path.join(prefix, 'share', 'pf_localization')
        os.makedirs(share)
        open(os.path.join(share, 'package.xml'), 'w').close()
        with self.env_with():
            self.assertEqual(locate.package_dir(tool), share)
        self.assertIsNone(locate.shared_data(share))  # an install space has no ../shared/data
        self.assertEqual(locate.shared_data(REPO), os.path.join(os.path.dirname(REPO), 'shared', 'data'))


if __name__ == '__main__':
    unittest.main()
