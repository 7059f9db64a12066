#!/usr/bin/python3
"""End to end, a bag of one's own: a bundled bag without /ground_truth (bags/small.bag with that topic
left out, made here with the rosbag API) through scripts/demo.sh, as the README's "Localizing a bag
of your own" runs it, from the right start pose and from one 2 m off; and pf_bag_runner on bags whose
topics or frames are not the ones it expects, which must name what the bag has and the option to use.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs the workspace built (scripts/build.sh; $PF_WS or scripts/workspace.bash's default, as demo.sh
finds it) and ROS 1's rosbag; skipped without them, and in the quick tier (it replays bags). About a
minute.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
# This checkout's package, built or not (before any installed pf_localization).
sys.path.insert(0, os.path.join(REPO, 'src'))
from pf_localization import evaluate as pfe  # noqa: E402
from pf_localization import locate  # noqa: E402

WS = os.environ.get('PF_WS') or locate.default_workspace(REPO)  # the one demo.sh uses
RUNNER = os.path.join(WS, 'devel', 'lib', 'pf_localization', 'pf_bag_runner')
try:
    import rosbag
except ImportError:
    rosbag = None
SMALL_BAG, SMALL_MAP = os.path.join(REPO, 'bags', 'small.bag'), os.path.join(REPO, 'maps', 'small.yaml')
START = ('2.5', '2.6', '0')       # small.bag's start pose (bags/README.md)
OFF_2M = ('2.5', '0.6', '0')      # 2 m off it, across the room
# The run from its start pose: nearly every beam fits the map at the estimate (99.9 % on average,
# 98.3 % at worst); a filter that lost its way, or a fit measured at the wrong pose, is far below.
FIT_MEAN_FLOOR, FIT_MIN_FLOOR = 0.95, 0.90
PICTURES = ('trajectory.png', 'fit.png', 'scans.png', 'spread.png', 'cpu.png', 'particles.gif')

needs_workspace = unittest.skipUnless(
    os.path.isfile(RUNNER) and rosbag is not None,
    'needs the workspace built (bash scripts/build.sh: no %s) and ROS 1\'s rosbag (/usr/bin/python3)' % RUNNER)
replays = unittest.skipIf(os.environ.get('PF_TEST_TIER') == 'quick',
                          'replays bags: scripts/test.sh runs it, --quick does not')


def copy_bag(src, dst, keep=lambda topic, msg: (topic, msg)):
    """src's messages into dst through keep(topic, msg) -> (topic, msg), or None or (topic, None)
    to leave it out."""
    with rosbag.Bag(src) as a, rosbag.Bag(dst, 'w') as b:
        for topic, msg, t in a.read_messages():
            kept = keep(topic, msg)
            if kept is not None and kept[1] is not None:
                b.write(kept[0], kept[1], t)


def without_transforms(msg, drop):
    """A TFMessage without the transforms drop(parent, child) says to drop; None when none is left."""
    msg.transforms = [t for t in msg.transforms if not drop(t.header.frame_id, t.child_frame_id)]
    return msg if msg.transforms else None


def demo(bag, report, pose):
    """scripts/demo.sh on bag and small.yaml from pose, its report in report: (exit status, output)."""
    p = subprocess.run(['bash', os.path.join(REPO, 'scripts', 'demo.sh'), '--bag', bag, '--map', SMALL_MAP,
                        '--initial-pose'] + list(pose) + ['--report', report],
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=900)
    return p.returncode, p.stdout


@needs_workspace
@replays
class OwnBagReportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix='pf_own_bag_')
        cls.bag = os.path.join(cls.tmp, 'small_no_reference.bag')
        copy_bag(SMALL_BAG, cls.bag, lambda topic, msg: None if topic == '/ground_truth' else (topic, msg))
        cls.good = os.path.join(cls.tmp, 'good')
        cls.good_status, cls.good_out = demo(cls.bag, cls.good, START)
        cls.off = os.path.join(cls.tmp, 'off')
        cls.off_status, cls.off_out = demo(cls.bag, cls.off, OFF_2M)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def summary(self, report):
        with open(os.path.join(report, 'summary.json')) as f:
            return json.load(f)

    def test_a_bag_without_reference_gets_a_report_and_exit_0(self):
        self.assertEqual(self.good_status, 0, self.good_out[-3000:])
        self.assertIn('pf_evaluate: no reference (the bag has no /ground_truth', self.good_out)
        for f in PICTURES:
            path = os.path.join(self.good, f)
            self.assertTrue(os.path.isfile(path) and os.path.getsize(path) > 10000, 'no picture %s' % path)
        self.assertFalse(os.path.exists(os.path.join(self.good, 'error.png')))
        m = self.summary(self.good)
        self.assertFalse(m['has_reference'])
        self.assertEqual(m['plots'], ['trajectory.png', 'fit.png', 'spread.png', 'cpu.png', 'scans.png',
                                      'changes.png', 'particles.gif'])
        self.assertEqual((m['scans']['topics'], m['scans']['robot_frame'], m['scans']['warnings']),
                         (['/scan'], ['base_link'], []))

    def test_the_right_start_fits_and_is_localized_throughout(self):
        a = self.summary(self.good)['self_assessment']
        self.assertGreaterEqual(a['fit']['mean'], FIT_MEAN_FLOOR)
        self.assertGreaterEqual(a['fit']['min'], FIT_MIN_FLOOR)
        v = a['verdict']
        self.assertTrue(v['localized_throughout'], v['stretches_s'])
        self.assertEqual(v['judgement'], 'localized throughout (all %d updates)' % v['updates'])
        self.assertLess(a['covariance_size']['position_std_m']['max'], 0.05)
        self.assertIn('  verdict:        localized throughout', self.good_out)
        self.assertRegex(self.good_out, r'  beams fit: +mean (9[5-9]|100)\.\d %')

    def test_a_start_2_m_off_shows_in_the_fit_and_the_verdict(self):
        self.assertEqual(self.off_status, 0, self.off_out[-3000:])
        a = self.summary(self.off)['self_assessment']
        v = a['verdict']
        # The first update sees its scan off the walls: few beams fit, and the verdict is not localized.
        self.assertLess(a['fit']['min'], pfe.FIT_LOST)
        self.assertNotEqual(v['stretches_s'][0][0], 'localized')
        self.assertFalse(v['localized_throughout'])
        # It recovers: localized from some time on, to the end.
        self.assertEqual(v['final_state'], 'localized')
        self.assertGreater(v['localized_from_s'], 0.0)
        self.assertRegex(self.off_out, r'verdict: +localized from \d+\.\d s to the end')
        self.assertRegex(self.off_out, r'timeline: +(lost|uncertain) 0\.0-')

    def test_the_scans_lie_on_the_walls_at_the_estimate(self):
        # What scans.png draws: each scan's end points through the laser's mounting (base_link ->
        # base_laser_link, turned by pi) placed at the estimate, against the map's occupied cells.
        est = pfe.read_tum(os.path.join(self.good, 'trajectory.tum'))
        stamps = est[::10, 0]
        scans, warnings = pfe.read_bag_scans(self.bag, ['/scan'], stamps)
        self.assertEqual((len(scans), warnings), (len(stamps), []))
        grey, (x0, x1, y0, y1) = pfe.read_map(SMALL_MAP)
        rows, cols = np.nonzero(grey < 0.5)
        res = (x1 - x0) / grey.shape[1]
        walls = np.c_[x0 + (cols + 0.5) * res, y1 - (rows + 0.5) * res]
        near = []
        for s in scans:
            pose, kind = pfe.associate(est, np.array([s['t']]))
            x, y, yaw = pose[0]
            c, sn = np.cos(yaw), np.sin(yaw)
            pts = np.c_[x + c * s['xy'][:, 0] - sn * s['xy'][:, 1], y + sn * s['xy'][:, 0] + c * s['xy'][:, 1]]
            d = np.sqrt(((pts[:, None, :] - walls[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
            near.append(np.mean(d < 0.15))
        # Without the mounting's half turn the points would lie mirrored, off the walls.
        self.assertGreater(np.mean(near), 0.9)



def runner(bag, *extra):
    """pf_bag_runner on bag and small.yaml: (exit status, stderr)."""
    with tempfile.TemporaryDirectory() as d:
        p = subprocess.run([RUNNER, '--bag', bag, '--map', SMALL_MAP, '--out', os.path.join(d, 't.tum'),
                            '--initial-pose'] + list(START) + ['--quiet'] + list(extra),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True, timeout=300)
    return p.returncode, p.stderr


@needs_workspace
class UnknownBagTest(unittest.TestCase):
    """A first run on a bag whose topics or frames are not pf_bag_runner's defaults is told what the
    bag has and the option to use, before it replays anything."""

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='pf_unknown_bag_')

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def bag(self, name, keep):
        path = os.path.join(self.tmp, name + '.bag')
        copy_bag(SMALL_BAG, path, keep)
        return path

    def test_another_scan_topic_is_named_with_the_option(self):
        bag = self.bag('laser', lambda topic, msg: ('/laser' if topic == '/scan' else topic, msg))
        status, err = runner(bag)
        self.assertEqual(status, 2, err)
        self.assertIn('no /scan topic in the bag; its sensor_msgs/LaserScan topics: /laser. Name each '
                      "sensor's with --scan-topic TOPIC", err)
        status, err = runner(bag, '--scan-topic', '/laser')
        self.assertEqual(status, 0, err)

    def test_a_missing_laser_mounting_names_the_frames(self):
        bag = self.bag('no_mount', lambda topic, msg: (topic, without_transforms(
            msg, lambda parent, child: child == 'base_laser_link')) if topic == '/tf' else (topic, msg))
        status, err = runner(bag)
        self.assertEqual(status, 2, err)
        self.assertIn('no transform from base_link to base_laser_link, the frame of /scan (the sensor\'s '
                      'mounting; its frames in the bag: base_laser_link; the bag\'s transforms: odom -> '
                      'base_link)', err)
        self.assertIn("Name the robot's frames in a --params FILE.yaml (odom_frame: ..., base_frame: ...)", err)

    def test_missing_odometry_names_the_topics_and_frames(self):
        def keep(topic, msg):
            if topic == '/odom':
                return None
            if topic == '/tf':
                return topic, without_transforms(msg, lambda parent, child: parent == 'odom')
            return topic, msg
        status, err = runner(self.bag('no_odom', keep))
        self.assertEqual(status, 2, err)
        self.assertIn('no odometry odom -> base_link: not on /tf, and no /odom topic in the bag (the bag\'s '
                      'transforms: base_link -> base_laser_link; its nav_msgs/Odometry topics: none)', err)
        self.assertIn('the odometry topic with --odom-topic TOPIC', err)

    def test_odometry_on_another_topic_and_frame(self):
        # Odometry only on /wheel_odom, odom -> base_footprint: the frame is named from the topic.
        def keep(topic, msg):
            if topic == '/odom':
                msg.child_frame_id = 'base_footprint'
                return '/wheel_odom', msg
            if topic == '/tf':
                return topic, without_transforms(msg, lambda parent, child: parent == 'odom')
            return topic, msg
        bag = self.bag('wheel_odom', keep)
        status, err = runner(bag, '--odom-topic', '/wheel_odom')
        self.assertEqual(status, 2, err)
        self.assertIn('no odometry odom -> base_link: not on /tf, and /wheel_odom has odom -> base_footprint',
                      err)


if __name__ == '__main__':
    unittest.main()
