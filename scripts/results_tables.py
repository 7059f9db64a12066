#!/usr/bin/python3
"""results_tables: writes the results tables of README.md and docs/results.md from one benchmark run.

usage: /usr/bin/python3 scripts/results_tables.py [--from DIR] [--check] [--keep DIR]

Without --from, runs `scripts/benchmark_datasets 0 5000 --no-plots` (the default configuration and
a 5000-particle budget, seed 1: every recording with a reference under ../shared/data, and the
bundled bags) into a temporary folder; with --from DIR, reads DIR/results.csv of such a run. Then
writes each table between its markers:

    <!-- results:NAME:begin --> ... <!-- results:NAME:end -->

README.md holds `headline`, docs/results.md holds `full`. pf_bag_runner is deterministic for a seed,
so every accuracy figure is the same on every run; the CPU column depends on the machine and its
load, and the line under each table names the machine it was measured on.

--check writes nothing: it exits 1, naming the file and the first row that differs, when a table's
accuracy figures differ from the run's (CPU times and the machine line are not compared). Rows of
recordings the run did not have (../shared/data absent) are not compared. --keep DIR keeps the
benchmark run in DIR.
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.realpath(__file__)))

# dataset name in benchmark.py: how the tables call it.
NAMES = {
    'fr079': 'fr079 (public CARMEN log, 47 x 18 m office floor, 18 min)',
    'intel_lab': 'Intel lab (public CARMEN log, sparse scans, poor odometry)',
    'neato_ac109_1': 'AC109 (a real Neato, ceiling-AprilTag reference)',
    'sim_tracking': '`bags/tracking.bag`',
    'sim_reverse': '`bags/reverse.bag` (odometry logs reversing as forwards)',
    'sim_crowd': '`bags/crowd.bag` (fourteen people not on the map)',
    'sim_sparse': '`bags/sparse.bag` (a scan every 2 s)',
    'sim_corridor': '`bags/corridor.bag` (16 m of plain corridor, a scan every 2.5 s)',
    'sim_global': '`bags/global.bag` (global localization, twin rooms)',
    'sim_kidnap': '`bags/kidnap.bag` (carried 11.8 m)',
    'sim_warehouse': '`bags/warehouse_tracking.bag` (118 x 78 m, twin aisles)',
    'sim_warehouse_global': '`bags/warehouse_global.bag` (global localization among twin aisles)',
    'sim_warehouse_kidnap': '`bags/warehouse_kidnap.bag` (carried into the twin aisle)',
}
HEADLINE = ['fr079', 'intel_lab', 'neato_ac109_1', 'sim_tracking', 'sim_crowd', 'sim_corridor',
            'sim_warehouse']
FULL = ['fr079', 'intel_lab', 'neato_ac109_1', 'sim_tracking', 'sim_reverse', 'sim_crowd', 'sim_sparse',
        'sim_corridor', 'sim_global', 'sim_kidnap', 'sim_warehouse', 'sim_warehouse_global',
        'sim_warehouse_kidnap']
# (csv column, header, format); the last column of every table is the CPU, which is not checked.
HEADLINE_COLUMNS = [('ate_rmse_m', 'ATE RMSE', '%.3f m'), ('max_m', 'max', '%.2f m'),
                    ('confidently_wrong_updates', 'confidently wrong', '%d')]
FULL_COLUMNS = [('ate_rmse_m', 'ATE RMSE', '%.3f'), ('ate_aligned_rmse_m', 'aligned', '%.3f'),
                ('median_m', 'median', '%.3f'), ('max_m', 'max', '%.2f'), ('off_pct', '> 0.5 m off %', '%.1f'),
                ('confidently_wrong_updates', 'confidently wrong', '%d'),
                ('inside_95_pct', 'in 95 % ellipse %', '%.1f'), ('nees_mean', 'NEES mean', '%.2f'),
                ('yaw_rmse_deg', 'yaw RMSE deg', '%.2f'), ('convergence_time_s', 'converged s', '%.1f')]
CPU = ('cpu_ms_per_update', 'CPU ms per update', '%.2f')
FILES = {'headline': 'README.md', 'full': 'docs/results.md'}


def machine():
    model = 'unknown processor'
    try:
        for line in open('/proc/cpuinfo'):
            if line.startswith('model name'):
                model = line.split(':', 1)[1].strip()
                break
    except OSError:
        pass
    return '%s, %d cores' % (model, os.cpu_count() or 1)


def fmt(row, key, f):
    v = row.get(key, '')
    if v in ('', None):
        return 'never' if key == 'convergence_time_s' else '-'
    return f % (int(float(v)) if f.endswith('d') else float(v))


def table(rows, names, columns, budgets, label):
    head = ['recording'] + (['particles'] if len(budgets) > 1 else []) + [h for _, h, _ in columns] + [CPU[1]]
    lines = ['| ' + ' | '.join(head) + ' |', '|' + '---|' * len(head)]
    for name in names:
        for budget in budgets:
            row = rows.get((name, budget))
            if row is None:
                continue
            cells = [label(name)] + ([budget] if len(budgets) > 1 else [])
            cells += [fmt(row, k, f) for k, _, f in columns] + [fmt(row, *CPU[::2])]
            lines.append('| ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines) + '\n'


def blocks(rows):
    cpu_line = ('\nCPU per update: pf_bag_runner\'s mean, measured on %s (not checked: it depends on the '
                'machine and its load).\n' % machine())
    headline = table(rows, HEADLINE, HEADLINE_COLUMNS, ['default'], lambda n: NAMES[n])
    full = table(rows, FULL, FULL_COLUMNS, ['default', '5000'], lambda n: NAMES[n])
    return {'headline': headline + cpu_line, 'full': full + cpu_line}


def markers(name):
    return '<!-- results:%s:begin -->\n' % name, '<!-- results:%s:end -->' % name


def split(text, name, path):
    begin, end = markers(name)
    if begin not in text or end not in text:
        sys.exit('results_tables: %s has no %s ... %s markers' % (path, begin.strip(), end))
    head, rest = text.split(begin, 1)
    body, tail = rest.split(end, 1)
    return head + begin, body, end + tail


def checked_view(block):
    """The rows of a table without their CPU cell, keyed by their label cells; other lines dropped."""
    out = {}
    for line in block.splitlines():
        if not line.startswith('| ') or line.startswith('| recording'):
            continue
        cells = [c.strip() for c in line.strip('|').split('|')]
        key = tuple(cells[:2]) if re.fullmatch(r'default|\d+', cells[1]) else (cells[0],)
        out[key] = cells[:-1]
    return out


def run_benchmark(out):
    cmd = ['/usr/bin/python3', os.path.join(REPO, 'scripts', 'benchmark_datasets'), '0', '5000', '--no-plots',
           '--out', out]
    print('results_tables: %s' % ' '.join(cmd), flush=True)
    with open(os.path.join(out, 'benchmark.log'), 'w') as log:
        if subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT) != 0:
            sys.exit('results_tables: benchmark_datasets failed (log: %s)' % log.name)


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0], epilog=__doc__[__doc__.index('Without'):],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument('--from', dest='source', help='a benchmark_datasets output folder (its results.csv)')
    p.add_argument('--check', action='store_true', help='compare the tables with the run; write nothing')
    p.add_argument('--keep', help='run the benchmark into this folder (kept)')
    args = p.parse_args()
    source = args.source
    if source is None:
        source = args.keep or tempfile.mkdtemp(prefix='pf_results_tables.')
        os.makedirs(source, exist_ok=True)
        run_benchmark(source)
    with open(os.path.join(source, 'results.csv')) as f:
        rows = {(r['dataset'], r['particles']): r for r in csv.DictReader(f) if r['status'] == 'ok'}
    missing = sorted(n for n in FULL if (n, 'default') not in rows)
    if missing:
        print('results_tables: not in this run (not %s): %s' % ('compared' if args.check else 'written',
                                                                 ', '.join(missing)))
    fresh = blocks(rows)
    bad = 0
    for name, rel in FILES.items():
        path = os.path.join(REPO, rel)
        text = open(path).read()
        head, body, tail = split(text, name, rel)
        if not args.check:
            if missing:  # keep the rows of recordings this run did not have
                fresh_lines = fresh[name].splitlines()
                kept = [l for l in body.splitlines() if l.startswith('| ') and any(
                    l.startswith('| ' + NAMES[m] + ' |') for m in missing)]
                fresh_lines[2:2] = kept
                fresh[name] = '\n'.join(fresh_lines) + '\n'
            open(path, 'w').write(head + fresh[name] + tail)
            print('results_tables: wrote the %s table of %s' % (name, rel))
            continue
        have, want = checked_view(body), checked_view(fresh[name])
        compared = 0
        for key, cells in want.items():
            compared += 1
            if have.get(key) != cells:
                print('results_tables: %s, the %s table differs from a fresh run:\n  table: %s\n  run:   %s'
                      % (rel, name, ' | '.join(have.get(key, ['(no such row)'])), ' | '.join(cells)))
                bad += 1
        extra = [k for k in have if k not in want and not any(k[0] == NAMES[m] for m in missing)]
        for key in extra:
            print('results_tables: %s, the %s table has a row the run has not: %s' % (rel, name, ' | '.join(key)))
            bad += 1
        if compared and not bad:
            print('results_tables: %s: the %s table matches the run (%d rows)' % (rel, name, compared))
    if bad:
        print('results_tables: run `/usr/bin/python3 scripts/results_tables.py` (or `--from DIR` of a benchmark_datasets 0 5000 run) '
              'to rewrite them')
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
