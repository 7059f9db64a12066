#!/usr/bin/python3
"""Tests of pf_tune (pf_localization.tune): the search space and params files, the self-supervised score on the
bundled simulated bags, the choice of the best against the seeds' noise, and whole studies on a
2-worker Dask LocalCluster (a 6-trial study, a worker killed mid-study, a study stopped after 3
trials and continued).

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs pf_bag_runner built (scripts/build.sh; the workspace is $PF_WS or scripts/workspace.bash's
default, found as scripts/pf_tune finds it: pf_localization/locate.py), python3-optuna, python3-distributed, python3-sklearn and ROS 1's rosbag. About 2 minutes.
"""
import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import yaml

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
TUNE = os.path.join(REPO, 'scripts', 'pf_tune')
# This checkout's package, built or not (before any installed pf_localization).
sys.path.insert(0, os.path.join(REPO, 'src'))
from pf_localization import locate  # noqa: E402
from pf_localization import tune_objective, tune_space, tune_study, tune_tasks  # noqa: E402


try:
    RUNNER, NO_RUNNER = locate.find_runner(TUNE), None  # the one scripts/pf_tune uses
except locate.NotFound as e:
    RUNNER, NO_RUNNER = '', str(e)
SMALL = ['--bags', os.path.join(REPO, 'bags', 'small.bag'), '--map', os.path.join(REPO, 'maps', 'small.yaml'),
         '--initial-pose', '2.5', '2.6', '0']
TWO_BAGS = ['--bags', os.path.join(REPO, 'bags', 'small.bag'), os.path.join(REPO, 'bags', 'tracking.bag'),
            '--map', os.path.join(REPO, 'maps', 'small.yaml'), '--map', os.path.join(REPO, 'maps', 'building.yaml'),
            '--initial-pose', '2.5', '2.6', '0', '--initial-pose', '1.5', '7.6', '0']
# The quick tier (scripts/test.sh --quick) leaves out what replays bags: the score, the studies and
# benchmark_datasets on Dask (about 100 s of the 2 minutes); the full run has them.
REPLAYS = unittest.skipIf(os.environ.get('PF_TEST_TIER') == 'quick',
                          'replays bags: scripts/test.sh runs it, --quick does not')
# A bad parameter set: motion noise ten to fifteen times too large, a hit model seven times too wide.
BAD = dict(odom_alpha1=3.0, odom_alpha2=3.0, odom_alpha3=3.0, odom_alpha4=3.0, laser_sigma_hit=1.5)


def base_params():
    with open(os.path.join(REPO, 'config', 'pf.yaml')) as f:
        return yaml.safe_load(f)


def tune_cmd(out, *extra):
    return ['/usr/bin/python3', TUNE, '--out', out, '--workers', '2', '--seed', '3', '--no-progress'] + list(extra)


def run_until(cmd, act, period):
    """Runs pf_tune as `cmd` and calls act(proc) every `period` s until it
    returns something other than None (or 300 s pass); then waits for the end.
    Returns what act returned, the output and the exit status."""
    import psutil
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    done = None
    try:
        deadline = time.monotonic() + 300
        while done is None and time.monotonic() < deadline and proc.poll() is None:
            try:
                done = act(proc)
            except psutil.NoSuchProcess:
                pass  # a process ended while it was looked at: look again
            time.sleep(period)
        out, _ = proc.communicate(timeout=600)
    finally:
        if proc.poll() is None:
            proc.kill()
    return done, out, proc.returncode


def completed_trials(out):
    import optuna
    from optuna.trial import TrialState
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.load_study(study_name='pf_tune', storage='sqlite:///%s/study.db' % out)
    return study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,)), study


class SpaceAndParamsTest(unittest.TestCase):
    def test_default_space_names_parameters_of_pf_yaml(self):
        space = tune_space.load_space(None, base_params())
        for name in ('odom_alpha1', 'odom_alpha4', 'laser_sigma_hit', 'laser_z_hit', 'laser_z_rand',
                     'laser_likelihood_exponent', 'recovery_alpha_slow', 'recovery_alpha_fast', 'laser_max_beams'):
            self.assertIn(name, space)
        self.assertEqual(space['laser_max_beams']['type'], 'int')
        self.assertTrue(space['odom_alpha1']['log'])

    def test_bad_space_files_are_explained(self):
        cases = [('odom_alfa1: {low: 0.1, high: 1}\n', 'not a parameter'),
                 ('odom_alpha1: {low: 1, high: 0.1}\n', 'must be below'),
                 ('odom_alpha1: {low: 0, high: 1, log: true}\n', 'log scale needs low > 0'),
                 ('odom_alpha1: {low: 0.1}\n', 'needs "low" and "high"'),
                 ('odom_alpha1: {low: 0.1, high: 1, scale: log}\n', 'unknown key'),
                 ('- odom_alpha1\n', 'expected a mapping'),
                 ('odom_alpha1: {low: [0.1, high: 1}\n', 'not valid YAML')]
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, 'space.yaml')
            for text, message in cases:
                with open(path, 'w') as f:
                    f.write(text)
                with self.assertRaises(tune_space.TuneError) as cm:
                    tune_space.load_space(path, base_params())
                self.assertIn(message, str(cm.exception), text)
            with self.assertRaises(tune_space.TuneError) as cm:
                tune_space.load_space(os.path.join(d, 'missing.yaml'), base_params())
            self.assertIn('space file not found', str(cm.exception))

    def test_missing_bag_is_a_clear_error(self):
        with tempfile.TemporaryDirectory() as d:
            p = subprocess.run(tune_cmd(d, '--bags', os.path.join(d, 'nope.bag'), '--map',
                                        os.path.join(REPO, 'maps', 'small.yaml'), '--trials', '2'),
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
            self.assertEqual(p.returncode, 2, p.stdout)
            self.assertIn('bag not found: %s' % os.path.join(d, 'nope.bag'), p.stdout)

    def test_params_file_keeps_comments_and_takes_the_values(self):
        with open(os.path.join(REPO, 'config', 'pf.yaml')) as f:
            text = f.read()
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, 'best.yaml')
            tune_space.write_params_yaml(text, {'odom_alpha1': 0.0123456789, 'laser_max_beams': 90}, path, '# head\n')
            with open(path) as f:
                out = f.read()
            loaded = yaml.safe_load(out)
        base = base_params()
        self.assertEqual(loaded['odom_alpha1'], 0.0123456789)
        self.assertEqual(loaded['laser_max_beams'], 90)
        self.assertIsInstance(loaded['laser_max_beams'], int)
        self.assertEqual({k: v for k, v in loaded.items() if k not in ('odom_alpha1', 'laser_max_beams')},
                         {k: v for k, v in base.items() if k not in ('odom_alpha1', 'laser_max_beams')})
        # The line keeps config/pf.yaml's comment, whatever the generated file words it as.
        comment = re.search(r'\nodom_alpha1: \S+ +(# .*)\n', text).group(1)
        self.assertRegex(out, r'\nodom_alpha1: 0\.0123456789 +' + re.escape(comment) + r'\n')


    def test_the_best_replaces_the_baseline_only_by_a_margin_beyond_the_seeds_noise(self):
        # Values per seed, as the confirmation runs give them (the first is the study's own).
        base = [0.0055, 0.0057, 0.0059, 0.0056]
        # AC109's case: trial 49 was the luckiest single draw, trial 37 has the lowest mean, and
        # neither is lower than the baseline by more than --min-gain.
        lucky = {48: [0.0036, 0.0060, 0.0062, 0.0039], 36: [0.0038, 0.0057, 0.0053, 0.0040]}
        chosen, stats, verdict = tune_study.choose(base, lucky, 0.005)
        self.assertIsNone(chosen)
        self.assertIn("trial 37's", verdict)
        self.assertIn('not by more than --min-gain 0.005', verdict)
        self.assertAlmostEqual(stats[36][0], 0.0047)
        self.assertAlmostEqual(stats['baseline'][0], 0.005675)
        # Without a minimum gain, the spread of the seeds still decides: 0.00098 is more than twice
        # the standard error here, 0.00002 is not.
        self.assertEqual(tune_study.choose(base, lucky, 0.0)[0], 36)
        chosen, _, verdict = tune_study.choose(base, {5: [0.0056, 0.0058, 0.0055, 0.0058]}, 0.0)
        self.assertIsNone(chosen)
        self.assertIn('twice the standard error', verdict)
        # A clear gain on every seed wins; among several, the lowest mean, not the lowest first value.
        chosen, stats, _ = tune_study.choose([0.081, 0.080, 0.083, 0.085],
                                             {33: [0.0340, 0.0347, 0.0353, 0.0345],
                                              34: [0.0339, 0.0342, 0.0347, 0.0361]},
                                             0.005)
        self.assertEqual(chosen, 33)
        # No other trial: the baseline.
        self.assertIsNone(tune_study.choose(base, {}, 0.005)[0])


@REPLAYS
class ScoreTest(unittest.TestCase):
    def setUp(self):
        self.assertTrue(RUNNER, NO_RUNNER)

    def run_bag(self, bag, mapname, pose, params, objective='self'):
        full = base_params()
        full.update(params)
        return tune_tasks.evaluate_bag(dict(runner=RUNNER, bag=os.path.join(REPO, 'bags', bag),
                                            map=os.path.join(REPO, 'maps', mapname), pose=pose, reference=None,
                                            params=full, seed=1, objective=objective,
                                            fit_distance=tune_objective.FIT_DISTANCE,
                                            timeout=300, odom_frame='odom', base_frame='base_link'))

    def test_self_supervised_score_ranks_defaults_above_wrong_alphas_and_sigma_hit(self):
        for bag, mapname, pose in (('tracking.bag', 'building.yaml', (1.5, 7.6, 0.0)),
                                   ('small.bag', 'small.yaml', (2.5, 2.6, 0.0)),
                                   ('crowd.bag', 'building.yaml', (1.5, 7.6, 0.0))):
            good = self.run_bag(bag, mapname, pose, {})
            bad = self.run_bag(bag, mapname, pose, BAD)
            self.assertTrue(good['ok'] and bad['ok'], (good.get('error'), bad.get('error')))
            # and the reference agrees that the bad set is worse
            ref_good = self.run_bag(bag, mapname, pose, {}, 'reference')
            ref_bad = self.run_bag(bag, mapname, pose, BAD, 'reference')
            self.assertLess(ref_good['metrics']['ate_rmse_m'], ref_bad['metrics']['ate_rmse_m'], bag)
            self.assertLess(good['score'], bad['score'] - 0.3, '%s: %r vs %r' % (bag, good, bad))
            self.assertGreater(good['metrics']['fit'], bad['metrics']['fit'] + 0.2, bag)
            self.assertEqual(good['metrics']['scans_with_pose'], good['metrics']['scans'], bag)

    def test_with_two_lidars_the_fit_is_over_both_lidars_scans(self):
        job = dict(runner=RUNNER, bag=os.path.join(REPO, 'bags', 'two_lidar.bag'),
                   map=os.path.join(REPO, 'maps', 'building.yaml'), pose=(1.2, 7.6, 0.0), reference=None,
                   params=base_params(), seed=1, objective='self', fit_distance=tune_objective.FIT_DISTANCE,
                   timeout=300,
                   odom_frame='odom', base_frame='base_link', scan_topics=['/scan_front', '/scan_rear'])
        both = tune_tasks.evaluate_bag(job)
        front = tune_tasks.evaluate_bag(dict(job, scan_topics=['/scan_front']))
        self.assertTrue(both['ok'] and front['ok'], (both.get('error'), front.get('error')))
        # 942 front and 753 rear scans, each with the pose published at its stamp but the last one
        # (the bag's odometry ends before it)
        self.assertEqual(both['metrics']['scans'], 942 + 753)
        self.assertEqual(both['metrics']['scans_with_pose'], both['metrics']['scans'] - 1)
        self.assertEqual(front['metrics']['scans'], 942)
        self.assertGreater(both['metrics']['fit'], 0.9)

    def test_a_run_that_fails_is_reported_and_scored_as_a_failure(self):
        with tempfile.TemporaryDirectory() as d:
            broken = os.path.join(d, 'broken.bag')
            with open(broken, 'w') as f:
                f.write('not a bag\n')
            job = dict(runner=RUNNER, bag=broken, map=os.path.join(REPO, 'maps', 'small.yaml'), pose=None,
                       reference=None, params=base_params(), seed=1, objective='self', fit_distance=0.1, timeout=60,
                       odom_frame='odom', base_frame='base_link')
            r = tune_tasks.evaluate_bag(job)
        self.assertFalse(r['ok'])
        self.assertEqual(r['score'], tune_objective.FAIL_SCORE['self'])
        self.assertIn('pf_bag_runner exit', r['error'])


@REPLAYS
class StudyTest(unittest.TestCase):
    def setUp(self):
        self.assertTrue(RUNNER, NO_RUNNER)
        self.out = tempfile.mkdtemp(prefix='pf_tune_test_')

    def tearDown(self):
        shutil.rmtree(self.out, ignore_errors=True)

    def test_six_trials_on_two_bags_write_a_loadable_best_yaml_and_a_report(self):
        p = subprocess.run(tune_cmd(self.out, '--trials', '6', *TWO_BAGS), stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn('objective: reference', p.stdout)
        self.assertIn('LocalCluster of 2 workers', p.stdout)
        trials, study = completed_trials(self.out)
        self.assertEqual(len(trials), 6)
        self.assertEqual(trials[0].params['odom_alpha1'], 0.2)  # the baseline comes first
        self.assertTrue(all(r['ok'] for t in trials for r in t.user_attrs['bags']))
        self.assertLessEqual(study.best_value, trials[0].value)
        # best.yaml holds the trial the confirmation runs chose (the baseline unless one beat it).
        chosen = study.trials[study.user_attrs['chosen_trial']]
        best = os.path.join(self.out, 'best.yaml')
        with open(best) as f:
            loaded = yaml.safe_load(f)
        for k, v in chosen.params.items():
            self.assertAlmostEqual(loaded[k], v, places=12)
        self.assertIn('pf_tune: chosen: trial %d' % (chosen.number + 1), p.stdout)
        r = subprocess.run([RUNNER, '--bag', os.path.join(REPO, 'bags', 'small.bag'), '--map',
                            os.path.join(REPO, 'maps', 'small.yaml'), '--initial-pose', '2.5', '2.6', '0',
                            '--out', os.path.join(self.out, 'check.tum'), '--quiet', '--params', best],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        self.assertEqual(r.returncode, 0, r.stdout)
        with open(os.path.join(self.out, 'report.md')) as f:
            report = f.read()
        self.assertIn('## Confirmation: the lowest trials again, with 4 seed(s) each', report)
        self.assertIn('| 1 (baseline)', report)
        self.assertIn('| small.bag |', report)
        self.assertIn('| tracking.bag |', report)
        for png in ('history.png', 'importances.png'):
            self.assertGreater(os.path.getsize(os.path.join(self.out, png)), 1000, png)
            self.assertIn('(%s)' % png, report)

    def test_killing_a_worker_mid_study_still_completes_every_trial(self):
        import psutil
        n = 6

        def kill_worker(proc):
            # a worker process (a child of pf_tune) that is running pf_bag_runner right now
            for child in psutil.Process(proc.pid).children():
                if any('pf_bag_runner' in ' '.join(g.cmdline()) for g in child.children()):
                    child.send_signal(signal.SIGKILL)
                    return child.pid
            return None

        killed, out, returncode = run_until(tune_cmd(self.out, '--trials', str(n), *TWO_BAGS), kill_worker,
                                            0.05)
        self.assertIsNotNone(killed, 'no worker was caught running pf_bag_runner')
        self.assertEqual(returncode, 0, out)
        trials, _ = completed_trials(self.out)
        self.assertEqual(len(trials), n, out)
        # the task on the killed worker ran again: no bag of any trial is scored as a failure
        self.assertTrue(all(r['ok'] for t in trials for r in t.user_attrs['bags']), out)
        self.assertTrue(os.path.isfile(os.path.join(self.out, 'best.yaml')))

    def test_a_study_killed_mid_trial_runs_that_trial_again(self):
        import psutil
        from optuna.trial import TrialState

        def stop_study(proc):
            for d in psutil.Process(proc.pid).children(recursive=True):
                if 'pf_bag_runner' in ' '.join(d.cmdline()) and os.path.isfile(
                        os.path.join(self.out, 'study.db')):
                    proc.send_signal(signal.SIGTERM)  # as `kill PID` does
                    return True
            return None

        stopped, out, returncode = run_until(tune_cmd(self.out, '--trials', '4', *SMALL), stop_study, 0.02)
        self.assertTrue(stopped, out)
        self.assertEqual(returncode, 130, out)
        self.assertIn('run the same command again to continue', out)
        p = subprocess.run(tune_cmd(self.out, '--trials', '4', *SMALL), stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertRegex(p.stdout, r'trial \d+ was interrupted: it is run again')
        trials, study = completed_trials(self.out)
        self.assertEqual(len(trials), 4)
        failed = study.get_trials(deepcopy=False, states=(TrialState.FAIL,))
        self.assertEqual(len(failed), 1)
        self.assertIn(failed[0].params, [t.params for t in trials if t.number > failed[0].number])

    def test_a_bag_that_breaks_the_runner_is_reported_and_the_study_goes_on(self):
        broken = os.path.join(self.out, 'broken.bag')
        with open(broken, 'w') as f:
            f.write('not a bag\n')
        p = subprocess.run(tune_cmd(self.out, '--trials', '2', '--bags', os.path.join(REPO, 'bags', 'small.bag'),
                                    broken, '--map', os.path.join(REPO, 'maps', 'small.yaml'),
                                    '--initial-pose', '2.5', '2.6', '0'),
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn('objective: self (no reference for broken.bag)', p.stdout)
        self.assertIn('trial 1: broken.bag failed: pf_bag_runner exit 2', p.stdout)
        self.assertIn('trial 2: broken.bag failed: pf_bag_runner exit 2', p.stdout)
        trials, _ = completed_trials(self.out)
        self.assertEqual(len(trials), 2)
        for t in trials:
            ok = {os.path.basename(r['bag']): (r['ok'], r['score']) for r in t.user_attrs['bags']}
            self.assertEqual(ok['broken.bag'], (False, tune_objective.FAIL_SCORE['self']))
            self.assertTrue(ok['small.bag'][0])
        with open(os.path.join(self.out, 'report.md')) as f:
            self.assertIn('| broken.bag | failed: pf_bag_runner exit 2', f.read())

    def test_a_study_stopped_after_three_trials_continues_at_the_fourth(self):
        p = subprocess.run(tune_cmd(self.out, '--trials', '3', *SMALL), stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout)
        first, _ = completed_trials(self.out)
        self.assertEqual([t.number for t in first], [0, 1, 2])
        p = subprocess.run(tune_cmd(self.out, '--trials', '6', *SMALL), stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout)
        self.assertIn('resumed, 3 of 6 trials done', p.stdout)
        self.assertIn('pf_tune: trial 4:', p.stdout)
        self.assertNotIn('pf_tune: trial 3:', p.stdout)
        trials, _ = completed_trials(self.out)
        self.assertEqual([t.number for t in trials], list(range(6)))
        for a, b in zip(first, trials[:3]):
            self.assertEqual((a.params, a.value), (b.params, b.value))
        # a third run has nothing left to do, and a different set-up of the same study is refused
        p = subprocess.run(tune_cmd(self.out, '--trials', '6', *SMALL), stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertIn('resumed, 6 of 6 trials done', p.stdout)
        self.assertEqual(len(completed_trials(self.out)[0]), 6)
        p = subprocess.run(tune_cmd(self.out, '--trials', '7', '--objective', 'self', *SMALL),
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)
        self.assertEqual(p.returncode, 2, p.stdout)
        self.assertIn('set up differently (objective differ)', p.stdout)


def bundled_datasets():
    sys.path.insert(0, os.path.join(REPO, 'src'))
    from pf_localization import benchmark
    return list(benchmark.BUNDLED)


@REPLAYS
class BenchmarkOnDaskTest(unittest.TestCase):
    def test_benchmark_datasets_on_a_local_cluster_gives_the_sequential_table(self):
        self.assertTrue(RUNNER, NO_RUNNER)
        tables = []
        with tempfile.TemporaryDirectory() as d:
            for extra in ([], ['--workers', '2']):
                out = os.path.join(d, 'dask' if extra else 'plain')
                p = subprocess.run(['/usr/bin/python3', os.path.join(REPO, 'scripts', 'benchmark_datasets'),
                                    '--data', os.path.join(d, 'no_data'), '--no-plots', '--out', out] + extra,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                                   timeout=600)
                self.assertEqual(p.returncode, 0, p.stdout)
                with open(os.path.join(out, 'results.csv')) as f:
                    rows = list(csv.DictReader(f))
                tables.append([(r['dataset'], r['ate_rmse_m'], r['max_m'], r['status']) for r in rows])
        # every bundled bag with ground truth, as benchmark.py lists them
        self.assertEqual(sorted(r[0] for r in tables[0]), sorted(bundled_datasets()))
        self.assertTrue(all(r[3] == 'ok' for r in tables[0]))
        self.assertEqual(tables[0], tables[1])


if __name__ == '__main__':
    unittest.main()
