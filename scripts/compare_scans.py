#!/usr/bin/python3
"""Compares the laser scans of two bags: the histogram of valid ranges and
the fraction of invalid beams, side by side.

    scripts/compare_scans.py bags/tracking.bag /path/to/real.bag [--topic /scan]

A beam is invalid when it is 0, inf, NaN, below range_min or at or above
range_max; that is how a Neato reports "no return". Valid ranges are binned
every 0.5 m up to 5 m, as fractions of each bag's valid beams. The mean
length of runs of consecutive invalid beams tells single dropouts from
bursts. Used to tune pf_simulator's laser model against a real Neato.
"""
import argparse
import os

import numpy as np
import rosbag

BINS = np.arange(0.0, 5.01, 0.5)


def scan_stats(path, topic):
    valid_ranges, invalid, beams, scans, runs = [], 0, 0, 0, []
    with rosbag.Bag(path) as bag:
        for _, msg, _ in bag.read_messages(topics=[topic]):
            r = np.asarray(msg.ranges, dtype=float)
            with np.errstate(invalid='ignore'):
                bad = ~np.isfinite(r) | (r <= 0) | (r < msg.range_min) | (r >= msg.range_max)
            valid_ranges.append(r[~bad])
            invalid += int(bad.sum())
            beams += r.size
            scans += 1
            # Lengths of the runs of invalid beams: edges of the 0/1 sequence.
            edges = np.diff(np.concatenate(([0], bad.astype(int), [0])))
            runs.extend(np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1))
    if scans == 0:
        raise SystemExit('%s: no messages on %s' % (path, topic))
    valid = np.concatenate(valid_ranges)
    hist = np.histogram(valid, BINS)[0] / max(valid.size, 1)
    return {'hist': hist, 'invalid': invalid / beams, 'scans': scans,
            'beams': beams // scans, 'run': float(np.mean(runs)) if runs else 0.0}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('bags', nargs=2, help='two bags with LaserScan messages')
    parser.add_argument('--topic', default='/scan')
    args = parser.parse_args()
    stats = [scan_stats(b, args.topic) for b in args.bags]
    names = [os.path.basename(b) for b in args.bags]
    row = '%-18s %16s %16s'
    print(row % ('', names[0], names[1]))
    print(row % ('scans x beams', *('%d x %d' % (s['scans'], s['beams']) for s in stats)))
    for i in range(len(BINS) - 1):
        print(row % ('range %.1f-%.1f m' % (BINS[i], BINS[i + 1]),
                     *('%.3f' % s['hist'][i] for s in stats)))
    print(row % ('invalid fraction', *('%.3f' % s['invalid'] for s in stats)))
    print(row % ('mean invalid run', *('%.2f' % s['run'] for s in stats)))


if __name__ == '__main__':
    main()
