"""Kidnapped into the warehouse's twin aisle (bags/warehouse_kidnap.bag), the default budget,
seeds 1-10: never "localized" wrong, and back within 0.3 m of the truth for good by 84.5 s,
10 s after the scans first fit the twin clearly better (74.5 s, docs/design.md, "Look-alike
places"). With each look-alike given a share of the survivors instead of a copy of them,
seed 8 lost the twin on the next scan and was back only at 87.5 s. About 20 s.
"""
import functools
import os

import pytest

from replay_support import WS, holds, replay, seed_ids

SEEDS = range(1, 11)
BACK_BY_S = 84.5  # 10 s after the scans first fit the twin clearly better


@functools.lru_cache(maxsize=None)
def kidnap(seed):
    return replay(os.path.join(WS, 'warehouse_kidnap', 'seed%d' % seed), 'bags/warehouse_kidnap.bag',
                  'maps/warehouse.yaml', 0.5, '--seed', seed, '--initial-pose', '5.0', '6.0', '1.5707963')


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_never_localized_at_the_wrong_place(seed):
    """No update "localized" more than 1 m off, in the twin aisle or anywhere."""
    wrong = kidnap(seed).summary['confidently_wrong_updates']
    holds(wrong == 0, '%d updates confidently wrong' % wrong)


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_found_again_within_10_s_of_the_first_telling_scans(seed):
    """Back within 0.3 m of the truth for good by 84.5 s."""
    back = kidnap(seed).summary['convergence_time_s']
    holds(back is not None and back <= BACK_BY_S, 'back within 0.3 m for good at %s (bound %.1f s)'
          % ('%.1f s' % back if back is not None else 'never', BACK_BY_S))
