"""Benchmark pf_bag_runner on every recording that has a reference trajectory.

usage: benchmark_datasets [PARTICLES ...] [--data DIR] [--out DIR] [--seed S]
                          [--max-beams B] [--params FILE.yaml] [--no-plots] [--no-bundled]
                          [--workers N | --scheduler tcp://HOST:8786]

For every dataset under DIR (default: ../shared/data beside the package's source folder) that has
a reference, and for the package's own simulated bags (bags/, exact ground truth), runs
pf_bag_runner (from scripts/: $PF_WS's or scripts/build.sh's workspace's; with rosrun: the one of
the same devel or install space, and the bundled bags of the package ROS finds: see
pf_localization/locate.py)
from the dataset's known initial pose (global localization for bags/global.bag), with the default
configuration (config/pf.yaml's values; add particle counts, e.g. 5000, for more rows), evaluates
the trajectory with pf_evaluate, and prints one table: ATE RMSE (raw, and after the best rigid fit
onto the reference), median and max error, the share of the run more than 0.5 m off after its first
10 s, the confidently wrong updates (state "localized" while more than 1 m off), the published
covariance's honesty after the first 10 s (share of reference poses inside its 95 % ellipse, with
the reference's own noise added; mean NEES, 2 if honest), yaw RMSE, convergence time, CPU time per
update and wall time per run. With --workers N (a Dask LocalCluster of N worker processes) or --scheduler (a running Dask
cluster: docs/tuning.md) every run is a Dask task, as in pf_tune; the
table is the same, but CPU and wall times then include the contention of parallel runs. Each run's files (trajectory, update log, covariance, runner output, evaluation report) go to
OUT/<dataset>_<particles>/; the table is also written to OUT/results.csv and OUT/results.md. Exit
status 0 if every run succeeded, 1 if not (a missing data folder is not a failure: it is reported,
and the bundled bags still run).
"""
import argparse
import contextlib
import csv
import io
import json
import os
import subprocess
import sys
import time

from pf_localization import evaluate
from pf_localization import locate

# name: folder ('{data}' for ../shared/data/<name>, '{repo}' for the package), bag, map, initial
# pose (x, y, yaw) in the map frame or None for global localization, reference (pf_evaluate option,
# file in the folder), ref_std: the reference's own position std dev per axis (m, pf_evaluate
# --ref-std: added to the published covariance when judging it; the bundled bags' is 0, exact truth)
DATASETS = {
    # AprilTag reference "good to about 0.1 m" (README.txt). The tags' frame is turned ~3 deg from the
    # map's (the aligned ATE's fit finds 3 deg), which no covariance of a pose on the map should
    # cover: the covariance is judged after the rigid fit (cov_aligned), so the reference's noise is
    # measured after that fit too. The folder's scan-to-map match of every scan
    # (ac109_1_scanmatch_tum.txt), fitted onto the reference the same way, is 0.061 m RMS off:
    # sigma = 0.061 / sqrt(2) = 0.043 m per axis, the scan matcher's own error included, so at most
    # that. (Its raw distance, median 0.078 m, mixes in the 3 deg turn.)
    'neato_ac109_1': dict(dir='{data}/neato_ac109_1', bag='ac109_1.bag', map='ac109_1.yaml',
                          pose=(3.972, -0.090, 2.904), ref=('--bag', 'ac109_1.bag'), ref_std=0.043,
                          cov_aligned=True),
    # GMapping's corrected poses, a SLAM result. The map was ray-cast from these very poses, so the
    # SLAM run's global error is shared by map and reference and does not count; what does is its
    # local jitter, ~1-3 cm per step (README.txt, "good to a few cm locally"): 0.03 m. Scan end points
    # lie on the map's walls (mean 0.014 m off, 83 % within 5 cm), which bounds it too.
    'intel_lab': dict(dir='{data}/intel_lab', bag='intel.bag', map='intel_map.yaml',
                      pose=(0.600, -0.032, -0.355), ref=('--ref', 'intel_reference_tum.txt'), ref_std=0.03),
    # Made like intel_lab, but its scans fit the map less well (end points 0.033 m off on average,
    # 72 % within 5 cm): 0.05 m.
    'fr079': dict(dir='{data}/fr079', bag='fr079.bag', map='fr079_map.yaml', pose=(0.001, -0.001, 0.0),
                  ref=('--ref', 'fr079_reference_tum.txt'), ref_std=0.05),
}
BUNDLED = {
    'sim_tracking': dict(dir='{repo}', bag='bags/tracking.bag', map='maps/building.yaml', pose=(1.5, 7.6, 0.0),
                         ref=('--bag', 'bags/tracking.bag')),
    'sim_global': dict(dir='{repo}', bag='bags/global.bag', map='maps/building.yaml', pose=None,
                       ref=('--bag', 'bags/global.bag')),
    'sim_kidnap': dict(dir='{repo}', bag='bags/kidnap.bag', map='maps/building.yaml', pose=(4.0, 7.6, 3.14159265),
                       ref=('--bag', 'bags/kidnap.bag')),
    'sim_reverse': dict(dir='{repo}', bag='bags/reverse.bag', map='maps/building.yaml', pose=(1.5, 7.6, 0.0),
                        ref=('--bag', 'bags/reverse.bag')),
    'sim_crowd': dict(dir='{repo}', bag='bags/crowd.bag', map='maps/building.yaml', pose=(1.5, 7.6, 0.0),
                      ref=('--bag', 'bags/crowd.bag')),
    # One scan every 2 s: compared at the scans only (the runner writes one
    # pose per scan; interpolating 2 s across a turnaround would be the
    # metric's error, not the filter's).
    'sim_sparse': dict(dir='{repo}', bag='bags/sparse.bag', map='maps/building.yaml', pose=(1.5, 7.6, 0.0),
                       ref=('--bag', 'bags/sparse.bag'), eval_args=('--max-gap', '0.1')),
    # A 35.6 m corridor with 16.2 m of plain walls, one scan every 2.5 s: compared at the scans
    # only, as sim_sparse.
    'sim_corridor': dict(dir='{repo}', bag='bags/corridor.bag', map='maps/corridor.yaml', pose=(2.5, 3.95, 0.0),
                         ref=('--bag', 'bags/corridor.bag'), eval_args=('--max-gap', '0.1')),
    # A 118 x 78 m warehouse of ten twin aisles (bags/README.md).
    'sim_warehouse': dict(dir='{repo}', bag='bags/warehouse_tracking.bag', map='maps/warehouse.yaml',
                          pose=(5.0, 6.0, 1.5707963), ref=('--bag', 'bags/warehouse_tracking.bag')),
    'sim_warehouse_global': dict(dir='{repo}', bag='bags/warehouse_global.bag', map='maps/warehouse.yaml',
                                 pose=None, ref=('--bag', 'bags/warehouse_global.bag')),
    'sim_warehouse_kidnap': dict(dir='{repo}', bag='bags/warehouse_kidnap.bag', map='maps/warehouse.yaml',
                                 pose=(5.0, 6.0, 1.5707963), ref=('--bag', 'bags/warehouse_kidnap.bag')),
}
SKIPPED = {
    'comprobo_mac_first_floor_take_2': 'no ground truth (its scan-match TUM is derived from the map itself, '
                                       'so it cannot judge a map-based localizer)',
    'neato_ksoltan_2018': 'no ground truth (a symmetric box: smoke test only)',
}
COLUMNS = [('dataset', 'dataset', '%s'), ('particles', 'particles', '%s'), ('particles_mean', 'mean n', '%.0f'),
           ('ate_rmse_m', 'ATE RMSE m', '%.3f'), ('ate_aligned_rmse_m', 'ATE aligned m', '%.3f'),
           ('median_m', 'median m', '%.3f'), ('max_m', 'max m', '%.2f'),
           ('off_pct', '> 0.5 m off %', '%.1f'), ('confidently_wrong_updates', 'confidently wrong', '%d'),
           ('inside_95_pct', 'in 95 % ellipse %', '%.1f'), ('nees_mean', 'NEES mean', '%.2f'),
           ('yaw_rmse_deg', 'yaw RMSE deg', '%.2f'),
           ('convergence_time_s', 'converged s', '%.1f'), ('cpu_ms_per_update', 'CPU ms/update', '%.2f'),
           ('wall_s', 'wall s', '%.1f'), ('status', 'status', '%s')]


def run_one(runner, folder, name, spec, n, out, args):
    """Runs the runner and pf_evaluate for one dataset and particle count (0: the default
    configuration's); returns a table row."""
    d = folder
    label = 'default' if n == 0 else str(n)
    run_dir = os.path.join(out, '%s_%s' % (name, label))
    os.makedirs(run_dir, exist_ok=True)
    traj, log = os.path.join(run_dir, 'traj.tum'), os.path.join(run_dir, 'updates.csv')
    cov = os.path.join(run_dir, 'cov.csv')
    for f in (traj, log, cov):
        if os.path.exists(f):
            os.remove(f)
    cmd = [runner, '--bag', os.path.join(d, spec['bag']), '--map', os.path.join(d, spec['map']),
           '--seed', str(args.seed), '--out', traj, '--log', log, '--covariance', cov, '--quiet']
    if spec['pose'] is not None:
        cmd += ['--initial-pose'] + ['%.6f' % v for v in spec['pose']]
    if n:
        cmd += ['--particles', str(n)]
    if args.max_beams:
        cmd += ['--max-beams', str(args.max_beams)]
    if args.params:
        cmd += ['--params', os.path.abspath(args.params)]
    row = {'dataset': name, 'particles': label}
    env = dict(os.environ)
    env['LD_LIBRARY_PATH'] = ':'.join(filter(None, [os.path.dirname(os.path.dirname(runner)),  # devel/lib
                                                    env.get('LD_LIBRARY_PATH')]))
    print('== %s, %s particles: %s' % (name, label, ' '.join(cmd)), flush=True)
    t0 = time.monotonic()
    with open(os.path.join(run_dir, 'runner.log'), 'w') as rl:
        rc = subprocess.call(cmd, stdout=rl, stderr=subprocess.STDOUT, env=env)
    row['wall_s'] = time.monotonic() - t0
    if rc != 0 or not os.path.isfile(traj) or os.path.getsize(traj) == 0:
        row['status'] = 'runner failed (exit %d%s)' % (rc, '' if os.path.isfile(traj) else ', no trajectory')
        print('   %s, see %s' % (row['status'], os.path.join(run_dir, 'runner.log')), flush=True)
        return row
    ev = ['--traj', traj, spec['ref'][0], os.path.join(d, spec['ref'][1]), '--map', os.path.join(d, spec['map']),
          '--out', os.path.join(run_dir, 'eval'), '--title', '%s, %s particles' % (name, label)]
    if os.path.isfile(log):
        ev += ['--log', log]
    if os.path.isfile(cov):
        ev += ['--cov', cov, '--ref-std', str(spec.get('ref_std', 0.0))]
        if spec.get('cov_aligned'):
            ev += ['--cov-aligned']
    ev += list(spec.get('eval_args', ()))
    if args.no_plots:
        ev.append('--no-plots')
    status, output = run_evaluation(ev)
    print('   ' + output.strip().replace('\n', '\n   '), flush=True)
    if status != 0:
        row['status'] = 'evaluation failed'
        return row
    with open(os.path.join(run_dir, 'eval', 'summary.json')) as f:
        m = json.load(f)
    row.update({k: m.get(k) for k in ('ate_rmse_m', 'ate_aligned_rmse_m', 'median_m', 'yaw_rmse_deg', 'max_m',
                                      'convergence_time_s', 'particles_mean', 'confidently_wrong_updates')})
    c = m.get('covariance') or {}
    row.update(inside_95_pct=c.get('inside_95_percent'), nees_mean=c.get('nees_mean'))
    if m.get('off_fraction_after_settle') is not None:
        row['off_pct'] = 100.0 * m['off_fraction_after_settle']
    if m.get('cpu_ms_mean') is not None:
        row['cpu_ms_per_update'] = m['cpu_ms_mean']
    row['status'] = 'ok'
    return row


def run_evaluation(argv):
    """pf_evaluate's main(argv) in this process; returns its exit status and what it printed."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        try:
            status = evaluate.main(argv)
        except SystemExit as e:  # argparse's
            status = e.code
        except Exception as e:  # a bug or an unreadable input: this run's failure, not the table's
            print('pf_evaluate: %s: %s' % (type(e).__name__, e))
            status = 1
    return status, out.getvalue()


def cell(row, key, f):
    v = row.get(key)
    if v is None:  # a successful run without convergence time never converged
        return 'never' if key == 'convergence_time_s' and row.get('status') == 'ok' else '-'
    return f % v


def print_table(rows, total, out):
    cells = [[h for _, h, _ in COLUMNS]] + [[cell(r, k, f) for k, _, f in COLUMNS] for r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(COLUMNS))]
    line = lambda c: '  '.join(s.ljust(w) if i in (0, len(c) - 1) else s.rjust(w)
                               for i, (s, w) in enumerate(zip(c, widths))).rstrip()
    print('\n' + line(cells[0]) + '\n' + '  '.join('-' * w for w in widths))
    for c in cells[1:]:
        print(line(c))
    print('total runtime: %.1f s; runs in %s' % (total, out))
    with open(os.path.join(out, 'results.md'), 'w') as f:
        f.write('| ' + ' | '.join(cells[0]) + ' |\n|' + '---|' * len(COLUMNS) + '\n')
        f.writelines('| ' + ' | '.join(c) + ' |\n' for c in cells[1:])
        f.write('\ntotal runtime: %.1f s\n' % total)
    with open(os.path.join(out, 'results.csv'), 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=[k for k, _, _ in COLUMNS])
        w.writeheader()
        w.writerows(rows)


def parse_args(argv, package):
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0], epilog=__doc__[__doc__.index('For every'):],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('particles', nargs='*', type=int, default=[0],
                   help='max_particles of each run (0, the default: the configuration\'s own)')
    data = locate.shared_data(package)
    p.add_argument('--data', default=data,
                   help='dataset folder (default: %s)' % (data or 'none: only the bundled bags'))
    p.add_argument('--out', default='/tmp/pf_benchmark-' + time.strftime('%Y%m%d-%H%M%S'),
                   help='output folder (default /tmp/pf_benchmark-<time>)')
    p.add_argument('--seed', type=int, default=1)
    p.add_argument('--max-beams', type=int, help='passed to the runner')
    p.add_argument('--params', help='parameter YAML passed to the runner')
    p.add_argument('--no-plots', action='store_true', help='summary.json only, no PNGs')
    p.add_argument('--no-bundled', action='store_true', help='only the recordings under --data')
    p.add_argument('--workers', type=int, help='run on a Dask LocalCluster of this many worker processes')
    p.add_argument('--scheduler', help='run on the Dask cluster of this scheduler, e.g. tcp://host:8786')
    return p.parse_args(argv)


def datasets_to_run(data, bundled):
    """[(name, spec)]: the known recordings found under data (None: none), then the bundled bags."""
    todo = []
    if data is None:
        print('benchmark_datasets: no --data folder given: skipping the real recordings')
    elif not os.path.isdir(data):
        print('benchmark_datasets: no dataset folder at %s: skipping the real recordings' % data)
    else:
        for name in sorted(os.listdir(data)):
            if not os.path.isdir(os.path.join(data, name)):
                continue
            if name in DATASETS:
                todo.append((name, DATASETS[name]))
            else:
                print('skipping %s: %s' % (name, SKIPPED.get(name, 'not in the benchmark table (no known '
                                                                     'reference and initial pose)')))
        for name in sorted(set(DATASETS) - set(n for n, _ in todo)):
            print('skipping %s: not found under %s' % (name, data))
    if bundled:
        todo += sorted(BUNDLED.items())
    return todo


def run_all(runs, args):
    """The table's rows: run_one over `runs`, here or as Dask tasks."""
    if not (args.workers or args.scheduler):
        return [run_one(*r) for r in runs]
    from pf_localization.cluster import close_client, open_client
    client = open_client(args.scheduler, args.workers)
    try:
        return client.gather([client.submit(run_one, *r, pure=False) for r in runs])
    finally:
        close_client(client)


def main(argv=None):
    package = locate.package_dir()
    args = parse_args(sys.argv[1:] if argv is None else argv, package)
    try:
        runner = locate.find_runner()
    except locate.NotFound as e:
        print('benchmark_datasets: %s' % e, file=sys.stderr)
        return 1
    if package is None:
        print('benchmark_datasets: cannot find the package\'s bags and maps (ROS does not know '
              'pf_localization: source the workspace\'s setup.bash)', file=sys.stderr)
        return 1
    todo = datasets_to_run(os.path.normpath(args.data) if args.data else None, not args.no_bundled)
    if not todo:
        print('benchmark_datasets: nothing to run')
        return 0
    os.makedirs(args.out, exist_ok=True)
    args.out = os.path.abspath(args.out)
    if args.params:
        if not os.path.isfile(args.params):
            print('benchmark_datasets: parameter file not found: %s' % args.params, file=sys.stderr)
            return 1
        args.params = os.path.abspath(args.params)  # the workers may run elsewhere
    data = os.path.normpath(args.data) if args.data else ''
    runs = [(runner, spec['dir'].format(data=data, repo=package), name, spec, n, args.out, args)
            for name, spec in todo for n in args.particles]
    start = time.monotonic()
    from pf_localization.cluster import ClusterError
    try:
        rows = run_all(runs, args)
    except ClusterError as e:
        print('benchmark_datasets: %s' % e, file=sys.stderr)
        return 1
    print_table(rows, time.monotonic() - start, args.out)
    return 0 if all(r['status'] == 'ok' for r in rows) else 1


if __name__ == '__main__':
    sys.exit(main())
