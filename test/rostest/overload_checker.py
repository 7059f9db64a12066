#!/usr/bin/python3
"""rostest checker for pf_node under overload.

Watches, while the bag plays (from the first to the last /ground_truth):
  - map -> odom on /tf, as a recorder of /tf sees it (every message, in the
    order it arrives): the gaps between consecutive stamps (sim time), raw,
    which must stay below max_raw_tf_gap [s] wherever pf_node could have
    published: a longer one only where /clock itself moved from one stamp's
    time to the next's in a single step (no /clock value between them, the
    stamps taken back by transform_tolerance; stamps come from /clock, so
    no publisher could do better); and with the clock's jumps taken out,
    below max_tf_gap [s]. A gap the clock
    itself made is not pf_node's: a timer under simulated time can only fire
    when /clock moves, which rosbag play does in steps of rate / 100 s (40 ms
    at 4x), and by a second at once when it is starved of CPU and catches up.
    So the /clock steps inside a gap (consecutive /clock values, the stamps
    taken back by transform_tolerance [s], default 0.1, pf_node's) are
    subtracted from it: the sum of those longer than one tf period
    (tf_period [s], default 0.05; the clock's jumps), or the largest step
    if that is more (the clock's resolution). A republishing timer stuck
    behind the filter shows up whole in both, since the clock moves in small
    steps meanwhile. The clock's own steps are printed (a raw gap can be no
    smaller than the step it spans), and stamps that arrive out of order
    (not later than the one before) are counted and fail max_raw_tf_gap;
  - pf_node's pf_status (latency_*, update_time_*, dropped_scans,
    particle_cap): the last report must satisfy the bounds below;
  - pf_node's resident memory (/proc/PID/status VmRSS): from rss_after [s of
    sim time after the first ground truth] to the end it may grow by at most
    max_rss_growth_mb;
  - tracking: for each /ground_truth stamped t (from start_after [s] on), the
    tf lookup map -> base_link at t; RMSE must stay below rmse_below [m]
    and every error at most max_error [m];
  - a new map, when asked (map_on_topic_at, set_map_at [s of sim time after
    the first ground truth]): the map on /map published again by this node,
    or sent to set_map with the pose on amcl_pose; the new maps must be
    installed (pf_node's "map W x H cells" lines on /rosout) and set_map
    must succeed;
  - a lift ride, when asked (ride_topic, the bag's floor topic: a new name
    on it is a ride): change_floor with that floor and the latest
    /ground_truth pose; the call must succeed, every tracking error from
    ride_settle [s, default 2] after the ride at most ride_max_error [m],
    and pf_floor name the floor of the last ride;
  - global localization on every floor, when asked (global_at [s of sim time
    after the first ground truth], global_floor: the floor the robot is on):
    /global_localization called once; pf_floor must then name global_floor,
    and never another floor, and from ride_settle after it names it every
    error must be at most ride_max_error;
and that pf_node is alive at the end. Every figure is printed (rostest --text,
or the XML result's <system-out>) whether the test passes or not.

Params (all optional; unset: only reported):
  max_raw_tf_gap [s], max_tf_gap [s], tf_gap_p99 [s] (99 % of the gaps
  without the clock's jumps at most this),
  max_latency_p95_ms, latency_p95_over_update_ms (latency p95
  must stay below update_time p95 + this), max_update_time_p50_ms,
  max_update_time_p95_ms, max_particle_cap (particle_cap must be reported
  and at most this),
  min_dropped_scans, max_scan_age_p95_ms, max_rss_growth_mb, rss_after [s],
  rmse_below [m], start_after [s, default 5], min_samples (default 50),
  idle_timeout [s wall, default 8], wall_timeout [s wall, default 150],
  pf_node (default /pf_node), ride_topic, ride_settle [s], ride_max_error [m],
  global_at [s], global_floor.
"""

import bisect
import math
import sys
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
import tf2_ros
from diagnostic_msgs.msg import DiagnosticStatus
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from nav_msgs.msg import OccupancyGrid
from nav_msgs.srv import SetMap
from pf_localization.srv import ChangeFloor
from std_msgs.msg import String
from std_srvs.srv import Empty
from rosgraph_msgs.msg import Log
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

PKG = 'pf_localization'


def opt(name, default=None):
    v = rospy.get_param('~' + name, default)
    return None if v == '' else v


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def node_pid(node):
    try:
        uri = rosgraph.Master(rospy.get_name()).lookupNode(node)
        code, _, pid = xmlrpc.client.ServerProxy(uri).getPid(rospy.get_name())
        return pid if code == 1 else None
    except Exception:  # noqa: BLE001 - not there: no pid
        return None


def rss_mb(pid):
    try:
        with open('/proc/%d/status' % pid) as f:
            for line in f:
                if line.startswith('VmRSS:'):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        return None
    return None


class OverloadChecker:
    def __init__(self):
        self.lock = threading.Lock()
        self.node = opt('pf_node', '/pf_node')
        self.start_after = float(opt('start_after', 5.0))
        self.buffer = tf2_ros.Buffer(rospy.Duration(60.0))
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.gt = []          # (stamp, x, y, yaw), waiting to be compared
        self.first_gt = None
        self.last_gt_wall = None
        self.errors = []      # (t, position error, yaw error deg)
        self.tf_stamps = []   # map -> odom stamps (sim s), while ground truth flows
        self.status = None
        self.statuses = 0
        self.rss = []         # (t sim rel, MB)
        rospy.Subscriber('/ground_truth', PoseStamped, self._on_gt, queue_size=200)
        rospy.Subscriber('/tf', TFMessage, self._on_tf, queue_size=500)
        rospy.Subscriber('/pf_status', DiagnosticStatus, self._on_status, queue_size=20)
        self.clock = []       # /clock values (sim s), in order of arrival
        rospy.Subscriber('/clock', Clock, self._on_clock, queue_size=1000)
        self.swaps = MapSwaps(self.node)
        self.rides = FloorRides()

    def _on_clock(self, msg):
        with self.lock:
            self.clock.append(msg.clock.to_sec())

    def _on_gt(self, msg):
        with self.lock:
            t = msg.header.stamp.to_sec()
            if self.first_gt is None:
                self.first_gt = t
            self.last_gt_wall = time.time()
            self.gt.append((t, msg.pose.position.x, msg.pose.position.y, yaw_of(msg.pose.orientation)))
            self.rides.truth = msg

    def _on_tf(self, msg):
        with self.lock:
            if self.first_gt is None:
                return
            for t in msg.transforms:
                if t.header.frame_id == 'map' and t.child_frame_id == 'odom':
                    self.tf_stamps.append((t.header.stamp.to_sec(), time.time(),
                                           rospy.Time.now().to_sec()))

    def _on_status(self, msg):
        with self.lock:
            self.status = {kv.key: kv.value for kv in msg.values}
            self.statuses += 1

    def _compare(self, flush=False):
        now = rospy.Time.now().to_sec()
        with self.lock:
            pending, self.gt = self.gt, []
        keep = []
        for (t, x, y, yaw) in pending:
            if not flush and now - t < 1.0:
                keep.append((t, x, y, yaw))
                continue
            if t - self.first_gt < self.start_after:
                continue
            try:
                tr = self.buffer.lookup_transform('map', 'base_link', rospy.Time.from_sec(t))
            except tf2_ros.TransformException:
                try:
                    tr = self.buffer.lookup_transform('map', 'base_link', rospy.Time(0))
                except tf2_ros.TransformException:
                    continue
            p = tr.transform.translation
            dyaw = math.degrees(abs(math.atan2(math.sin(yaw_of(tr.transform.rotation) - yaw),
                                               math.cos(yaw_of(tr.transform.rotation) - yaw))))
            self.errors.append((t - self.first_gt, math.hypot(p.x - x, p.y - y), dyaw))
        with self.lock:
            self.gt = keep + self.gt

    def run(self):
        idle = float(opt('idle_timeout', 8.0))
        wall_timeout = float(opt('wall_timeout', 150.0))
        rss_after = float(opt('rss_after', 0.0))
        start = time.time()
        pid = None
        while not rospy.is_shutdown() and time.time() - start < wall_timeout:
            time.sleep(0.5)
            self._compare()
            if pid is None:
                pid = node_pid(self.node)
            with self.lock:
                first, last_wall = self.first_gt, self.last_gt_wall
            if first is not None and pid is not None:
                t_rel = rospy.Time.now().to_sec() - first
                mb = rss_mb(pid)
                if mb is not None and t_rel >= rss_after:
                    self.rss.append((t_rel, mb))
            if first is not None:
                self.swaps.when_due(rospy.Time.now().to_sec() - first)
                self.rides.when_due(rospy.Time.now().to_sec() - first)
            if last_wall is not None and time.time() - last_wall > idle:
                break
        self._compare(flush=True)
        return self.evaluate(pid)

    def evaluate(self, pid):
        failures, info = [], []
        # tf gaps
        arrived = [t[0] for t in self.tf_stamps]
        out_of_order = sum(1 for a, b in zip(arrived, arrived[1:]) if b <= a)
        stamps = sorted(self.tf_stamps)
        clock = sorted(self.clock)
        steps = [(a, b - a) for a, b in zip(clock, clock[1:])]  # (from, step)
        period = float(opt('tf_period', 0.05))
        tol = float(opt('transform_tolerance', 0.1))  # pf_node's: stamps are clock + this
        gaps = []
        j = 0
        for a, b in zip(stamps, stamps[1:]):
            raw = b[0] - a[0]
            # The largest clock step overlapping [a, b] (stamps minus the tolerance).
            lo, hi = a[0] - tol, b[0] - tol
            while j < len(steps) and steps[j][0] + steps[j][1] < lo:
                j += 1
            k, largest, jumps = j, 0.0, 0.0
            while k < len(steps) and steps[k][0] < hi:
                largest = max(largest, steps[k][1])
                if steps[k][1] > period:
                    jumps += steps[k][1]
                k += 1
            jump = max(largest, jumps)
            gaps.append((raw - jump, raw, jump, a[0] - self.first_gt))
        gaps.sort(reverse=True)
        max_gap = gaps[0][0] if gaps else float('inf')
        raw_max = max((g[1] for g in gaps), default=float('inf'))
        info.append('map->odom: %d messages while the bag played, largest gap %.3f s '
                    '(raw stamp gap %.3f s; /clock: %d values, largest step %.3f s)' %
                    (len(stamps), max_gap, raw_max, len(clock), max((s for _, s in steps), default=0.0)))
        info.append('largest gaps (gap, raw stamp gap, clock step inside, at t) s: ' +
                    ', '.join('(%.3f %.3f %.3f %.1f)' % g for g in gaps[:5]))
        by_raw = sorted(gaps, key=lambda g: g[1], reverse=True)
        bound = opt('max_raw_tf_gap')
        # The raw gaps over the bound that span no /clock value: the clock's single step.
        over, of_clock = [], 0
        for g in by_raw:
            if bound is None or g[1] <= float(bound):
                break
            lo, hi = g[3] + self.first_gt - tol, g[3] + self.first_gt + g[1] - tol
            k = bisect.bisect_right(clock, lo + 1e-3)
            if k < len(clock) and clock[k] < hi - 1e-3:
                over.append(g)
            else:
                of_clock += 1
        info.append('largest raw stamp gaps (raw, clock step inside, at t) s: ' +
                    ', '.join('(%.3f %.3f %.1f)' % (g[1], g[2], g[3]) for g in by_raw[:5]) +
                    '; %d raw gaps over 0.1 s, %d stamps out of order; /clock steps over '
                    '0.1 s: %d (information: a raw gap spans at least one step)' %
                    (sum(1 for g in gaps if g[1] > 0.1), out_of_order,
                     sum(1 for _, st in steps if st > 0.1)))
        if bound is not None:
            info.append('raw gaps over max_raw_tf_gap %s s: %d where /clock moved in one step '
                        '(rosbag play behind), %d where pf_node skipped a /clock' %
                        (bound, of_clock, len(over)))
        if over:
            failures.append('map->odom raw stamp gap %.3f s at t=%.1f s > max_raw_tf_gap %.3f s '
                            'over /clock values pf_node did not publish at (%d such gaps)' %
                            (over[0][1], over[0][3], float(bound), len(over)))
        if bound is not None and out_of_order:
            failures.append('%d map->odom stamps arrived out of order' % out_of_order)
        bound = opt('max_tf_gap')
        if bound is not None and not max_gap <= float(bound):
            failures.append('map->odom gap %.3f s > max_tf_gap %.3f s' % (max_gap, float(bound)))
        bound = opt('tf_gap_p99')
        if gaps:
            p99 = sorted(g[0] for g in gaps)[int(0.99 * (len(gaps) - 1))]
            over = sum(1 for g in gaps if g[0] > float(bound or 2 * period))
            info.append('map->odom gaps: p99 %.3f s; %d of %d longer than %.3f s' %
                        (p99, over, len(gaps), float(bound or 2 * period)))
            if bound is not None and not p99 <= float(bound):
                failures.append('map->odom gap p99 %.3f s > tf_gap_p99 %s s' % (p99, bound))
        # diagnostics
        s = self.status or {}
        keys = ['particles', 'max_particles', 'particle_cap', 'dropped_scans',
                'latency_p50_ms', 'latency_p95_ms', 'latency_max_ms',
                'scan_age_p50_ms', 'scan_age_p95_ms', 'scan_age_max_ms',
                'update_time_p50_ms', 'update_time_p95_ms', 'update_time_max_ms']
        info.append('last pf_status (%d received): %s' %
                    (self.statuses, ', '.join('%s=%s' % (k, s[k]) for k in keys if k in s)))
        if not s:
            failures.append('no pf_status received')
        else:
            def value(k):
                return float(s.get(k, 'nan'))

            def check(name, key, ok):
                b = opt(name)
                if b is not None and not ok(value(key), float(b)):
                    failures.append('%s = %s breaks %s = %s' % (key, s.get(key), name, b))
            check('max_latency_p95_ms', 'latency_p95_ms', lambda v, b: v <= b)
            check('max_update_time_p50_ms', 'update_time_p50_ms', lambda v, b: v <= b)
            check('max_update_time_p95_ms', 'update_time_p95_ms', lambda v, b: v <= b)
            check('max_particle_cap', 'particle_cap', lambda v, b: v <= b)
            check('max_scan_age_p95_ms', 'scan_age_p95_ms', lambda v, b: v <= b)
            check('min_dropped_scans', 'dropped_scans', lambda v, b: v >= b)
            over = opt('latency_p95_over_update_ms')
            if over is not None:
                lim = value('update_time_p95_ms') + float(over)
                info.append('latency p95 bound: update_time p95 + %s ms = %.1f ms' % (over, lim))
                if not value('latency_p95_ms') <= lim:
                    failures.append('latency_p95_ms %s > update_time_p95_ms + %s = %.1f' %
                                    (s.get('latency_p95_ms'), over, lim))
        # memory
        if self.rss:
            base, end, peak = self.rss[0][1], self.rss[-1][1], max(m for _, m in self.rss)
            info.append('pf_node RSS: %.1f MB at t=%.0f s, %.1f MB at the end, peak %.1f MB' %
                        (base, self.rss[0][0], end, peak))
            b = opt('max_rss_growth_mb')
            if b is not None and not end - base <= float(b):
                failures.append('RSS grew by %.1f MB > max_rss_growth_mb %s' % (end - base, b))
        elif opt('max_rss_growth_mb') is not None:
            failures.append('no RSS sample of %s' % self.node)
        # tracking
        n = len(self.errors)
        if n:
            rmse = math.sqrt(sum(e * e for _, e, _ in self.errors) / n)
            yaw_rmse = math.sqrt(sum(y * y for _, _, y in self.errors) / n)
            worst = max(self.errors, key=lambda e: e[1])
            info.append('tracking: %d samples, RMSE %.3f m, yaw RMSE %.2f deg, max %.3f m at t=%.1f s' %
                        (n, rmse, yaw_rmse, worst[1], worst[0]))
            b = opt('rmse_below')
            if b is not None and not rmse <= float(b):
                failures.append('RMSE %.3f m > rmse_below %s m' % (rmse, b))
            b = opt('max_error')
            if b is not None and not worst[1] <= float(b):
                failures.append('error %.3f m at t=%.1f s > max_error %s m' % (worst[1], worst[0], b))
        if n < int(opt('min_samples', 50)):
            failures.append('only %d tracking samples' % n)
        self.swaps.evaluate(info, failures)
        self.rides.evaluate(info, failures, self.errors, self.first_gt)
        if node_pid(self.node) is None:
            failures.append('%s is not alive at the end' % self.node)
        text = '\n'.join(info + ['FAIL: ' + f for f in failures] or ['ok'])
        print('overload_checker:\n' + text)
        return not failures, text


class MapSwaps:
    """Gives pf_node the map it has again, on /map and through set_map, when asked."""

    def __init__(self, node):
        self.at = {'topic': opt('map_on_topic_at'), 'set_map': opt('set_map_at')}
        self.done = {}        # way -> (sim s, wall s the call took, success)
        self.map = None
        self.pose = None
        self.installed = 0    # pf_node's "map ... cells" lines since the first swap
        self.first_swap = None  # sim s
        self.node = node
        self.threads = []
        if not any(v is not None for v in self.at.values()):
            return
        self.publisher = rospy.Publisher('/map', OccupancyGrid, queue_size=1, latch=True)
        rospy.Subscriber('/map', OccupancyGrid, self._on_map, queue_size=1)
        rospy.Subscriber('/amcl_pose', PoseWithCovarianceStamped, self._on_pose, queue_size=2)
        rospy.Subscriber('/rosout', Log, self._on_log, queue_size=100)

    def _on_map(self, msg):
        if self.map is None:
            self.map = msg

    def _on_pose(self, msg):
        self.pose = msg

    def _on_log(self, msg):
        if msg.name == self.node and msg.msg.startswith('pf_node: map ') and ' cells at ' in msg.msg \
                and self.first_swap is not None and msg.header.stamp.to_sec() >= self.first_swap:
            self.installed += 1

    def when_due(self, t):
        for way, at in self.at.items():
            if at is None or way in self.done or t < float(at) or self.map is None:
                continue
            self.done[way] = (t, None, None)
            if self.first_swap is None:
                self.first_swap = rospy.Time.now().to_sec()
            thread = threading.Thread(target=self._swap, args=(way, t))
            thread.start()
            self.threads.append(thread)

    def _swap(self, way, t):
        start = time.time()
        if way == 'topic':
            self.publisher.publish(self.map)
            self.done[way] = (t, 0.0, True)
            return
        rospy.wait_for_service('/set_map', timeout=10.0)
        pose = self.pose
        ok = rospy.ServiceProxy('/set_map', SetMap)(self.map, pose).success
        self.done[way] = (t, time.time() - start, ok)

    def evaluate(self, info, failures):
        asked = [way for way, at in self.at.items() if at is not None]
        if not asked:
            return
        for thread in self.threads:
            thread.join(30.0)
        for way in asked:
            if way not in self.done:
                failures.append('the map was never given again by %s (at %s s)' % (way, self.at[way]))
                continue
            t, took, ok = self.done[way]
            info.append('map given again by %s at t=%.1f s%s' %
                        (way, t, '' if took is None else ': the call took %.2f s wall' % took))
            if not ok:
                failures.append('giving the map by %s failed' % way)
        info.append('pf_node installed %d maps since' % self.installed)
        if self.installed != len(asked):
            failures.append('pf_node installed %d maps, not %d' % (self.installed, len(asked)))


class FloorRides:
    """Calls change_floor at each ride on the bag's floor topic, with the true pose then."""

    def __init__(self):
        self.topic = opt('ride_topic')
        self.global_at, self.global_floor = opt('global_at'), opt('global_floor')
        self.global_called = None  # sim s of the global_localization call
        self.floors_named = []     # (sim s, floor) of every pf_floor after it
        self.truth = None      # the latest /ground_truth
        self.floor = None      # the bag's floor
        self.rides = []        # (sim s, floor, wall s the call took, success, message)
        self.pf_floor = None   # the last pf_floor
        self.threads = []
        if self.topic is not None:
            rospy.Subscriber(self.topic, String, self._on_floor, queue_size=10)
        if self.topic is not None or self.global_at is not None:
            rospy.Subscriber('/pf_floor', String, self._on_pf_floor, queue_size=10)

    def _on_pf_floor(self, msg):
        self.pf_floor = msg.data
        if self.global_called is not None:
            self.floors_named.append((rospy.Time.now().to_sec(), msg.data))

    def when_due(self, t):
        if self.global_at is None or self.global_called is not None or t < float(self.global_at):
            return
        self.global_called = rospy.Time.now().to_sec()
        rospy.ServiceProxy('/global_localization', Empty)()

    def _on_floor(self, msg):
        first, self.floor = self.floor is None, msg.data
        if first or self.truth is None:
            return
        # The ride's time: the bag's clock as the floor's name arrives.
        thread = threading.Thread(target=self._ride,
                                  args=(rospy.Time.now().to_sec(), msg, self.truth))
        thread.start()
        self.threads.append(thread)

    def _ride(self, t, msg, truth):
        pose = PoseWithCovarianceStamped()
        pose.header = truth.header
        pose.pose.pose = truth.pose
        for i, v in ((0, 0.05 ** 2), (7, 0.05 ** 2), (35, 0.05 ** 2)):
            pose.pose.covariance[i] = v
        start = time.time()
        rospy.wait_for_service('/change_floor', timeout=10.0)
        res = rospy.ServiceProxy('/change_floor', ChangeFloor)(msg.data, pose)
        self.rides.append((t, msg.data, time.time() - start, res.success, res.message))

    def evaluate(self, info, failures, errors, first_gt):
        self._evaluate_global(info, failures, errors, first_gt)
        if self.topic is None:
            return
        for thread in self.threads:
            thread.join(30.0)
        if not self.rides:
            failures.append('no ride on %s' % self.topic)
            return
        settle, bound = float(opt('ride_settle', 2.0)), opt('ride_max_error')
        for t, floor, took, ok, message in self.rides:
            t_rel = t - first_gt
            after = [e for e in errors if e[0] >= t_rel + settle]
            worst = max(after, key=lambda e: e[1]) if after else (float('nan'), float('nan'), 0.0)
            info.append('ride to %s at t=%.1f s: change_floor took %.2f s wall, %s: %s; '
                        'from %.0f s after it, %d samples, max error %.3f m at t=%.1f s' %
                        (floor, t_rel, took, 'ok' if ok else 'FAILED', message, settle,
                         len(after), worst[1], worst[0]))
            if not ok:
                failures.append('change_floor to %s failed: %s' % (floor, message))
            if bound is not None and not (after and worst[1] <= float(bound)):
                failures.append('after the ride to %s: error %.3f m > ride_max_error %s m' %
                                (floor, worst[1], bound))
        info.append('pf_floor: %s' % self.pf_floor)
        if self.pf_floor != self.rides[-1][1]:
            failures.append('pf_floor is %s, not %s' % (self.pf_floor, self.rides[-1][1]))


    def _evaluate_global(self, info, failures, errors, first_gt):
        if self.global_at is None:
            return
        if self.global_called is None:
            failures.append('global_localization was never called')
            return
        named = [(t, f) for t, f in self.floors_named if f]
        info.append('global localization on every floor at t=%.1f s; pf_floor then: %s' %
                    (self.global_called - first_gt,
                     ', '.join('%s at t=%.1f s' % (f, t - first_gt) for t, f in named) or 'none'))
        wrong = [f for _, f in named if f != self.global_floor]
        if wrong:
            failures.append('pf_floor named %s, not %s' % (wrong[0], self.global_floor))
        if not named:
            failures.append('no floor found (pf_floor stayed empty)')
            return
        t_rel = named[0][0] - first_gt
        after = [e for e in errors if e[0] >= t_rel + float(opt('ride_settle', 2.0))]
        worst = max(after, key=lambda e: e[1]) if after else (float('nan'), float('nan'), 0.0)
        info.append('from %.0f s after it was found, %d samples, max error %.3f m at t=%.1f s' %
                    (float(opt('ride_settle', 2.0)), len(after), worst[1], worst[0]))
        bound = opt('ride_max_error')
        if bound is not None and not (after and worst[1] <= float(bound)):
            failures.append('after the floor was found: error %.3f m > ride_max_error %s m' %
                            (worst[1], bound))


class OverloadCheckerTest(unittest.TestCase):
    def test_overload_checker(self):
        ok, text = OverloadChecker().run()
        sys.stdout.flush()
        self.assertTrue(ok, text)


if __name__ == '__main__':
    rospy.init_node('overload_checker')
    rostest.rosrun(PKG, 'overload_checker', OverloadCheckerTest, sys.argv)
