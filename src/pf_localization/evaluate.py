"""Evaluate a pf_localization run against a reference trajectory.

usage: pf_evaluate --traj TRAJ.tum (--bag BAG | --ref REF.tum) [--map MAP.yaml]
                   [--log UPDATES.csv] [--particles PARTICLES.csv|.bin] [--out DIR]
                   [--cov COV.csv] [--ref-std 0] [--lost 0.3] [--max-gap 0.5] [--hold]
                   [--gif-seconds 30] [--hypotheses HYP.csv] [--scan-topic /scan]...

A bag without the reference topic (most bags of a real robot) gets a report all the same, and exit
status 0: in place of the error against a reference, what the filter itself knows (below).

Inputs
  TRAJ.tum   the filter's estimates, one line per scan: t x y z qx qy qz qw (map frame).
  reference  the bag's /ground_truth (geometry_msgs/PoseStamped, header stamps) or a TUM file.
  COV.csv    pf_bag_runner --covariance: t,xx,xy,yy,yawyaw,xyaw,yyaw, the published covariance
             (pf_pose) in force from each stamp on.
  HYP.csv    pf_bag_runner --hypotheses: t,rank,x,y,yaw,weight,std_x,std_y,cov_xy, what pf_hypotheses
             publishes at each filter update (one line per hypothesis, rank 1 the heaviest).

Time association: every reference pose gets the estimate at its stamp, linearly interpolated in
x, y and along the shorter arc in yaw between the two bracketing estimates when both lie within
--max-gap seconds of it; otherwise the newest estimate at or before it within --max-gap (zero-order
hold, which is all --hold uses); an estimate within 0.1 ms counts as exact. References with neither
are unmatched and lower the coverage.

Metrics (DIR/summary.json)
  position error e = |(x, y)_est - (x, y)_ref|: RMSE (the ATE, no alignment: both are map frame),
  median, mean, max; yaw error = |wrap(yaw_est - yaw_ref)|: RMSE and max in degrees;
  convergence time = first matched reference time (relative to the first reference pose) from which
  on every error is <= --lost (null if the last one is not); lost fraction = share of matched
  references with e > --lost; coverage = matched / all references.
  Aligned ATE: the RMSE after the best rigid 2D fit (rotation + translation, no scale; Umeyama
  1991) of the matched estimate positions onto the reference's, with the fit's rotation and
  translation: what is left once a reference turned or shifted against the map is taken out.
  With --cov, the covariance's honesty over the matched references after the first 10 s (as
  off_fraction_after_settle): d^2 = e^T S^-1 e, e = (x, y) error, S = the published xy covariance
  in force at the reference's time (newest row at or before it, within --max-gap) + --ref-std^2 I
  (the reference's own noise); inside_95_percent = share with d^2 <= 5.991 (chi-square, 2 dof:
  95 if honest), NEES mean (2 if honest) and median (2 ln 2 = 1.39 if honest) of the finite d^2.
  A singular S (a degenerate covariance) counts as not covering (d^2 = inf) and is counted.
  With --log, the mean/p95 update CPU time and particle counts from the runner's update log.
  With --hypotheses, whether the true place is among the published hypotheses: the share of the
  updates (with a reference pose within --max-gap, interpolated as above) where one lies within
  1 m of it, over all of them and over those with several hypotheses (while ambiguous), and how
  many hypotheses there were.

What the filter itself knows (DIR/summary.json's self_assessment, with a reference or without),
  from --log: the share of the beams that fit the map at the estimate (the log's hit_fraction:
  mean, median, p5, min, the shares below 75 and 50 %, the verdict's default thresholds); the
  verdict (the log's state: localized / uncertain / lost) over time: its shares of the updates,
  its stretches [state, from, to, updates], when it was localized from to the end, and one line
  that says so; the covariance's size: the larger semi-axis of the 1-sigma position ellipse and
  the yaw std of the published covariance (--cov), else the log's std_x, std_y, std_yaw; the share
  of the beams that saw a change of the map (map_changed_share).

Plots (PNG): trajectory.png (map, estimate, reference; without one, the estimate at each update
coloured by its verdict), error.png (position and yaw error over time, with a reference); with
--log fit.png (the beams that fit, the verdict, the covariance's size over time), spread.png
(particle std dev) and cpu.png (update CPU time, particle count); with --bag and --map scans.png
(the scans of --scan-topic placed at the estimate on the map at five moments and the one with the
fewest beams fitting; the laser's mounting from the bag's /tf_static or /tf, up from the scan's
frame to --base-frame or to the frame odometry moves, the child of --odom-frame);
with --cov nees.png (d^2 over time against the 95 % bound);
with --particles particles.gif (the cloud over the map for the first --gif-seconds).
Exit status: 0 on success, 2 on bad input (missing file, nothing matched).
"""
import argparse
import json
import os
import sys

import numpy as np

# The report's parts, one module each. Their names stay importable from here
# (pf_localization.evaluate.NAME), where benchmark, tune, the rostest checkers and the tests find them.
from pf_localization.evaluate_inputs import (  # noqa: F401
    COV_COLUMNS, EvalError, HYP_COLUMNS, NoReference, _map_yaml, _need_file, quat_yaw, read_bag_reference,
    read_columns, read_covariance, read_hypotheses, read_map, read_particles, read_pnm, read_tum,
    read_update_log)
from pf_localization.evaluate_reference import (  # noqa: F401
    CHI2_95_2DOF, EXACT_S, HYPOTHESIS_NEAR_M, OFF_M, SETTLE_S, WRONG_M, aligned_ate, associate,
    confidently_wrong, convergence_time, covariance_at, covariance_metrics, describe_covariance,
    describe_hypotheses, describe_reference, evaluate, hypotheses_metrics, inside_ellipse, mahalanobis_sq,
    rigid_fit, rigid_move, wrap)
from pf_localization.map_changes import (  # noqa: F401
    CHANGE_ADDED, CHANGE_AS_MAPPED, CHANGE_REMOVED, CHANGE_UNSEEN, _near, change_metrics, describe_changes,
    read_change_image)
from pf_localization.report_plots import (  # noqa: F401
    TIME_SINCE_ESTIMATE, TIME_SINCE_REFERENCE, _break_gaps, _plot_cpu_times, _relative, _show_map,
    cpu_axis_top, make_particle_gif, plot_changes, plot_cpu, plot_errors, plot_fit, plot_nees, plot_spread,
    plot_trajectory)
from pf_localization.scans_at_estimate import (  # noqa: F401
    MOUNT_SEARCH_S, SCAN_WINDOW_S, _matrix, _mount, _mount_resolved, _nearest_scans, _read_parents,
    bag_scan_topics, plot_scans, read_bag_scans, scan_moments)
from pf_localization.self_assessment import (  # noqa: F401
    FIT_LOCALIZED, FIT_LOST, STATES, STATE_COLOURS, _stats, covariance_size, describe_self, log_metrics,
    missing_sensors, self_assessment, verdict_judgement, verdict_stretches)


# --------------------------------------------------------------------------------------- main
def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0], epilog=__doc__[__doc__.index('Inputs'):],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--traj', required=True, help='estimated trajectory (TUM)')
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument('--bag', help='bag with the reference on --ref-topic')
    g.add_argument('--ref', help='reference trajectory (TUM)')
    p.add_argument('--ref-topic', default='/ground_truth', help='PoseStamped topic in --bag')
    p.add_argument('--map', help='map_server YAML drawn under the trajectories')
    p.add_argument('--log', help="runner's per-update CSV log")
    p.add_argument('--particles', help='particle dump (CSV t,x,y,yaw or .bin float64 records)')
    p.add_argument('--out', help='report directory (default: TRAJ without extension + _eval)')
    p.add_argument('--cov', help="runner's covariance CSV (pf_bag_runner --covariance)")
    p.add_argument('--hypotheses', help="runner's hypotheses CSV (pf_bag_runner --hypotheses)")
    p.add_argument('--changes', help="runner's map changes layer (pf_bag_runner --changes), drawn and "
                   'counted')
    p.add_argument('--change-mask', help='the true change mask (pf_simulator --change-mask) the changes '
                   'layer is scored against')
    p.add_argument('--ref-std', type=float, default=0.0,
                   help="the reference's own position std dev (m), added as ref_std^2 I to the covariance")
    p.add_argument('--cov-aligned', action='store_true',
                   help='judge the covariance on the errors after the rigid fit (a reference turned from the map)')
    p.add_argument('--lost', type=float, default=0.3, help='lost / convergence threshold (m)')
    p.add_argument('--max-gap', type=float, default=0.5, help='max time between reference and estimate (s)')
    p.add_argument('--hold', action='store_true', help='no interpolation: newest estimate at or before')
    p.add_argument('--gif-seconds', type=float, default=30.0, help='length of the particle GIF (s)')
    p.add_argument('--title', help='name used in plot titles (default: the recording\'s name: the --bag '
                                   'or --ref file\'s, without its extension)')
    p.add_argument('--scan-topic', action='append', help="LaserScan topic of --bag whose scans are drawn at the "
                   'estimate (scans.png; once per lidar; default: /scan, else the bag\'s first LaserScan topic)')
    p.add_argument('--base-frame', help="the robot's frame the laser's mounting is read up to (default: the frame "
                   'odometry moves, the child of --odom-frame)')
    p.add_argument('--odom-frame', default='odom', help='the odometry frame (default: odom)')
    p.add_argument('--no-plots', action='store_true', help='only write summary.json')
    return p.parse_args(argv)


def reference_or_none(args):
    """The reference trajectory, or None (with the reason) when --bag has none on --ref-topic."""
    if args.ref:
        return read_tum(args.ref, 'reference'), None
    try:
        return read_bag_reference(args.bag, args.ref_topic), None
    except NoReference:
        import rosbag
        with rosbag.Bag(args.bag) as bag:
            topics = sorted(bag.get_type_and_topic_info().topics)
        return None, 'the bag has no %s; its topics: %s' % (args.ref_topic, ', '.join(topics))


def draw_scans(args, out, est, log, the_map, t0, title, m):
    """scans.png: the scans of --bag at the estimate at a few moments (scan_moments). Returns whether
    it was drawn; what kept it from being drawn, or a mounting not found, goes to m['scans']."""
    try:
        topics = args.scan_topic or [t for t in bag_scan_topics(args.bag) if t == '/scan'] or \
            bag_scan_topics(args.bag)[:1]
    except ImportError:
        m['scans'] = {'drawn': False, 'why': 'cannot import rosbag (run with /usr/bin/python3)'}
        return False
    if not topics:
        m['scans'] = {'drawn': False, 'why': 'no sensor_msgs/LaserScan topic in the bag'}
        return False
    moments = scan_moments(est, log)
    scans, warnings = read_bag_scans(args.bag, topics, [mo['t'] for mo in moments], args.base_frame,
                                     args.odom_frame)
    m['scans'] = {'drawn': bool(scans), 'topics': topics, 'moments_s': [mo['t'] - t0 for mo in moments],
                  'robot_frame': sorted({s['base'] for s in scans if s['base']}), 'warnings': warnings}
    if not scans:
        m['scans']['why'] = 'no scan on %s' % ', '.join(topics)
        return False
    plot_scans(os.path.join(out, 'scans.png'), the_map, est, scans, moments, t0, title)
    return True


def run(args):
    est = read_tum(args.traj)
    ref, no_ref = reference_or_none(args)
    the_map = read_map(args.map) if args.map else None
    log = read_update_log(args.log) if args.log else None
    parts = read_particles(args.particles) if args.particles else None
    cov = read_covariance(args.cov) if args.cov else None
    hyp = read_hypotheses(args.hypotheses) if args.hypotheses else None
    if args.change_mask and not args.changes:
        raise EvalError('--change-mask needs --changes (the layer to score)')
    changes = read_change_image(args.changes) if args.changes else None
    mask = read_change_image(args.change_mask) if args.change_mask else None
    if not (np.isfinite(args.ref_std) and args.ref_std >= 0):
        raise EvalError('--ref-std must be a finite number >= 0, got %g' % args.ref_std)
    out = args.out or os.path.splitext(args.traj)[0] + '_eval'
    os.makedirs(out, exist_ok=True)
    title = args.title or os.path.splitext(os.path.basename(args.bag or args.ref))[0]

    if ref is not None:
        m, match = evaluate(est, ref, args.max_gap, args.lost, not args.hold)
        t0, xlabel = match['t0'], TIME_SINCE_REFERENCE
    else:
        # No reference: what the filter itself knows, on the estimates' time.
        m, match = {'n_estimates': int(len(est)), 'duration_s': float(est[-1, 0] - est[0, 0])}, None
        t0, xlabel = float(est[0, 0]), TIME_SINCE_ESTIMATE
        m['reference'] = {'none': no_ref}
    m['has_reference'] = ref is not None
    if log is not None:
        m.update(log_metrics(log))
        m['self_assessment'] = self_assessment(log, t0, est[-1, 0], cov)
        if match is not None:
            count, times = confidently_wrong(log, match, args.max_gap)
            if count is not None:
                m.update(confidently_wrong_updates=count, confidently_wrong_times_s=times,
                         confidently_wrong_threshold_m=WRONG_M)
    cov_samples = None
    if cov is not None and match is not None:
        m['covariance'], cov_samples = covariance_metrics(cov, match, args.max_gap, args.ref_std,
                                                          args.cov_aligned)
    elif cov is not None:
        m.setdefault('self_assessment', {'updates': 0})
        _, pos, yaw, source = covariance_size(cov=cov)
        m['self_assessment']['covariance_size'] = {'source': source, 'position_std_m': _stats(pos),
                                                   'yaw_std_deg': _stats(np.degrees(yaw))}
    if hyp is not None and ref is not None:
        m['hypotheses'] = hypotheses_metrics(hyp, ref, args.max_gap, not args.hold)
    if changes is not None:
        m['map_changes'] = change_metrics(changes, mask)
    m['inputs'] = {k: os.path.abspath(v) for k, v in (('traj', args.traj), ('bag', args.bag), ('ref', args.ref),
                   ('map', args.map), ('log', args.log), ('particles', args.particles), ('cov', args.cov),
                   ('hypotheses', args.hypotheses), ('changes', args.changes),
                   ('change_mask', args.change_mask)) if v}
    plots = []
    if not args.no_plots:
        import matplotlib
        matplotlib.use('Agg')
        plot_trajectory(os.path.join(out, 'trajectory.png'), est, ref, the_map,
                        title + (': trajectory' if ref is not None else ': track (no reference)'), log)
        plots.append('trajectory.png')
        if match is not None:
            plot_errors(os.path.join(out, 'error.png'), m, match, title)
            plots.append('error.png')
        if log is not None:
            plot_fit(os.path.join(out, 'fit.png'), log, t0, title, cov, xlabel)
            plot_spread(os.path.join(out, 'spread.png'), log, t0, title, xlabel)
            plot_cpu(os.path.join(out, 'cpu.png'), log, t0, title, xlabel)
            plots += ['fit.png', 'spread.png', 'cpu.png']
        if args.bag and the_map is not None and draw_scans(args, out, est, log, the_map, t0, title, m):
            plots.append('scans.png')
        if cov_samples is not None:
            plot_nees(os.path.join(out, 'nees.png'), m['covariance'], cov_samples, title)
            plots.append('nees.png')
        if changes is not None and the_map is not None:
            plot_changes(os.path.join(out, 'changes.png'), the_map, changes, mask, title)
            plots.append('changes.png')
        if parts is not None:
            m['gif_frames'] = make_particle_gif(os.path.join(out, 'particles.gif'), parts, est,
                                                ref if ref is not None else np.zeros((0, 4)), the_map,
                                                args.gif_seconds, title)
            plots.append('particles.gif')
    m['plots'] = plots
    summary = os.path.join(out, 'summary.json')
    with open(summary, 'w') as f:
        json.dump(m, f, indent=2)
        f.write('\n')
    return m, summary


def describe(m, summary):
    if m.get('has_reference', True):
        lines = describe_reference(m)
    else:
        lines = ['pf_evaluate: no reference (%s): the report says what the filter itself knows'
                 % m['reference']['none'],
                 '  track:          %d poses over %.1f s' % (m['n_estimates'], m['duration_s'])]
    lines += describe_self(m.get('self_assessment') or {})
    if 'covariance' in m:
        lines.append(describe_covariance(m['covariance']))
    if 'hypotheses' in m:
        lines.append(describe_hypotheses(m['hypotheses']))
    if 'map_changes' in m:
        lines.append(describe_changes(m['map_changes']))
    for name, v in m.get('sensors_missing', {}).items():
        lines.append('  sensor missing: %s in %.0f %% of the updates (%s s)' % (
            name, 100 * v['share'], ', '.join('%.1f-%.1f' % tuple(x) for x in v['stretches_s'])))
    if 'cpu_ms_mean' in m:
        lines.append('  update CPU:     mean %.2f ms  p95 %.2f ms  (%d log rows)'
                     % (m['cpu_ms_mean'], m['cpu_ms_p95'], m['n_log_rows']))
    for w in m.get('scans', {}).get('warnings', []):
        lines.append('  scans:          %s' % w)
    if m.get('scans') and not m['scans']['drawn']:
        lines.append('  scans:          not drawn: %s' % m['scans'].get('why', '?'))
    lines.append('  report: %s' % summary + (' (+ %s)' % ', '.join(m['plots']) if m['plots'] else ''))
    return '\n'.join(lines)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        m, summary = run(args)
    except (EvalError, OSError) as e:
        print('pf_evaluate: error: %s' % e, file=sys.stderr)
        return 2
    print(describe(m, summary))
    return 0


if __name__ == '__main__':
    sys.exit(main())
