#!/usr/bin/python3
"""Unit tests of pf_evaluate (pf_localization.evaluate): association and metrics on tiny literal
trajectories, the covariance's honesty (coverage of the 95 % ellipse, NEES) and the aligned ATE on
synthetic runs with errors of known covariance, and the CPU plot's axis.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs numpy only (no ROS, no matplotlib).
"""
import json
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

    @staticmethod
    def read_log(text):
        """pf_evaluate's reading of an update log with `text` in it."""
        with tempfile.NamedTemporaryFile('w', suffix='.csv', delete=False) as f:
            f.write(text)
        try:
            return pfe.read_update_log(f.name)
        finally:
            os.remove(f.name)

    def test_update_log_keeps_the_state_column(self):
        log = self.read_log('t,particles,state\n1.0,500,localized\n2.0,600,lost\n')
        self.assertEqual(list(log['state']), ['localized', 'lost'])
        self.assertEqual(list(log['particles']), [500.0, 600.0])

    def test_missing_sensors_are_named_with_their_stretches(self):
        log = self.read_log('t,particles,missing\n10,500,\n11,500,front\n12,500,front rear\n13,500,\n'
                            '14,500,front\n')
        m = pfe.log_metrics(log)['sensors_missing']
        self.assertEqual(sorted(m), ['front', 'rear'])
        self.assertAlmostEqual(m['front']['share'], 0.6)
        self.assertEqual(m['front']['stretches_s'], [[1.0, 2.0], [4.0, 4.0]])
        self.assertEqual(m['rear']['stretches_s'], [[2.0, 2.0]])
        # a run where no sensor was ever missing: an empty column, still text
        log = self.read_log('t,particles,missing\n10,500,\n11,500,\n')
        self.assertEqual(pfe.log_metrics(log)['sensors_missing'], {})

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


def noisy_run(n, cov, rng, dt=0.1):
    """A reference wandering over 20 x 10 m for n samples every dt s, and an estimate off it by
    errors drawn from N(0, cov) (2 x 2)."""
    t = np.arange(n) * dt
    ref = np.c_[t, 10 + 10 * np.sin(t / 37.0), 5 + 5 * np.cos(t / 23.0), np.zeros(n)]
    est = ref.copy()
    est[:, 1:3] += rng.multivariate_normal([0.0, 0.0], cov, size=n)
    return est, ref


def cov_rows(t, cov):
    """Covariance file rows (t, xx, xy, yy, yawyaw, xyaw, yyaw) with cov (2 x 2) at each time t."""
    return np.array([(tk, cov[0][0], cov[0][1], cov[1][1], 0.01, 0.0, 0.0) for tk in t], dtype=float)


class CovarianceTest(unittest.TestCase):
    S = np.array([[0.04, 0.015], [0.015, 0.01]])      # correlated, 0.2 m x 0.1 m
    N = 4000

    def metrics(self, est, ref, cov, ref_std=0.0):
        _, match = pfe.evaluate(est, ref)
        return pfe.covariance_metrics(cov, match, ref_std=ref_std)[0]

    def test_honest_covariance_covers_95_percent_with_nees_2(self):
        est, ref = noisy_run(self.N, self.S, np.random.default_rng(1))
        c = self.metrics(est, ref, cov_rows(est[:, 0], self.S))
        n_after = int(np.sum(ref[:, 0] - ref[0, 0] >= pfe.SETTLE_S))
        self.assertEqual(c['samples'], n_after)           # the first 10 s are left out
        # binomial std of the share over ~3900 samples: 0.35 %; NEES mean's std: 2 / sqrt(n) = 0.03
        self.assertAlmostEqual(c['inside_95_percent'], 95.0, delta=1.5)
        self.assertAlmostEqual(c['nees_mean'], 2.0, delta=0.15)
        self.assertAlmostEqual(c['nees_median'], 2 * math.log(2), delta=0.15)
        self.assertEqual(c['degenerate'], 0)

    def test_overconfident_covariance_covers_far_fewer(self):
        est, ref = noisy_run(self.N, self.S, np.random.default_rng(2))
        c = self.metrics(est, ref, cov_rows(est[:, 0], self.S / 10))
        # d^2 ten times larger: P(chi2_2 <= 0.599) = 26 %
        self.assertLess(c['inside_95_percent'], 40.0)
        self.assertGreater(c['nees_mean'], 15.0)

    def test_reference_noise_is_added_to_the_covariance(self):
        r = 0.1
        est, ref = noisy_run(self.N, self.S + r * r * np.eye(2), np.random.default_rng(3))
        rows = cov_rows(est[:, 0], self.S)
        self.assertLess(self.metrics(est, ref, rows)['inside_95_percent'], 90.0)
        c = self.metrics(est, ref, rows, ref_std=r)
        self.assertAlmostEqual(c['inside_95_percent'], 95.0, delta=1.5)
        self.assertAlmostEqual(c['nees_mean'], 2.0, delta=0.15)

    def test_each_reference_uses_the_covariance_in_force(self):
        ref = traj([(t, 0.0, 0.0, 0.0) for t in np.arange(0.0, 20.0, 0.5)])
        est = ref + [0, 0.3, 0.0, 0]                                 # 0.3 m off in x
        big, tiny = [[1.0, 0.0], [0.0, 1.0]], [[1e-4, 0.0], [0.0, 1e-4]]
        # rows 10 ms after each reference: the one in force is the newest at or before it, so
        # the reference at 14.0 s still has the big one (the tiny one's 14.01 s is nearer)
        cov = np.r_[cov_rows(np.arange(0.0, 14.0, 0.5) + 0.01, big),
                    cov_rows(np.arange(14.0, 20.0, 0.5) + 0.01, tiny)]
        c = self.metrics(est, ref, cov)
        self.assertEqual((c['samples'], c['without_covariance']), (20, 0))   # 10 .. 19.5 s
        self.assertAlmostEqual(c['inside_95_percent'], 100.0 * 9 / 20)        # 10 .. 14 s
        self.assertAlmostEqual(c['nees_mean'], (9 * 0.09 + 11 * 900.0) / 20)
        self.assertAlmostEqual(c['nees_median'], 900.0)
        # a row is held at most --max-gap (0.5 s): without those at 11.01 .. 12.51 s,
        # the references at 11.5 .. 13.0 s have none
        gap = (cov[:, 0] > 11.0) & (cov[:, 0] < 13.0)
        c = self.metrics(est, ref, cov[~gap])
        self.assertEqual((c['samples'], c['without_covariance']), (16, 4))
        # a row written before any estimate (nan) is no covariance either
        nan_rows = cov.copy()
        nan_rows[:, 1:] = np.nan
        c = self.metrics(est, ref, nan_rows)
        self.assertEqual((c['samples'], c['without_covariance'], c['inside_95_percent']), (0, 20, None))

    def test_singular_covariance_does_not_cover_and_is_counted(self):
        est, ref = noisy_run(200, self.S, np.random.default_rng(4))
        for singular in ([[0.0, 0.0], [0.0, 0.0]], [[0.04, 0.02], [0.02, 0.01]], [[-0.01, 0], [0, 0.01]]):
            c = self.metrics(est, ref, cov_rows(est[:, 0], singular))
            self.assertEqual(c['degenerate'], c['samples'])
            self.assertEqual(c['inside_95_percent'], 0.0)
            self.assertIsNone(c['nees_mean'])
        # the reference's own noise makes a zero covariance invertible
        c = self.metrics(est, ref, cov_rows(est[:, 0], [[0.0, 0.0], [0.0, 0.0]]), ref_std=0.2)
        self.assertEqual(c['degenerate'], 0)
        self.assertGreater(c['inside_95_percent'], 80.0)

    def test_command_line_writes_the_covariance_summary_and_plot(self):
        est, ref = noisy_run(300, self.S, np.random.default_rng(5))
        rows = cov_rows(est[:, 0], self.S)
        rows[:5, 1:4] = 0.0                                          # degenerate while settling
        with tempfile.TemporaryDirectory() as d:
            for name, a in (('traj.tum', est), ('ref.tum', ref)):
                with open(os.path.join(d, name), 'w') as f:
                    f.writelines('%.6f %.6f %.6f 0 0 0 %.9f %.9f\n' % (r[0], r[1], r[2], math.sin(r[3] / 2),
                                                                      math.cos(r[3] / 2)) for r in a)
            with open(os.path.join(d, 'cov.csv'), 'w') as f:
                f.write('t,xx,xy,yy,yawyaw,xyaw,yyaw\n')
                f.writelines(','.join('%.9g' % v for v in r) + '\n' for r in rows)
            argv = ['--traj', os.path.join(d, 'traj.tum'), '--ref', os.path.join(d, 'ref.tum'),
                    '--cov', os.path.join(d, 'cov.csv'), '--out', os.path.join(d, 'eval')]
            try:
                import matplotlib  # noqa: F401
            except ImportError:
                argv.append('--no-plots')
            self.assertEqual(pfe.main(argv), 0)
            with open(os.path.join(d, 'eval', 'summary.json')) as f:
                m = json.load(f)
            c = m['covariance']
            self.assertEqual((c['samples'], c['degenerate']), (200, 0))  # 10 s of 30 left out
            self.assertGreater(c['inside_95_percent'], 88.0)
            if '--no-plots' not in argv:
                self.assertTrue(os.path.isfile(os.path.join(d, 'eval', 'nees.png')))
            self.assertEqual(pfe.main(argv + ['--ref-std', '-1']), 2)


class HypothesesTest(unittest.TestCase):
    """Whether the true place is among the published hypotheses (pf_bag_runner --hypotheses)."""
    # The robot at x = t along y = 0 for 10 s, a reference pose every 0.5 s.
    ref = traj([(0.5 * k, 0.5 * k, 0.0, 0.0) for k in range(21)])

    @staticmethod
    def rows(updates):
        """(t, [(x, y, weight), ...]) per update -> the runner's rows t,rank,x,y,yaw,weight,sx,sy."""
        return traj([(t, rank + 1, x, y, 0.0, w, 0.1, 0.1, 0.0)
                     for t, listed in updates for rank, (x, y, w) in enumerate(listed)])

    def test_the_truth_among_several_counts_and_a_miss_is_timed(self):
        hyp = self.rows([
            (1.0, [(5.75, 0.0, 0.5), (1.2, 0.3, 0.4)]),    # the truth second, 0.36 m off: in
            (2.25, [(2.25, 0.0, 0.6), (7.0, 0.0, 0.3)]),   # interpolated reference (2.25, 0): in
            (3.0, [(7.75, 0.0, 0.55), (3.0, 1.1, 0.45)]),  # 1.1 m off: a miss while ambiguous
            (4.0, [(4.05, 0.0, 1.0)]),                     # one, on the truth
            (5.0, [(6.5, 0.0, 1.0)]),                      # one, 1.5 m off
            (30.0, [(30.0, 0.0, 1.0)]),                    # no reference near it: left out
        ])
        h = pfe.hypotheses_metrics(hyp, self.ref)
        self.assertEqual((h['updates'], h['updates_matched'], h['updates_with_several']), (6, 5, 3))
        self.assertAlmostEqual(h['contain_truth_share'], 3 / 5)
        self.assertAlmostEqual(h['contain_truth_share_with_several'], 2 / 3)
        self.assertEqual(h['misses_s'], [3.0, 5.0])
        self.assertEqual(h['most_hypotheses'], 2)
        self.assertAlmostEqual(h['mean_hypotheses'], 9 / 6)
        # A stricter radius drops the 0.36 m one.
        self.assertAlmostEqual(pfe.hypotheses_metrics(hyp, self.ref, near=0.3)['contain_truth_share'],
                               2 / 5)

    def test_a_spread_place_holds_the_truth_inside_its_ellipse(self):
        # An aisle-long cluster: std 3 m along x, 0.2 m across. The truth 2.25 m along it is
        # inside its 95 % ellipse (NEES 0.56), though 2.25 m from its mean; 1.2 m across it is
        # not (NEES 36); a tilted ellipse follows its correlation.
        def rows(sx, sy, cxy, x, y):
            return np.array([[2.25, 1, x, y, 0.0, 1.0, sx, sy, cxy]])
        along = pfe.hypotheses_metrics(rows(3.0, 0.2, 0.0, 4.5, 0.0), self.ref)
        self.assertAlmostEqual(along['contain_truth_share'], 1.0)
        self.assertAlmostEqual(along['near_truth_share'], 0.0)
        across = pfe.hypotheses_metrics(rows(3.0, 0.2, 0.0, 2.25, 1.2), self.ref)
        self.assertAlmostEqual(across['contain_truth_share'], 0.0)
        self.assertEqual(across['misses_s'], [2.25])
        # The same cluster turned 45 degrees, its long axis along (1, 1): the truth 1.4 m from its
        # mean along that axis is inside, 1.4 m across it is not.
        c = np.hypot(3.0, 0.2) ** 2 / 2
        sxy = (9.0 - 0.04) / 2
        tilted = lambda x, y: pfe.hypotheses_metrics(rows(np.sqrt(c), np.sqrt(c), sxy, x, y),
                                                     self.ref)['contain_truth_share']
        self.assertAlmostEqual(tilted(2.25 - 1.0, -1.0), 1.0)
        self.assertAlmostEqual(tilted(2.25 - 1.0, 1.0), 0.0)
        # A degenerate covariance holds nothing beyond the radius.
        self.assertAlmostEqual(pfe.hypotheses_metrics(rows(0.0, 0.0, 0.0, 4.5, 0.0),
                                                      self.ref)['contain_truth_share'], 0.0)

    def test_read_hypotheses_sorts_by_time_and_rank_and_wants_its_columns(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, 'hyp.csv')
            with open(path, 'w') as f:
                f.write('t,rank,x,y,yaw,weight,std_x,std_y\n2.0,1,5,5,0,1,0.1,0.1\n'
                        '1.0,2,3,3,0,0.4,0.1,0.1\n1.0,1,1,1,0,0.6,0.1,0.1\n')
            a = pfe.read_hypotheses(path)
            self.assertEqual(a[:, :3].tolist(), [[1.0, 1.0, 1.0], [1.0, 2.0, 3.0], [2.0, 1.0, 5.0]])
            with open(path, 'w') as f:
                f.write('t,x,y\n1.0,1,1\n')
            with self.assertRaises(pfe.EvalError):
                pfe.read_hypotheses(path)

    def test_command_line_reports_the_share_in_summary_and_text(self):
        est = self.ref.copy()
        with tempfile.TemporaryDirectory() as d:
            for name, a in (('traj.tum', est), ('ref.tum', self.ref)):
                with open(os.path.join(d, name), 'w') as f:
                    f.writelines('%.6f %.6f %.6f 0 0 0 0 1\n' % tuple(r[:3]) for r in a)
            with open(os.path.join(d, 'hyp.csv'), 'w') as f:
                f.write('t,rank,x,y,yaw,weight,std_x,std_y,cov_xy\n')
                f.writelines(','.join('%.6g' % v for v in r) + '\n' for r in self.rows(
                    [(1.0, [(1.0, 0.0, 0.5), (5.75, 0.0, 0.5)]), (2.0, [(9.0, 0.0, 1.0)])]))
            argv = ['--traj', os.path.join(d, 'traj.tum'), '--ref', os.path.join(d, 'ref.tum'),
                    '--hypotheses', os.path.join(d, 'hyp.csv'), '--out', os.path.join(d, 'eval'),
                    '--no-plots']
            m, summary = pfe.run(pfe.parse_args(argv))
            with open(summary) as f:
                h = json.load(f)['hypotheses']
            self.assertAlmostEqual(h['contain_truth_share'], 0.5)
            self.assertAlmostEqual(h['contain_truth_share_with_several'], 1.0)
            self.assertIn('the true place within 1.0 m of one or inside its 95 % ellipse in 50.0 % of 2 '
                          'updates (within 1.0 m: 50.0 %); in 100.0 % of the 1 with several (up to 2, '
                          'mean 1.50)', pfe.describe(m, summary))


class SelfAssessmentTest(unittest.TestCase):
    """What the report says without a reference: the fit, the verdict over time, the covariance."""

    @staticmethod
    def log(states, fits, t0=100.0):
        n = len(states)
        return {'t': t0 + np.arange(n, dtype=float), 'state': np.array(states), 'hit_fraction': np.array(fits),
                'std_x': np.full(n, 0.02), 'std_y': np.full(n, 0.05), 'std_yaw': np.full(n, 0.01),
                'map_changed_share': np.zeros(n)}

    def test_localized_throughout(self):
        a = pfe.self_assessment(self.log(['localized'] * 4, [1.0, 0.9, 0.95, 1.0]), 100.0, 104.5)
        self.assertAlmostEqual(a['fit']['mean'], 0.9625)
        self.assertEqual(a['fit']['min'], 0.9)
        self.assertEqual(a['fit']['below_localized_share'], 0.0)
        v = a['verdict']
        self.assertTrue(v['localized_throughout'])
        self.assertEqual(v['stretches_s'], [['localized', 0.0, 4.5, 4]])
        self.assertEqual(v['judgement'], 'localized throughout (all 4 updates)')
        # without the published covariance, the larger of the estimate's std_x and std_y
        self.assertEqual(a['covariance_size']['source'], 'the estimate (update log)')
        self.assertAlmostEqual(a['covariance_size']['position_std_m']['max'], 0.05)

    def test_a_wrong_start_then_recovered(self):
        a = pfe.self_assessment(self.log(['lost', 'uncertain', 'uncertain', 'localized', 'localized'],
                                         [0.3, 0.7, 0.8, 0.95, 1.0]), 100.0)
        self.assertAlmostEqual(a['fit']['below_localized_share'], 0.4)
        self.assertAlmostEqual(a['fit']['below_lost_share'], 0.2)
        v = a['verdict']
        self.assertEqual(v['stretches_s'], [['lost', 0.0, 1.0, 1], ['uncertain', 1.0, 3.0, 2],
                                            ['localized', 3.0, 4.0, 2]])
        self.assertEqual((v['first_localized_s'], v['localized_from_s'], v['final_state']),
                         (3.0, 3.0, 'localized'))
        self.assertEqual(v['judgement'], 'localized from 3.0 s to the end (the last 2 of 5 updates)')
        self.assertAlmostEqual(v['shares']['uncertain'], 0.4)

    def test_judgements(self):
        j = lambda states: pfe.self_assessment(self.log(states, [1.0] * len(states)),
                                               100.0)['verdict']['judgement']
        self.assertEqual(j(['uncertain', 'localized', 'localized']),
                         'localized at every update but the first (uncertain), from 1.0 s to the end')
        self.assertEqual(j(['localized', 'uncertain', 'localized', 'lost', 'lost', 'localized']),
                         'localized at the end (since 5.0 s); before, 2 stretches not localized: '
                         'uncertain 1.0 s (1 update), lost 2.0 s (2 updates)')
        self.assertEqual(j(['localized', 'lost', 'lost']),
                         'not localized at the end: lost since 1.0 s (localized first at 0.0 s)')
        self.assertEqual(j(['uncertain', 'lost']), 'never localized (2 updates)')

    def test_published_covariance_size_is_the_ellipse_s_larger_semi_axis(self):
        # xx = yy = 0.05, xy = 0.04: eigenvalues 0.09 and 0.01, so 0.3 m; yaw 0.0004 rad^2: 1.15 deg
        cov = np.array([[100.0, 0.05, 0.04, 0.05, 0.0004, 0.0, 0.0]])
        _, pos, yaw, source = pfe.covariance_size(cov=cov)
        self.assertAlmostEqual(pos[0], 0.3)
        self.assertAlmostEqual(np.degrees(yaw[0]), np.degrees(0.02))
        self.assertEqual(source, 'published covariance (pf_pose)')

    def test_the_laser_mounting_is_read_up_to_the_frame_odometry_moves(self):
        def tr(x, y, yaw):
            m = np.eye(4)
            m[:2, :2] = [[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]]
            m[:2, 3] = x, y
            return m
        # laser <- plate <- base_link <- odom: the laser 0.1 m ahead of a plate turned by pi, 0.2 m
        # behind base_link
        parents = {'laser': ('plate', tr(0.1, 0.0, 0.0)), 'plate': ('base_link', tr(-0.2, 0.0, math.pi)),
                   'base_link': ('odom', tr(5.0, 5.0, 1.0))}
        mount, base = pfe._mount(parents, 'laser', None, 'odom')
        self.assertEqual(base, 'base_link')
        np.testing.assert_allclose(mount @ [1.0, 0.0, 0.0, 1.0], [-1.3, 0.0, 0.0, 1.0], atol=1e-12)
        self.assertEqual(pfe._mount(parents, 'laser', 'plate', 'odom')[1], 'plate')
        self.assertIsNone(pfe._mount(parents, 'laser', 'base_footprint', 'odom')[0])

    def test_describe_without_reference(self):
        m = {'has_reference': False, 'reference': {'none': 'the bag has no /ground_truth; its topics: /scan'},
             'n_estimates': 5, 'duration_s': 4.0, 'plots': [],
             'self_assessment': pfe.self_assessment(self.log(['lost', 'localized'], [0.3, 1.0]), 100.0)}
        text = pfe.describe(m, 'S')
        self.assertIn('pf_evaluate: no reference (the bag has no /ground_truth; its topics: /scan)', text)
        self.assertIn('beams fit:      mean 65.0 %  median 65.0 %', text)
        self.assertIn('verdict:        localized at every update but the first (lost), from 1.0 s to the end',
                      text)
        self.assertIn('timeline:       lost 0.0-1.0 s (1 update), localized 1.0-1.0 s (1 update)', text)


class AlignedAteTest(unittest.TestCase):
    def test_rotation_and_translation_are_recovered(self):
        rng = np.random.default_rng(6)
        sigma, n = 0.02, 2000
        _, ref = noisy_run(n, np.zeros((2, 2)), rng)
        angle, shift = math.radians(3.0), np.array([0.4, -0.25])
        c, s = math.cos(angle), math.sin(angle)
        est = ref.copy()
        est[:, 1] = c * ref[:, 1] - s * ref[:, 2] + shift[0]
        est[:, 2] = s * ref[:, 1] + c * ref[:, 2] + shift[1]
        est[:, 1:3] += rng.normal(0.0, sigma, (n, 2))
        m, _ = pfe.evaluate(est, ref)
        self.assertGreater(m['ate_rmse_m'], 0.4)                     # 3 deg at ~11 m and the shift
        # what is left is the noise: radial RMS sigma * sqrt(2)
        self.assertAlmostEqual(m['ate_aligned_rmse_m'], sigma * math.sqrt(2), delta=0.003)
        self.assertAlmostEqual(m['aligned_rotation_deg'], -3.0, delta=0.05)   # est -> ref: the inverse
        inverse_shift = -np.array([[c, s], [-s, c]]) @ shift
        np.testing.assert_allclose(m['aligned_translation_m'], inverse_shift, atol=0.01)

    def test_no_misalignment_leaves_the_ate(self):
        ref = traj([(t, t, 0.5 * t * t, 0.0) for t in range(10)])
        est = ref + [0, 0.0, 0.1, 0]
        m, _ = pfe.evaluate(est, ref)
        self.assertAlmostEqual(m['ate_rmse_m'], 0.1, places=12)
        self.assertAlmostEqual(m['ate_aligned_rmse_m'], 0.0, places=9)   # a pure shift is taken out


if __name__ == '__main__':
    unittest.main()


class ChangeMetricsTest(unittest.TestCase):
    """The changes layer against the true mask (pixels as pf_bag_runner --changes and
    pf_simulator --change-mask write them)."""

    @staticmethod
    def layer():
        # 20 x 20 cells, all seen; the mask: an added box (rows 2-4, cols 2-6) and a removed
        # strip (row 12, cols 5-14).
        mask = np.full((20, 20), pfe.CHANGE_AS_MAPPED, dtype=np.uint8)
        mask[2:5, 2:7] = pfe.CHANGE_ADDED
        mask[12, 5:15] = pfe.CHANGE_REMOVED
        return mask

    def test_a_layer_equal_to_the_mask_is_perfect(self):
        mask = self.layer()
        m = pfe.change_metrics(mask.copy(), mask)
        self.assertEqual(m['precision'], 1.0)
        self.assertEqual(m['recall'], 1.0)
        self.assertEqual(m['true_cells_seen'], 15 + 10)

    def test_a_face_marked_one_cell_before_it_counts_and_two_cells_do_not(self):
        mask = self.layer()
        layer = np.full_like(mask, pfe.CHANGE_AS_MAPPED)
        layer[1, 2:7] = pfe.CHANGE_ADDED        # the row above the box: within one cell
        layer[8, 2:7] = pfe.CHANGE_ADDED        # four rows below it: a false mark
        m = pfe.change_metrics(layer, mask)
        self.assertAlmostEqual(m['added']['precision'], 0.5)
        # Found: the box's first row (within one cell of the marks), 5 of its 15 cells.
        self.assertAlmostEqual(m['added']['recall'], 5 / 15)
        self.assertIsNone(m['removed']['precision'])
        self.assertEqual(m['removed']['recall'], 0.0)

    def test_a_kind_mistaken_is_not_found(self):
        mask = self.layer()
        layer = mask.copy()
        layer[mask == pfe.CHANGE_REMOVED] = pfe.CHANGE_ADDED
        m = pfe.change_metrics(layer, mask)
        self.assertAlmostEqual(m['precision'], 15 / 25)
        self.assertEqual(m['removed']['recall'], 0.0)

    def test_recall_counts_only_the_changes_the_lidar_saw(self):
        mask = self.layer()
        layer = np.full_like(mask, pfe.CHANGE_UNSEEN)
        layer[12, 5:15] = pfe.CHANGE_REMOVED    # the strip seen; the box never
        m = pfe.change_metrics(layer, mask)
        self.assertEqual(m['recall'], 1.0)
        self.assertEqual(m['true_cells_seen'], 10)
        self.assertEqual(m['cells_seen'], 10)
        self.assertEqual(m['changed_share_of_seen'], 1.0)

    def test_without_a_mask_only_the_share_marked(self):
        layer = np.full((10, 10), pfe.CHANGE_AS_MAPPED, dtype=np.uint8)
        layer[0, 0] = pfe.CHANGE_ADDED
        layer[5:, :] = pfe.CHANGE_UNSEEN
        m = pfe.change_metrics(layer)
        self.assertEqual(m['cells_seen'], 50)
        self.assertAlmostEqual(m['changed_share_of_seen'], 1 / 50)
        self.assertNotIn('recall', m)

    def test_another_maps_mask_is_an_error(self):
        with self.assertRaises(pfe.EvalError):
            pfe.change_metrics(np.zeros((5, 5), np.uint8), np.zeros((5, 6), np.uint8))
