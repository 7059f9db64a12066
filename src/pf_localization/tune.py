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
import os
import signal
import sys
import time

import yaml

from pf_localization import locate
from pf_localization.cluster import ClusterError, close_client, open_client
# The parts, each in a module of its own: the search space and params files (tune_space), the data
# the self-supervised score reads (tune_bag_data), the scores (tune_objective), the Dask tasks
# (tune_tasks), the study and the choice of the best (tune_study), the outputs (tune_report).
from pf_localization.tune_bag_data import bag_has_topic
from pf_localization.tune_objective import FIT_DISTANCE
from pf_localization.tune_report import write_outputs
from pf_localization.tune_space import DEFAULT_SPACE, TuneError, format_value, load_space
from pf_localization.tune_study import tune

CONFIRM_TOP, CONFIRM_SEEDS, MIN_GAIN = 5, 3, 0.005  # choosing the best: see "Choosing the best"


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
