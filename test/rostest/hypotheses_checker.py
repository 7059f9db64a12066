#!/usr/bin/python3
"""rostest checker for pf_hypotheses: while the robot is in a room
identical to another, pf_node must publish both places; once it has left
and says it is localized, one.

Each /pf_hypotheses message is compared with the /ground_truth nearest its
stamp (within 0.25 s). Times are bag seconds after the first ground truth.

    twin_box       "x0 y0 x1 y1" (m): the room the robot starts in
    twin_offset    "dx dy" (m): where its twin is, relative to it
    skip_updates   the first updates, while global localization's cloud is
                   still everywhere, are not checked (default 3)
    near_error     [m] a hypothesis "is" a place within this (default 0.5)
    min_twin_updates  at least this many updates checked in the room
    min_localized_updates  at least this many checked once localized and out
    wall_timeout   [s wall] evaluates whatever it has then (default 50)

In the room (after skip_updates): at least two hypotheses, one within
near_error of the truth and one within near_error of its twin, and the
update's status (/diagnostics, as pf_status) counting them (its value
"hypotheses"). Out of the room, at every update
after which pf_status says localized: one hypothesis, within near_error of
the truth. Every update is printed, whether the test passes or not.
"""

import bisect
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped

from pf_localization.msg import PoseHypotheses

PKG = 'pf_localization'


def floats(text, n):
    values = [float(v) for v in str(text).split()]
    if len(values) != n:
        raise ValueError('%r: %d numbers expected' % (text, n))
    return values


class HypothesesChecker(unittest.TestCase):
    def test_hypotheses_name_both_twins_then_one(self):
        rospy.init_node('hypotheses_checker')
        x0, y0, x1, y1 = floats(rospy.get_param('~twin_box'), 4)
        dx, dy = floats(rospy.get_param('~twin_offset'), 2)
        skip = int(rospy.get_param('~skip_updates', 3))
        near = float(rospy.get_param('~near_error', 0.5))
        min_twin = int(rospy.get_param('~min_twin_updates'))
        min_localized = int(rospy.get_param('~min_localized_updates'))
        wall_timeout = float(rospy.get_param('~wall_timeout', 50.0))
        lock = threading.Lock()
        truth = []  # (stamp, x, y), in order
        updates = []  # (stamp, [(x, y, weight)], count)
        statuses = {}  # stamp: (state, its "hypotheses" value, message)
        last_gt_wall = [None]

        def on_gt(msg):
            with lock:
                truth.append((msg.header.stamp.to_sec(), msg.pose.position.x, msg.pose.position.y))
                last_gt_wall[0] = time.time()

        def on_hypotheses(msg):
            listed = [(p.pose.position.x, p.pose.position.y, w)
                      for p, w in zip(msg.poses, msg.weights)]
            with lock:
                updates.append((msg.header.stamp.to_sec(), listed, msg.count))

        def on_diagnostics(msg):
            # pf_status's DiagnosticStatus, stamped (pf_status itself is not)
            # with the update's stamp, as pf_hypotheses is.
            for status in msg.status:
                if not status.name.endswith(': localization'):
                    continue
                values = {kv.key: kv.value for kv in status.values}
                with lock:
                    statuses[msg.header.stamp.to_sec()] = (
                        values.get('state'), int(values.get('hypotheses', '-1')), status.message)

        rospy.Subscriber('/ground_truth', PoseStamped, on_gt, queue_size=200)
        rospy.Subscriber('/pf_hypotheses', PoseHypotheses, on_hypotheses, queue_size=50)
        rospy.Subscriber('/diagnostics', DiagnosticArray, on_diagnostics, queue_size=50)
        deadline = time.time() + wall_timeout
        while time.time() < deadline and not rospy.is_shutdown():
            with lock:
                if last_gt_wall[0] is not None and time.time() - last_gt_wall[0] > 5.0:
                    break  # the bag has ended
            time.sleep(0.2)
        with lock:
            truth = list(truth)
            updates = list(updates)
            statuses = dict(statuses)
        self.assertTrue(truth, 'no /ground_truth received')
        self.assertTrue(updates, 'no /pf_hypotheses received')
        t0 = truth[0][0]
        stamps = [t for t, _, _ in truth]

        def nearest_truth(stamp):
            i = bisect.bisect_left(stamps, stamp)
            best = min((abs(stamps[j] - stamp), j) for j in (i - 1, i) if 0 <= j < len(stamps))
            return truth[best[1]] if best[0] <= 0.25 else None

        def distance_to(listed, x, y):
            return min(math.hypot(hx - x, hy - y) for hx, hy, _ in listed) if listed else math.inf

        failures, twin_checked, localized_checked = [], 0, 0
        for k, (stamp, listed, count) in enumerate(updates):
            gt = nearest_truth(stamp)
            state, status_count, message = statuses.get(stamp, (None, -1, ''))
            if gt is None:
                print('hypotheses_checker: update %d at %.2f s: no ground truth' % (k + 1, stamp - t0))
                continue
            _, x, y = gt
            in_twin = x0 <= x <= x1 and y0 <= y <= y1
            to_truth = distance_to(listed, x, y)
            to_twin = distance_to(listed, x + dx, y + dy)
            print('hypotheses_checker: update %d at %.2f s: truth (%.2f, %.2f)%s, %d hypotheses '
                  '[%s], nearest %.2f m, to the twin %.2f m; %s: %s'
                  % (k + 1, stamp - t0, x, y, ' in the twin room' if in_twin else '', count,
                     ', '.join('(%.2f, %.2f) %.0f %%' % (hx, hy, 100 * w) for hx, hy, w in listed),
                     to_truth, to_twin, state, message), flush=True)
            if k < skip:
                continue
            where = 'update %d at %.2f s' % (k + 1, stamp - t0)
            if in_twin:
                twin_checked += 1
                if count < 2 or len(listed) < 2:
                    failures.append('%s in the twin room: %d hypotheses' % (where, count))
                if to_truth > near:
                    failures.append('%s: no hypothesis within %.2f m of the truth (%.2f m)'
                                    % (where, near, to_truth))
                if to_twin > near:
                    failures.append('%s: no hypothesis within %.2f m of the twin place (%.2f m)'
                                    % (where, near, to_twin))
                if status_count != count:
                    failures.append('%s: pf_status counts %d hypotheses, pf_hypotheses %d'
                                    % (where, status_count, count))
            elif state == 'localized':
                localized_checked += 1
                if count != 1:
                    failures.append('%s, localized: %d hypotheses' % (where, count))
                if to_truth > near:
                    failures.append('%s, localized: %.2f m from the truth' % (where, to_truth))
        print('hypotheses_checker: %d updates, %d checked in the twin room, %d localized outside'
              % (len(updates), twin_checked, localized_checked), flush=True)
        self.assertGreaterEqual(twin_checked, min_twin,
                                'only %d updates checked in the twin room' % twin_checked)
        self.assertGreaterEqual(localized_checked, min_localized,
                                'only %d localized updates checked outside' % localized_checked)
        self.assertFalse(failures, '\n'.join(failures))


if __name__ == '__main__':
    rostest.rosrun(PKG, 'hypotheses_checker', HypothesesChecker, sys.argv)
