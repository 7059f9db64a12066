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
    odom->base_link from the bag). When that lookup fails, the newest map->odom
    is composed with odom->base_link at t (or, failing that too, the newest
    map->base_link) and the sample is counted as a "fallback". Times below are
    in seconds of sim time relative to the first ground truth.

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

import csv
import http.client
import math
import re
import sys
import threading
import time
import unittest
import xmlrpc.client

import rospy
import rosgraph
import rostest
import tf2_ros

from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TransformStamped, Quaternion
from nav_msgs.msg import OccupancyGrid, Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import LaserScan, PointCloud2, PointField

PKG = 'pf_localization'
NAME = 'pose_checker'


# ----------------------------------------------------------------------------
# small helpers


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def quat_from_yaw(yaw):
    return Quaternion(0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def compose(a, b):
    """(x, y, yaw) a * b."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def pose2_of_transform(t):
    return (t.transform.translation.x, t.transform.translation.y, yaw_of(t.transform.rotation))


def pose2_of_pose(p):
    return (p.position.x, p.position.y, yaw_of(p.orientation))


def pos_err(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])


def yaw_err_deg(a, b):
    return abs(math.degrees(wrap(a[2] - b[2])))


def param(name, default=None):
    return rospy.get_param('~' + name, default)


def opt_float(name):
    v = rospy.get_param('~' + name, None)
    if v is None or v == '':
        return None
    return float(v)


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout):
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


def node_alive(node, timeout=3.0):
    """(alive, why): the node is registered and answers its XML-RPC API."""
    try:
        master = rosgraph.Master(rospy.get_name())
        uri = master.lookupNode(node)
    except Exception as e:  # noqa: BLE001 - any master error means "not alive"
        return False, 'not registered with the master (%s)' % e
    try:
        code, _, pid = xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout)).getPid(rospy.get_name())
        if code != 1:
            return False, 'getPid returned code %s' % code
        return True, 'pid %s' % pid
    except (OSError, http.client.HTTPException, xmlrpc.client.Error) as e:
        return False, 'does not answer at %s (%s)' % (uri, e)


def node_publishes(node, topic):
    try:
        state = rosgraph.Master(rospy.get_name()).getSystemState()
    except Exception:  # noqa: BLE001
        return False
    for t, nodes in state[0]:
        if t == topic and node in nodes:
            return True
    return False


def fmt(x, unit='', prec=3):
    if x is None:
        return '-'
    return ('%.' + str(prec) + 'f%s') % (x, unit)


# ----------------------------------------------------------------------------
# track / initialpose


class Sample:
    __slots__ = ('t', 'stamp', 'truth', 'est', 'err', 'yaw_err', 'fallback')

    def __init__(self, t, stamp, truth, est, fallback):
        self.t = t
        self.stamp = stamp
        self.truth = truth
        self.est = est
        self.fallback = fallback
        if est is None:
            self.err = float('inf')
            self.yaw_err = float('inf')
        else:
            self.err = pos_err(est, truth)
            self.yaw_err = yaw_err_deg(est, truth)


class PoseChecker:
    def __init__(self, mode):
        self.mode = mode
        self.global_frame = param('global_frame', 'map')
        self.odom_frame = param('odom_frame', 'odom')
        self.base_frame = param('base_frame', 'base_link')
        self.start_after = float(param('start_after', 0.0 if mode == 'initialpose' else 5.0))
        self.start_after_map = opt_float('start_after_map')
        self.map_not_before = opt_float('map_not_before')
        self.max_error = opt_float('max_error')
        self.max_yaw_error = opt_float('max_yaw_error')
        self.rmse_below = opt_float('rmse_below')
        self.yaw_rmse_below = opt_float('yaw_rmse_below')
        self.converge_within = opt_float('converge_within')
        self.converge_error = opt_float('converge_error')
        ev = rospy.get_param('~event_time', None)
        self.event_auto = isinstance(ev, str) and ev.strip().lower() == 'auto'
        self.event_time = None if (self.event_auto or ev in (None, '')) else float(ev)
        self.jump_threshold = float(param('jump_threshold', 1.0))
        self.recover_within = opt_float('recover_within')
        self.recover_error = opt_float('recover_error')
        self.min_samples = int(param('min_samples', 20))
        self.duration = float(param('duration', 0.0))
        self.idle_timeout = float(param('idle_timeout', 8.0))
        self.wait_timeout = float(param('wait_timeout', 60.0))
        self.wall_timeout = float(param('wall_timeout', 0.0))
        self.min_pf_pose = int(param('min_pf_pose', 1))
        self.check_alive = param('check_alive', '/pf_node')
        self.expect_failure = bool(param('expect_failure', False))
        self.samples_file = param('samples_file', '')
        self.saved_pose_ns = param('saved_pose_ns', '')
        self.saved_pose_error = float(param('saved_pose_error', 0.5))
        # initialpose mode
        self.ip_time = float(param('initialpose_time', 10.0))
        self.ip_offset = (float(param('initialpose_offset_x', 0.0)), float(param('initialpose_offset_y', 0.0)),
                          float(param('initialpose_offset_a', 0.0)))
        self.ip_cov = (float(param('initialpose_cov_xx', 0.25)), float(param('initialpose_cov_yy', 0.25)),
                       float(param('initialpose_cov_aa', 0.06853891945200942)))
        self.ip_error = float(param('initialpose_error', 0.3))
        self.ip_timeout = float(param('initialpose_timeout', 10.0))
        # Live parameters of pf_node to set right after the /initialpose (a
        # dictionary; empty: none), e.g. update thresholds held off before it.
        self.reconfigure_after_ip = dict(param('reconfigure_after_initialpose', {}) or {})
        self.reconfigure_node = param('reconfigure_node', '/pf_node')
        self.wrong_min_error = float(param('wrong_min_error', 0.5))
        mcw = param('max_confidently_wrong', None)
        self.max_confidently_wrong = None if mcw in (None, '') else int(mcw)
        self.wrong_error = float(param('wrong_error', 1.0))

        self.lock = threading.Lock()
        self.pending = []          # ground truth not yet compared
        self.samples = []
        self.t0 = None             # stamp of the first ground truth
        self.last_gt_wall = None
        self.last_gt = None        # latest ground truth message
        self.map_stamp = None      # sim time the first /map arrived
        self.ip_next = None
        self.ip_done = False
        self.pf_poses = []         # (receipt sim time, msg)
        self.states = []           # (receipt sim time, pf_status state)
        self.ip_sent = None        # (stamp, P) of the published /initialpose
        self.ip_notes = []         # initialpose-mode findings (failures)
        self.ip_info = []          # initialpose-mode information

        self.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(30.0))
        self.tf_listener = tf2_ros.TransformListener(self.tf_buffer)
        self.ip_pub = rospy.Publisher('/initialpose', PoseWithCovarianceStamped, queue_size=1, latch=False)
        rospy.Subscriber('/ground_truth', PoseStamped, self._on_gt, queue_size=1000)
        rospy.Subscriber(param('pf_pose_topic', '/pf_pose'), PoseWithCovarianceStamped, self._on_pf_pose,
                         queue_size=100)
        rospy.Subscriber(param('map_topic', '/map'), OccupancyGrid, self._on_map, queue_size=1)
        rospy.Subscriber(param('status_topic', '/pf_status'), DiagnosticStatus, self._on_status, queue_size=100)

    # -- callbacks
    def _on_status(self, msg):
        state = next((kv.value for kv in msg.values if kv.key == 'state'), '')
        with self.lock:
            self.states.append((rospy.Time.now(), state))

    def _on_gt(self, msg):
        with self.lock:
            if self.t0 is None:
                self.t0 = msg.header.stamp
            self.pending.append(msg)
            self.last_gt = msg
            self.last_gt_wall = time.time()

    def _on_pf_pose(self, msg):
        with self.lock:
            self.pf_poses.append((rospy.Time.now(), msg))

    def _on_map(self, _msg):
        with self.lock:
            if self.map_stamp is None:
                self.map_stamp = rospy.Time.now()

    @property
    def map_t(self):
        """Sim time (relative to the first ground truth) the first /map arrived, or None."""
        if self.map_stamp is None or self.t0 is None:
            return None
        if self.map_stamp.is_zero():  # arrived before the first /clock: there from the start
            return 0.0
        return self.rel(self.map_stamp)

    def rel(self, stamp):
        return (stamp - self.t0).to_sec()

    # -- estimate lookups
    def _estimate(self, stamp, allow_fallback):
        """(pose2 or None, fallback)."""
        try:
            t = self.tf_buffer.lookup_transform(self.global_frame, self.base_frame, stamp)
            return pose2_of_transform(t), False
        except tf2_ros.TransformException:
            if not allow_fallback:
                return None, False
        try:
            mo = self.tf_buffer.lookup_transform(self.global_frame, self.odom_frame, rospy.Time(0))
            ob = self.tf_buffer.lookup_transform(self.odom_frame, self.base_frame, stamp)
            return compose(pose2_of_transform(mo), pose2_of_transform(ob)), True
        except tf2_ros.TransformException:
            pass
        try:
            t = self.tf_buffer.lookup_transform(self.global_frame, self.base_frame, rospy.Time(0))
            return pose2_of_transform(t), True
        except tf2_ros.TransformException:
            return None, True

    def _process_pending(self, flush=False, lag=0.5):
        now = rospy.Time.now()
        with self.lock:
            pending, self.pending = self.pending, []
        keep = []
        for msg in pending:
            late = flush or (now - msg.header.stamp).to_sec() > lag
            est, fb = self._estimate(msg.header.stamp, allow_fallback=late)
            if est is None and not late:
                keep.append(msg)
                continue
            self.samples.append(Sample(self.rel(msg.header.stamp), msg.header.stamp,
                                       pose2_of_pose(msg.pose), est, fb))
        if keep:
            with self.lock:
                self.pending = keep + self.pending

    # -- the watch
    def run(self):
        wall_start = time.time()
        while not rospy.is_shutdown() and self.t0 is None:
            if time.time() - wall_start > self.wait_timeout:
                return False, 'no /ground_truth received within %.0f s (wall): is the bag playing?' % self.wait_timeout
            time.sleep(0.05)
        end_reason = 'shutdown'
        while not rospy.is_shutdown():
            self._process_pending()
            if self.mode == 'initialpose':
                self._initialpose_step()
            with self.lock:
                last_t = self.rel(self.last_gt.header.stamp)
                idle = time.time() - self.last_gt_wall
            if self.duration > 0 and last_t >= self.duration:
                end_reason = 'duration %.1f s reached' % self.duration
                break
            if idle > self.idle_timeout:
                end_reason = 'ground truth stopped (none for %.1f s wall) at t=%.1f s' % (idle, last_t)
                break
            if self.wall_timeout > 0 and time.time() - wall_start > self.wall_timeout:
                end_reason = 'wall_timeout %.0f s reached at t=%.1f s' % (self.wall_timeout, last_t)
                break
            time.sleep(0.02)
        self._process_pending(flush=True)
        return self.evaluate(end_reason)

    def _reconfigure(self, values):
        """Sets live parameters of pf_node through dynamic_reconfigure, as a user would."""
        import dynamic_reconfigure.client
        try:
            client = dynamic_reconfigure.client.Client(self.reconfigure_node, timeout=10.0)
            got = client.update_configuration(values)
            self.ip_info.append('after the /initialpose, %s set to %s' % (
                self.reconfigure_node, ', '.join('%s %s' % (k, got.get(k)) for k in sorted(values))))
        except Exception as e:  # the test then fails on tracking, with this as the reason
            self.ip_notes.append('could not reconfigure %s after the /initialpose: %s' % (self.reconfigure_node, e))

    # -- initialpose mode
    def _initialpose_step(self):
        if self.ip_sent is None:
            with self.lock:
                gt = self.last_gt
            if self.rel(gt.header.stamp) < self.ip_time:
                return
            # Is the filter really wrong before we correct it?
            t_gt = self.rel(gt.header.stamp)
            before = [s.err for s in self.samples if t_gt - 2.0 <= s.t < t_gt and s.est is not None]
            if not before:
                self.ip_notes.append('no estimate at all in the 2 s before the /initialpose (t=%.1f s)' % t_gt)
            else:
                mean_before = sum(before) / len(before)
                self.ip_info.append('mean error in the 2 s before /initialpose: %.2f m (n=%d)' % (mean_before, len(before)))
                if mean_before <= self.wrong_min_error:
                    self.ip_notes.append(
                        'test setup: the estimate was already within %.2f m (mean %.2f m) before the /initialpose '
                        'at t=%.1f s, so the test cannot show a re-initialisation (start it further off)'
                        % (self.wrong_min_error, mean_before, t_gt))
            p = compose(pose2_of_pose(gt.pose), (0.0, 0.0, 0.0))
            p = (p[0] + self.ip_offset[0], p[1] + self.ip_offset[1], wrap(p[2] + self.ip_offset[2]))
            msg = PoseWithCovarianceStamped()
            msg.header.frame_id = self.global_frame
            msg.header.stamp = rospy.Time.now()
            msg.pose.pose.position.x, msg.pose.pose.position.y = p[0], p[1]
            msg.pose.pose.orientation = quat_from_yaw(p[2])
            cov = [0.0] * 36
            cov[0], cov[7], cov[35] = self.ip_cov
            msg.pose.covariance = cov
            self.ip_pub.publish(msg)
            with self.lock:
                self.ip_sent = (msg.header.stamp, p, time.time())
            if self.reconfigure_after_ip:
                threading.Thread(target=self._reconfigure, args=(self.reconfigure_after_ip,),
                                 daemon=True).start()
            rospy.loginfo('pose_checker: published /initialpose at t=%.2f s: x=%.3f y=%.3f yaw=%.3f (truth at t=%.2f s)',
                          self.rel(msg.header.stamp), p[0], p[1], p[2], t_gt)
            self.ip_info.append('/initialpose published at t=%.2f s (ground truth of t=%.2f s%s)' % (
                self.rel(msg.header.stamp), t_gt,
                '' if self.ip_offset == (0.0, 0.0, 0.0) else ' + offset %s' % (self.ip_offset,)))
            return
        if self.ip_done:
            return
        stamp, p, _ = self.ip_sent
        with self.lock:
            after = [(r, m) for r, m in self.pf_poses if m.header.stamp >= stamp]
        if after:
            r, m = after[0]
            est = pose2_of_pose(m.pose.pose)
            self.ip_next = (r, m)
            self.ip_done = True
            e, ye = pos_err(est, p), yaw_err_deg(est, p)
            info = ('first pf_pose after /initialpose: stamp t=%.2f s (received t=%.2f s), %.3f m / %.1f deg from P'
                    % (self.rel(m.header.stamp), self.rel(r), e, ye))
            self.ip_info.append(info)
            if e > self.ip_error:
                self.ip_notes.append('t=%.2f s: first pf_pose after /initialpose is %.2f m > %.2f m from the '
                                     'published pose (pf_node did not re-initialise?)'
                                     % (self.rel(m.header.stamp), e, self.ip_error))
        elif (rospy.Time.now() - stamp).to_sec() > self.ip_timeout:
            self.ip_done = True
            self.ip_notes.append('no pf_pose stamped at or after the /initialpose (t=%.2f s) within %.1f s'
                                 % (self.rel(stamp), self.ip_timeout))

    # -- evaluation
    def _window_start(self):
        start = self.start_after
        if self.mode == 'initialpose':
            start = self.ip_time + self.start_after
            if self.ip_sent is not None:
                start = self.rel(self.ip_sent[0]) + self.start_after
        if self.start_after_map is not None and self.map_t is not None:
            start = max(start, self.map_t + self.start_after_map)
        return start

    def evaluate(self, end_reason):
        failures = []
        hard = []  # failures that expect_failure never excuses (crash, no output, too little data)
        info = []
        samples = sorted(self.samples, key=lambda s: s.t)
        start = self._window_start()
        if self.start_after_map is not None and self.map_t is None:
            failures.append('no /map received (start_after_map is set)')
        if self.map_not_before is not None and self.map_t is not None and self.map_t < self.map_not_before:
            failures.append('test setup: /map arrived at t=%.1f s, before t=%.1f s (map_not_before): the map was '
                            'not late, raise map_delay' % (self.map_t, self.map_not_before))
        win = [s for s in samples if s.t >= start]
        have = [s for s in win if s.est is not None]
        missing = [s for s in win if s.est is None]
        fallbacks = [s for s in win if s.fallback and s.est is not None]

        if self.mode == 'initialpose':
            if self.ip_sent is None:
                failures.append('the /initialpose was never published (ground truth ended before t=%.1f s)' % self.ip_time)
            elif not self.ip_done:
                failures.append('no pf_pose after the /initialpose before the end')
            failures.extend(self.ip_notes)

        if len(have) < self.min_samples:
            hard.append('only %d compared poses after t=%.1f s (min_samples %d)' % (len(have), start, self.min_samples))
        if missing:
            s = missing[0]
            failures.append('t=%.1f s: no estimate (%s -> %s unavailable on tf); %d ground-truth poses without an estimate'
                            % (s.t, self.global_frame, self.base_frame, len(missing)))

        def first_over(seq, attr, bound, unit, what):
            bad = [s for s in seq if getattr(s, attr) > bound]
            if bad:
                worst = max(bad, key=lambda s: getattr(s, attr))
                failures.append('t=%.1f s: %s %.3f%s > %.3f%s (%d of %d poses over; worst %.3f%s at t=%.1f s)' % (
                    bad[0].t, what, getattr(bad[0], attr), unit, bound, unit, len(bad), len(seq),
                    getattr(worst, attr), unit, worst.t))

        if self.max_error is not None:
            first_over(have, 'err', self.max_error, ' m', 'error')
        if self.max_yaw_error is not None:
            first_over(have, 'yaw_err', self.max_yaw_error, ' deg', 'yaw error')

        errs = [s.err for s in have]
        yerrs = [s.yaw_err for s in have]
        rmse = math.sqrt(sum(e * e for e in errs) / len(errs)) if errs else None
        yrmse = math.sqrt(sum(e * e for e in yerrs) / len(yerrs)) if yerrs else None
        median = sorted(errs)[len(errs) // 2] if errs else None
        worst = max(have, key=lambda s: s.err) if have else None
        if self.rmse_below is not None and rmse is not None and rmse > self.rmse_below:
            failures.append('position RMSE %.3f m > %.3f m (t >= %.1f s, n=%d)' % (rmse, self.rmse_below, start, len(errs)))
        if self.yaw_rmse_below is not None and yrmse is not None and yrmse > self.yaw_rmse_below:
            failures.append('yaw RMSE %.2f deg > %.2f deg (t >= %.1f s, n=%d)' % (yrmse, self.yaw_rmse_below, start, len(yerrs)))

        def settle(seq, t_from, within, bound, what):
            """Checks that the error is below `bound` from some time <= t_from + within to the end."""
            seq = [s for s in seq if s.t >= t_from]
            if not seq:
                failures.append('%s: no ground truth after t=%.1f s' % (what, t_from))
                return
            last_bad = None
            for s in seq:
                if s.err >= bound:
                    last_bad = s
            deadline = t_from + within
            if seq[-1].t < deadline:
                failures.append('%s: ground truth ended at t=%.1f s, before the deadline t=%.1f s' % (what, seq[-1].t, deadline))
                return
            if last_bad is None:
                info.append('%s: below %.2f m from t=%.1f s on' % (what, bound, seq[0].t))
                return
            after = [s for s in seq if s.t > last_bad.t]
            settled_at = after[0].t if after else None
            if settled_at is not None and settled_at <= deadline:
                info.append('%s: below %.2f m from t=%.1f s on (deadline t=%.1f s)' % (what, bound, settled_at, deadline))
                return
            err = 'no estimate' if last_bad.est is None else 'error %.3f m > %.3f m' % (last_bad.err, bound)
            over = [s for s in seq if s.t >= deadline and s.err >= bound]
            failures.append('t=%.1f s: %s (%s: must stay below %.2f m from t=%.1f s on; %d of %d poses after the deadline over)' % (
                last_bad.t, err, what, bound, deadline, len(over), len([s for s in seq if s.t >= deadline])))

        if self.converge_within is not None:
            settle(samples, 0.0, self.converge_within, self.converge_error if self.converge_error is not None else 0.3,
                   'convergence')
        if self.event_auto:
            # The event is the first jump of the ground truth by more than jump_threshold.
            for a, b in zip(samples, samples[1:]):
                if pos_err(a.truth, b.truth) > self.jump_threshold:
                    self.event_time = b.t
                    info.append('ground truth jumps %.2f m at t=%.2f s (event_time auto)' % (pos_err(a.truth, b.truth), b.t))
                    break
            else:
                failures.append('event_time auto: the ground truth never jumps by more than %.2f m' % self.jump_threshold)
        if self.event_time is not None and self.recover_within is not None:
            settle(samples, self.event_time, self.recover_within,
                   self.recover_error if self.recover_error is not None else 0.3, 'recovery after t=%.1f s' % self.event_time)

        self._check_confidently_wrong(have, start, failures, info)

        with self.lock:
            n_pf = len([1 for r, _ in self.pf_poses if self.t0 is not None and self.rel(r) >= start])
            n_pf_all = len(self.pf_poses)
        if n_pf < self.min_pf_pose:
            hard.append('only %d pf_pose messages after t=%.1f s (min_pf_pose %d; %d in total)' % (
                n_pf, start, self.min_pf_pose, n_pf_all))

        if self.saved_pose_ns:
            self._check_saved_pose(failures, info)

        if self.check_alive:
            ok, why = node_alive(self.check_alive)
            if not ok:
                hard.append('%s is not alive at the end: %s' % (self.check_alive, why))
            else:
                info.append('%s alive at the end (%s)' % (self.check_alive, why))

        summary = ('n=%d (t >= %.1f s; %d fallback lookups, %d without estimate, %d before the window)  '
                   'position error RMSE %s  median %s  max %s%s  |  yaw RMSE %s  max %s  |  pf_pose msgs %d'
                   % (len(have), start, len(fallbacks), len(missing), len(samples) - len(win),
                      fmt(rmse, ' m'), fmt(median, ' m'), fmt(worst.err if worst else None, ' m'),
                      (' (t=%.1f s)' % worst.t) if worst else '',
                      fmt(yrmse, ' deg', 2), fmt(max(yerrs) if yerrs else None, ' deg', 2), n_pf_all))
        if self.map_stamp is not None and self.map_stamp.is_zero():
            info.append('/map arrived before the clock started')
        elif self.map_t is not None:
            info.append('/map arrived at t=%.1f s' % self.map_t)
        info.append('watch ended: %s' % end_reason)
        if self.mode == 'initialpose':
            info = self.ip_info + info
        self._print_timeline(samples, start)
        self._write_samples(samples)

        text = 'pose_checker [%s]: %s\n  %s' % (self.mode, summary, '\n  '.join(info))
        return self._verdict(failures, hard, text)

    def _check_confidently_wrong(self, have, start, failures, info):
        """pf_status verdicts of "localized" while the estimate was more than wrong_error off."""
        with self.lock:
            states = [(self.rel(r), st) for r, st in self.states if self.t0 is not None and not r.is_zero()]
        times = [s.t for s in have]
        wrong = []
        for t, state in states:
            if t < start or state != 'localized' or not times:
                continue
            k = min(range(len(times)), key=lambda i: abs(times[i] - t))
            if abs(times[k] - t) <= 0.5 and have[k].err > self.wrong_error:
                wrong.append((t, have[k].err))
        n = len([1 for t, _ in states if t >= start])
        info.append('confidently wrong: %d of %d pf_status messages said "localized" while more than %.1f m off%s'
                    % (len(wrong), n, self.wrong_error,
                       (' (first at t=%.1f s, %.2f m)' % wrong[0]) if wrong else ''))
        if self.max_confidently_wrong is not None and len(wrong) > self.max_confidently_wrong:
            failures.append('%d pf_status messages said "localized" while more than %.1f m off (at most %d allowed); '
                            'first at t=%.1f s, %.2f m off' % (len(wrong), self.wrong_error,
                                                             self.max_confidently_wrong, wrong[0][0], wrong[0][1]))

    def _check_saved_pose(self, failures, info):
        ns = self.saved_pose_ns.rstrip('/')
        try:
            saved = tuple(float(rospy.get_param('%s/initial_pose_%s' % (ns, k))) for k in 'xya')
        except KeyError as e:
            failures.append('no saved pose on the parameter server: %s is not set' % e)
            return
        if self.last_gt is None:
            return
        truth = pose2_of_pose(self.last_gt.pose)
        e = pos_err(saved, truth)
        info.append('saved pose %s/initial_pose_*: x=%.3f y=%.3f a=%.3f, %.3f m / %.1f deg from the last '
                    'ground truth' % (ns, saved[0], saved[1], saved[2], e, yaw_err_deg(saved, truth)))
        if not e <= self.saved_pose_error:
            failures.append('saved pose %s/initial_pose_* is %.2f m > %.2f m from the last ground truth'
                            % (ns, e, self.saved_pose_error))

    def _verdict(self, failures, hard, text):
        if hard:
            msg = 'FAILED: %s\n%s' % ('\n  '.join(hard + failures), text)
            print(msg)
            return False, msg
        if self.expect_failure:
            if failures:
                msg = 'EXPECTED FAILURE (expect_failure is set): %s\n%s' % ('; '.join(failures), text)
                print(msg)
                return True, msg
            msg = 'UNEXPECTED PASS: remove expect_failure from the test, the checks now pass.\n%s' % text
            print(msg)
            return False, msg
        if failures:
            msg = 'FAILED: %s\n%s' % ('\n  '.join(failures), text)
            print(msg)
            return False, msg
        msg = 'PASSED\n%s' % text
        print(msg)
        return True, msg

    def _print_timeline(self, samples, start):
        if not samples:
            return
        lines = ['pose_checker timeline (5 s bins of sim time; position error max/mean, yaw error max):']
        b = 0
        t_end = samples[-1].t
        while b * 5.0 <= t_end:
            lo, hi = b * 5.0, (b + 1) * 5.0
            bin_s = [s for s in samples if lo <= s.t < hi]
            est = [s for s in bin_s if s.est is not None]
            if bin_s:
                if est:
                    lines.append('  t=%5.1f..%5.1f s%s  max %.3f m  mean %.3f m  yaw max %5.1f deg  n=%d%s' % (
                        lo, hi, '*' if hi <= start else ' ', max(s.err for s in est),
                        sum(s.err for s in est) / len(est), max(s.yaw_err for s in est), len(est),
                        '' if len(est) == len(bin_s) else '  (%d without estimate)' % (len(bin_s) - len(est))))
                else:
                    lines.append('  t=%5.1f..%5.1f s%s  no estimate (n=%d)' % (lo, hi, '*' if hi <= start else ' ', len(bin_s)))
            b += 1
        lines.append('  (* = before the evaluation window starts at t=%.1f s)' % start)
        print('\n'.join(lines))

    def _write_samples(self, samples):
        if not self.samples_file:
            return
        try:
            with open(self.samples_file, 'w', newline='') as f:
                w = csv.writer(f)
                w.writerow(['t', 'stamp', 'true_x', 'true_y', 'true_yaw', 'est_x', 'est_y', 'est_yaw', 'error_m',
                            'yaw_error_deg', 'fallback'])
                for s in samples:
                    e = s.est or (float('nan'),) * 3
                    w.writerow(['%.3f' % s.t, '%.6f' % s.stamp.to_sec(), s.truth[0], s.truth[1], s.truth[2],
                                e[0], e[1], e[2], s.err, s.yaw_err, int(s.fallback)])
        except OSError as e:
            rospy.logwarn('pose_checker: cannot write %s: %s', self.samples_file, e)


# ----------------------------------------------------------------------------
# bad_input


class GridMap:
    """Ray casting and free-space search in a nav_msgs/OccupancyGrid (numpy)."""

    def __init__(self, msg):
        import numpy as np
        self.np = np
        info = msg.info
        self.res = info.resolution
        self.w, self.h = info.width, info.height
        self.ox, self.oy = info.origin.position.x, info.origin.position.y
        self.oyaw = yaw_of(info.origin.orientation)
        g = np.array(msg.data, dtype=np.int16).reshape(self.h, self.w)
        self.occ = g >= 50
        self.free = (g >= 0) & (g < 50)

    def free_pose(self):
        """The free cell farthest from any occupied or unknown cell (4-neighbour erosion)."""
        np = self.np
        m = self.free.copy()
        last = m
        for _ in range(max(self.w, self.h)):
            e = m.copy()
            e[1:, :] &= m[:-1, :]
            e[:-1, :] &= m[1:, :]
            e[:, 1:] &= m[:, :-1]
            e[:, :-1] &= m[:, 1:]
            e[0, :] = e[-1, :] = False
            e[:, 0] = e[:, -1] = False
            if not e.any():
                break
            last, m = e, e
        ys, xs = np.nonzero(last)
        if len(xs) == 0:
            raise RuntimeError('the map has no free cell')
        i = len(xs) // 2
        return self.cell_to_world(xs[i] + 0.5, ys[i] + 0.5)

    def cell_to_world(self, cx, cy):
        c, s = math.cos(self.oyaw), math.sin(self.oyaw)
        lx, ly = cx * self.res, cy * self.res
        return (self.ox + c * lx - s * ly, self.oy + s * lx + c * ly)

    def cast(self, pose, angles, range_max):
        np = self.np
        step = self.res * 0.5
        d = np.arange(step, range_max, step)
        a = pose[2] + np.asarray(angles) - self.oyaw
        wx = pose[0] - self.ox
        wy = pose[1] - self.oy
        c, s = math.cos(-self.oyaw), math.sin(-self.oyaw)
        lx, ly = c * wx - s * wy, s * wx + c * wy
        px = (lx + np.outer(np.cos(a), d)) / self.res
        py = (ly + np.outer(np.sin(a), d)) / self.res
        ix, iy = np.floor(px).astype(int), np.floor(py).astype(int)
        inside = (ix >= 0) & (iy >= 0) & (ix < self.w) & (iy < self.h)
        hit = np.zeros_like(inside)
        hit[inside] = self.occ[iy[inside], ix[inside]]
        first = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
        return [float(d[k]) if k >= 0 else float('inf') for k in first]


class BadInputChecker:
    def __init__(self):
        self.node = param('pf_node', '/pf_node')
        self.map_wait = float(param('map_wait', 60.0))
        self.good_error = float(param('good_error', 0.5))
        self.require_warning = bool(param('require_warning', True))
        self.keywords = [k.lower() for k in param('warning_keywords',
                                                  ['nan', 'finite', 'valid', 'beam', 'map', 'frame', 'increment',
                                                   'ignor', 'reject', 'drop'])]
        self.lock = threading.Lock()
        self.map_msg = None
        self.pf_poses = []
        self.logs = []
        self.failures = []
        self.info = []
        self.odom_pose = (0.0, 0.0, 0.0)   # odom -> base_link
        self.scan_seq = 0
        self.scan_pub = rospy.Publisher('scan', LaserScan, queue_size=10)
        # A cloud topic of pf_node's cloud_topics: malformed clouds go there too.
        self.cloud_topic = param('cloud_topic', '')
        self.cloud_pub = rospy.Publisher(self.cloud_topic, PointCloud2, queue_size=10) if self.cloud_topic else None
        self.odom_pub = rospy.Publisher('odom', Odometry, queue_size=10)
        self.ip_pub = rospy.Publisher('/initialpose', PoseWithCovarianceStamped, queue_size=10)
        self.tf_pub = tf2_ros.TransformBroadcaster()
        self.static_pub = tf2_ros.StaticTransformBroadcaster()
        rospy.Subscriber(param('map_topic', '/map'), OccupancyGrid, self._on_map, queue_size=1)
        rospy.Subscriber(param('pf_pose_topic', '/pf_pose'), PoseWithCovarianceStamped, self._on_pf_pose,
                         queue_size=100)
        rospy.Subscriber('/rosout', Log, self._on_log, queue_size=1000)

    def _on_map(self, msg):
        with self.lock:
            if self.map_msg is None:
                self.map_msg = msg

    def _on_pf_pose(self, msg):
        with self.lock:
            self.pf_poses.append((time.time(), msg))

    def _on_log(self, msg):
        if msg.name == self.node and msg.level >= Log.WARN:
            with self.lock:
                self.logs.append(msg)

    # -- input
    def publish_tf(self):
        now = rospy.Time.now()
        t = TransformStamped()
        t.header.stamp = now
        t.header.frame_id = 'odom'
        t.child_frame_id = 'base_link'
        t.transform.translation.x, t.transform.translation.y = self.odom_pose[0], self.odom_pose[1]
        t.transform.rotation = quat_from_yaw(self.odom_pose[2])
        self.tf_pub.sendTransform(t)
        o = Odometry()
        o.header.stamp = now
        o.header.frame_id = 'odom'
        o.child_frame_id = 'base_link'
        o.pose.pose.position.x, o.pose.pose.position.y = self.odom_pose[0], self.odom_pose[1]
        o.pose.pose.orientation = quat_from_yaw(self.odom_pose[2])
        self.odom_pub.publish(o)

    def make_scan(self, ranges, angle_increment=None, n=360):
        s = LaserScan()
        s.header.stamp = rospy.Time.now()
        s.header.frame_id = 'base_laser_link'
        s.angle_min = -math.pi
        s.angle_increment = (2.0 * math.pi / max(n, 1)) if angle_increment is None else angle_increment
        s.angle_max = s.angle_min + s.angle_increment * (max(n, 1) - 1)
        s.range_min = 0.05
        s.range_max = 10.0
        s.scan_time = 0.2
        s.ranges = ranges
        return s

    def bad_scans(self):
        nan, inf = float('nan'), float('inf')
        n = 360
        return [
            ('scan with only NaN ranges', self.make_scan([nan] * n)),
            ('scan with only +inf ranges', self.make_scan([inf] * n)),
            ('scan with only -inf ranges', self.make_scan([-inf] * n)),
            ('scan with NaN/+inf ranges mixed', self.make_scan([nan if i % 2 else inf for i in range(n)])),
            ('scan with no ranges at all', self.make_scan([], n=0)),
            ('scan with angle_increment 0', self.make_scan([2.0] * n, angle_increment=0.0)),
            ('scan with angle_increment NaN', self.make_scan([2.0] * n, angle_increment=nan)),
        ]

    def make_cloud(self, names='xyz', datatype=PointField.FLOAT32, points=None, data_bytes=None):
        """A PointCloud2 of `points` (x, y, z tuples) with one field per letter of `names`."""
        import struct
        points = points if points is not None else [(2.0, 0.0, 0.5)] * 10
        size = 8 if datatype == PointField.FLOAT64 else 4
        c = PointCloud2()
        c.header.stamp = rospy.Time.now()
        c.header.frame_id = 'base_laser_link'
        c.height, c.width = 1, len(points)
        c.fields = [PointField(n, i * size, datatype, 1) for i, n in enumerate(names)]
        c.point_step = size * len(names)
        c.row_step = c.point_step * c.width
        fmt = '<' + ('d' if size == 8 else 'f') * len(names)
        data = b''.join(struct.pack(fmt, *p[:len(names)]) for p in points)
        c.data = data[:data_bytes] if data_bytes is not None else data
        c.is_dense = False
        return c

    def bad_clouds(self):
        if not self.cloud_pub:
            return []
        nan = float('nan')
        return [
            ('cloud without a z field', self.make_cloud(names='xy')),
            ('cloud with float64 x, y and z', self.make_cloud(datatype=PointField.FLOAT64)),
            ('cloud whose data is shorter than its points', self.make_cloud(data_bytes=20)),
            ('cloud of NaN points only', self.make_cloud(points=[(nan, nan, nan)] * 100)),
        ]

    def initialpose(self, x, y, yaw, frame='map', cov=(0.05, 0.05, 0.02), quat=None):
        m = PoseWithCovarianceStamped()
        m.header.stamp = rospy.Time.now()
        m.header.frame_id = frame
        m.pose.pose.position.x, m.pose.pose.position.y = x, y
        m.pose.pose.orientation = quat if quat is not None else quat_from_yaw(yaw)
        c = [0.0] * 36
        c[0], c[7], c[35] = cov
        m.pose.covariance = c
        return m

    def bad_initialposes(self):
        nan = float('nan')
        return [
            ('/initialpose with NaN x', self.initialpose(nan, 0.0, 0.0)),
            ('/initialpose with NaN yaw', self.initialpose(0.0, 0.0, nan)),
            ('/initialpose with NaN covariance', self.initialpose(0.0, 0.0, 0.0, cov=(nan, nan, nan))),
            ('/initialpose with a zero quaternion', self.initialpose(0.0, 0.0, 0.0, quat=Quaternion(0, 0, 0, 0))),
            ('/initialpose in the unknown frame "no_such_frame"', self.initialpose(0.0, 0.0, 0.0, frame='no_such_frame')),
        ]

    def check_alive(self, after):
        ok, why = node_alive(self.node)
        if not ok:
            self.failures.append('%s died after: %s (%s)' % (self.node, after, why))
            return False
        return True

    def feed_bad(self, phase):
        bad = [(self.scan_pub, what, m) for what, m in self.bad_scans()]
        bad += [(self.cloud_pub, what, m) for what, m in self.bad_clouds()]
        for pub, what, msg in bad:
            for _ in range(3):
                self.publish_tf()
                msg.header.stamp = rospy.Time.now()
                pub.publish(msg)
                time.sleep(0.1)
            time.sleep(0.3)
            if not self.check_alive('%s (%s)' % (what, phase)):
                return False
        for what, m in self.bad_initialposes():
            m.header.stamp = rospy.Time.now()
            self.ip_pub.publish(m)
            self.publish_tf()
            time.sleep(0.5)
            if not self.check_alive('%s (%s)' % (what, phase)):
                return False
        if not node_publishes(self.node, '/pf_pose'):
            self.failures.append('%s does not advertise /pf_pose after the bad input (%s)' % (self.node, phase))
        self.info.append('%s survived every bad input %s' % (self.node, phase))
        return True

    def wait_connected(self, timeout=30.0):
        t0 = time.time()
        while time.time() - t0 < timeout and not rospy.is_shutdown():
            if (self.scan_pub.get_num_connections() > 0 and self.ip_pub.get_num_connections() > 0
                    and (not self.cloud_pub or self.cloud_pub.get_num_connections() > 0)):
                return True
            time.sleep(0.1)
        return False

    def nomotion_update(self):
        from std_srvs.srv import Empty
        master = rosgraph.Master(rospy.get_name())
        for name in ('/request_nomotion_update', self.node + '/request_nomotion_update'):
            try:
                master.lookupService(name)
            except Exception:  # noqa: BLE001
                continue
            try:
                rospy.ServiceProxy(name, Empty)()
                return name
            except (rospy.ServiceException, rospy.ROSException) as e:
                self.info.append('%s failed: %s' % (name, e))
        return None

    def run(self):
        if not self.wait_connected():
            self.failures.append('%s never subscribed to scan and /initialpose within 30 s' % self.node)
            return self.verdict()
        time.sleep(0.5)
        # Static laser mounting (identity) once; odom -> base_link on every publish_tf().
        st = TransformStamped()
        st.header.stamp = rospy.Time.now()
        st.header.frame_id = 'base_link'
        st.child_frame_id = 'base_laser_link'
        st.transform.rotation.w = 1.0
        self.static_pub.sendTransform(st)

        with self.lock:
            have_map = self.map_msg is not None
        if have_map:
            self.info.append('NOTE: the map was already there, no before-map phase (raise map_delay)')
        elif not self.feed_bad('before the map exists'):
            return self.verdict()

        t0 = time.time()
        while not rospy.is_shutdown():
            with self.lock:
                if self.map_msg is not None:
                    break
            if time.time() - t0 > self.map_wait:
                self.failures.append('no /map within %.0f s' % self.map_wait)
                return self.verdict()
            self.publish_tf()
            time.sleep(0.1)
        time.sleep(1.0)  # let pf_node take the map
        if not self.check_alive('receiving the map (after bad input)'):
            return self.verdict()
        if not self.feed_bad('after the map exists'):
            return self.verdict()

        # Good input.
        grid = GridMap(self.map_msg)
        px, py = grid.free_pose()
        truth_start = (px, py, 0.3)
        # odom starts at (0, 0, 0); map -> odom is therefore the truth at start.
        self.odom_pose = (0.0, 0.0, 0.0)
        self.info.append('good input at the free pose x=%.2f y=%.2f yaw=%.2f' % truth_start)
        n = 360
        angles = [-math.pi + i * 2.0 * math.pi / n for i in range(n)]
        self.publish_tf()
        ip = self.initialpose(*truth_start)
        self.ip_pub.publish(ip)
        t_ip = time.time()
        time.sleep(0.5)
        srv = None
        truth = truth_start
        truths = [(ip.header.stamp.to_sec(), truth_start)]
        rate_hz, rot_speed = 5.0, 0.4
        steps = int(8.0 * rate_hz)
        for k in range(steps):
            if rospy.is_shutdown():
                break
            if k == 3:
                srv = self.nomotion_update()
            if k >= 8:  # rotate in place to trigger a motion update
                self.odom_pose = (0.0, 0.0, wrap(self.odom_pose[2] + rot_speed / rate_hz))
            truth = compose(truth_start, self.odom_pose)
            self.publish_tf()
            scan = self.make_scan(grid.cast(truth, angles, 10.0))
            truths.append((scan.header.stamp.to_sec(), truth))
            self.scan_pub.publish(scan)
            time.sleep(1.0 / rate_hz)
        self.info.append('request_nomotion_update: %s' % (srv or 'service not found'))
        time.sleep(1.0)
        if not self.check_alive('the good input'):
            return self.verdict()
        with self.lock:
            good = [m for r, m in self.pf_poses if r > t_ip]
        if not good:
            self.failures.append('no pf_pose published after the valid /initialpose and %d valid scans' % steps)
        else:
            last = good[-1]
            est = pose2_of_pose(last.pose.pose)
            # The truth at the pose's stamp (the robot turns in place; the last
            # update may be a few scans old).
            st = last.header.stamp.to_sec()
            truth = min(truths, key=lambda tt: abs(tt[0] - st))[1]
            e, ye = pos_err(est, truth), yaw_err_deg(est, truth)
            self.info.append('%d pf_pose after the valid input; the last (stamp %.2f s after the /initialpose) is '
                             '%.3f m / %.1f deg from the truth at its stamp'
                             % (len(good), st - ip.header.stamp.to_sec(), e, ye))
            if e > self.good_error:
                self.failures.append('last pf_pose after valid input is %.2f m > %.2f m from the true pose' % (e, self.good_error))
        with self.lock:
            logs = list(self.logs)
        if logs:
            self.info.append('%d warnings/errors logged by %s:' % (len(logs), self.node))
            seen = set()
            for m in logs:
                if m.msg not in seen:
                    seen.add(m.msg)
                    self.info.append('    [%s] %s' % ({Log.WARN: 'WARN', Log.ERROR: 'ERROR', Log.FATAL: 'FATAL'}.get(m.level, m.level), m.msg))
        if self.require_warning:
            if not any(any(k in m.msg.lower() for k in self.keywords) for m in logs):
                self.failures.append('%s logged no warning mentioning any of %s about the bad input' % (self.node, self.keywords))
        if self.cloud_pub and not any('cannot read the point cloud' in m.msg for m in logs):
            self.failures.append('%s logged no warning that it cannot read a malformed point cloud' % self.node)
        self.check_rate_limited(logs)
        return self.verdict()

    def check_rate_limited(self, logs, period=5.0):
        """The same warning (numbers aside) at most once per `period` s of wall time.

        Every bad scan was sent 3 times within 0.3 s, in both phases: without
        the rate limit each would be logged each time."""
        by_text = {}
        for m in logs:
            by_text.setdefault(re.sub(r'[0-9.]+', 'N', m.msg), []).append(m.header.stamp.to_sec())
        repeated = []
        for text, stamps in by_text.items():
            stamps.sort()
            gaps = [b - a for a, b in zip(stamps, stamps[1:])]
            if gaps and min(gaps) < period - 0.5:
                repeated.append('%r %d times, %.2f s apart' % (text, len(stamps), min(gaps)))
        self.info.append('rate limit: %d warnings for %d bad scans, %d bad clouds and %d bad initial poses; '
                         'no text repeated within %.0f s: %s'
                         % (len(logs), 2 * 3 * len(self.bad_scans()), 2 * 3 * len(self.bad_clouds()),
                            2 * len(self.bad_initialposes()), period, 'yes' if not repeated else 'NO'))
        for r in repeated:
            self.failures.append('warning not rate-limited: ' + r)

    def verdict(self):
        text = 'pose_checker [bad_input]:\n  ' + '\n  '.join(self.info)
        if self.failures:
            msg = 'FAILED: %s\n%s' % ('\n  '.join(self.failures), text)
            print(msg)
            return False, msg
        msg = 'PASSED\n%s' % text
        print(msg)
        return True, msg


# ----------------------------------------------------------------------------


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
