#!/usr/bin/python3
"""rostest checker: pf_node's parameters change live (dynamic_reconfigure).

While bags/tracking.bag plays (test/rostest/reconfigure.test), through
dynamic_reconfigure's Python client, as rqt_reconfigure and dynparam do:

1. the server's description has config/pf.yaml's defaults, and its values
   are the node's (launch file's) parameters;
2. at change_at (s of bag time after the first /ground_truth) it sets
   odom_alpha1, laser_sigma_hit and max_particles; the server answers with
   them, and pf_status (after the filter's next update) reports them with
   config_generation 1, while the node keeps tracking: every pf_pose after the
   change lies within max_error (m) of /ground_truth, RMSE below rmse_below;
3. amcl's kld_z sets kld_confidence (Phi(kld_z));
4. at refuse_at it asks for laser_sigma_hit -1 and for min_particles above
   max_particles: both are refused (the answer holds the values in effect,
   the node logs an error with the start-up message "invalid parameter ...")
   and pf_status keeps reporting the accepted values and generation;
5. the node still updates and tracks until end_at;
6. amcl's restore_defaults brings back the start-up values.
"""
import bisect
import math
import os
import sys
import threading
import time
import unittest

import rospy
import rostest
import roslib.packages
import yaml
from diagnostic_msgs.msg import DiagnosticStatus
from dynamic_reconfigure.client import Client
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from rosgraph_msgs.msg import Log

PKG = 'pf_localization'
NAME = 'reconfigure_checker'

NEW_VALUES = {'odom_alpha1': 0.3, 'laser_sigma_hit': 0.15, 'max_particles': 60000}


class ReconfigureTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.node = rospy.get_param('~node', '/pf_node')
        cls.change_at = rospy.get_param('~change_at', 10.0)
        cls.refuse_at = rospy.get_param('~refuse_at', 40.0)
        cls.end_at = rospy.get_param('~end_at', 70.0)
        cls.max_error = rospy.get_param('~max_error', 0.3)
        cls.rmse_below = rospy.get_param('~rmse_below', 0.15)
        cls.wall_timeout = rospy.get_param('~wall_timeout', 150.0)
        cls.lock = threading.Lock()
        cls.truth = []  # (stamp, x, y), in order
        cls.poses = []  # (stamp, x, y) of every pf_pose
        cls.t0 = None
        cls.status = None
        cls.status_count = 0
        cls.log_errors = []
        rospy.Subscriber('/ground_truth', PoseStamped, cls.on_truth, queue_size=100)
        rospy.Subscriber('/pf_pose', PoseWithCovarianceStamped, cls.on_pose, queue_size=100)
        rospy.Subscriber('/pf_status', DiagnosticStatus, cls.on_status, queue_size=10)
        rospy.Subscriber('/rosout', Log, cls.on_log, queue_size=100)

    @classmethod
    def on_truth(cls, msg):
        with cls.lock:
            t = msg.header.stamp.to_sec()
            if cls.t0 is None:
                cls.t0 = t
            cls.truth.append((t, msg.pose.position.x, msg.pose.position.y))

    @classmethod
    def on_pose(cls, msg):
        with cls.lock:
            p = msg.pose.pose.position
            cls.poses.append((msg.header.stamp.to_sec(), p.x, p.y))

    @classmethod
    def truth_at(cls, t):
        """The ground truth at t, interpolated (scans and truth are not stamped alike)."""
        i = bisect.bisect_left(cls.truth, (t,))
        if i == 0 or i == len(cls.truth):
            return None
        (t0, x0, y0), (t1, x1, y1) = cls.truth[i - 1], cls.truth[i]
        if t1 - t0 > 0.25:
            return None
        f = (t - t0) / (t1 - t0)
        return x0 + f * (x1 - x0), y0 + f * (y1 - y0)

    @classmethod
    def on_status(cls, msg):
        with cls.lock:
            cls.status = {kv.key: kv.value for kv in msg.values}
            cls.status_count += 1

    @classmethod
    def on_log(cls, msg):
        if msg.level >= Log.ERROR and msg.name == cls.node:
            with cls.lock:
                cls.log_errors.append(msg.msg)

    def bag_time(self):
        with self.lock:
            if self.t0 is None:
                return None
            return rospy.get_time() - self.t0

    def wait_bag_time(self, t, deadline):
        while not rospy.is_shutdown() and time.time() < deadline:
            now = self.bag_time()
            if now is not None and now >= t:
                return
            time.sleep(0.05)
        self.fail('bag time %.1f s not reached before the wall timeout (at %s)' % (t, self.bag_time()))

    def wait_status(self, predicate, deadline, what):
        while not rospy.is_shutdown() and time.time() < deadline:
            with self.lock:
                status = dict(self.status) if self.status else None
            if status and predicate(status):
                return status
            time.sleep(0.05)
        self.fail('pf_status never showed %s; last: %s' % (what, status))

    def tracking(self, start, end):
        errors = []
        with self.lock:
            for t, x, y in self.poses:
                truth = self.truth_at(t)
                if truth is not None and start <= t - self.t0 <= end:
                    errors.append(math.hypot(x - truth[0], y - truth[1]))
        self.assertGreaterEqual(len(errors), 20, 'only %d poses compared in [%.0f, %.0f] s'
                                % (len(errors), start, end))
        worst = max(errors)
        rmse = math.sqrt(sum(e * e for e in errors) / len(errors))
        print('reconfigure_checker: [%.0f, %.0f] s: %d poses, RMSE %.3f m, worst %.3f m'
              % (start, end, len(errors), rmse, worst))
        self.assertLessEqual(worst, self.max_error, 'lost track in [%.0f, %.0f] s: worst error '
                             '%.3f m' % (start, end, worst))
        self.assertLessEqual(rmse, self.rmse_below)

    def test_live_changes(self):
        deadline = time.time() + self.wall_timeout
        client = Client(self.node, timeout=30)

        # 1. The .cfg's defaults are config/pf.yaml's; the server's values the node's.
        with open(os.path.join(roslib.packages.get_pkg_dir(PKG), 'config', 'pf.yaml')) as f:
            pf_yaml = yaml.safe_load(f)
        described = {}
        for d in client.get_parameter_descriptions():
            described[d['name']] = d
        self.assertIn('kld_z', described)
        for name, d in described.items():
            if name in ('kld_z', 'restore_defaults'):
                continue
            self.assertIn(name, pf_yaml, '%s is in the .cfg but not in config/pf.yaml' % name)
            self.assertAlmostEqual(float(d['default']), float(pf_yaml[name]), places=9,
                                   msg='%s: .cfg default %s, config/pf.yaml %s'
                                   % (name, d['default'], pf_yaml[name]))
        start = client.get_configuration(timeout=10)
        for name in described:
            if name not in ('kld_z', 'restore_defaults'):
                self.assertAlmostEqual(float(start[name]), float(pf_yaml[name]), places=9,
                                       msg='%s: server %s, config/pf.yaml %s'
                                       % (name, start[name], pf_yaml[name]))
        self.assertAlmostEqual(start['kld_z'], 2.3263, places=3)

        # 2. A change takes effect at the next update, and the filter keeps tracking.
        self.wait_bag_time(self.change_at, deadline)
        with self.lock:
            before = self.status_count
        answer = client.update_configuration(NEW_VALUES)
        for name, value in NEW_VALUES.items():
            self.assertAlmostEqual(answer[name], value, msg='server answered %s = %s' % (name, answer[name]))
        status = self.wait_status(
            lambda s: s.get('config_generation') == '1' and
            all(abs(float(s[k]) - v) < 1e-9 for k, v in NEW_VALUES.items()),
            deadline, 'the new values with config_generation 1')
        with self.lock:
            self.assertGreater(self.status_count, before)
        print('reconfigure_checker: in effect: %s' % {k: status[k] for k in
              ['config_generation', 'particles'] + list(NEW_VALUES)})

        # 3. amcl's name for kld_confidence.
        answer = client.update_configuration({'kld_z': 3.0})
        self.assertAlmostEqual(answer['kld_confidence'], 0.5 * math.erfc(-3.0 / math.sqrt(2.0)), places=9)
        self.assertAlmostEqual(answer['kld_z'], 3.0, places=6)
        self.wait_status(lambda s: s.get('config_generation') == '2', deadline, 'config_generation 2')

        self.wait_bag_time(self.refuse_at, deadline)
        self.tracking(self.change_at + 2.0, self.refuse_at)

        # 4. Invalid values are refused with the start-up message; the old ones stay.
        answer = client.update_configuration({'laser_sigma_hit': -1.0})
        self.assertAlmostEqual(answer['laser_sigma_hit'], NEW_VALUES['laser_sigma_hit'])
        answer = client.update_configuration({'min_particles': 70000})
        self.assertEqual(answer['min_particles'], 500)
        self.assertEqual(answer['max_particles'], NEW_VALUES['max_particles'])
        time.sleep(2.0)
        with self.lock:
            errors = list(self.log_errors)
        print('reconfigure_checker: refusals logged: %s' % errors)
        self.assertTrue(any('invalid parameter laser_sigma_hit = 0: must be > 0' in e for e in errors),
                        errors)
        self.assertTrue(any('invalid parameter max_particles = 60000: must be >= min_particles (70000)'
                            in e for e in errors), errors)
        current = client.get_configuration(timeout=10)
        self.assertAlmostEqual(current['laser_sigma_hit'], NEW_VALUES['laser_sigma_hit'])
        self.assertEqual(current['min_particles'], 500)

        # 5. Still alive, still the accepted values, still tracking.
        with self.lock:
            before = self.status_count
        self.wait_bag_time(self.end_at, deadline)
        with self.lock:
            self.assertGreater(self.status_count, before, 'no pf_status after the refusals')
            status = dict(self.status)
        self.assertEqual(status['config_generation'], '2')
        self.assertAlmostEqual(float(status['laser_sigma_hit']), NEW_VALUES['laser_sigma_hit'])
        self.tracking(self.refuse_at, self.end_at)

        # 6. amcl's restore_defaults: back to the start-up values.
        answer = client.update_configuration({'restore_defaults': True})
        self.assertFalse(answer['restore_defaults'])
        for name in NEW_VALUES:
            self.assertAlmostEqual(answer[name], start[name], msg=name)
        self.assertAlmostEqual(answer['kld_confidence'], start['kld_confidence'])
        self.wait_status(lambda s: s.get('config_generation') == '3' and
                         abs(float(s['laser_sigma_hit']) - start['laser_sigma_hit']) < 1e-9,
                         deadline, 'the start-up values with config_generation 3')


if __name__ == '__main__':
    rospy.init_node(NAME)
    rostest.rosrun(PKG, NAME, ReconfigureTest, sys.argv)
