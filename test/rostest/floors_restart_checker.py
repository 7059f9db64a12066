#!/usr/bin/python3
"""rostest checker: pf_node with a building's floors (floors_file) restarts on the floor it saved its
pose on, at that pose, and with each floor's change layer.

Starts the pf_node binary itself (as map_changes_restart_checker.py does), named `node`, with
config/pf.yaml's defaults, floors_file `floors`, save_pose_rate 2 Hz and map_changes_file in a fresh
temporary folder, under this test's master with /use_sim_time set:
  1. pf_node from the true pose at `first_from` s of `bag` (on the initial floor), the bag played at
     `rate` up to `restart_at` s: at the bag's ride (its /floor names another floor) change_floor is
     called with the true pose then. SIGINT: it must exit 0 and leave ~saved_pose_map naming the
     floor it was on.
  2. pf_node again, under the same name (the saved ~initial_pose_* and ~saved_pose_map are read
     back): before any scan pf_floor must name the saved floor, and its log say it resumes from the
     saved pose there; then the bag from `restart_at` s for `second_seconds` s: the first pf_pose
     must be within `max_first_error` m of the ground truth (interpolated at its stamp: the robot
     moved on between the two runs' scans), and every one from `settle` s after the restart within
     `max_error` m.
Each floor's change layer (pf_map_changes) goes to its own file beside map_changes_file: run 2
publishes the upper floor's before any scan, and, on change_floor to the ground floor after the bag,
the ground floor's (left at run 1's ride), each with at least `min_share` of the cells run 1's last
one of that floor had seen.
  3. pf_node on a floors file whose upper floor has another map (`other_map`): on change_floor there
     it says once, however many rides, that the upper floor's layer was learned on another map.
  4. pf_node on `floors` with a saved pose on a floor it does not have: it starts on the initial
     floor, and says why once.
The nodes' logs are read from their output.

Private params: bag, floors, other_map, node (pf_floors), min_share (0.9), first_from [s of the bag] (30), restart_at (44),
second_seconds (16), rate (2), max_first_error [m] (0.5), settle [s] (1), max_error [m] (0.05),
wait [s of wall time for each step] (30).
"""
import bisect
import math
import os
import shutil
import sys
import tempfile
import threading
import time
import unittest

import roslib.packages
import rosbag
import rospy
import rostest
import yaml
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from pf_localization.srv import ChangeFloor
from nav_msgs.msg import OccupancyGrid
from std_msgs.msg import String

from node_runs import NodeRuns, binary
from pose_checker_poses import yaw_of

PKG = 'pf_localization'
NAME = 'floors_restart_checker'


def truth_of(bag_path):
    """The bag's start (s) and its ground truth: sorted stamps and (x, y, yaw)."""
    stamps, poses = [], []
    with rosbag.Bag(bag_path) as bag:
        start = bag.get_start_time()
        for _, msg, _ in bag.read_messages(topics=['/ground_truth']):
            stamps.append(msg.header.stamp.to_sec())
            p = msg.pose
            poses.append((p.position.x, p.position.y, yaw_of(p.orientation)))
    return start, stamps, poses


class Watch:
    """pf_floor, pf_pose, the bag's /floor and /ground_truth, as they arrive."""

    def __init__(self):
        self.lock = threading.Lock()
        self.floors = []       # pf_floor's values since the last clear()
        self.poses = []        # (stamp s, x, y) of pf_pose since the last clear()
        self.truth = None      # the latest /ground_truth
        self.bag_floor = []    # the bag's /floor names since the last clear()
        rospy.Subscriber('/pf_floor', String, self._on_floor, queue_size=10)
        rospy.Subscriber('/pf_pose', PoseWithCovarianceStamped, self._on_pose, queue_size=100)
        rospy.Subscriber('/ground_truth', PoseStamped, self._on_truth, queue_size=10)
        rospy.Subscriber('/floor', String, self._on_bag_floor, queue_size=10)
        self.layers = []       # pf_map_changes' messages since the last clear()
        rospy.Subscriber('/pf_map_changes', OccupancyGrid, self._on_layer, queue_size=10)

    def clear(self):
        with self.lock:
            self.floors, self.poses, self.bag_floor, self.layers = [], [], [], []

    def _on_layer(self, msg):
        with self.lock:
            self.layers.append(msg)

    def layer(self):
        """The cells the latest pf_map_changes has seen, and how many came."""
        with self.lock:
            if not self.layers:
                return None, 0
            return {i for i, v in enumerate(self.layers[-1].data) if v != -1}, len(self.layers)

    def _on_floor(self, msg):
        with self.lock:
            self.floors.append(msg.data)

    def _on_pose(self, msg):
        p = msg.pose.pose.position
        with self.lock:
            self.poses.append((msg.header.stamp.to_sec(), p.x, p.y))

    def _on_truth(self, msg):
        with self.lock:
            self.truth = msg

    def _on_bag_floor(self, msg):
        with self.lock:
            self.bag_floor.append((msg.data, self.truth))


class FloorsRestartTest(NodeRuns, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.pf_node = binary('pf_node')
        with open(os.path.join(roslib.packages.get_pkg_dir(PKG), 'config', 'pf.yaml')) as f:
            cls.defaults = yaml.safe_load(f)
        cls.bag = rospy.get_param('~bag')
        cls.floors = rospy.get_param('~floors')
        cls.other_map = rospy.get_param('~other_map')
        cls.min_share = float(rospy.get_param('~min_share', 0.9))
        cls.node = rospy.get_param('~node', 'pf_floors')
        cls.first_from = float(rospy.get_param('~first_from', 30.0))
        cls.restart_at = float(rospy.get_param('~restart_at', 44.0))
        cls.second_seconds = float(rospy.get_param('~second_seconds', 16.0))
        cls.rate = float(rospy.get_param('~rate', 2.0))
        cls.max_first_error = float(rospy.get_param('~max_first_error', 0.5))
        cls.settle = float(rospy.get_param('~settle', 1.0))
        cls.max_error = float(rospy.get_param('~max_error', 0.05))
        cls.wait = float(rospy.get_param('~wait', 30.0))
        cls.start, cls.truth_t, cls.truth = truth_of(cls.bag)
        cls.dir = tempfile.mkdtemp(prefix='floors_restart_')
        cls.file = os.path.join(cls.dir, 'layer', cls.node + '.map_changes')
        cls.floor_file = {f: os.path.join(cls.dir, 'layer', '%s.%s.map_changes' % (cls.node, f))
                          for f in ('ground', 'upper')}
        cls.seen = {}  # floor -> the cells run 1's last pf_map_changes on it had seen
        cls.watch = Watch()
        cls.procs = []
        cls.report = []

    @classmethod
    def tearDownClass(cls):
        cls.kill_all()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def truth_at(self, t):
        """The ground truth at stamp `t`, interpolated (None outside the bag's)."""
        i = bisect.bisect_left(self.truth_t, t)
        if i == 0 or i >= len(self.truth_t):
            return None
        t0, t1 = self.truth_t[i - 1], self.truth_t[i]
        a = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
        (x0, y0, _), (x1, y1, yaw1) = self.truth[i - 1], self.truth[i]
        return x0 + a * (x1 - x0), y0 + a * (y1 - y0), yaw1

    def start_pf_node(self, run):
        return self.start_proc(run, [self.pf_node, '__name:=' + self.node])

    def play(self, name, from_s, seconds):
        player = self.start_proc(name, ['rosbag', 'play', '--clock', '-q', '-r', str(self.rate),
                                        '-s', str(from_s), '-u', str(seconds), self.bag])
        player.wait(timeout=seconds / self.rate + self.wait)
        time.sleep(1.0)

    def wait_for(self, what, check, run):
        deadline = time.monotonic() + self.wait
        while time.monotonic() < deadline:
            if check():
                return
            time.sleep(0.1)
        self.fail('%s: never %s; its output:\n%s' % (run, what, self.output(run)))

    def wait_for_line(self, run, text):
        self.wait_for('logged "%s"' % text, lambda: text in self.output(run), run)

    def wait_for_floor(self, run, floor):
        def named():
            with self.watch.lock:
                return bool(self.watch.floors) and self.watch.floors[-1] == floor
        self.wait_for('named floor %s on pf_floor' % floor, named, run)

    def change_floor(self, run, floor):
        """change_floor to `floor` without a pose."""
        res = rospy.ServiceProxy('/change_floor', ChangeFloor)(floor, PoseWithCovarianceStamped())
        self.assertTrue(res.success, '%s: change_floor %s: %s' % (run, floor, res.message))

    def wait_for_layer(self, run, after):
        """The cells pf_map_changes has seen once more than `after` messages came."""
        self.wait_for('published pf_map_changes', lambda: self.watch.layer()[1] > after, run)
        return self.watch.layer()

    def check_restored(self, run, floor, seen):
        self.wait_for_line(run, "floor '%s': restored the map changes learned on this map from %s"
                           % (floor, self.floor_file[floor]))
        kept = len(self.seen[floor] & seen) / float(len(self.seen[floor]))
        self.report.append('%s: floor %s\'s layer restored: %d cells seen, %.3f of run 1\'s %d'
                           % (run.replace('run', 'run '), floor, len(seen), kept,
                              len(self.seen[floor])))
        self.assertGreaterEqual(kept, self.min_share, '; '.join(self.report))

    def ride(self, run):
        """change_floor at each of the bag's rides seen since the last clear(), with the true pose."""
        with self.watch.lock:
            rides, self.watch.bag_floor = self.watch.bag_floor, []
        if rides:
            self.seen['ground'] = self.watch.layer()[0]
        for floor, truth in rides:
            self.assertIsNotNone(truth, 'no ground truth before the ride to ' + floor)
            pose = PoseWithCovarianceStamped()
            pose.header = truth.header
            pose.pose.pose = truth.pose
            res = rospy.ServiceProxy('/change_floor', ChangeFloor)(floor, pose)
            self.assertTrue(res.success, '%s: change_floor %s: %s' % (run, floor, res.message))
        return [floor for floor, _ in rides]

    def first_run(self):
        for key, value in self.defaults.items():
            rospy.set_param('/%s/%s' % (self.node, key), value)
        for key in ('initial_pose_x', 'initial_pose_y', 'initial_pose_a', 'saved_pose_map'):
            if rospy.has_param('/%s/%s' % (self.node, key)):
                rospy.delete_param('/%s/%s' % (self.node, key))
        rospy.set_param('/%s/floors_file' % self.node, self.floors)
        rospy.set_param('/%s/save_pose_rate' % self.node, 2.0)
        rospy.set_param('/%s/map_changes_file' % self.node, self.file)
        x, y, yaw = self.truth_at(self.start + self.first_from)
        for key, value in zip(('initial_pose_x', 'initial_pose_y', 'initial_pose_a'), (x, y, yaw)):
            rospy.set_param('/%s/%s' % (self.node, key), value)
        self.watch.clear()
        proc = self.start_pf_node('run1')
        self.wait_for_floor('run1', 'ground')
        rospy.wait_for_service('/change_floor', timeout=self.wait)
        # The ride is called as the bag's /floor names the new floor (the robot stands in the lift).
        riding = threading.Event()

        def rides():
            while not riding.is_set():
                time.sleep(0.05)
                self.ride('run1')
        thread = threading.Thread(target=rides)
        thread.start()
        try:
            self.play('play1', self.first_from, self.restart_at - self.first_from)
        finally:
            riding.set()
            thread.join()
        self.wait_for_floor('run1', 'upper')
        self.seen['upper'] = self.watch.layer()[0]
        self.interrupt('run1', proc)
        for floor in ('ground', 'upper'):
            self.assertTrue(self.seen[floor], 'run 1 saw no cell on floor ' + floor)
            self.assertTrue(os.path.exists(self.floor_file[floor]), self.floor_file[floor])
        self.assertFalse(os.path.exists(self.file), 'a floor\'s layer in the single map\'s file')
        saved = rospy.get_param('/%s/saved_pose_map' % self.node)
        self.report.append('run 1 saved: ...' + saved[saved.index('; pose'):])
        self.assertTrue(saved.endswith('; floor upper'), saved)

    def second_run(self):
        self.watch.clear()
        proc = self.start_pf_node('run2')
        self.wait_for_floor('run2', 'upper')
        self.wait_for_line('run2', "starting on floor 'upper', where the earlier run saved its pose")
        self.wait_for_line('run2', "resuming from the pose saved by an earlier run at")
        seen, _ = self.wait_for_layer('run2', 0)
        with self.watch.lock:  # the pose at start-up is stamped 0
            updates = [p for p in self.watch.poses if p[0] > 0]
        self.assertFalse(updates, 'run 2: an update before the bag played')
        self.check_restored('run2', 'upper', seen)
        self.play('play2', self.restart_at, self.second_seconds)
        with self.watch.lock:
            poses, floors = list(self.watch.poses), list(self.watch.floors)
        self.assertEqual(['upper'], floors, 'run 2: pf_floor named %s' % floors)
        errors = []
        for t, x, y in poses:
            truth = self.truth_at(t)
            if truth is not None:
                errors.append((t - self.start, math.hypot(x - truth[0], y - truth[1])))
        self.assertGreaterEqual(len(errors), 5, 'run 2: %d poses on pf_pose' % len(errors))
        # The robot moved on between run 1's last scan and run 2's first: that gap's error first.
        first = errors[0]
        settled = [e for e in errors if e[0] >= self.restart_at + self.settle]
        worst = max(settled, key=lambda e: e[1])
        self.report.append('run 2: pf_floor %s, %d poses; the first at %.1f s of the bag off by '
                           '%.3f m; from %.1f s on, the worst %.3f m at %.1f s'
                           % (floors, len(errors), first[0], first[1], self.restart_at + self.settle,
                              worst[1], worst[0]))
        self.assertLessEqual(first[1], self.max_first_error, '; '.join(self.report))
        self.assertLessEqual(worst[1], self.max_error, '; '.join(self.report))
        # The ground floor's layer, left at run 1's ride, comes back with its map.
        count = self.watch.layer()[1]
        self.change_floor('run2', 'ground')
        seen, _ = self.wait_for_layer('run2', count)
        self.check_restored('run2', 'ground', seen)
        return proc

    def third_run(self):
        """The upper floor's map changed: its layer is refused, said once."""
        with open(self.floors) as f:
            floors = yaml.safe_load(f)
        folder = os.path.dirname(self.floors)
        for floor in floors['floors']:
            floor['map'] = os.path.join(folder, floor['map'])
            if floor['name'] == 'upper':
                floor['map'] = self.other_map
        changed = os.path.join(self.dir, 'changed_floors.yaml')
        with open(changed, 'w') as f:
            yaml.safe_dump(floors, f)
        rospy.set_param('/%s/floors_file' % self.node, changed)
        rospy.delete_param('/%s/saved_pose_map' % self.node)  # the pose as given: ground floor
        self.watch.clear()
        proc = self.start_pf_node('run3')
        self.wait_for_floor('run3', 'ground')
        rospy.wait_for_service('/change_floor', timeout=self.wait)
        for floor in ('upper', 'ground', 'upper'):
            self.change_floor('run3', floor)
        self.wait_for_floor('run3', 'upper')
        refused = "floor 'upper': the map changes in %s were learned on another map" \
            % self.floor_file['upper']
        lines = [l for l in self.output('run3').splitlines() if refused in l]
        self.assertEqual(1, len(lines), 'run 3 said %d times "%s":\n%s'
                         % (len(lines), refused, self.output('run3')))
        self.assertIn('WARN', lines[0])
        self.report.append('run 3: ' + lines[0][lines[0].index('pf_node:'):][:150] + '...')
        self.interrupt('run3', proc)
        rospy.set_param('/%s/floors_file' % self.node, self.floors)

    def fourth_run(self):
        """A pose saved on a floor the floors file does not have: the initial floor, said once."""
        pose = [rospy.get_param('/%s/%s' % (self.node, k))
                for k in ('initial_pose_x', 'initial_pose_y', 'initial_pose_a')]
        rospy.set_param('/%s/saved_pose_map' % self.node,
                        'some map; pose %r %r %r; floor attic' % tuple(pose))
        self.watch.clear()
        proc = self.start_pf_node('run4')
        self.wait_for_floor('run4', 'ground')
        why = "it was saved on floor 'attic', which the floors file does not have. " \
              "Starting on floor 'ground' with global localization"
        self.wait_for_line('run4', why)
        lines = [l for l in self.output('run4').splitlines() if 'attic' in l]
        self.assertEqual(1, len(lines), 'run 4:\n' + self.output('run4'))
        self.assertIn('WARN', lines[0])
        self.report.append('run 4: ' + lines[0][lines[0].index('pf_node:'):])
        self.interrupt('run4', proc)

    def test_restart(self):
        self.first_run()
        second = self.second_run()
        self.interrupt('run2', second)
        self.third_run()
        self.fourth_run()
        print('floors_restart_checker:\n  ' + '\n  '.join(self.report))
        sys.stdout.flush()


if __name__ == '__main__':
    rospy.init_node(NAME)
    rostest.rosrun(PKG, NAME, FloorsRestartTest, sys.argv)
