"""The error of a run against a reference trajectory (pf_evaluate's Metrics, evaluate.py): the
estimate at each reference pose (interpolated or held), the position and yaw errors, convergence,
the ATE before and after the best rigid fit (Umeyama 1991), the published covariance's honesty (d^2
against the chi-square bound, 2 dof), the "localized" updates that were far off, whether the true
place is among the published hypotheses; and the text summary's lines on them."""
import numpy as np

from pf_localization.evaluate_inputs import EvalError


EXACT_S = 1e-4  # estimates this close to a reference stamp count as taken at it
OFF_M = 0.5     # an estimate this far from the reference is "off" (the issue trackers' figure)
SETTLE_S = 10.0  # the start of a run that off_fraction_after_settle leaves out
WRONG_M = 1.0    # "localized" while this far off is confidently wrong
# A hypothesis this close to the reference holds the true place: as WRONG_M, the distance at which
# an estimate stops being a noisy version of the right place (a twin room is 4.75 m away).
HYPOTHESIS_NEAR_M = 1.0
CHI2_95_2DOF = 5.991  # 95 % quantile of the chi-square distribution with 2 degrees of freedom


def wrap(a):
    """Angle(s) wrapped to [-pi, pi)."""
    return (np.asarray(a, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def associate(est, ref_t, max_gap=0.5, interpolate=True):
    """Estimate (x, y, yaw) at each reference time.
    Returns (poses (N, 3) with NaN rows for unmatched references, kind (N,) with
    0 unmatched, 1 exact, 2 interpolated, 3 held)."""
    et = est[:, 0]
    n = len(ref_t)
    poses, kind = np.full((n, 3), np.nan), np.zeros(n, dtype=int)
    for k, t in enumerate(ref_t):
        i = int(np.searchsorted(et, t, side='right')) - 1          # newest at or before t
        j = i + 1                                                  # first after t
        if j < len(et) and et[j] - t <= EXACT_S and (i < 0 or et[j] - t < t - et[i]):
            poses[k], kind[k] = est[j, 1:], 1
        elif i >= 0 and t - et[i] <= EXACT_S:
            poses[k], kind[k] = est[i, 1:], 1
        elif interpolate and i >= 0 and j < len(et) and t - et[i] <= max_gap and et[j] - t <= max_gap:
            s = (t - et[i]) / (et[j] - et[i])
            a, b = est[i, 1:], est[j, 1:]
            poses[k] = (a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]),
                        wrap(a[2] + s * wrap(b[2] - a[2])))
            kind[k] = 2
        elif i >= 0 and t - et[i] <= max_gap:
            poses[k], kind[k] = est[i, 1:], 3
    return poses, kind


def convergence_time(times, errors, lost, t0):
    """Time (relative to t0) of the first sample from which on all errors are <= lost, else None."""
    bad = np.nonzero(np.asarray(errors) > lost)[0]
    if len(bad) == 0:
        return float(times[0] - t0)
    if bad[-1] == len(errors) - 1:
        return None
    return float(times[bad[-1] + 1] - t0)


def rigid_fit(src, dst):
    """The rotation (rad) and translation (2,) that best map the points src (N, 2) onto dst (N, 2)
    in the least-squares sense, no scale: Umeyama (1991) / Horn (1987) in 2D, where the rotation
    has a closed form: atan2 of the summed cross and dot products of the centred pairs."""
    src, dst = np.asarray(src, dtype=float), np.asarray(dst, dtype=float)
    ms, md = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - ms, dst - md
    angle = float(np.arctan2(np.sum(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]), np.sum(a * b)))
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return angle, md - rot @ ms


def rigid_move(xy, angle, shift):
    """The points xy (N, 2) turned by angle (rad) about the origin, then shifted by shift (2,)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.c_[c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]] + shift


def aligned_ate(est_xy, ref_xy):
    """ATE RMSE after rigid_fit of the estimates onto the reference: (rmse, angle rad, (tx, ty))."""
    angle, shift = rigid_fit(est_xy, ref_xy)
    moved = rigid_move(est_xy, angle, shift)
    return float(np.sqrt(np.mean(np.sum((moved - ref_xy) ** 2, axis=1)))), angle, shift


def evaluate(est, ref, max_gap=0.5, lost=0.3, interpolate=True):
    """est, ref: (N, 4) arrays t, x, y, yaw. Returns (metrics dict, per-match dict of arrays)."""
    if len(est) == 0:
        raise EvalError('the trajectory is empty')
    if len(ref) == 0:
        raise EvalError('the reference is empty')
    poses, kind = associate(est, ref[:, 0], max_gap, interpolate)
    ok = kind > 0
    if not ok.any():
        raise EvalError('no estimate matched a reference pose within %.3g s (estimates %.3f..%.3f s, '
                        'reference %.3f..%.3f s)' % (max_gap, est[0, 0], est[-1, 0], ref[0, 0], ref[-1, 0]))
    t, r, p = ref[ok, 0], ref[ok, 1:], poses[ok]
    pos = np.hypot(p[:, 0] - r[:, 0], p[:, 1] - r[:, 1])
    yaw = np.abs(wrap(p[:, 2] - r[:, 2]))
    t0 = float(ref[0, 0])
    aligned, angle, shift = aligned_ate(p[:, :2], r[:, :2])
    m = {
        'n_reference': int(len(ref)), 'n_matched': int(ok.sum()),
        'n_exact': int((kind == 1).sum()), 'n_interpolated': int((kind == 2).sum()),
        'n_held': int((kind == 3).sum()),
        'coverage': float(ok.mean()),
        'ate_rmse_m': float(np.sqrt(np.mean(pos ** 2))), 'median_m': float(np.median(pos)),
        'mean_m': float(np.mean(pos)), 'max_m': float(np.max(pos)),
        'ate_aligned_rmse_m': aligned, 'aligned_rotation_deg': float(np.degrees(angle)),
        'aligned_translation_m': [float(shift[0]), float(shift[1])],
        'yaw_rmse_deg': float(np.degrees(np.sqrt(np.mean(yaw ** 2)))),
        'yaw_max_deg': float(np.degrees(np.max(yaw))),
        'convergence_time_s': convergence_time(t, pos, lost, t0),
        'lost_fraction': float(np.mean(pos > lost)),
        # The share of the run (after its first SETTLE_S seconds, which a
        # global localization may need) spent more than OFF_M off.
        'off_fraction_after_settle': float(np.mean(pos[t - t0 >= SETTLE_S] > OFF_M))
        if np.any(t - t0 >= SETTLE_S) else None,
        'off_threshold_m': OFF_M, 'settle_s': SETTLE_S,
        'lost_threshold_m': lost, 'max_gap_s': max_gap,
        'association': 'interpolate' if interpolate else 'hold',
        'reference_start_s': t0, 'reference_duration_s': float(ref[-1, 0] - ref[0, 0]),
        'n_estimates': int(len(est)),
    }
    match = {'t': t, 'est': p, 'ref': r, 'pos_err': pos, 'yaw_err': yaw, 'matched': ok,
             'ref_t': ref[:, 0], 'unmatched_t': ref[~ok, 0], 't0': t0, 'alignment': (angle, shift)}
    return m, match


def covariance_at(cov, t, max_gap=0.5):
    """The xy covariance rows (N, 3: xx, xy, yy) in force at the times t: the newest row at or
    before each (one within EXACT_S after it counts as at it), at most max_gap before; NaN rows
    where none is."""
    ct = cov[:, 0]
    out = np.full((len(t), 3), np.nan)
    for k, tk in enumerate(t):
        i = int(np.searchsorted(ct, tk + EXACT_S, side='right')) - 1
        if i >= 0 and tk - ct[i] <= max_gap:
            out[k] = cov[i, 1:4]
    return out


def mahalanobis_sq(err, s_xy, ref_std=0.0):
    """d^2 = e^T S^-1 e for each (x, y) error e (N, 2), S = [[xx, xy], [xy, yy]] from s_xy (N, 3)
    + ref_std^2 I. Returns (d2, degenerate): a non-finite or numerically singular S (determinant
    <= 1e-12 of xx * yy, or a non-positive variance) gives d2 = inf and degenerate True."""
    xx, xy, yy = (s_xy[:, i] + (ref_std ** 2 if i != 1 else 0.0) for i in range(3))
    det = xx * yy - xy * xy
    with np.errstate(invalid='ignore'):
        degenerate = ~(np.isfinite(det) & (xx > 0) & (yy > 0) & (det > 1e-12 * xx * yy))
    ex, ey = err[:, 0], err[:, 1]
    d2 = np.full(len(err), np.inf)
    ok = ~degenerate
    d2[ok] = (yy[ok] * ex[ok] ** 2 - 2 * xy[ok] * ex[ok] * ey[ok] + xx[ok] * ey[ok] ** 2) / det[ok]
    return d2, degenerate


def covariance_metrics(cov, match, max_gap=0.5, ref_std=0.0, aligned=False):
    """How honest the published covariance is, over the matched references after the first
    SETTLE_S seconds (the samples of off_fraction_after_settle). With aligned, the errors are
    measured after the rigid fit onto the reference (for a reference whose frame is turned from
    the map's, which no covariance of a pose on the map should cover). Returns (the summary's
    "covariance" dict, per-sample dict t, d2, degenerate for the plot)."""
    t = match['t']
    s_xy = covariance_at(cov, t, max_gap)
    has = np.all(np.isfinite(s_xy), axis=1)
    use = has & (t - match['t0'] >= SETTLE_S)
    est = match['est'][:, :2]
    if aligned:
        angle, shift = match['alignment']
        est = rigid_move(est, angle, shift)
        # The covariance turns with the estimate.
        c, s = np.cos(angle), np.sin(angle)
        xx, xy, yy = s_xy[:, 0], s_xy[:, 1], s_xy[:, 2]
        s_xy = np.c_[c * c * xx - 2 * c * s * xy + s * s * yy,
                     c * s * (xx - yy) + (c * c - s * s) * xy,
                     s * s * xx + 2 * c * s * xy + c * c * yy]
    err = est - match['ref'][:, :2]
    d2, degenerate = mahalanobis_sq(err[use], s_xy[use], ref_std)
    finite = d2[np.isfinite(d2)]
    c = {
        'samples': int(use.sum()), 'degenerate': int(degenerate.sum()),
        'without_covariance': int((~has & (t - match['t0'] >= SETTLE_S)).sum()),
        'inside_95_percent': float(100.0 * np.mean(d2 <= CHI2_95_2DOF)) if use.any() else None,
        'nees_mean': float(finite.mean()) if len(finite) else None,
        'nees_median': float(np.median(finite)) if len(finite) else None,
        'chi2_95': CHI2_95_2DOF, 'after_s': SETTLE_S, 'ref_std_m': float(ref_std),
        'after_rigid_fit': bool(aligned),
    }
    return c, {'t': t[use], 'd2': d2, 'degenerate': degenerate, 't0': match['t0']}


def confidently_wrong(log, match, max_gap=0.5):
    """Updates whose state was "localized" while the estimate was more than WRONG_M off: the
    error users fear most. Each log row is compared with the matched reference pose nearest in
    time (within max_gap). Returns (count, times relative to the reference start)."""
    if 'state' not in log or len(match['t']) == 0:
        return None, []
    t, err = match['t'], match['pos_err']
    times = []
    for lt, state in zip(log['t'], log['state']):
        if state != 'localized':
            continue
        k = int(np.clip(np.searchsorted(t, lt), 1, len(t) - 1))
        k = k - 1 if abs(t[k - 1] - lt) <= abs(t[k] - lt) else k
        if abs(t[k] - lt) <= max_gap and err[k] > WRONG_M:
            times.append(float(lt - match['t0']))
    return len(times), times


def inside_ellipse(hyp, x, y, quantile=CHI2_95_2DOF):
    """Whether (x, y) lies inside each hypothesis's position ellipse of that chi-square quantile
    (rows as read_hypotheses gives them); False where the covariance is degenerate."""
    dx, dy = x - hyp[:, 2], y - hyp[:, 3]
    sxx, syy, sxy = hyp[:, 6] ** 2, hyp[:, 7] ** 2, hyp[:, 8]
    det = sxx * syy - sxy * sxy
    ok = det > 1e-18
    safe = np.where(ok, det, 1.0)
    nees = (syy * dx * dx - 2.0 * sxy * dx * dy + sxx * dy * dy) / safe
    return ok & (nees <= quantile)


def hypotheses_metrics(hyp, ref, max_gap=0.5, interpolate=True, near=HYPOTHESIS_NEAR_M):
    """Whether the reference pose is among each update's hypotheses: within `near` m of one's mean
    or inside its 95 % position ellipse (a place the cloud holds is a spread, not a point: an
    aisle-long cluster holds every pose along the aisle). The share within `near` m alone is
    reported too. Updates without a reference pose within max_gap are left out (and counted)."""
    times, first = np.unique(hyp[:, 0], return_index=True)
    counts = np.diff(np.append(first, len(hyp)))
    truth, kind = associate(ref, times, max_gap, interpolate)
    matched = kind > 0
    contains = np.zeros(len(times), dtype=bool)
    close = np.zeros(len(times), dtype=bool)
    for k in np.flatnonzero(matched):
        rows = hyp[first[k]:first[k] + counts[k]]
        close[k] = bool(np.any(np.hypot(rows[:, 2] - truth[k, 0], rows[:, 3] - truth[k, 1]) <= near))
        contains[k] = close[k] or bool(np.any(inside_ellipse(rows, truth[k, 0], truth[k, 1])))
    several = matched & (counts > 1)
    share = lambda hit, mask: float(np.mean(hit[mask])) if mask.any() else None
    return {
        'updates': int(len(times)), 'updates_matched': int(matched.sum()),
        'contain_truth_share': share(contains, matched),
        'near_truth_share': share(close, matched),
        'updates_with_several': int(several.sum()),
        'contain_truth_share_with_several': share(contains, several),
        'most_hypotheses': int(counts.max()),
        'mean_hypotheses': float(counts.mean()),
        'misses_s': [float(t - ref[0, 0]) for t in times[matched & ~contains]],
        'near_m': float(near),
    }


def describe_reference(m):
    """The text summary's lines on the error against the reference."""
    conv = m['convergence_time_s']
    lines = [
        'pf_evaluate: %d/%d reference poses matched (coverage %.1f %%: %d exact, %d interpolated, %d held)'
        % (m['n_matched'], m['n_reference'], 100 * m['coverage'], m['n_exact'], m['n_interpolated'],
           m['n_held']),
        '  position error: RMSE %.3f m  median %.3f  mean %.3f  max %.3f m'
        % (m['ate_rmse_m'], m['median_m'], m['mean_m'], m['max_m']),
        '  aligned ATE:    RMSE %.3f m after the best rigid fit onto the reference (rotation %.2f deg, '
        'translation %.3f, %.3f m)' % ((m['ate_aligned_rmse_m'], m['aligned_rotation_deg']) + tuple(m['aligned_translation_m'])),
        '  yaw error:      RMSE %.2f deg  max %.2f deg' % (m['yaw_rmse_deg'], m['yaw_max_deg']),
        '  converged:      %s; lost (> %.2f m) %.1f %% of matched poses'
        % ('after %.2f s' % conv if conv is not None else 'never', m['lost_threshold_m'],
           100 * m['lost_fraction']),
    ]
    if m.get('off_fraction_after_settle') is not None:
        lines.append('  off (> %.1f m):  %.1f %% of the run after its first %.0f s'
                     % (m['off_threshold_m'], 100 * m['off_fraction_after_settle'], m['settle_s']))
    if 'confidently_wrong_updates' in m:
        lines.append('  confidently wrong: %d updates "localized" while more than %.0f m off'
                     % (m['confidently_wrong_updates'], m['confidently_wrong_threshold_m']))
    return lines


def describe_covariance(c):
    """The text summary's covariance line."""
    if not c['samples']:
        return '  covariance:     no matched pose with a covariance after the first %.0f s' % c['after_s']
    fmt = lambda v: '-' if v is None else '%.2f' % v
    return ('  covariance:     %.1f %% of %d poses after the first %.0f s inside the 95 %% ellipse '
            '(honest: 95); NEES mean %s, median %s (honest: 2, 1.39); %d degenerate; ref std %.3f m'
            % (c['inside_95_percent'], c['samples'], c['after_s'], fmt(c['nees_mean']),
               fmt(c['nees_median']), c['degenerate'], c['ref_std_m'])
            + (', after the rigid fit' if c.get('after_rigid_fit') else ''))


def describe_hypotheses(h):
    """The text summary's hypotheses line."""
    pct = lambda v: '-' if v is None else '%.1f %%' % (100 * v)
    return ('  hypotheses:     the true place within %.1f m of one or inside its 95 %% ellipse in %s '
            'of %d updates (within %.1f m: %s); in %s of the %d with several (up to %d, mean %.2f)'
            % (h['near_m'], pct(h['contain_truth_share']), h['updates_matched'], h['near_m'],
               pct(h.get('near_truth_share')), pct(h['contain_truth_share_with_several']),
               h['updates_with_several'], h['most_hypotheses'], h['mean_hypotheses']))
