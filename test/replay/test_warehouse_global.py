"""Global localization among the simulated warehouse's twin aisles (bags/warehouse_global.bag).

With a million particles (seed 2): never "localized" at the wrong place, and the true
place among the published hypotheses (within 1 m of one's mean or inside its 95 %
ellipse) in every update. Without GlobalSearch (the smoothed likelihood, then the
settling), seed 1: 57 updates confidently wrong, the truth listed in 59 %; with 32
hypotheses listed instead of 64, seed 2 misses it in 2 updates. About 10 s.

At the default budget (50 000), seeds 1-10: never "localized" at the wrong place; the
true place among the hypotheses in at least 99.9 % of the updates (one miss in 2 500);
and "localized" (so, at the right place) within 10 s of the first scan that tells the
aisles apart (34.1 s, README), by 44.1 s. Such a cloud may hold the true aisle only a
rack bay or two from the truth: with the look-alikes of the estimate alone listed, not
those of every place the cloud holds, seeds 2, 4 and 8 left the truth off in 10 updates
between 0.9 and 1.7 s (99.6 %). While the fit had to be below the usual one too before a
better look-alike got a copy of the cloud, seeds 4 and 8 were localized only at 45.9 and
44.3 s. And the published covariance covers the look-alikes until a scan tells the place
apart (ConfidenceTracker::coverLookAlikes), and the map's error once it is told apart
(ScanRefiner::mapErrorCovariance): each seed has 85-99 % of the reference poses inside
its 95 % ellipse (90.4-93.4 % today) and a NEES mean of at most 5 (2.2-2.8). While it was
one aisle's, 33-77 % and up to 8e5 (7 seeds over 3e4), the cloud alone in a wrong twin
aisle saying 1 cm; without the map's error, 72-77 %, the simulator's walls half a cell
nearer than the map's and the fit saying 1 cm. About 30 s.
"""
import functools
import os

import pytest

from replay_support import WS, holds, replay, seed_ids

BAG, MAP = 'bags/warehouse_global.bag', 'maps/warehouse.yaml'
SEEDS = range(1, 11)
LOCALIZED_BY_S = 44.1  # 10 s after the first scan that tells the aisles apart
HYPOTHESES_SHARE = 0.999  # of the updates of all seeds, the truth among the hypotheses


@functools.lru_cache(maxsize=None)
def million():
    return replay(os.path.join(WS, 'warehouse_global'), BAG, MAP, 0.5, '--seed', 2, '--particles', 1000000)


@functools.lru_cache(maxsize=None)
def default_budget(seed):
    return replay(os.path.join(WS, 'warehouse_global_default', 'seed%d' % seed), BAG, MAP, 0.5, '--seed', seed)


def test_a_million_particles_never_localized_at_the_wrong_place():
    """1 000 000 particles, seed 2: no update "localized" more than 1 m off."""
    wrong = million().summary['confidently_wrong_updates']
    holds(wrong == 0, '%d updates confidently wrong' % wrong)


def test_a_million_particles_list_the_truth_among_the_hypotheses_in_every_update():
    """1 000 000 particles, seed 2: the true place among the published hypotheses in every
    update (with 32 listed instead of 64, it was left off in 2)."""
    h = million().summary['hypotheses']
    holds(h['contain_truth_share'] == 1.0, 'the truth among the hypotheses in %.1f %% of %d updates (missed at: %s)'
          % (100 * h['contain_truth_share'], h['updates'], ', '.join('%.2f s' % t for t in h['misses_s']) or 'none'))


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_default_budget_never_localized_at_the_wrong_place(seed):
    """The default budget: no update "localized" more than 1 m off."""
    wrong = default_budget(seed).summary['confidently_wrong_updates']
    holds(wrong == 0, '%d updates confidently wrong' % wrong)


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_default_budget_localized_within_10_s_of_the_first_telling_scan(seed):
    """The default budget: "localized" by 44.1 s, 10 s after the first scan that tells the
    aisles apart."""
    at = default_budget(seed).localized_after_s()
    holds(at <= LOCALIZED_BY_S, 'localized at %.1f s (bound %.1f s)' % (at, LOCALIZED_BY_S))


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_default_budget_covariance_covers_85_to_99_percent(seed):
    """The default budget: 85-99 % of the reference poses inside the published 95 % ellipse."""
    inside = default_budget(seed).summary['covariance']['inside_95_percent']
    holds(85 <= inside <= 99, '%.1f %% inside the published 95 %% ellipse (bounds 85-99)' % inside)


@pytest.mark.parametrize('seed', SEEDS, ids=seed_ids)
def test_default_budget_nees_mean_at_most_5(seed):
    """The default budget: the published covariance's NEES mean at most 5 (an honest one
    gives 2)."""
    nees = default_budget(seed).summary['covariance']['nees_mean']
    holds(nees <= 5, 'NEES mean %.2f (bound 5)' % nees)


def test_default_budget_lists_the_truth_among_the_hypotheses_in_999_updates_of_1000():
    """The default budget, seeds 1-10 together: the true place among the published
    hypotheses in at least 99.9 % of the updates."""
    runs = [default_budget(s).summary['hypotheses'] for s in SEEDS]
    updates = sum(h['updates'] for h in runs)
    listed = sum(h['contain_truth_share'] * h['updates'] for h in runs)
    misses = ['seed %d at %s s' % (s, ', '.join('%.2f' % t for t in h['misses_s']))
              for s, h in zip(SEEDS, runs) if h['misses_s']]
    holds(listed >= HYPOTHESES_SHARE * updates, 'the truth among the hypotheses in %.2f %% of %d updates '
          '(bound %.1f %%; missed: %s)' % (100 * listed / updates, updates, 100 * HYPOTHESES_SHARE,
                                          '; '.join(misses) or 'none'))
