"""What the replay tests (test/replay/test_*.py) share: the built workspace, and one replay of a bag.

A replay is pf_bag_runner on a bag and its map, then pf_evaluate against the bag's
ground truth. pf_bag_runner is deterministic for a seed, so a loaded machine changes
no figure: each test holds the filter to a fixed threshold on a fixed run.

The workspace is $PF_WS (scripts/test.sh sets it), else scripts/build.sh's own
(`bash scripts/build.sh --where`); it must hold a built pf_bag_runner
(`bash scripts/build.sh pf_bag_runner`). Each replay writes to a folder of the
workspace (e.g. <ws>/warehouse_global/seed2): the trajectory, the update log, the
hypotheses, the covariance, runner.log, and pf_evaluate's eval/summary.json.

Run from the repository root:  /usr/bin/python3 -m pytest test/replay
"""
import csv
import json
import os
import shutil
import subprocess

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
PYTHON = '/usr/bin/python3'


def _workspace():
    if os.environ.get('PF_WS'):
        return os.environ['PF_WS']
    return subprocess.run(['bash', os.path.join(REPO, 'scripts', 'build.sh'), '--where'],
                          check=True, capture_output=True, text=True).stdout.strip()


WS = _workspace()
LIB = os.path.join(WS, 'devel', 'lib', 'pf_localization')
RUNNER = os.path.join(LIB, 'pf_bag_runner')


def tail(path, lines=5):
    try:
        with open(path) as f:
            return ''.join(f.readlines()[-lines:])
    except OSError:
        return '(no %s)' % path


def run_logged(cmd, log, env=None):
    """Runs cmd in the repository with its output in log; fails with the log's tail."""
    with open(log, 'w') as f:
        rc = subprocess.run(cmd, cwd=REPO, stdin=subprocess.DEVNULL, stdout=f, stderr=subprocess.STDOUT,
                            env=env).returncode
    assert rc == 0, '%s exited %d; the end of %s:\n%s' % (' '.join(cmd[:2]), rc, log, tail(log))


def workspace_env():
    """The environment with PF_WS set to the workspace, for the scripts the tests run."""
    return dict(os.environ, PF_WS=WS)


class Replay:
    """One replay's outputs: pf_evaluate's summary and pf_bag_runner's update log."""

    def __init__(self, out):
        self.out = out
        with open(os.path.join(out, 'eval', 'summary.json')) as f:
            self.summary = json.load(f)

    def updates(self):
        with open(os.path.join(self.out, 'updates.csv')) as f:
            return list(csv.DictReader(f))

    def localized_after_s(self):
        """Seconds from the first reference pose to the first update "localized", or inf."""
        for row in self.updates():
            if row['state'] == 'localized':
                return float(row['t']) - self.summary['reference_start_s']
        return float('inf')


def replay(out, bag, map_yaml, max_gap, *runner_args):
    """pf_bag_runner on bag and map_yaml (paths in the repository) with runner_args into
    the folder out, then pf_evaluate (a reference pose matched within max_gap s), with the
    hypotheses and the published covariance. Returns the Replay."""
    assert os.access(RUNNER, os.X_OK), 'no %s: build it (bash scripts/build.sh pf_bag_runner)' % RUNNER
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    files = {name: os.path.join(out, name) for name in ('traj.tum', 'updates.csv', 'hypotheses.csv', 'cov.csv')}
    run_logged([RUNNER, '--bag', bag, '--map', map_yaml] + [str(a) for a in runner_args] +
               ['--out', files['traj.tum'], '--log', files['updates.csv'], '--hypotheses', files['hypotheses.csv'],
                '--covariance', files['cov.csv'], '--quiet'], os.path.join(out, 'runner.log'))
    run_logged([PYTHON, os.path.join(LIB, 'pf_evaluate'), '--traj', files['traj.tum'], '--bag', bag,
                '--map', map_yaml, '--log', files['updates.csv'], '--hypotheses', files['hypotheses.csv'],
                '--cov', files['cov.csv'], '--max-gap', str(max_gap), '--out', os.path.join(out, 'eval'),
                '--no-plots'], os.path.join(out, 'eval.log'))
    return Replay(out)


def seed_ids(seed):
    return 'seed%d' % seed


def holds(condition, figures):
    """Prints the figures a test judges (pytest -s shows them beside its verdict) and fails
    with them when the condition does not hold."""
    print(' ' + figures, end=' ')
    assert condition, figures
