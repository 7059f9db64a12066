"""pf_tune's Dask tasks: one run of pf_bag_runner on one bag with one parameter set, scored
(evaluate_bag); the tasks of a parameter set over every bag (jobs_for); and their running on a Dask
client, a task lost with its worker submitted again (run_jobs)."""
import ctypes
import os
import shutil
import signal
import subprocess
import tempfile
import time

import numpy as np
import yaml

from pf_localization import evaluate as pfe
from pf_localization.tune_bag_data import load_distance_map, read_bag_data
from pf_localization.tune_objective import FAIL_SCORE, reference_score, self_supervised


MAX_ATTEMPTS = 3        # a task whose worker died is submitted at most this often by pf_tune


def _die_with_parent():
    """In the runner's child process: SIGKILL it when the worker that started it dies."""
    try:
        ctypes.CDLL('libc.so.6', use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def evaluate_bag(job):
    """One Dask task: run pf_bag_runner on one bag with one parameter set and score the run.
    Never raises for a failed run: returns {'ok': False, 'error': ...} and the failure score."""
    t0 = time.monotonic()
    res = {'bag': job['bag'], 'ok': False, 'score': FAIL_SCORE[job['objective']], 'host': os.uname()[1]}
    work = tempfile.mkdtemp(prefix='pf_tune_')
    try:
        params = os.path.join(work, 'params.yaml')
        with open(params, 'w') as f:
            yaml.safe_dump(job['params'], f)
        traj, logf = os.path.join(work, 'traj.tum'), os.path.join(work, 'updates.csv')
        cmd = [job['runner'], '--bag', job['bag'], '--map', job['map'], '--out', traj, '--log', logf,
               '--quiet', '--seed', str(job['seed']), '--params', params]
        if job['pose'] is not None:
            cmd += ['--initial-pose'] + ['%.6f' % v for v in job['pose']]
        for flag, topics in (('--scan-topic', job.get('scan_topics')), ('--cloud-topic', job.get('cloud_topics'))):
            for t in topics or []:
                cmd += [flag, t]
        try:
            p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                               timeout=job['timeout'], preexec_fn=_die_with_parent)
        except subprocess.TimeoutExpired:
            res['error'] = 'pf_bag_runner timed out after %g s' % job['timeout']
            return res
        except OSError as e:
            res['error'] = 'cannot run %s: %s' % (job['runner'], e)
            return res
        if p.returncode != 0 or not os.path.isfile(traj):
            tail = [ln for ln in p.stdout.strip().splitlines() if ln.strip()][-3:]
            res['error'] = 'pf_bag_runner exit %d: %s' % (p.returncode, ' | '.join(tail) or 'no output')
            return res
        try:
            est = pfe.read_tum(traj)
        except pfe.EvalError:
            est = np.zeros((0, 4))
        log = pfe.read_update_log(logf) if os.path.isfile(logf) and os.path.getsize(logf) > 0 else None
        if job['objective'] == 'reference':
            if len(est) == 0:
                res['error'] = 'the runner published no pose'
                return res
            ref = pfe.read_tum(job['reference'], 'reference') if job['reference'] else \
                pfe.read_bag_reference(job['bag'])
            res['score'], res['metrics'] = reference_score(est, ref)
        else:
            data = [read_bag_data(job['bag'], t, odom_frame=job['odom_frame'], base_frame=job['base_frame'])
                    for t in job.get('scan_topics') or ['/scan']]
            res['score'], res['metrics'] = self_supervised(est, log, data, load_distance_map(job['map']),
                                                           job['fit_distance'])
        res['ok'] = True
        if job.get('keep'):
            os.makedirs(job['keep'], exist_ok=True)
            for f in (traj, logf, params):
                if os.path.isfile(f):
                    shutil.copy(f, job['keep'])
        return res
    except Exception as e:  # a bad bag or reference: reported, scored as a failure
        res['error'] = '%s: %s' % (type(e).__name__, e)
        return res
    finally:
        res['wall_s'] = time.monotonic() - t0
        shutil.rmtree(work, ignore_errors=True)


# --------------------------------------------------------------------------- Dask tasks
def run_jobs(client, jobs, say=print):
    """Runs the jobs (evaluate_bag dicts) as Dask tasks; a task lost with its worker is submitted
    again, up to MAX_ATTEMPTS times in all. Returns the results in the jobs' order."""
    from distributed import as_completed
    futures = {client.submit(evaluate_bag, j, pure=False): (i, 1) for i, j in enumerate(jobs)}
    results = [None] * len(jobs)
    ac = as_completed(list(futures))
    for fut in ac:
        i, attempt = futures.pop(fut)
        try:
            results[i] = fut.result()
        except Exception as e:  # KilledWorker, a lost connection, ...
            if attempt < MAX_ATTEMPTS:
                say('pf_tune: task for %s failed (%s: %s): retrying (attempt %d of %d)'
                    % (jobs[i]['bag'], type(e).__name__, e, attempt + 1, MAX_ATTEMPTS))
                nf = client.submit(evaluate_bag, jobs[i], pure=False)
                futures[nf] = (i, attempt + 1)
                ac.add(nf)
            else:
                results[i] = {'bag': jobs[i]['bag'], 'ok': False, 'score': FAIL_SCORE[jobs[i]['objective']],
                              'error': 'task lost %d times: %s: %s' % (attempt, type(e).__name__, e)}
    return results


def jobs_for(setup, args, params, keep=None, seed=None):
    full = dict(setup['base'])
    full.update(params)
    seed = args.seed if seed is None else seed
    return [dict(runner=setup['runner'], bag=b, map=m, pose=pose, reference=r, params=full, seed=seed,
                 objective=setup['objective'], fit_distance=args.fit_distance, timeout=args.timeout,
                 scan_topics=args.scan_topic or [], cloud_topics=args.cloud_topic or [],
                 odom_frame=str(full.get('odom_frame', 'odom')),
                 base_frame=str(full.get('base_frame', 'base_link')),
                 keep=os.path.join(keep, os.path.splitext(os.path.basename(b))[0]) if keep else None)
            for b, m, pose, r in zip(setup['bags'], setup['maps'], setup['poses'], setup['refs'])]
