#!/usr/bin/python3
"""Unit tests of pf_evaluate (pf_localization.evaluate): association and metrics on tiny literal
trajectories, and the CPU plot's axis.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs numpy only (no ROS, no matplotlib).
"""
import math
import os
import sys
import tempfile
import unittest

import numpy as np

# This checkout's package, built or not (before any installed pf_localization).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'src'))
from pf_localization import evaluate as pfe  # noqa: E402


def traj(rows):
    return np.array(rows, dtype=float)


class MetricsTest(unittest.TestCase):
    def test_off_fraction_leaves_out_the_first_ten_seconds(self):
        ref = traj([(t, 0.0, 0.0, 0.0) for t in range(30)])       # t = 0 .. 29 s
        est = ref.copy()
        est[:10, 1] = 5.0                                          # 5 m off while settling
        est[[12, 20], 1] = 0.6                                     # two poses of 20 after it off
        m, _ = pfe.evaluate(est, ref)
        self.assertAlmostEqual(m['off_fraction_after_settle'], 2 / 20, places=12)

    def test_confidently_wrong_counts_localized_updates_more_than_a_metre_off(self):
        ref = traj([(t, 0.0, 0.0, 0.0) for t in range(10)])
        est = ref.copy()
        est[[3, 4, 5], 1] = [1.5, 2.0, 0.9]                        # 1.5 and 2 m off, then 0.9
        _, match = pfe.evaluate(est, ref)
        log = {'t': np.array([1.0, 3.0, 4.0, 5.0, 4.02]),
               'state': np.array(['localized', 'localized', 'uncertain', 'localized', 'lost'])}
        count, times = pfe.confidently_wrong(log, match)
        self.assertEqual(count, 1)                                 # t = 3 only
        self.assertEqual(times, [3.0])
        self.assertEqual(pfe.confidently_wrong({'t': log['t']}, match), (None, []))

    def test_update_log_keeps_the_state_column(self):
        with tempfile.NamedTemporaryFile('w', suffix='.csv', delete=False) as f:
            f.write('t,particles,state\n1.0,500,localized\n2.0,600,lost\n')
        try:
            log = pfe.read_update_log(f.name)
        finally:
            os.remove(f.name)
        self.assertEqual(list(log['state']), ['localized', 'lost'])
        self.assertEqual(list(log['particles']), [500.0, 600.0])

    def test_constant_offset(self):
        ref = traj([(t, t, 0.0, 0.0) for t in range(10)])
        est = ref + [0, 0.06, 0.08, 0]                       # 0.1 m off everywhere
        m, _ = pfe.evaluate(est, ref, lost=0.3)
        for k in ('ate_rmse_m', 'median_m', 'mean_m', 'max_m'):
            self.assertAlmostEqual(m[k], 0.1, places=12)
        self.assertEqual(m['yaw_rmse_deg'], 0.0)
        self.assertEqual((m['n_matched'], m['n_exact'], m['coverage']), (10, 10, 1.0))
        self.assertEqual(m['convergence_time_s'], 0.0)
        self.assertEqual(m['lost_fraction'], 0.0)

    def test_step_error_convergence(self):
        ref = traj([(10.0 + t, 0, 0, 0) for t in range(10)])
        est = ref.copy()
        est[:4, 1] = 1.0                                     # 1 m off at t = 10..13
        est[2, 1] = 0.1                                      # a dip below the threshold does not count
        m, _ = pfe.evaluate(est, ref, lost=0.3)
        self.assertEqual(m['convergence_time_s'], 4.0)       # relative to the first reference (t=10)
        self.assertAlmostEqual(m['lost_fraction'], 0.3)
        self.assertAlmostEqual(m['ate_rmse_m'], math.sqrt((3 * 1.0 + 0.01) / 10))
        self.assertAlmostEqual(m['max_m'], 1.0)
        est[-1, 1] = 0.5                                     # lost at the end: never converged
        self.assertIsNone(pfe.evaluate(est, ref, lost=0.3)[0]['convergence_time_s'])

    def test_yaw_wraparound(self):
        ref = traj([(0, 0, 0, math.pi - 0.01), (1, 0, 0, -math.pi + 0.01)])
        est = traj([(0, 0, 0, -math.pi + 0.01), (1, 0, 0, math.pi - 0.01)])
        m, _ = pfe.evaluate(est, ref)
        self.assertAlmostEqual(m['yaw_rmse_deg'], math.degrees(0.02), places=9)

    def test_interpolation_and_shortest_arc(self):
        # estimates at t=0 and t=0.4 bracket the reference at t=0.1 (both within 0.5 s)
        est = traj([(0.0, 0.0, 0.0, math.pi - 0.1), (0.4, 0.4, 0.8, -math.pi + 0.1)])
        ref = traj([(0.1, 0.1, 0.2, math.pi - 0.05)])       # on the line, yaw across +-pi
        m, match = pfe.evaluate(est, ref)
        self.assertEqual(m['n_interpolated'], 1)
        self.assertAlmostEqual(m['ate_rmse_m'], 0.0, places=12)
        self.assertAlmostEqual(m['yaw_rmse_deg'], 0.0, places=9)
        # zero-order hold instead: newest estimate at or before (t=0)
        m, _ = pfe.evaluate(est, ref, interpolate=False)
        self.assertEqual(m['n_held'], 1)
        self.assertAlmostEqual(m['ate_rmse_m'], math.hypot(0.1, 0.2))

    def test_max_gap_and_coverage(self):
        est = traj([(0, 0, 0, 0), (2, 2, 0, 0)])
        ref = traj([(-1, 0, 0, 0), (0.3, 0.3, 0, 0), (1.0, 1, 0, 0), (2.2, 2, 0, 0)])
        m, match = pfe.evaluate(est, ref, max_gap=0.5)
        # t=-1: nothing before; t=0.3: next estimate 1.7 s away -> held (0.3 m off);
        # t=1.0: 1 s from both -> unmatched; t=2.2: held, exact position
        self.assertEqual((m['n_matched'], m['n_held'], m['n_reference']), (2, 2, 4))
        self.assertAlmostEqual(m['coverage'], 0.5)
        self.assertAlmostEqual(m['ate_rmse_m'], math.sqrt(0.09 / 2))
        np.testing.assert_allclose(match['unmatched_t'], [-1.0, 1.0])
        self.assertAlmostEqual(m['convergence_time_s'], 1.3)  # first matched ref (0.3) - first ref (-1)

    def test_nothing_matched_raises(self):
        with self.assertRaises(pfe.EvalError):
            pfe.evaluate(traj([(100, 0, 0, 0)]), traj([(0, 0, 0, 0)]))

    def test_read_tum_sorts_and_converts_quaternion(self):
        with tempfile.NamedTemporaryFile('w', suffix='.tum', delete=False) as f:
            f.write('# t x y z qx qy qz qw\n2 1 2 0 0 0 %.12f %.12f\n1 0 0 0 0 0 0 1\n'
                    % (math.sin(-1.5), math.cos(-1.5)))
        try:
            a = pfe.read_tum(f.name)
        finally:
            os.unlink(f.name)
        np.testing.assert_allclose(a, [[1, 0, 0, 0], [2, 1, 2, -3.0]], atol=1e-9)

    def test_cpu_axis_is_clipped_only_when_a_few_updates_squash_the_rest(self):
        bulk = np.r_[9.4, np.linspace(0.08, 0.12, 499)]   # one slow first update, then ~0.1 ms
        top = pfe.cpu_axis_top(bulk)
        self.assertGreater(top, 0.12)                      # the bulk stays in view...
        self.assertLess(top, 0.5)                          # ...spread over the axis, not at its foot
        self.assertIsNone(pfe.cpu_axis_top(np.linspace(0.08, 0.12, 500)))  # nothing to clip
        self.assertIsNone(pfe.cpu_axis_top(np.array([np.nan])))

    def test_read_pnm_p6_averages_channels(self):
        with tempfile.NamedTemporaryFile('wb', suffix='.ppm', delete=False) as f:
            f.write(b'P6\n# comment\n2 1\n255\n' + bytes([0, 0, 0, 255, 255, 0]))
        try:
            v = pfe.read_pnm(f.name)
        finally:
            os.unlink(f.name)
        np.testing.assert_allclose(v, [[0.0, 2 / 3]])


if __name__ == '__main__':
    unittest.main()
