"""pose_checker's track and initialpose modes (pose_checker.py's docstring): the watch that compares
every /ground_truth with the localizer's estimate on tf, and in initialpose mode publishes the
/initialpose and checks the first pf_pose after it. The evaluation is TrackEvaluation's
(pose_checker_evaluation.py)."""
import threading
import time

import rospy
import tf2_ros

from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from nav_msgs.msg import OccupancyGrid

from pose_checker_evaluation import TrackEvaluation
from pose_checker_node import opt_float, param
from pose_checker_poses import compose, pos_err, pose2_of_pose, pose2_of_transform, quat_from_yaw, wrap, yaw_err_deg

# s of sim time a ground-truth pose waits for the localizer's estimate at its
# stamp before a fallback lookup stands in: a player catching up after a
# stall sends seconds of the bag before its /clock, and both the localizer
# and this node's tf lag by as much (the tf cache below holds 30 s).
EXACT_LOOKUP_WAIT_S = 5.0


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


class PoseChecker(TrackEvaluation):
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

    def _process_pending(self, flush=False):
        now = rospy.Time.now()
        with self.lock:
            pending, self.pending = self.pending, []
        keep = []
        for msg in pending:
            late = flush or (now - msg.header.stamp).to_sec() > EXACT_LOOKUP_WAIT_S
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
