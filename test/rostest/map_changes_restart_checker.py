#!/usr/bin/python3
"""rostest checker: pf_node's layer of the map's changes survives a restart, is cleared on request,
and is not restored on another map.

Starts the pf_node binary itself (as bad_params_checker.py does), with config/pf.yaml's defaults,
save_pose_rate 2 Hz and map_changes_file in a fresh temporary folder, and a map_publisher per map
(each on its own topic), under this test's master with /use_sim_time set:
  1. pf_node on `map`, the first `play_seconds` of `bag` played at `rate` from `initial_pose`: its
     layer learns; then SIGINT: it must exit 0 and leave the file.
  2. pf_node on the same map, no bag: before any scan it must publish pf_map_changes with at least
     `min_share` of the cells the last layer of run 1 marked new or gone still marked (the file
     may hold a few scans more than that message), and log that it restored them from the file.
     Then clear_map_changes: pf_map_changes with no cell marked; SIGINT.
  3. pf_node on the same map again: it restores the cleared layer (the file was overwritten), no
     cell marked; SIGINT.
  4. pf_node on `other_map`: it must say the file was learned on another map, and publish no
     marked cell; SIGINT.
The nodes' logs are read from their output (a subscriber to /rosout may connect after the line).

Private params: bag, map, other_map, initial_pose ("x y yaw"), play_seconds [s of the bag] (40),
rate (8), min_share (0.9), wait [s of wall time for each step] (25).
"""
import os
import shutil
import sys
import tempfile
import threading
import time
import unittest

import roslib.packages
import rospy
import rostest
import yaml
from diagnostic_msgs.msg import DiagnosticStatus
from nav_msgs.msg import OccupancyGrid
from std_srvs.srv import Empty

from node_runs import NodeRuns, binary

PKG = 'pf_localization'
NAME = 'map_changes_restart_checker'


def marked(msg):
    """The indices of the cells a pf_map_changes message marks new (100) or gone (50)."""
    return {i for i, v in enumerate(msg.data) if v in (100, 50)}


class Layers:
    """The latest pf_map_changes message of each publishing node, by its name."""

    def __init__(self):
        self.lock = threading.Lock()
        self.latest = {}
        self.count = {}
        self.status = {}  # node -> the values of its latest pf_status
        rospy.Subscriber('/pf_map_changes', OccupancyGrid, self._on_layer, queue_size=5)
        rospy.Subscriber('/pf_status', DiagnosticStatus, self._on_status, queue_size=5)

    def _on_status(self, msg):
        with self.lock:
            self.status[msg._connection_header.get('callerid', '')] = {v.key: v.value for v in msg.values}

    def _on_layer(self, msg):
        node = msg._connection_header.get('callerid', '')
        with self.lock:
            self.latest[node] = msg
            self.count[node] = self.count.get(node, 0) + 1

    def get(self, node):
        with self.lock:
            return self.latest.get(node), self.count.get(node, 0)


class MapChangesRestartTest(NodeRuns, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.pf_node = binary('pf_node')
        cls.map_publisher = binary('map_publisher')
        with open(os.path.join(roslib.packages.get_pkg_dir(PKG), 'config', 'pf.yaml')) as f:
            cls.defaults = yaml.safe_load(f)
        cls.bag = rospy.get_param('~bag')
        cls.map = rospy.get_param('~map')
        cls.other_map = rospy.get_param('~other_map')
        cls.pose = [float(v) for v in rospy.get_param('~initial_pose').split()]
        cls.play_seconds = float(rospy.get_param('~play_seconds', 40.0))
        cls.rate = float(rospy.get_param('~rate', 8.0))
        cls.min_share = float(rospy.get_param('~min_share', 0.9))
        cls.wait = float(rospy.get_param('~wait', 25.0))
        cls.dir = tempfile.mkdtemp(prefix='map_changes_restart_')
        cls.file = os.path.join(cls.dir, 'layer', 'pf_node.map_changes')
        cls.layers = Layers()
        cls.procs = []

    @classmethod
    def tearDownClass(cls):
        cls.kill_all()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def start_map(self, name, path):
        return self.start_proc(name, [self.map_publisher, path, '__name:=' + name, 'map:=/' + name])

    def start_pf_node(self, name, map_topic, pose=None):
        for key, value in self.defaults.items():
            rospy.set_param('/%s/%s' % (name, key), value)
        rospy.set_param('/%s/save_pose_rate' % name, 2.0)
        rospy.set_param('/%s/map_changes_file' % name, self.file)
        if pose:
            for key, value in zip(('initial_pose_x', 'initial_pose_y', 'initial_pose_a'), pose):
                rospy.set_param('/%s/%s' % (name, key), value)
        return self.start_proc(name, [self.pf_node, '__name:=' + name, 'map:=/' + map_topic])

    def wait_for_line(self, name, text):
        deadline = time.monotonic() + self.wait
        while time.monotonic() < deadline:
            if text in self.output(name):
                return
            time.sleep(0.1)
        self.fail('%s never logged "%s"; its output:\n%s' % (name, text, self.output(name)))

    def wait_for_layer(self, name, after=0):
        """pf_map_changes from node `name` once it has sent more than `after`."""
        deadline = time.monotonic() + self.wait
        while time.monotonic() < deadline:
            msg, count = self.layers.get('/' + name)
            if count > after:
                return msg, count
            time.sleep(0.1)
        self.fail('no pf_map_changes from %s in %.0f s; its output:\n%s'
                  % (name, self.wait, self.output(name)))

    def test_restart(self):
        report = []
        self.start_map('map_a', self.map)
        # 1. learn from the bag, then stop.
        first = self.start_pf_node('pf_restart_1', 'map_a', self.pose)
        self.wait_for_line('pf_restart_1', 'no map changes saved in ' + self.file)
        player = self.start_proc('player', ['rosbag', 'play', '--clock', '-q', '-r', str(self.rate),
                                       '-u', str(self.play_seconds), self.bag])
        player.wait(timeout=self.play_seconds / self.rate + self.wait)
        time.sleep(1.0)
        learned, _ = self.wait_for_layer('pf_restart_1')
        learned = marked(learned)
        with self.layers.lock:
            status = self.layers.status.get('/pf_restart_1', {})
        self.assertIn('map changes', status, 'pf_status says nothing of the map changes')
        self.assertGreater(float(status['map_cells_new']) + float(status['map_cells_gone']), 0)
        report.append('run 1 pf_status: map changes: ' + status['map changes'])
        self.interrupt('pf_restart_1', first)
        self.assertTrue(learned, 'run 1 learned no change from the bag')
        self.assertTrue(os.path.getsize(self.file) > 0, 'no layer saved at ' + self.file)
        report.append('run 1: %d cells marked, %d bytes saved' % (len(learned), os.path.getsize(self.file)))

        # 2. the same map, no scan: the layer comes back at once; then cleared.
        second = self.start_pf_node('pf_restart_2', 'map_a')
        restored, count = self.wait_for_layer('pf_restart_2')
        restored = marked(restored)
        self.wait_for_line('pf_restart_2', 'restored the map changes learned on this map from ' + self.file)
        line = [l for l in self.output('pf_restart_2').splitlines() if 'restored the map changes' in l][0]
        report.append('run 2: ' + line[line.index('pf_node:'):])
        kept = len(learned & restored) / float(len(learned))
        report.append('run 2: %d cells marked before any scan, %.3f of run 1\'s' % (len(restored), kept))
        self.assertGreaterEqual(kept, self.min_share, '; '.join(report))
        rospy.wait_for_service('/clear_map_changes', timeout=self.wait)
        rospy.ServiceProxy('/clear_map_changes', Empty)()
        cleared, _ = self.wait_for_layer('pf_restart_2', count)
        self.assertEqual(set(), marked(cleared), 'clear_map_changes left cells marked')
        self.wait_for_line('pf_restart_2', 'map changes cleared')
        self.interrupt('pf_restart_2', second)

        # 3. the same map again: the cleared layer was saved over the learned one.
        third = self.start_pf_node('pf_restart_3', 'map_a')
        after_clear, _ = self.wait_for_layer('pf_restart_3')
        self.wait_for_line('pf_restart_3', ': 0 cells new, 0 gone')
        self.assertEqual(set(), marked(after_clear))
        self.interrupt('pf_restart_3', third)

        # 4. another map: the file is not its, the layer starts empty.
        self.start_map('map_b', self.other_map)
        fourth = self.start_pf_node('pf_restart_4', 'map_b')
        self.wait_for_line('pf_restart_4', 'were learned on another map')
        line = [l for l in self.output('pf_restart_4').splitlines() if 'another map' in l][0]
        report.append('run 4: ' + line[line.index('pf_node:'):])
        self.assertIn('WARN', line)
        msg, _ = self.layers.get('/pf_restart_4')
        self.assertTrue(msg is None or not marked(msg), 'run 4 published marked cells')
        self.interrupt('pf_restart_4', fourth)
        print('map_changes_restart_checker:\n  ' + '\n  '.join(report))
        sys.stdout.flush()


if __name__ == '__main__':
    rospy.init_node(NAME)
    rostest.rosrun(PKG, NAME, MapChangesRestartTest, sys.argv)
