"""pf_evaluate's figures: the track over the map, the error against the reference and the
covariance's d^2 over time, the beams that fit with the verdict and the covariance's size, the
particle spread, the update CPU time, the map's changes, and the particle cloud as a GIF. Each
function writes one file with matplotlib (whose backend the caller picks) and closes its figure."""
import numpy as np

from pf_localization.evaluate_inputs import EvalError
from pf_localization.evaluate_reference import CHI2_95_2DOF, associate
from pf_localization.map_changes import CHANGE_ADDED, CHANGE_REMOVED, CHANGE_UNSEEN
from pf_localization.self_assessment import (FIT_LOCALIZED, FIT_LOST, STATE_COLOURS, STATES, covariance_size,
                                             verdict_stretches)


TIME_SINCE_REFERENCE = 'time since first reference pose (s)'
TIME_SINCE_ESTIMATE = 'time since the first estimate (s)'


def _relative(t, t0):
    """Times relative to the reference start; a log on another clock is made relative to itself."""
    t = np.asarray(t, dtype=float)
    return t - t0 if len(t) and abs(t[0] - t0) < 3600 else t - (t[0] if len(t) else 0)


def _break_gaps(a, factor=10.0):
    """Copy of a (t, ...) array with NaN rows inserted where the time step exceeds factor x median,
    so that plotted lines do not bridge gaps in the data."""
    if len(a) < 3:
        return a
    dt = np.diff(a[:, 0])
    cut = np.nonzero(dt > factor * max(np.median(dt), 1e-6))[0] + 1
    return np.insert(a, cut, np.nan, axis=0)


def _show_map(ax, the_map, xs, ys, margin_frac=0.1, min_margin=0.5):
    """Draw the map (if any) and crop the view to the points xs, ys plus a margin."""
    if the_map is not None:
        ax.imshow(the_map[0], cmap='gray', vmin=0, vmax=1, extent=the_map[1], origin='upper',
                  interpolation='nearest', zorder=0)
    x0, x1, y0, y1 = np.nanmin(xs), np.nanmax(xs), np.nanmin(ys), np.nanmax(ys)
    mg = max(min_margin, margin_frac * max(x1 - x0, y1 - y0))
    ax.set_xlim(x0 - mg, x1 + mg)
    ax.set_ylim(y0 - mg, y1 + mg)
    ax.set_aspect('equal')
    ax.set_xlabel('x (m, map frame)')
    ax.set_ylabel('y (m, map frame)')


def plot_trajectory(path, est, ref, the_map, title, log=None):
    """The estimate over the map, with the reference when there is one; without one, the estimate at
    each update coloured by the verdict (the log's state)."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 7))
    has_ref = ref is not None and len(ref) > 0
    both = np.r_[est, ref] if has_ref else est
    # Without a reference, a wider view: the walls around the track are what a reader checks it by.
    _show_map(ax, the_map, both[:, 1], both[:, 2], min_margin=0.5 if has_ref else 2.0)
    e = _break_gaps(est)
    if has_ref:
        r = _break_gaps(ref)
        ax.plot(r[:, 1], r[:, 2], '-', color='tab:green', lw=1.6, label='reference')
        ax.plot(e[:, 1], e[:, 2], '-', color='tab:red', lw=1.0, alpha=0.85, label='estimate')
        ax.plot(ref[0, 1], ref[0, 2], 'o', color='tab:green', ms=7, label='reference start')
        ax.plot(est[0, 1], est[0, 2], 'x', color='tab:red', ms=8, mew=2, label='estimate start')
    else:
        ax.plot(e[:, 1], e[:, 2], '-', color='tab:blue', lw=1.0, alpha=0.85, label='estimate')
        ax.plot(est[0, 1], est[0, 2], 'x', color='tab:blue', ms=8, mew=2, label='estimate start')
        if log is not None and 'state' in log:
            poses, kind = associate(est, log['t'])
            for st in STATES:
                on = (log['state'] == st) & (kind > 0)
                if on.any():
                    ax.plot(poses[on, 0], poses[on, 1], 'o', color=STATE_COLOURS[st], ms=3.5,
                            label='update: %s (%d)' % (st, on.sum()))
    ax.set_title(title)
    ax.legend(loc='best', fontsize=8, framealpha=0.85)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_errors(path, m, match, title):
    import matplotlib.pyplot as plt
    # one sample per reference pose, NaN where unmatched, so lines break at coverage gaps
    t = match['ref_t'] - match['t0']
    pos, yaw = np.full(len(t), np.nan), np.full(len(t), np.nan)
    pos[match['matched']], yaw[match['matched']] = match['pos_err'], np.degrees(match['yaw_err'])
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a1.plot(t, pos, '.-', color='tab:blue', ms=3, lw=0.8, label='position error')
    a1.axhline(m['lost_threshold_m'], color='tab:red', ls='--', lw=1,
               label='lost threshold %.2f m' % m['lost_threshold_m'])
    if m['convergence_time_s'] is not None:
        for a in (a1, a2):
            a.axvline(m['convergence_time_s'], color='tab:purple', ls=':', lw=1.2)
        a1.plot([], [], color='tab:purple', ls=':', label='converged %.1f s' % m['convergence_time_s'])
    if len(match['unmatched_t']):
        a1.plot(match['unmatched_t'] - match['t0'], np.zeros(len(match['unmatched_t'])), '|',
                color='grey', ms=8, label='unmatched reference (%d)' % len(match['unmatched_t']))
    a1.set_ylabel('position error (m)')
    a1.set_ylim(bottom=0)
    a1.set_title('%s: ATE RMSE %.3f m, yaw RMSE %.2f deg' % (title, m['ate_rmse_m'], m['yaw_rmse_deg']))
    a1.legend(loc='upper right', fontsize=8)
    a2.plot(t, yaw, '.-', color='tab:orange', ms=3, lw=0.8, label='|yaw error|')
    a2.set_ylabel('yaw error (deg)')
    a2.set_xlabel('time since first reference pose (s)')
    a2.set_ylim(bottom=0)
    a2.legend(loc='upper right', fontsize=8)
    for a in (a1, a2):
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_nees(path, c, samples, title):
    """d^2 of every covariance sample over time on a log axis, with the 95 % bound; degenerate
    covariances (d^2 = inf) as triangles on the axis's top."""
    import matplotlib.pyplot as plt
    t, d2 = samples['t'] - samples['t0'], samples['d2']
    fin = np.isfinite(d2)
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.semilogy(t[fin], np.maximum(d2[fin], 1e-6), '.', color='tab:blue', ms=3, label='d$^2$ = e$^T$ S$^{-1}$ e')
    ax.axhline(CHI2_95_2DOF, color='tab:red', ls='--', lw=1, label='95 %% bound (%.3f)' % CHI2_95_2DOF)
    ax.axhline(2.0, color='tab:green', ls=':', lw=1, label='consistent mean (2)')
    top = max(10 * CHI2_95_2DOF, float(d2[fin].max()) * 2 if fin.any() else 0.0)
    if (~fin).any():
        ax.plot(t[~fin], np.full(int((~fin).sum()), top), 'v', color='tab:purple', ms=6,
                label='degenerate S (%d)' % (~fin).sum())
    inside = c['inside_95_percent']
    ax.set_title('%s: %s inside the 95 %% ellipse, NEES mean %s (after the first %.0f s)'
                 % (title, '-' if inside is None else '%.1f %%' % inside,
                    '-' if c['nees_mean'] is None else '%.2f' % c['nees_mean'], c['after_s']))
    ax.set_xlabel('time since first reference pose (s)')
    ax.set_ylabel('normalised squared error d$^2$')
    ax.grid(alpha=0.3, which='both')
    ax.legend(loc='upper right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_fit(path, log, t0, title, cov=None, xlabel=TIME_SINCE_ESTIMATE):
    """What the filter knows over time: the share of the beams that fit the map at the estimate
    (and of those that saw a change of the map), the verdict, the covariance's size."""
    import matplotlib.pyplot as plt
    t = _relative(log['t'], t0)
    fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True,
                                     gridspec_kw={'height_ratios': [3, 0.7, 2.2]})
    if 'hit_fraction' in log:
        a1.plot(t, log['hit_fraction'], '.-', color='tab:blue', ms=3, lw=0.8,
                label='beams that fit the map at the estimate')
    if 'map_changed_share' in log and np.nanmax(log['map_changed_share'], initial=0.0) > 0:
        a1.plot(t, log['map_changed_share'], '-', color='tab:grey', lw=0.8,
                label='beams that saw a change of the map')
    a1.axhline(FIT_LOCALIZED, color='tab:green', ls='--', lw=1, label='%.0f %% (localized, default)'
               % (100 * FIT_LOCALIZED))
    a1.axhline(FIT_LOST, color='tab:red', ls='--', lw=1, label='%.0f %% (lost, default)' % (100 * FIT_LOST))
    a1.set_ylim(-0.02, 1.05)
    a1.set_ylabel('share of the beams')
    a1.legend(loc='lower left', fontsize=8, framealpha=0.85)
    a1.set_title('%s: what the filter knows (no reference needed)' % title)
    if 'state' in log and len(t):
        for st, t_from, t_to, _ in verdict_stretches(t, log['state']):
            a2.broken_barh([(t_from, max(t_to - t_from, 1e-3))], (0, 1), color=STATE_COLOURS.get(st, 'grey'))
        from matplotlib.patches import Patch
        a2.plot(t, np.full(len(t), 0.5), '|', color='k', ms=6, alpha=0.4)
        share = lambda st: 100 * np.mean(log['state'] == st)
        a2.legend(handles=[Patch(color=STATE_COLOURS[st], label='%s %.0f %%' % (st, share(st))) for st in STATES],
                  loc='center left', bbox_to_anchor=(1.0, 0.5), fontsize=7, frameon=False,
                  title='of the updates', title_fontsize=7)
    a2.set_yticks([])
    a2.set_ylabel('verdict', rotation=0, ha='right', va='center')
    size = covariance_size(log, cov)
    if size is not None:
        ct, pos, yaw, source = size
        ct = ct - (log['t'][0] - t[0]) if len(t) else _relative(ct, t0)  # on the log's time axis
        h = a3.plot(ct, pos, '-', color='tab:purple', lw=1, label='position std (m)')
        a3.set_ylabel('position std (m)')
        v = pos[np.isfinite(pos) & (pos > 0)]
        if len(v) and v.max() / v.min() > 30:
            a3.set_yscale('log')
        b = a3.twinx()
        h += b.plot(ct, np.degrees(yaw), '-', color='tab:orange', lw=1, label='yaw std (deg)')
        b.set_ylabel('yaw std (deg)')
        b.set_ylim(bottom=0)
        a3.legend(handles=h, loc='upper right', fontsize=8, title='1-sigma, %s' % source, title_fontsize=8)
    else:
        a3.text(0.5, 0.5, 'no covariance in the log', transform=a3.transAxes, ha='center')
    a3.set_xlabel(xlabel)
    for a in (a1, a3):
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_spread(path, log, t0, title, xlabel=TIME_SINCE_REFERENCE):
    import matplotlib.pyplot as plt
    t = _relative(log['t'], t0)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for name, c in (('std_x', 'tab:blue'), ('std_y', 'tab:green')):
        if name in log:
            a1.plot(t, log[name], color=c, lw=1, label='%s (m)' % name)
    if 'std_yaw' in log:
        a2.plot(t, np.degrees(log['std_yaw']), color='tab:orange', lw=1, label='std_yaw (deg)')
    for a, unit in ((a1, 'm'), (a2, 'deg')):
        v = np.concatenate([l.get_ydata() for l in a.get_lines()]) if a.get_lines() else np.array([])
        v = v[np.isfinite(v) & (v > 0)]
        if len(v) and v.max() / v.min() > 100:
            a.set_yscale('log')
        a.set_ylabel('particle std dev (%s)' % unit)
        a.grid(alpha=0.3)
        if a.get_lines():
            a.legend(loc='upper right', fontsize=8)
        else:
            a.text(0.5, 0.5, 'not in log', transform=a.transAxes, ha='center')
    a1.set_title('%s: particle spread' % title)
    a2.set_xlabel(xlabel)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cpu_axis_top(c, percentile=99.0, headroom=1.5):
    """The top of the CPU time axis: all of c when its largest value is within `headroom` x the
    `percentile`th, else that (a few slow updates, e.g. the first, would squash the rest onto the
    axis). None when c has no finite value."""
    c = np.asarray(c, dtype=float)
    c = c[np.isfinite(c)]
    if len(c) == 0:
        return None
    clip = headroom * float(np.percentile(c, percentile))
    return clip if c.max() > clip > 0 else None


def _plot_cpu_times(ax, t, c):
    """The CPU times as dots, with their mean; the few above the axis's top drawn on it as
    triangles and counted in the legend. Returns the legend's handles."""
    handles = ax.plot(t, c, '.', color='tab:blue', ms=3, label='update CPU time')
    if not np.isfinite(c).any():
        return handles
    handles.append(ax.axhline(np.nanmean(c), color='tab:blue', ls='--', lw=1,
                              label='mean %.2f ms' % np.nanmean(c)))
    top = cpu_axis_top(c)
    if top is None:
        ax.set_ylim(bottom=0)
        return handles
    ax.set_ylim(0, top)
    over = np.isfinite(c) & (c > top)
    handles += ax.plot(t[over], np.full(int(over.sum()), top), '^', color='tab:purple', ms=6, clip_on=False,
                       label='%d above %.2f ms (max %.1f ms)' % (over.sum(), top, np.nanmax(c)))
    return handles


def plot_cpu(path, log, t0, title, xlabel=TIME_SINCE_REFERENCE):
    import matplotlib.pyplot as plt
    t = _relative(log['t'], t0)
    fig, ax = plt.subplots(figsize=(9, 4.5))
    handles = []
    if 'cpu_ms' in log:
        handles += _plot_cpu_times(ax, t, log['cpu_ms'])
    ax.set_ylabel('CPU time per update (ms)')
    ax.set_xlabel(xlabel)
    ax.grid(alpha=0.3)
    if 'particles' in log:
        a2 = ax.twinx()
        handles += a2.plot(t, log['particles'], '-', color='tab:red', lw=1, label='particle count')
        a2.set_ylabel('particles')
        a2.set_ylim(bottom=0, top=1.1 * np.nanmax(log['particles']) + 1)
    ax.set_title('%s: update CPU time and particle count' % title)
    if handles:
        ax.legend(handles=handles, loc='upper right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_changes(path, the_map, changes, mask, title):
    """The map with the changes layer over it: added cells red, removed blue; the true mask's
    changed cells, when given, as a faint outline (orange, cyan) under them."""
    import matplotlib.pyplot as plt
    grey, extent = the_map
    if changes.shape != grey.shape:
        raise EvalError('the changes layer is %dx%d cells, the map %dx%d: not the same map'
                        % (changes.shape[1], changes.shape[0], grey.shape[1], grey.shape[0]))
    rgb = np.repeat(grey[:, :, None], 3, axis=2)
    rgb[changes == CHANGE_UNSEEN] *= 0.85
    if mask is not None:
        rgb[mask == CHANGE_ADDED] = (1.0, 0.75, 0.4)
        rgb[mask == CHANGE_REMOVED] = (0.6, 0.9, 1.0)
    rgb[changes == CHANGE_ADDED] = (0.85, 0.1, 0.1)
    rgb[changes == CHANGE_REMOVED] = (0.1, 0.3, 0.9)
    fig, ax = plt.subplots(figsize=(8, 8 * grey.shape[0] / max(grey.shape[1], 1) + 0.6))
    ax.imshow(rgb, extent=extent, origin='upper', interpolation='nearest')
    ax.set_xlabel('x (m)')
    ax.set_ylabel('y (m)')
    ax.set_title(title + ': where the world no longer matches the map (red added, blue removed%s)'
                 % ('; the truth light' if mask is not None else ''), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def make_particle_gif(path, parts, est, ref, the_map, seconds, title, max_frames=60,
                      max_particles=2000):
    """Animated GIF of the particle cloud for the first `seconds` of the dump."""
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation, PillowWriter
    times, starts = np.unique(parts[:, 0], return_index=True)
    ends = np.r_[starts[1:], len(parts)]
    sel = np.nonzero(times <= times[0] + seconds)[0]
    sel = sel[np.unique(np.linspace(0, len(sel) - 1, min(max_frames, len(sel))).round().astype(int))]
    rng = np.random.default_rng(0)
    frames = []
    for k in sel:
        idx = np.arange(starts[k], ends[k])
        if len(idx) > max_particles:
            idx = rng.choice(idx, max_particles, replace=False)
        frames.append((times[k], ends[k] - starts[k], parts[idx, 1:3]))
    t_end = times[sel[-1]]
    win = lambda a: a[(a[:, 0] >= times[0] - 1) & (a[:, 0] <= t_end + 1)]
    e, r = win(est), win(ref)
    xs = np.concatenate([f[2][:, 0] for f in frames] + [e[:, 1], r[:, 1]])
    ys = np.concatenate([f[2][:, 1] for f in frames] + [e[:, 2], r[:, 2]])
    fig, ax = plt.subplots(figsize=(4.2, 4.6))
    _show_map(ax, the_map, xs, ys, margin_frac=0.05, min_margin=0.3)
    ax.tick_params(labelsize=7)
    ax.xaxis.label.set_size(8)
    ax.yaxis.label.set_size(8)
    cloud = ax.scatter([], [], s=2.5, c='tab:blue', alpha=0.6, lw=0, label='particles')
    ref_dot, = ax.plot([], [], 'o', color='tab:green', ms=5, label='reference')
    est_dot, = ax.plot([], [], 'x', color='tab:red', ms=6, mew=2, label='estimate')
    handles = [cloud, ref_dot, est_dot] if len(ref) else [cloud, est_dot]
    # Below the axes: inside, wherever it went, the cloud passes under it sooner or later.
    fig.legend(handles=handles, loc='lower center', ncol=len(handles), fontsize=6, markerscale=1.5,
               frameon=False)
    head = ax.set_title('', fontsize=8)

    def near(a, t):
        if len(a) == 0:
            return [], []
        i = int(np.argmin(np.abs(a[:, 0] - t)))
        return ([a[i, 1]], [a[i, 2]]) if abs(a[i, 0] - t) < 1.0 else ([], [])

    def draw(f):
        t, n, xy = f
        cloud.set_offsets(xy)
        ref_dot.set_data(*near(ref, t))
        est_dot.set_data(*near(est, t))
        head.set_text('%s  t=%.1f s  (%d of %d particles)' % (title, t - times[0], len(xy), n))
        return cloud, ref_dot, est_dot, head

    fig.tight_layout(rect=(0, 0.05, 1, 1))
    fps = max(1.0, min(8.0, len(frames) / max(seconds, 1e-3) * 2))
    FuncAnimation(fig, draw, frames=frames, blit=False).save(path, writer=PillowWriter(fps=fps), dpi=96)
    plt.close(fig)
    return len(frames)
