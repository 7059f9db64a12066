#!/usr/bin/python3
"""rostest checker for a sensor that stops: pf_node's pf_status
must name it as missing within max_delay [s] of it going, and not before,
and must stop naming it within max_delay of it coming back.

Times are bag seconds after the first /ground_truth (the bag's start).
Params: sensor (its name in scan_topics, e.g. scan_front), missing_from [s],
missing_to [s], max_delay [s, default 2], wall_timeout [s wall, default 120].
Every status change seen is printed, whether the test passes or not.
"""

import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PoseStamped

PKG = 'pf_localization'


class SensorChecker(unittest.TestCase):
    def test_missing_sensor_is_named(self):
        rospy.init_node('sensor_checker')
        sensor = rospy.get_param('~sensor')
        missing_from = float(rospy.get_param('~missing_from'))
        missing_to = float(rospy.get_param('~missing_to'))
        max_delay = float(rospy.get_param('~max_delay', 2.0))
        wall_timeout = float(rospy.get_param('~wall_timeout', 120.0))
        lock = threading.Lock()
        start = []
        changes = []  # (bag s, named as missing)
        last_gt = [0.0]

        def on_gt(msg):
            with lock:
                if not start:
                    start.append(msg.header.stamp.to_sec())
                last_gt[0] = msg.header.stamp.to_sec() - start[0]

        def on_status(msg):
            with lock:
                if not start:
                    return
                named = ('missing: ' in msg.message and sensor in msg.message.split('missing: ', 1)[1])
                t = rospy.Time.now().to_sec() - start[0]
                if not changes or changes[-1][1] != named:
                    changes.append((t, named))
                    print('sensor_checker: t=%.2f s: %s' % (t, msg.message), flush=True)

        rospy.Subscriber('/ground_truth', PoseStamped, on_gt, queue_size=100)
        rospy.Subscriber('/pf_status', DiagnosticStatus, on_status, queue_size=100)
        deadline = time.time() + wall_timeout
        while time.time() < deadline and not rospy.is_shutdown():
            with lock:
                if last_gt[0] > missing_to + max_delay + 1.0:
                    break
            time.sleep(0.2)
        with lock:
            seen = list(changes)
        self.assertTrue(seen, 'no pf_status received')
        went = [t for t, named in seen if named]
        self.assertTrue(went, '%s never named as missing (changes: %s)' % (sensor, seen))
        self.assertGreaterEqual(went[0], missing_from - 0.1, 'named before it went: %s' % seen)
        self.assertLessEqual(went[0], missing_from + max_delay, 'named too late: %s' % seen)
        back = [t for t, named in seen if not named and t > went[0]]
        self.assertTrue(back, 'still named after it came back: %s' % seen)
        self.assertLessEqual(back[0], missing_to + max_delay, 'named for too long: %s' % seen)
        print('sensor_checker: %s named missing at %.2f s (gone at %.1f), back at %.2f s (at %.1f)'
              % (sensor, went[0], missing_from, back[0], missing_to), flush=True)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'sensor_checker', SensorChecker, sys.argv)
