"""What the filter says of itself over a run, from pf_bag_runner's update log, with a reference or
without: the share of the beams that fit the map at the estimate, the verdict (localized /
uncertain / lost) over time, the covariance's size, the beams that saw a change of the map; the
log's own figures (update CPU time, particle counts, sensors missing); and the text summary's lines
on them."""
import numpy as np


# The verdict's states, and their colours in the figures.
STATES = ('localized', 'uncertain', 'lost')
STATE_COLOURS = {'localized': 'tab:green', 'uncertain': 'tab:orange', 'lost': 'tab:red'}
# The verdict's default fit thresholds (confidence_localized_hit_fraction, confidence_lost_hit_fraction):
# drawn on the fit plot as guides; the verdict itself is the runner's.
FIT_LOCALIZED = 0.75
FIT_LOST = 0.5


def _stats(v):
    v = np.asarray(v, dtype=float)
    v = v[np.isfinite(v)]
    if not len(v):
        return None
    return {'mean': float(v.mean()), 'median': float(np.median(v)), 'p5': float(np.percentile(v, 5)),
            'p95': float(np.percentile(v, 95)), 'min': float(v.min()), 'max': float(v.max()),
            'last': float(v[-1])}


def verdict_stretches(t, states, t_end=None):
    """The verdict's runs over time: [[state, from, to, updates], ...] with from the first update of
    the run and to the first of the next (the last run's: t_end, or its last update)."""
    out = []
    for tk, st in zip(t, states):
        if out and out[-1][0] == st:
            out[-1][3] += 1
            continue
        if out:
            out[-1][2] = float(tk)
        out.append([str(st), float(tk), float(tk), 1])
    if out:
        out[-1][2] = float(max(t[-1], t_end if t_end is not None else t[-1]))
    return out


def verdict_judgement(v):
    """One line on the verdict's timeline (the summary's "verdict" dict)."""
    n, runs = v['updates'], v['stretches_s']
    if v['localized_throughout']:
        return 'localized throughout (all %d updates)' % n
    if v['first_localized_s'] is None:
        return 'never localized (%d updates)' % n
    if v['localized_from_s'] is None:
        return 'not localized at the end: %s since %.1f s (localized first at %.1f s)' % (
            runs[-1][0], runs[-1][1], v['first_localized_s'])
    before = runs[:-1]
    if not any(r[0] == 'localized' for r in before):
        if n - v['localized_final_updates'] == 1:
            return 'localized at every update but the first (%s), from %.1f s to the end' % (
                before[0][0], v['localized_from_s'])
        return 'localized from %.1f s to the end (the last %d of %d updates)' % (
            v['localized_from_s'], v['localized_final_updates'], n)
    out = [r for r in before if r[0] != 'localized']
    return 'localized at the end (since %.1f s); before, %d stretch%s not localized: %s' % (
        v['localized_from_s'], len(out), 'es' if len(out) > 1 else '',
        ', '.join('%s %.1f s (%d update%s)' % (st, sum(r[2] - r[1] for r in out if r[0] == st),
                                              sum(r[3] for r in out if r[0] == st),
                                              '' if sum(r[3] for r in out if r[0] == st) == 1 else 's')
                  for st in STATES if any(r[0] == st for r in out)))


def covariance_size(log=None, cov=None):
    """The covariance's size over time: (t, position std (m), yaw std (rad)), from the published
    covariance (cov rows) when given: the larger semi-axis of the 1-sigma position ellipse; else
    from the update log's estimate: the larger of std_x and std_y. None when neither has it."""
    if cov is not None and len(cov):
        xx, xy, yy = cov[:, 1], cov[:, 2], cov[:, 3]
        major = 0.5 * (xx + yy) + np.sqrt(np.maximum(0.25 * (xx - yy) ** 2 + xy * xy, 0.0))
        return cov[:, 0], np.sqrt(np.maximum(major, 0.0)), np.sqrt(np.maximum(cov[:, 4], 0.0)), \
            'published covariance (pf_pose)'
    if log is not None and 'std_x' in log and 'std_y' in log:
        yaw = log['std_yaw'] if 'std_yaw' in log else np.full(len(log['t']), np.nan)
        return log['t'], np.maximum(log['std_x'], log['std_y']), yaw, 'the estimate (update log)'
    return None


def self_assessment(log, t0, t_end=None, cov=None):
    """What the filter says of itself over the run, from the runner's update log: the share of the
    beams that fit the map at the estimate (hit_fraction), the verdict (state) over time, the
    covariance's size (covariance_size), the share of the beams that saw a change of the map.
    Times relative to t0. Empty when the log has none of them."""
    t = log['t'] - t0
    out = {'updates': int(len(t))}
    if 'hit_fraction' in log:
        fit = log['hit_fraction']
        out['fit'] = _stats(fit)
        if out['fit'] is not None:
            ok = np.isfinite(fit)
            out['fit'].update(below_localized_share=float(np.mean(fit[ok] < FIT_LOCALIZED)),
                              below_lost_share=float(np.mean(fit[ok] < FIT_LOST)),
                              localized_guide=FIT_LOCALIZED, lost_guide=FIT_LOST)
    if 'state' in log and len(t):
        states = log['state']
        stretches = verdict_stretches(t, states, None if t_end is None else t_end - t0)
        loc = states == 'localized'
        final = stretches[-1]
        v = {'updates': int(len(t)),
             'shares': {s: float(np.mean(states == s)) for s in STATES},
             'first_localized_s': float(t[np.argmax(loc)]) if loc.any() else None,
             'localized_from_s': final[1] if final[0] == 'localized' else None,
             'localized_final_updates': int(len(t) - np.flatnonzero(~loc)[-1] - 1) if (~loc).any()
             else int(len(t)),
             'localized_throughout': bool(loc.all()),
             'left_localized': int(np.sum(loc[:-1] & ~loc[1:])),
             'final_state': final[0], 'stretches_s': stretches}
        v['judgement'] = verdict_judgement(v)
        out['verdict'] = v
    size = covariance_size(log, cov)
    if size is not None:
        _, pos, yaw, source = size
        out['covariance_size'] = {'source': source, 'position_std_m': _stats(pos),
                                  'yaw_std_deg': _stats(np.degrees(yaw))}
    if 'map_changed_share' in log:
        out['map_changed_beams'] = _stats(log['map_changed_share'])
    return out


def describe_self(a):
    """The text summary's lines on what the filter says of itself (self_assessment)."""
    lines = []
    pct = lambda v: '%.1f %%' % (100 * v)
    f = a.get('fit')
    if f:
        lines.append('  beams fit:      mean %s  median %s  p5 %s  min %s of the beams at the estimate; '
                     'below %.0f %% in %s of the updates, below %.0f %% in %s'
                     % (pct(f['mean']), pct(f['median']), pct(f['p5']), pct(f['min']),
                        100 * f['localized_guide'], pct(f['below_localized_share']), 100 * f['lost_guide'],
                        pct(f['below_lost_share'])))
    v = a.get('verdict')
    if v:
        sh = v['shares']
        lines.append('  verdict:        %s; localized in %s of %d updates, uncertain %s, lost %s'
                     % (v['judgement'], pct(sh['localized']), v['updates'], pct(sh['uncertain']),
                        pct(sh['lost'])))
        runs = v['stretches_s']
        one = lambda r: '%s %.1f-%.1f s (%d update%s)' % (tuple(r) + ('' if r[3] == 1 else 's',))
        text = ', '.join(one(r) for r in runs[:8])
        if len(runs) > 8:
            text += ', ... (%d stretches; the last: %s)' % (len(runs), one(runs[-1]))
        lines.append('  timeline:       %s' % text)
    c = a.get('covariance_size')
    if c and c['position_std_m']:
        p, y = c['position_std_m'], c['yaw_std_deg']
        lines.append('  covariance size: 1-sigma position median %.3f m, p95 %.3f, max %.3f, last %.3f m; '
                     'yaw median %.2f deg, max %.2f deg (%s)'
                     % (p['median'], p['p95'], p['max'], p['last'], y['median'] if y else float('nan'),
                        y['max'] if y else float('nan'), c['source']))
    ch = a.get('map_changed_beams')
    if ch and ch['max'] > 0:
        lines.append('  beams on map changes: mean %s, max %s of the beams per update'
                     % (pct(ch['mean']), pct(ch['max'])))
    return lines


def log_metrics(log):
    """Summary figures of the runner's update log."""
    m = {'n_log_rows': int(len(log['t']))}
    if 'cpu_ms' in log:
        c = log['cpu_ms'][np.isfinite(log['cpu_ms'])]
        if len(c):
            m.update(cpu_ms_mean=float(c.mean()), cpu_ms_p95=float(np.percentile(c, 95)),
                     cpu_ms_max=float(c.max()), cpu_s_total=float(c.sum() / 1000.0))
        if 'updated' in log:
            u = log['cpu_ms'][(log['updated'] > 0) & np.isfinite(log['cpu_ms'])]
            m['n_updates'] = int(len(u))
            if len(u):
                m['cpu_ms_mean_updated'] = float(u.mean())
    if 'particles' in log:
        m.update(particles_mean=float(np.nanmean(log['particles'])),
                 particles_max=int(np.nanmax(log['particles'])))
    if 'ess' in log:
        m['ess_mean'] = float(np.nanmean(log['ess']))
    if 'missing' in log:
        m['sensors_missing'] = missing_sensors(log)
    return m


def missing_sensors(log):
    """Each sensor the log names as missing (silent or blocked): its share of the log's rows and the
    stretches it was missing, [from, to] in s since the log's first row."""
    t = log['t'] - log['t'][0] if len(log['t']) else log['t']
    rows = [set(v.split()) for v in log['missing']]
    out = {}
    for name in sorted(set().union(*rows)) if rows else []:
        on = np.array([name in r for r in rows])
        edges = np.flatnonzero(np.diff(np.concatenate(([0], on.astype(int), [0]))))
        out[name] = {'share': float(on.mean()),
                     'stretches_s': [[float(t[a]), float(t[b - 1])] for a, b in zip(edges[::2], edges[1::2])]}
    return out
