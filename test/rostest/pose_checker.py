#!/usr/bin/python3
"""rostest checker for pf_localization: compares the localizer with the truth.

Run as a <test> node of a .test file (see test/rostest/*.test); rostest reports
the single test case `test_pose_checker` as passed or failed, with the summary
in the failure message. The summary (and a timeline of the error in 5 s bins)
is also printed in both cases: it is in the test's XML result (<system-out>,
test_results/pf_localization/rosunit-<test-name>.xml) and on screen with
`rostest --text`.

Modes (private param `mode`):

track (default)
    For every /ground_truth (geometry_msgs/PoseStamped, frame map, true
    base_link pose) stamped t, the estimate is the tf lookup
    global_frame -> base_frame at t (map->odom from the localizer composed with
    odom->base_link from the bag), retried until the clock is 5 s past t (a
    player catching up after a stall sends seconds of the bag ahead of its
    /clock, and both pf_node and this node's tf then lag). When that lookup
    still fails, the newest map->odom is composed with odom->base_link at t
    (or, failing that too, the newest map->base_link) and the sample is
    counted as a "fallback". Times below are in seconds of sim time relative
    to the first ground truth.

    start_after      [s]   errors count from this time on (default 5)
    start_after_map  [s]   ... and not before this long after /map arrived
                           (default: unset; set it to test a late map)
    map_not_before   [s]   the /map must arrive at or after this time, or the
                           late-map test proves nothing (default: unset)
    max_error        [m]   hard bound on the position error after start_after
    max_yaw_error    [deg] hard bound on the yaw error after start_after
    rmse_below       [m]   bound on the RMS position error after start_after
    yaw_rmse_below   [deg] bound on the RMS yaw error after start_after
    converge_within  [s]   the error must drop below converge_error at a time
    converge_error   [m]   <= converge_within and stay below it to the end
    event_time       [s]   kidnapping: from the sample at or after event_time
                           ("auto": the first jump of the ground truth by more
                           than jump_threshold, default 1 m, between two messages),
    recover_within   [s]   the error must be back below recover_error by
    recover_error    [m]   event_time + recover_within and stay below it
    min_samples            minimum number of compared poses (default 20)
    duration         [s]   sim time to watch, then evaluate (default 0: until
                           the ground truth stops for idle_timeout)
    idle_timeout     [s]   wall time without ground truth that ends the watch
                           once ground truth was seen (default 8)
    wait_timeout     [s]   wall time to wait for the first ground truth (default 60)
    wall_timeout     [s]   wall time after which it evaluates whatever it has
                           (default 0: none; keep it below the test's time-limit)
    max_confidently_wrong  at most this many pf_status messages may say "localized"
                           while the position error (of the compared pose nearest
                           in time, within 0.5 s) exceeds wrong_error (default
                           unset: only reported)
    wrong_error      [m]   (default 1.0)
    min_pf_pose            minimum number of pf_pose messages received after
                           the errors start to count (default 1)
    check_alive            node that must still answer at the end (default
                           /pf_node; empty: no check)
    expect_failure   [bool] the checks are known to fail (unimplemented
                           feature): a failure passes with "EXPECTED FAILURE:
                           ...", a pass FAILS with "UNEXPECTED PASS: remove
                           expect_failure ..." so nobody forgets it (a dead
                           node, too few samples or pf_pose messages still fail)
    samples_file           if set, every sample is written there as CSV
    pf_pose_topic          the estimate topic min_pf_pose counts (default /pf_pose)
    saved_pose_ns          if set (e.g. /amcl): at the end NS/initial_pose_x, _y and
                           _a, the pose the localizer saves on the parameter
                           server as amcl does, must lie within saved_pose_error
                           (m, default 0.5) of the last ground truth
    global_frame, odom_frame, base_frame   (default map, odom, base_link)

initialpose
    The localizer is started deliberately wrong (initial pose off by >1 m with a
    small covariance). At initialpose_time (s after the first ground truth) the
    checker checks that the estimate is indeed wrong (mean error of the last
    2 s > wrong_min_error, default 0.5 m; otherwise the test proves nothing and
    fails), then publishes, like rviz's "2D Pose Estimate", a
    PoseWithCovarianceStamped on /initialpose (frame map, stamped now) at
    P = the latest ground truth + (initialpose_offset_x, _y [m], _a [rad]),
    covariance initialpose_cov_xx/_yy/_aa (rviz's 0.25, 0.25, 0.0685).
    The first pf_pose stamped at or after that must arrive within
    initialpose_timeout (s sim, default 10) and lie within initialpose_error
    (m, default 0.3) of P. All track-mode bounds then apply from
    initialpose_time + start_after (start_after is relative to the
    /initialpose in this mode, default 0).

bad_input  (use_sim_time false)
    Feeds a running pf_node malformed input, before and after the map exists:
    scans whose ranges are all NaN, all +inf, all -inf or NaN/inf mixed, an
    empty scan, a scan with angle_increment 0, /initialpose with NaN position,
    NaN yaw, NaN covariance, a zero quaternion, and in an unknown frame. After
    each input /pf_node must still answer (XML-RPC ping) and advertise pf_pose.
    Then good input (a valid /initialpose at a free pose of the map, scans ray
    cast in the received map, odometry on /odom and /tf, a small rotation in
    place, request_nomotion_update) must produce a pf_pose within good_error
    (m, default 0.5) of the true pose, and pf_node must have logged at least
    one warning/error on /rosout containing one of warning_keywords.
    Params: pf_node (default /pf_node), map_wait (s, default 60),
    good_error, require_warning (default true), warning_keywords (list),
    cloud_topic (default none: a topic of pf_node's cloud_topics, which then
    also gets clouds without a z field, with float64 fields, with data shorter
    than their points and of NaN points only, and about which pf_node must
    warn that it cannot read the point cloud).
"""

import sys
import unittest

import rospy
import rostest

# Each mode in a module of its own beside this script (rostest runs it with this folder on sys.path):
# track and initialpose in pose_checker_track.py (its evaluation in pose_checker_evaluation.py),
# bad_input in pose_checker_bad_input.py; the helpers they share in pose_checker_poses.py and
# pose_checker_node.py.
from pose_checker_bad_input import BadInputChecker
from pose_checker_track import PoseChecker

PKG = 'pf_localization'
NAME = 'pose_checker'


class PoseCheckerTest(unittest.TestCase):
    def test_pose_checker(self):
        mode = rospy.get_param('~mode', 'track')
        if mode in ('track', 'initialpose'):
            ok, msg = PoseChecker(mode).run()
        elif mode == 'bad_input':
            ok, msg = BadInputChecker().run()
        else:
            ok, msg = False, 'unknown ~mode %r (track, initialpose or bad_input)' % mode
        sys.stdout.flush()
        self.assertTrue(ok, msg)


if __name__ == '__main__':
    rospy.init_node(NAME)
    rostest.rosrun(PKG, NAME, PoseCheckerTest, sys.argv)
