"""pf_bag_runner --pace (scripts/live_cpu.sh: the filter's work at pf_node's rhythm) only
waits between scans: bags/tracking.bag at 20 times its pace gives the trajectory of the run
back to back, byte for byte, and takes its duration divided by 20 (131.6 s / 20 = 6.6 s).
About 8 s.
"""
import filecmp
import functools
import os
import shutil
import time

from replay_support import RUNNER, WS, holds, run_logged

PACE = 20
BAG_S = 131.6  # bags/tracking.bag's duration


@functools.lru_cache(maxsize=None)
def runs():
    """The trajectory back to back and at --pace 20, and the paced run's wall time (s)."""
    out = os.path.join(WS, 'paced_runner')
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    took = {}
    for pace in ('none', str(PACE)):
        start = time.monotonic()
        run_logged([RUNNER, '--bag', 'bags/tracking.bag', '--map', 'maps/building.yaml',
                    '--initial-pose', '1.5', '7.6', '0.0', '--out', os.path.join(out, pace + '.tum'), '--quiet']
                   + ([] if pace == 'none' else ['--pace', pace]), os.path.join(out, pace + '.log'))
        took[pace] = time.monotonic() - start
    return os.path.join(out, 'none.tum'), os.path.join(out, '%d.tum' % PACE), took[str(PACE)]


def test_paced_trajectory_is_the_back_to_back_one_byte_for_byte():
    """Waiting between scans changes nothing the filter computes."""
    back_to_back, paced, _ = runs()
    holds(filecmp.cmp(back_to_back, paced, shallow=False), '%s and %s identical' % (back_to_back, paced))


def test_paced_run_takes_the_bags_duration_over_the_pace():
    """--pace 20 takes 6.5-20 s: at least the bag's duration over 20, and no run-away wait."""
    took = runs()[2]
    holds(6.5 <= took < 20, 'tracking.bag at --pace %d: %.1f s (bag %.1f s / %d = %.1f s; bounds 6.5-20 s)'
          % (PACE, took, BAG_S, PACE, BAG_S / PACE))
