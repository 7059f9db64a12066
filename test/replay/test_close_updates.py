"""Updates closer together than the defaults: bags/crowd.bag with an amcl configuration's
update_min_d 0.05 m and update_min_a 0.1 rad, seeds 1-16: never "localized" more than 1 m
off, and at least 15 of the 16 tracked as with the defaults (ATE RMSE within 0.03 m, max
within 0.15 m; seed 2 jumps and comes back, "uncertain" meanwhile). While the filter's
evidence, motion noise, fault tracking and recovery counted updates instead of views
(view_share.h), every seed jumped 9-16 m to a place that fits the scans people hide (ATE
3.6-5.9 m); while the scans of a suspect odometry counted whole views, 5 of the 16 did
(383 updates confidently wrong). About 20 s.
"""
import functools
import os

import pytest

from replay_support import WS, holds, replay, seed_ids

SEEDS = range(1, 17)
TRACKED_AT_LEAST = 15  # of the 16 seeds
MAX_RMSE_M, MAX_ERROR_M = 0.03, 0.15  # tracked as with the defaults


@functools.lru_cache(maxsize=None)
def crowd(seed):
    out = os.path.join(WS, 'close_updates')
    os.makedirs(out, exist_ok=True)
    params = os.path.join(out, 'params.yaml')
    with open(params, 'w') as f:
        f.write('update_min_d: 0.05\nupdate_min_a: 0.1\n')
    return replay(os.path.join(out, 'seed%d' % seed), 'bags/crowd.bag', 'maps/building.yaml', 0.5,
                  '--initial-pose', '1.5', '7.6', '0.0', '--params', params, '--seed', seed)


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_never_localized_at_the_wrong_place(seed):
    """No update "localized" more than 1 m off, though the crowd hides the walls."""
    wrong = crowd(seed).summary['confidently_wrong_updates']
    holds(wrong == 0, '%d updates confidently wrong' % wrong)


def test_15_of_16_seeds_tracked_as_with_the_defaults():
    """At least 15 of seeds 1-16 within 0.03 m ATE RMSE and 0.15 m of the truth at every pose."""
    runs = {s: crowd(s).summary for s in SEEDS}
    tracked = [s for s, d in runs.items() if d['ate_rmse_m'] <= MAX_RMSE_M and d['max_m'] <= MAX_ERROR_M]
    off = ['seed %d: %.3f m, max %.1f m' % (s, d['ate_rmse_m'], d['max_m']) for s, d in runs.items()
           if s not in tracked]
    holds(len(tracked) >= TRACKED_AT_LEAST, '%d seeds tracked within %.2f m RMSE and %.2f m max (bound %d; off: %s)'
          % (len(tracked), MAX_RMSE_M, MAX_ERROR_M, TRACKED_AT_LEAST, '; '.join(off) or 'none'))
