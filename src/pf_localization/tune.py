"""Tune pf_localization's parameters on recorded bags, on this machine or on a Dask cluster.

usage: pf_tune --bags B1.bag [B2.bag ...] --map MAP.yaml [--map MAP2.yaml ...]
               [--initial-pose X Y YAW | --initial-pose global]... [--reference REF.tum ...]
               [--params-from config/pf.yaml] [--space SPACE.yaml] --trials N --out DIR
               [--storage sqlite:///DIR/study.db] [--study-name NAME] [--seed S]
               [--objective auto|reference|self] [--scheduler tcp://HOST:8786 | --workers N]
               [--print-space]

How it works
  Optuna (TPE sampler, seeded with --seed) chooses the parameters of each trial from the search
  space; the first trial of a new study is the --params-from values themselves, so the study always
  holds the baseline. Each trial runs pf_bag_runner on every bag as its own Dask task (one trial over
  ten bags keeps ten workers busy) and scores each run; the trial's value is the mean over the bags
  (lower is better). Without --scheduler a dask.distributed LocalCluster with --workers worker
  processes (default: one per core) is started and closed by the tool; with --scheduler the same
  tasks go to an existing cluster (docs/tuning.md).

Objectives (chosen automatically unless --objective says otherwise, and printed)
  reference  every bag has /ground_truth, or --reference gives a TUM file per bag:
             ATE RMSE [m] + 10 m x the share of reference poses more than 0.5 m off (or unmatched).
  self       no reference: a self-supervised loss from the published poses and the scans alone:
             (1 - scan fit) + 0.5 x lost share + 0.2 x uncertain share + jump penalty, where the scan
             fit is the mean over all scans of the share of valid beams whose end point, placed from
             the published pose, lies within --fit-distance (fixed, default 0.1 m; not sigma_hit,
             which is tuned) of an occupied map cell; a scan without a published pose fits 0. The
             lost/uncertain shares are the runner's confidence states over the updates; a jump is a
             change of map -> odom by more than 0.3 m or 0.3 rad between two scans, and each costs
             20 / (number of scans), capped at 1.
  A bag whose run fails scores 100 (reference) or 3 (self), worse than any run that succeeds; its
  error is printed and tuning continues.

Choosing the best (the winner's curse)
  A trial's value is one run per bag with one seed, and the runs of a particle filter vary from seed
  to seed: the lowest of many such values is mostly the luckiest draw (on AC109, a trial that scored
  0.0036 averaged 0.0049 over four seeds, where the baseline averages 0.0057). So the --confirm-top K
  (default 5) lowest trials and the baseline are run again with --confirm-seeds S (default 3) more
  seeds, and compared by their mean over the S + 1 seeds. The lowest mean replaces the baseline only
  if it beats the baseline's by more than --min-gain (default 0.005: 5 mm of ATE, or half a percent
  of beams fitting) and by more than twice the standard error of the difference; otherwise best.yaml
  holds the baseline and pf_tune says that the bags could not tell the trials from it.

Faults
  The study lives in --storage (default sqlite:///DIR/study.db): run the same command again and it
  continues where it stopped (--trials is the total number of completed trials wanted). A worker
  killed mid-task costs that task a retry (Dask reschedules it; pf_tune resubmits it up to twice
  more), not the study.

Output in DIR
  best.yaml   the --params-from file with the chosen trial's values put in (comments kept): load it
              with pf_bag_runner --params DIR/best.yaml or localization.launch params:=DIR/best.yaml
  report.md   objective, best vs. baseline values, the confirmation runs and the verdict, per-bag
              baseline vs. best table, trial list
  history.png optimisation history; importances.png parameter importances (Optuna's matplotlib
              visualisation); runs/ the trajectories and logs of the baseline and the best trial
Exit status: 0 on success, 2 on bad input (missing bag or map, bad space YAML, ...).
"""
import argparse
import ctypes
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import types

import numpy as np
import yaml

from pf_localization import evaluate as pfe
from pf_localization import locate
from pf_localization.cluster import ClusterError, close_client, open_client

# The default search space: the motion model's alphas, the likelihood field's hit model, the
# likelihood exponent, the recovery rates and the number of beams.
DEFAULT_SPACE = {
    'odom_alpha1': {'low': 0.005, 'high': 2.0, 'log': True},
    'odom_alpha2': {'low': 0.005, 'high': 2.0, 'log': True},
    'odom_alpha3': {'low': 0.005, 'high': 2.0, 'log': True},
    'odom_alpha4': {'low': 0.005, 'high': 2.0, 'log': True},
    'laser_sigma_hit': {'low': 0.03, 'high': 0.6, 'log': True},
    'laser_z_hit': {'low': 0.5, 'high': 0.99},
    'laser_z_rand': {'low': 0.01, 'high': 0.5, 'log': True},
    'laser_likelihood_exponent': {'low': 0.02, 'high': 1.0, 'log': True},
    'recovery_alpha_slow': {'low': 0.001, 'high': 0.04, 'log': True},  # below alpha_fast's range:
    'recovery_alpha_fast': {'low': 0.05, 'high': 0.5, 'log': True},   # the runner needs fast > slow
    'laser_max_beams': {'low': 20, 'high': 180, 'step': 10, 'type': 'int'},
}

OFF_M = 0.5             # reference objective: an estimate this far off is "off"
OFF_WEIGHT = 10.0       # [m] added per unit share of the run spent off
FIT_DISTANCE = 0.1      # [m] self objective: a beam fits when it ends this close to an occupied cell
LOST_WEIGHT, UNCERTAIN_WEIGHT = 0.5, 0.2
JUMP_M, JUMP_RAD, JUMP_WEIGHT = 0.3, 0.3, 20.0
FAIL_SCORE = {'reference': 100.0, 'self': 3.0}
MAX_ATTEMPTS = 3        # a task whose worker died is submitted at most this often by pf_tune
CONFIRM_TOP, CONFIRM_SEEDS, MIN_GAIN = 5, 3, 0.005  # choosing the best: see "Choosing the best"


class TuneError(Exception):
    """Bad input; main() prints it and exits with status 2."""


# ------------------------------------------------------------------------------- helpers
def _worker_cache():
    """A module that lives as long as the (worker) process: caches of bag data and maps. It hangs
    off sys.modules so that it holds also for a function a Dask client shipped by value."""
    m = sys.modules.get('_pf_tune_cache')
    if m is None:
        m = types.ModuleType('_pf_tune_cache')
        m.bags, m.maps = {}, {}
        sys.modules['_pf_tune_cache'] = m
    return m


def wrap(a):
    return (np.asarray(a, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def yaw_of(q):
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


# ------------------------------------------------------------------------- the search space
def load_space(path, base):
    """SPACE.yaml -> {name: {'low', 'high', 'log', 'step', 'type'}}, checked against the base params."""
    if path is None:
        raw = DEFAULT_SPACE
        where = 'the default space'
    else:
        if not os.path.isfile(path):
            raise TuneError('space file not found: %s' % path)
        try:
            with open(path) as f:
                raw = yaml.safe_load(f)
        except yaml.YAMLError as e:
            raise TuneError('space file %s is not valid YAML: %s' % (path, e))
        where = path
    if not isinstance(raw, dict) or not raw:
        raise TuneError('%s: expected a mapping "parameter: {low: L, high: H[, log: true][, type: int]'
                        '[, step: S]}", got %r' % (where, raw))
    space = {}
    for name, spec in raw.items():
        if name not in base:
            raise TuneError('%s: "%s" is not a parameter of the --params-from file (known: %s)'
                            % (where, name, ', '.join(sorted(k for k, v in base.items()
                                                             if isinstance(v, (int, float))
                                                             and not isinstance(v, bool)))))
        if not isinstance(spec, dict) or 'low' not in spec or 'high' not in spec:
            raise TuneError('%s: %s needs "low" and "high", got %r' % (where, name, spec))
        unknown = set(spec) - {'low', 'high', 'log', 'step', 'type'}
        if unknown:
            raise TuneError('%s: %s has unknown key(s) %s (allowed: low, high, log, step, type)'
                            % (where, name, ', '.join(sorted(unknown))))
        kind = spec.get('type', 'int' if isinstance(base[name], int) and not isinstance(base[name], bool)
                        else 'float')
        if kind not in ('int', 'float'):
            raise TuneError('%s: %s: type must be int or float, got %r' % (where, name, kind))
        try:
            low, high = float(spec['low']), float(spec['high'])
        except (TypeError, ValueError):
            raise TuneError('%s: %s: low and high must be numbers, got %r, %r'
                            % (where, name, spec['low'], spec['high']))
        log = bool(spec.get('log', False))
        if not low < high:
            raise TuneError('%s: %s: low (%g) must be below high (%g)' % (where, name, low, high))
        if log and low <= 0:
            raise TuneError('%s: %s: a log scale needs low > 0, got %g' % (where, name, low))
        step = spec.get('step')
        if step is not None and (not isinstance(step, (int, float)) or step <= 0 or log):
            raise TuneError('%s: %s: step must be a positive number and not combined with log' % (where, name))
        if kind == 'int':
            low, high = int(round(low)), int(round(high))
            step = int(step or 1)
        space[name] = {'low': low, 'high': high, 'log': log, 'step': step, 'type': kind}
    return space


def suggest(trial, space):
    p = {}
    for name, s in space.items():
        if s['type'] == 'int':
            p[name] = trial.suggest_int(name, s['low'], s['high'], step=s['step'], log=s['log'])
        else:
            p[name] = trial.suggest_float(name, s['low'], s['high'], step=s['step'], log=s['log'])
    return p


def baseline_point(space, base):
    """The base file's values, clamped into the space (and onto its int step), for trial 0."""
    p = {}
    for name, s in space.items():
        v = min(max(float(base[name]), s['low']), s['high'])
        if s['type'] == 'int':
            v = s['low'] + int(round((v - s['low']) / s['step'])) * s['step']
            v = int(min(v, s['high']))
        p[name] = v
    return p


# ------------------------------------------------------------------------- params files
def format_value(v):
    if isinstance(v, bool):
        return 'true' if v else 'false'
    if isinstance(v, int):
        return str(v)
    return repr(float(v))


def write_params_yaml(base_text, values, path, header=''):
    """The base file's text with each value of `values` put on its key's line (comments kept)."""
    out, seen = [], set()
    for line in base_text.splitlines():
        stripped = line.lstrip()
        key = stripped.split(':', 1)[0].strip() if ':' in stripped and not stripped.startswith('#') else None
        if key in values and line == stripped:  # top-level keys only
            head = '%s: %s' % (key, format_value(values[key]))
            hash_at = line.find('#', len(key) + 1)
            if hash_at >= 0:  # keep the comment, at its column when the new value fits
                line = head.ljust(hash_at - 1) + ' ' + line[hash_at:]
            else:
                line = head
            seen.add(key)
        out.append(line)
    missing = [k for k in values if k not in seen]
    if missing:
        out.append('# set by pf_tune (not in the base file):')
        out += ['%s: %s' % (k, format_value(values[k])) for k in missing]
    with open(path, 'w') as f:
        f.write(header + '\n'.join(out) + '\n')


# --------------------------------------------------------------------- data read from bags
def bag_has_topic(bag, topic):
    """Whether the bag holds messages on topic; an unreadable bag has none (its runs will fail, be
    reported and scored as failures, and the study goes on)."""
    import rosbag
    try:
        with rosbag.Bag(bag) as b:
            info = b.get_type_and_topic_info().topics
            return topic in info and info[topic].message_count > 0
    except Exception as e:
        print('pf_tune: warning: cannot read %s: %s' % (bag, e), file=sys.stderr)
        return False


def read_bag_data(bag, scan_topic='/scan', odom_topic='/odom', odom_frame='odom', base_frame='base_link'):
    """What the self-supervised score needs from a bag, cached per process: the scans (stamps,
    ranges, beam angles), the laser's pose on the robot and the odometry at each scan."""
    c = _worker_cache()
    key = (os.path.realpath(bag), os.path.getmtime(bag), scan_topic, odom_topic)
    if key in c.bags:
        return c.bags[key]
    import rosbag
    stamps, ranges, angles, limits = [], [], None, None
    laser_frame, laser = None, None
    odom_t, odom_p, tf_t, tf_p = [], [], [], []
    static = {}
    with rosbag.Bag(bag) as b:
        for topic, m, _ in b.read_messages(topics=[scan_topic, odom_topic, '/tf', '/tf_static']):
            if topic == scan_topic:
                r = np.asarray(m.ranges, dtype=np.float32)
                if angles is None or len(angles) != len(r):
                    angles = m.angle_min + m.angle_increment * np.arange(len(r))
                    limits = (m.range_min, m.range_max)
                    laser_frame = m.header.frame_id.lstrip('/')
                if len(r) != len(angles):
                    continue
                stamps.append(m.header.stamp.to_sec())
                ranges.append(r)
            elif topic == odom_topic:
                p = m.pose.pose
                odom_t.append(m.header.stamp.to_sec())
                odom_p.append((p.position.x, p.position.y, yaw_of(p.orientation)))
            else:
                for t in m.transforms:
                    parent, child = t.header.frame_id.lstrip('/'), t.child_frame_id.lstrip('/')
                    tr, q = t.transform.translation, t.transform.rotation
                    if parent == odom_frame and child == base_frame:
                        tf_t.append(t.header.stamp.to_sec())
                        tf_p.append((tr.x, tr.y, yaw_of(q)))
                    elif (parent, child) not in static:
                        static[(parent, child)] = (tr.x, tr.y, yaw_of(q))
    if not stamps:
        raise TuneError('bag %s has no %s scans' % (bag, scan_topic))
    if (base_frame, laser_frame) in static:
        laser = static[(base_frame, laser_frame)]
    elif laser_frame == base_frame:
        laser = (0.0, 0.0, 0.0)
    else:
        laser = (0.0, 0.0, 0.0)
        print('pf_tune: warning: no %s -> %s transform in %s: laser assumed at the robot\'s origin'
              % (base_frame, laser_frame, bag), file=sys.stderr)
    ot, op = (odom_t, odom_p) if odom_t else (tf_t, tf_p)
    order = np.argsort(ot) if ot else []
    ot = np.asarray(ot, dtype=float)[order] if len(ot) else np.zeros(0)
    op = np.asarray(op, dtype=float)[order] if len(op) else np.zeros((0, 3))
    data = {'t': np.asarray(stamps), 'ranges': np.vstack(ranges), 'angles': np.asarray(angles, dtype=float),
            'range_min': float(limits[0]), 'range_max': float(limits[1]), 'laser': laser,
            'odom_t': ot, 'odom': op}
    c.bags[key] = data
    return data


def load_distance_map(yaml_path):
    """map_server YAML -> (distance to the nearest occupied cell [m] per cell, resolution, origin x, y)."""
    c = _worker_cache()
    key = (os.path.realpath(yaml_path), os.path.getmtime(yaml_path))
    if key in c.maps:
        return c.maps[key]
    from scipy import ndimage
    with open(yaml_path) as f:
        info = yaml.safe_load(f)
    image = os.path.join(os.path.dirname(os.path.abspath(yaml_path)), info['image'])
    if image.lower().endswith(('.pgm', '.ppm', '.pnm')):
        v = pfe.read_pnm(image)
    else:
        from PIL import Image
        v = np.asarray(Image.open(image).convert('L'), dtype=float) / 255.0
    occ = v if int(info.get('negate', 0)) else 1.0 - v
    occupied = occ > float(info.get('occupied_thresh', 0.65))
    res = float(info['resolution'])
    dist = ndimage.distance_transform_edt(~occupied) * res
    dist = dist[::-1]  # row 0 at the origin's y, as the map frame
    origin = [float(x) for x in info['origin']]
    c.maps[key] = (dist, res, origin[0], origin[1])
    return c.maps[key]


# ------------------------------------------------------------------------------- scores
def self_supervised(traj, log, data, dmap, fit_distance=FIT_DISTANCE):
    """The self-supervised loss of one run (lower is better) and its parts. traj: (N, 4) t, x, y, yaw
    of the published poses; log: the runner's update log (dict of columns) or None; data: one scan
    topic's read_bag_data, or a list of them (a robot with several lidars: the fit is over all their
    scans, the jumps are counted at the first one's)."""
    datas = data if isinstance(data, list) else [data]
    fits, poses = zip(*(scan_fits(traj, d, dmap, fit_distance) for d in datas))
    fits = np.concatenate(fits)
    counted = ~np.isnan(fits)  # scans without any valid beam say nothing
    fit = float(fits[counted].mean()) if counted.any() else 0.0
    n = len(fits)
    jumps = count_jumps(poses[0], datas[0])
    lost = uncertain = 0.0
    if log is not None and 'state' in log and len(log['state']):
        states = log['state']
        lost = float(np.mean(states == 'lost'))
        uncertain = float(np.mean(states == 'uncertain'))
    jump_pen = min(1.0, JUMP_WEIGHT * jumps / max(n, 1))
    loss = (1.0 - fit) + LOST_WEIGHT * lost + UNCERTAIN_WEIGHT * uncertain + jump_pen
    return loss, {'fit': fit, 'lost_share': lost, 'uncertain_share': uncertain, 'jumps': jumps,
                  'scans': n, 'scans_with_pose': int(sum(np.isfinite(p[:, 0]).sum() for p in poses))}


def scan_fits(traj, data, dmap, fit_distance):
    """Per scan of data: the share of its valid beams that end near an occupied cell from the
    published pose at its stamp (0 without one, NaN without a valid beam), and that pose."""
    dist, res, ox, oy = dmap
    st = data['t']
    n = len(st)
    fits = np.zeros(n)
    pose = np.full((n, 3), np.nan)
    if len(traj):
        tt = traj[:, 0]
        k = np.clip(np.searchsorted(tt, st), 0, len(tt) - 1)
        k0 = np.clip(k - 1, 0, len(tt) - 1)
        k = np.where(np.abs(tt[k0] - st) < np.abs(tt[k] - st), k0, k)
        near = np.abs(tt[k] - st) < 1e-3  # the runner writes one pose per scan, at its stamp
        pose[near] = traj[k[near], 1:]
    lx, ly, lyaw = data['laser']
    r = data['ranges'].astype(float)
    valid = np.isfinite(r) & (r > max(data['range_min'], 1e-3)) & (r < data['range_max'])
    h, w = dist.shape
    for i in np.nonzero(np.isfinite(pose[:, 0]))[0]:
        v = valid[i]
        nv = int(v.sum())
        if nv == 0:
            fits[i] = np.nan
            continue
        x, y, a = pose[i]
        sx, sy = x + math.cos(a) * lx - math.sin(a) * ly, y + math.sin(a) * lx + math.cos(a) * ly
        ang = a + lyaw + data['angles'][v]
        ex, ey = sx + r[i, v] * np.cos(ang), sy + r[i, v] * np.sin(ang)
        cx, cy = np.floor((ex - ox) / res).astype(int), np.floor((ey - oy) / res).astype(int)
        inside = (cx >= 0) & (cy >= 0) & (cx < w) & (cy < h)
        hit = np.zeros(nv, dtype=bool)
        hit[inside] = dist[cy[inside], cx[inside]] <= fit_distance
        fits[i] = hit.mean()
    return fits, pose


def count_jumps(pose, data):
    """Jumps of map -> odom, measured where the robot is: the published pose against the previous
    one moved by the odometry between the two scans (a far odom origin does not magnify them)."""
    st = data['t']
    jumps = 0
    if len(data['odom_t']) >= 2:
        ot, op = data['odom_t'], data['odom']
        have = np.isfinite(pose[:, 0]) & (st >= ot[0]) & (st <= ot[-1])
        idx = np.nonzero(have)[0]
        if len(idx) >= 2:
            t = st[idx]
            ox_, oy_ = np.interp(t, ot, op[:, 0]), np.interp(t, ot, op[:, 1])
            oyaw = np.interp(t, ot, np.unwrap(op[:, 2]))
            # odometry step in the robot's frame at the earlier scan
            c0, s0 = np.cos(oyaw[:-1]), np.sin(oyaw[:-1])
            dx, dy = np.diff(ox_), np.diff(oy_)
            fx, fy, dyaw = c0 * dx + s0 * dy, -s0 * dx + c0 * dy, np.diff(oyaw)
            e = pose[idx]
            c1, s1 = np.cos(e[:-1, 2]), np.sin(e[:-1, 2])
            px, py = e[:-1, 0] + c1 * fx - s1 * fy, e[:-1, 1] + s1 * fx + c1 * fy
            d = np.hypot(e[1:, 0] - px, e[1:, 1] - py)
            da = np.abs(wrap(e[1:, 2] - (e[:-1, 2] + dyaw)))
            jumps = int(np.sum((d > JUMP_M) | (da > JUMP_RAD)))
    return jumps


def reference_score(traj, ref):
    """ATE RMSE + OFF_WEIGHT x the share of reference poses more than OFF_M off or unmatched."""
    m, match = pfe.evaluate(traj, ref)
    off = (int(np.sum(match['pos_err'] > OFF_M)) + (m['n_reference'] - m['n_matched'])) / m['n_reference']
    return m['ate_rmse_m'] + OFF_WEIGHT * off, {'ate_rmse_m': m['ate_rmse_m'], 'off_share': off,
                                                 'max_m': m['max_m'], 'coverage': m['coverage']}


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


# ------------------------------------------------------------------------------- the CLI
def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0], epilog=__doc__[__doc__.index('How it'):],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--bags', nargs='+', help='bags to tune on')
    p.add_argument('--map', action='append', help='map YAML: one for all bags, or one per bag in order')
    p.add_argument('--initial-pose', action='append', nargs='+', metavar='X Y YAW',
                   help='start pose: once for all bags or once per bag in order; "global" for global '
                        'localization. Without it, BAG.pose (a sidecar file "X Y YAW") when present, '
                        'else global localization')
    p.add_argument('--reference', action='append', help='reference TUM file, one per bag in order')
    p.add_argument('--scan-topic', action='append', metavar='TOPIC',
                   help='a lidar\'s LaserScan topic, once per lidar, the same for every bag (default /scan); '
                        'the self-supervised fit is over all of their scans')
    p.add_argument('--cloud-topic', action='append', metavar='TOPIC',
                   help='a 3D lidar\'s or depth camera\'s PointCloud2 topic, once per sensor (scored with a '
                        'reference: the self-supervised fit reads scan topics only)')
    p.add_argument('--params-from', help='base parameter file (default: the package\'s config/pf.yaml)')
    p.add_argument('--space', help='search space YAML (default: the built-in space; --print-space shows it)')
    p.add_argument('--trials', type=int, help='completed trials the study should hold')
    p.add_argument('--out', help='output folder')
    p.add_argument('--storage', help='Optuna storage URL (default sqlite:///OUT/study.db)')
    p.add_argument('--study-name', default='pf_tune')
    p.add_argument('--seed', type=int, default=1, help='seed of the sampler and of every run (default 1)')
    p.add_argument('--objective', choices=['auto', 'reference', 'self'], default='auto')
    p.add_argument('--fit-distance', type=float, default=FIT_DISTANCE,
                   help='[m] self-supervised score: a beam fits within this of an occupied cell (fixed)')
    p.add_argument('--scheduler', help='address of a running Dask scheduler, e.g. tcp://host:8786')
    p.add_argument('--workers', type=int, help='LocalCluster worker processes (default: one per core)')
    p.add_argument('--batch', type=int, default=1,
                   help='trials evaluated at once (default 1: every trial sees all earlier results, so '
                        'the study does not depend on the number of workers)')
    p.add_argument('--confirm-top', type=int, default=CONFIRM_TOP,
                   help='the K lowest trials are run again with more seeds before one is chosen (default %d)'
                        % CONFIRM_TOP)
    p.add_argument('--confirm-seeds', type=int, default=CONFIRM_SEEDS,
                   help='extra seeds for those runs and the baseline\'s (default %d; 0: the study\'s own '
                        'values are compared, still against --min-gain)' % CONFIRM_SEEDS)
    p.add_argument('--min-gain', type=float, default=MIN_GAIN,
                   help='a trial replaces the baseline only if its mean over the seeds is lower by more than '
                        'this (default %g) and by more than twice the standard error' % MIN_GAIN)
    p.add_argument('--timeout', type=float, default=3600.0, help='[s] per run of pf_bag_runner')
    p.add_argument('--runner', help='pf_bag_runner to use (default: the one of the workspace or install space '
                                    'this command is in; see pf_localization/locate.py)')
    p.add_argument('--no-progress', action='store_true', help='no progress bar')
    p.add_argument('--print-space', action='store_true', help='print the default space as YAML and exit')
    return p.parse_args(argv)


def per_bag(values, n, what, default=None):
    if not values:
        return [default] * n
    if len(values) == 1:
        return values * n
    if len(values) != n:
        raise TuneError('%s: give one for all %d bags or one per bag, got %d' % (what, n, len(values)))
    return values


def parse_pose(v, bag):
    if v is None:
        side = bag + '.pose'
        if os.path.isfile(side):
            with open(side) as f:
                v = f.read().split()
        else:
            return None
    if len(v) == 1 and v[0] == 'global':
        return None
    try:
        if len(v) != 3:
            raise ValueError
        return tuple(float(x) for x in v)
    except ValueError:
        raise TuneError('initial pose for %s: expected X Y YAW or "global", got %s' % (bag, ' '.join(v)))


def prepare(args):
    """Checks the inputs; returns the study's setup."""
    if not args.bags:
        raise TuneError('--bags is required')
    if not args.map:
        raise TuneError('--map is required')
    if args.trials is None or args.trials < 1:
        raise TuneError('--trials N (N >= 1) is required')
    if not args.out:
        raise TuneError('--out DIR is required')
    if args.confirm_top < 1 or args.confirm_seeds < 0 or not args.min_gain >= 0:
        raise TuneError('--confirm-top must be >= 1, --confirm-seeds >= 0 and --min-gain >= 0')
    bags = [os.path.abspath(b) for b in args.bags]
    for b in bags:
        if not os.path.isfile(b):
            raise TuneError('bag not found: %s' % b)
    maps = [os.path.abspath(m) for m in per_bag(args.map, len(bags), '--map')]
    for m in maps:
        if not os.path.isfile(m):
            raise TuneError('map not found: %s' % m)
    poses = [parse_pose(v, b) for v, b in zip(per_bag(args.initial_pose, len(bags), '--initial-pose'), bags)]
    refs = per_bag([os.path.abspath(r) for r in args.reference] if args.reference else None, len(bags),
                   '--reference')
    for r in refs:
        if r and not os.path.isfile(r):
            raise TuneError('reference not found: %s' % r)
    if args.params_from is None:
        package = locate.package_dir()
        if package is None:
            raise TuneError('cannot find the package\'s config/pf.yaml: pass --params-from')
        args.params_from = os.path.join(package, 'config', 'pf.yaml')
    if not os.path.isfile(args.params_from):
        raise TuneError('parameter file not found: %s' % args.params_from)
    with open(args.params_from) as f:
        base_text = f.read()
    try:
        base = yaml.safe_load(base_text)
    except yaml.YAMLError as e:
        raise TuneError('parameter file %s is not valid YAML: %s' % (args.params_from, e))
    if not isinstance(base, dict):
        raise TuneError('parameter file %s is not a mapping of parameters' % args.params_from)
    space = load_space(args.space, base)
    try:
        runner = os.path.abspath(args.runner) if args.runner else locate.find_runner()
    except locate.NotFound as e:
        raise TuneError('%s; or pass --runner' % e)
    if not os.access(runner, os.X_OK):
        raise TuneError('--runner %s is not an executable file' % runner)
    if args.objective == 'auto':
        has_ref = [bool(r) or bag_has_topic(b, '/ground_truth') for b, r in zip(bags, refs)]
        objective = 'reference' if all(has_ref) else 'self'
        why = ('every bag has a reference' if all(has_ref) else
               'no reference for %s' % ', '.join(os.path.basename(b) for b, h in zip(bags, has_ref) if not h))
    else:
        objective, why = args.objective, 'chosen with --objective'
        if objective == 'reference':
            for b, r in zip(bags, refs):
                if not r and not bag_has_topic(b, '/ground_truth'):
                    raise TuneError('--objective reference: %s has no /ground_truth and no --reference' % b)
    if objective == 'self' and args.cloud_topic and not args.scan_topic:
        raise TuneError('the self-supervised objective scores LaserScan topics and --cloud-topic gives none: '
                        'add --scan-topic, or a reference for every bag (%s)' % why)
    return dict(bags=bags, maps=maps, poses=poses, refs=refs, base=base, base_text=base_text, space=space,
                runner=runner, objective=objective, why=why)


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


def study_signature(setup, args):
    return {'bags': setup['bags'], 'objective': setup['objective'], 'fit_distance': args.fit_distance,
            'space': {k: [v['low'], v['high'], v['log'], v['type']] for k, v in setup['space'].items()},
            'seed': args.seed, 'params_from': os.path.abspath(args.params_from),
            **({'sensors': (args.scan_topic or []) + (args.cloud_topic or [])}
               if args.scan_topic or args.cloud_topic else {})}


def tune(args, setup, client, say=print):
    import optuna
    from optuna.trial import TrialState
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    storage = args.storage or 'sqlite:///%s' % os.path.join(os.path.abspath(args.out), 'study.db')
    sig = study_signature(setup, args)
    existing = [s.study_name for s in optuna.study.get_all_study_summaries(storage)]
    resumed = args.study_name in existing
    if resumed:
        study = optuna.load_study(study_name=args.study_name, storage=storage)
        old = study.user_attrs.get('signature')
        if old is not None and old != sig:
            diff = [k for k in sig if sig[k] != old.get(k)]
            raise TuneError('study "%s" in %s was set up differently (%s differ): use another --out, '
                            '--storage or --study-name' % (args.study_name, storage, ', '.join(diff)))
    # A resumed study draws on with another seed, so that it does not repeat its first random points.
    n_before = len(optuna.load_study(study_name=args.study_name, storage=storage).trials) if resumed else 0
    sampler = optuna.samplers.TPESampler(seed=args.seed + n_before)
    study = optuna.create_study(study_name=args.study_name, storage=storage, sampler=sampler,
                                direction='minimize', load_if_exists=True)
    if not resumed:
        study.set_user_attr('signature', sig)
        study.enqueue_trial(baseline_point(setup['space'], setup['base']))
    # Trials left running by an interrupted pf_tune: failed, and their points evaluated again.
    for t in study.get_trials(deepcopy=False, states=(TrialState.RUNNING,)):
        study.tell(t.number, state=TrialState.FAIL)
        study.enqueue_trial(t.params)
        say('pf_tune: trial %d was interrupted: it is run again' % (t.number + 1))
    done = len(study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,)))
    say('pf_tune: study "%s" in %s: %s, %d of %d trials done' % (args.study_name, storage,
                                                                'resumed' if resumed else 'new', done, args.trials))
    bar = None
    if not args.no_progress:
        from tqdm import tqdm
        bar = tqdm(total=args.trials, initial=done, desc='pf_tune', unit='trial', file=sys.stderr,
                   dynamic_ncols=True)
        if done:
            bar.set_postfix_str('best %.4f (trial %d)' % (study.best_value, study.best_trial.number + 1))
    write = bar.write if bar else say
    while done < args.trials:
        trials = [study.ask() for _ in range(min(args.batch, args.trials - done))]
        points = [suggest(t, setup['space']) for t in trials]
        jobs = [j for pt in points for j in jobs_for(setup, args, pt)]
        results = run_jobs(client, jobs, write)
        nb = len(setup['bags'])
        for k, t in enumerate(trials):
            rs = results[k * nb:(k + 1) * nb]
            for r in rs:
                if not r['ok']:
                    write('pf_tune: trial %d: %s failed: %s' % (t.number + 1, os.path.basename(r['bag']),
                                                                r.get('error')))
            value = float(np.mean([r['score'] for r in rs]))
            t.set_user_attr('bags', [{k2: r.get(k2) for k2 in ('bag', 'ok', 'score', 'metrics', 'error',
                                                              'wall_s', 'host')} for r in rs])
            study.tell(t, value)
            done += 1
            if bar:
                bar.update(1)
                bar.set_postfix_str('best %.4f (trial %d)' % (study.best_value, study.best_trial.number + 1))
            else:
                say('pf_tune: trial %d: %.4f (best %.4f, trial %d)' % (t.number + 1, value, study.best_value,
                                                                         study.best_trial.number + 1))
    if bar:
        bar.close()
    return study


def choose(baseline, candidates, min_gain):
    """The trial that replaces the baseline, or None. baseline: the baseline's values, one per seed;
    candidates: {trial number: values, one per seed}. The candidate with the lowest mean wins if its
    mean is below the baseline's by more than min_gain and by more than twice the standard error of
    the difference (each mean's error from its seeds' spread; one seed has no spread). Returns
    (number or None, {number or 'baseline': (mean, standard error)}, the verdict as a sentence)."""
    def mean_se(v):
        v = np.asarray(v, dtype=float)
        return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else 0.0
    stats = {'baseline': mean_se(baseline)}
    stats.update({k: mean_se(v) for k, v in candidates.items()})
    if not candidates:
        return None, stats, 'no other trial completed: the baseline is kept'
    best = min(candidates, key=lambda k: (stats[k][0], k))
    (mb, sb), (mc, sc) = stats['baseline'], stats[best]
    gain, noise = mb - mc, 2.0 * math.hypot(sb, sc)
    if gain > min_gain and gain > noise:
        return best, stats, ('trial %d beats the baseline by %.4g, more than --min-gain %g and twice the '
                             'standard error (%.2g)' % (best + 1, gain, min_gain, noise))
    short = [w for w, ok in (('--min-gain %g' % min_gain, gain > min_gain),
                             ('twice the standard error (%.2g)' % noise, gain > noise)) if not ok]
    return None, stats, ('the lowest mean, trial %d\'s, beats the baseline by %.4g, not by more than %s: '
                         'the bags cannot tell it from the baseline, which is kept'
                         % (best + 1, gain, ' or '.join(short)))


def confirm(args, setup, study, client, say=print):
    """Runs the --confirm-top lowest trials and the baseline with --confirm-seeds more seeds. Returns
    the chosen trial's number, {number: (mean, standard error)}, the verdict and the per-seed values
    {number: [value per seed]}."""
    from optuna.trial import TrialState
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    baseline = complete[0]
    ranked = sorted((t for t in complete[1:]), key=lambda t: (t.value, t.number))[:args.confirm_top]
    seeds = [args.seed + k for k in range(1, args.confirm_seeds + 1)]
    values = {t.number: [t.value] for t in [baseline] + ranked}
    if seeds:
        say('pf_tune: confirming the %d lowest trials and the baseline with %d more seeds each'
            % (len(ranked), len(seeds)))
        nb = len(setup['bags'])
        trials = [baseline] + ranked
        jobs = [j for t in trials for sd in seeds for j in jobs_for(setup, args, t.params, seed=sd)]
        results = run_jobs(client, jobs, say)
        for i, t in enumerate(trials):
            for k in range(len(seeds)):
                rs = results[(i * len(seeds) + k) * nb:(i * len(seeds) + k + 1) * nb]
                values[t.number].append(float(np.mean([r['score'] for r in rs])))
    chosen, stats, verdict = choose(values[baseline.number], {t.number: values[t.number] for t in ranked},
                                    args.min_gain)
    stats[baseline.number] = stats.pop('baseline')
    return (chosen if chosen is not None else baseline.number), stats, verdict, values


def write_outputs(args, setup, study, client, say=print):
    from optuna.trial import TrialState
    out = os.path.abspath(args.out)
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    baseline = complete[0]
    chosen, stats, verdict, seed_values = confirm(args, setup, study, client, say)
    best = study.trials[chosen]
    study.set_user_attr('chosen_trial', chosen)
    nseeds = args.confirm_seeds + 1
    header = ''.join('# %s\n' % ln for ln in textwrap.wrap(
        'pf_tune: trial %d of %d (%s loss %.6g, mean over %d seed(s) %.6g; baseline %.6g) of study "%s", '
        'on %s: %s. Tuned: %s.' % (
            best.number + 1, len(complete), setup['objective'], best.value, nseeds, stats[chosen][0],
            stats[baseline.number][0],
            args.study_name, ', '.join(os.path.basename(b) for b in setup['bags']), verdict,
            ', '.join(sorted(best.params))), 98))
    values = {k: (int(v) if setup['space'][k]['type'] == 'int' else float(v)) for k, v in best.params.items()}
    write_params_yaml(setup['base_text'], values, os.path.join(out, 'best.yaml'), header)

    # The baseline's and the best trial's runs once more, keeping their files (same seed: same runs).
    runs = os.path.join(out, 'runs')
    shutil.rmtree(runs, ignore_errors=True)
    base_pt = baseline_point(setup['space'], setup['base'])
    kept = run_jobs(client, jobs_for(setup, args, base_pt, os.path.join(runs, 'baseline')) +
                    jobs_for(setup, args, values, os.path.join(runs, 'best')), say)
    nb = len(setup['bags'])
    before, after = kept[:nb], kept[nb:]
    pngs = save_study_plots(study, out, say)
    lines = report_lines(args, setup, study, out, dict(
        baseline=baseline, best=best, values=values, chosen=chosen, stats=stats, verdict=verdict,
        seed_values=seed_values, before=before, after=after, pngs=pngs))
    with open(os.path.join(out, 'report.md'), 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return best, baseline, verdict


def save_study_plots(study, out, say=print):
    """history.png and importances.png in out (Optuna's matplotlib plots); returns the
    (title, file) of those written."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    import optuna.visualization.matplotlib as ovm
    import warnings
    pngs = []
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        plots = [(ovm.plot_optimization_history, 'history.png', 'Optimisation history',
                  'no history plot'),
                 (ovm.plot_param_importances, 'importances.png', 'Parameter importances (fANOVA)',
                  'no importance plot (needs at least two distinct completed trials and scikit-learn)')]
        for plot, name, title, failed in plots:
            try:
                ax = plot(study)
                ax.figure.set_size_inches(8, 4.5)
                ax.figure.tight_layout()
                ax.figure.savefig(os.path.join(out, name), dpi=100)
                plt.close(ax.figure)
                pngs.append((title, name))
            except Exception as e:
                say('pf_tune: warning: %s: %s' % (failed, e))
    return pngs


def report_lines(args, setup, study, out, found):
    """report.md's lines; found: what write_outputs found (the baseline, best and chosen trials, the
    chosen values, the confirmation's statistics and verdict, the kept runs, the plots)."""
    from optuna.trial import TrialState
    complete = study.get_trials(deepcopy=False, states=(TrialState.COMPLETE,))
    baseline, best, values, chosen, stats = (found[k] for k in (
        'baseline', 'best', 'values', 'chosen', 'stats'))
    nseeds = args.confirm_seeds + 1

    def metric_cells(r):
        if not r.get('ok'):
            return ['failed: %s' % (r.get('error') or '?').replace('|', '/')[:80]]
        m = r.get('metrics', {})
        if setup['objective'] == 'reference':
            return ['%.4f' % r['score'], 'ATE %.3f m, %.1f %% off' % (m['ate_rmse_m'], 100 * m['off_share'])]
        return ['%.4f' % r['score'], 'fit %.3f, lost %.2f, uncertain %.2f, %d jumps'
                % (m['fit'], m['lost_share'], m['uncertain_share'], m['jumps'])]

    lines = ['# pf_tune report: study "%s"' % args.study_name, '',
             '- objective: **%s** (%s); lower is better; failure scores %g' % (
                 setup['objective'], setup['why'], FAIL_SCORE[setup['objective']]),
             '- bags: %s' % ', '.join('`%s`' % b for b in setup['bags']),
             '- sensors: %s' % ', '.join('`%s`' % t for t in (args.scan_topic or ['/scan']) +
                                         (args.cloud_topic or [])),
             '- trials: %d complete of %d; seed %d; storage `%s`' % (
                 len(complete), len(study.trials), args.seed,
                 args.storage or 'sqlite:///%s' % os.path.join(out, 'study.db')),
             '- baseline (trial %d, the --params-from values): **%.5f**; chosen: trial %d, **%.5f**' % (
                 baseline.number + 1, baseline.value, best.number + 1, best.value),
             '- choice: %s' % found['verdict'],
             '- parameters: `best.yaml` (load with `pf_bag_runner --params %s/best.yaml`)' % out, '',
             '## Parameters', '', '| parameter | range | baseline | best |', '|---|---|---|---|']
    for k, s in setup['space'].items():
        lines.append('| %s | %g .. %g%s | %s | %s |' % (k, s['low'], s['high'], ' (log)' if s['log'] else '',
                                                      format_value(setup['base'][k]), format_value(values[k])))
    lines += ['', '## Confirmation: the lowest trials again, with %d seed(s) each' % nseeds, '',
              'Seeds %s; a value is the mean over the bags, as in the study. See pf_tune --help, '
              '"Choosing the best".' % ', '.join(str(args.seed + k) for k in range(nseeds)), '',
              '| trial | value per seed | mean | standard error |', '|---|---|---|---|']
    for number, vals in found['seed_values'].items():
        m, se = stats[number]
        lines.append('| %d%s%s | %s | %.5f | %.5f |' % (
            number + 1, ' (baseline)' if number == baseline.number else '', ' **chosen**' if number == chosen else '',
            ', '.join('%.5f' % v for v in vals), m, se))
    lines += ['', '## Per bag: baseline vs. chosen', '', '| bag | baseline | | chosen | |', '|---|---|---|---|---|']
    for b, r0, r1 in zip(setup['bags'], found['before'], found['after']):
        c0, c1 = metric_cells(r0), metric_cells(r1)
        c0 += [''] * (2 - len(c0))
        c1 += [''] * (2 - len(c1))
        lines.append('| %s | %s | %s | %s | %s |' % (os.path.basename(b), c0[0], c0[1], c1[0], c1[1]))
    for title, png in found['pngs']:
        lines += ['', '## %s' % title, '', '![%s](%s)' % (title, png)]
    if found['pngs']:
        lines += ['', "(Optuna's plots number the trials from 0: trial N of this report is N - 1 there.)"]
    lines += ['', '## Trials', '', '| trial | value | state | failed bags |', '|---|---|---|---|']
    for t in study.trials:
        failed = [os.path.basename(r['bag']) for r in t.user_attrs.get('bags', []) if not r.get('ok')]
        lines.append('| %d | %s | %s | %s |' % (t.number + 1, '%.5f' % t.value if t.value is not None else '-',
                                               t.state.name, ', '.join(failed)))
    return lines


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.print_space:
        print(yaml.safe_dump(DEFAULT_SPACE, sort_keys=False), end='')
        return 0
    try:
        setup = prepare(args)
    except TuneError as e:
        print('pf_tune: error: %s' % e, file=sys.stderr)
        return 2
    os.makedirs(args.out, exist_ok=True)
    print('pf_tune: objective: %s (%s)' % (setup['objective'], setup['why']), flush=True)
    print('pf_tune: %d bag(s), %d parameter(s): %s' % (len(setup['bags']), len(setup['space']),
                                                       ', '.join(setup['space'])), flush=True)
    t0 = time.monotonic()

    def on_term(signum, frame):  # kill PID: stop as Ctrl-C does; the study resumes from its storage
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, on_term)
    try:
        client = open_client(args.scheduler, args.workers)
    except ClusterError as e:
        print('pf_tune: error: %s' % e, file=sys.stderr)
        return 2
    where = args.scheduler or 'a LocalCluster of %d workers' % len(client.scheduler_info()['workers'])
    print('pf_tune: Dask: %s' % where, flush=True)
    try:
        study = tune(args, setup, client)
        best, baseline, verdict = write_outputs(args, setup, study, client)
    except TuneError as e:
        print('pf_tune: error: %s' % e, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print('\npf_tune: interrupted: run the same command again to continue the study', file=sys.stderr)
        return 130
    finally:
        close_client(client)
    print('pf_tune: %s' % verdict)
    print('pf_tune: chosen: trial %d, %s %.5f (baseline %.5f); %s' % (
        best.number + 1, setup['objective'], best.value, baseline.value,
        ', '.join('%s=%s' % (k, format_value(v)) for k, v in best.params.items())))
    print('pf_tune: wrote %s/best.yaml and %s/report.md in %.1f s' % (args.out, args.out, time.monotonic() - t0))
    return 0


if __name__ == '__main__':
    sys.exit(main())
