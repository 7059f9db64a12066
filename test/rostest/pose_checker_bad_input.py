"""pose_checker's bad_input mode (pose_checker.py's docstring): malformed scans, clouds and initial
poses fed to a running pf_node before and after the map exists, then good input that must localize
it, and the warnings it logged, rate-limited."""
import math
import re
import threading
import time

import rospy
import rosgraph
import tf2_ros

from geometry_msgs.msg import PoseWithCovarianceStamped, TransformStamped, Quaternion
from nav_msgs.msg import OccupancyGrid, Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import LaserScan, PointCloud2, PointField

from pose_checker_grid_map import GridMap
from pose_checker_node import node_alive, node_publishes, param
from pose_checker_poses import compose, pos_err, pose2_of_pose, quat_from_yaw, wrap, yaw_err_deg


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
