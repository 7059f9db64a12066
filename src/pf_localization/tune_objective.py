"""pf_tune's scores of one run (lower is better; pf_tune --help, "Objectives"): against a
reference, ATE RMSE plus the share of the run spent off; without one, the self-supervised loss from
the published poses and the scans: the scans' fit to the map, the lost and uncertain shares and the
jumps of map -> odom."""
import math

import numpy as np

from pf_localization import evaluate as pfe


OFF_M = 0.5             # reference objective: an estimate this far off is "off"
OFF_WEIGHT = 10.0       # [m] added per unit share of the run spent off
FIT_DISTANCE = 0.1      # [m] self objective: a beam fits when it ends this close to an occupied cell
LOST_WEIGHT, UNCERTAIN_WEIGHT = 0.5, 0.2
JUMP_M, JUMP_RAD, JUMP_WEIGHT = 0.3, 0.3, 20.0
FAIL_SCORE = {'reference': 100.0, 'self': 3.0}


def wrap(a):
    return (np.asarray(a, dtype=float) + np.pi) % (2 * np.pi) - np.pi


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
