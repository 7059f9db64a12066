"""The results tables of README.md and docs/results.md are scripts/results_tables.py's output
from one run of `scripts/benchmark_datasets 0 5000`; pf_bag_runner is deterministic for a
seed, so a fresh run must give the same accuracy figures (the CPU column is the machine's,
not compared). Recordings of ../shared/data that are absent are not compared. About 15 s
on two idle cores.
"""
import os
import shutil

from replay_support import PYTHON, REPO, WS, run_logged, workspace_env


def test_results_tables_match_a_fresh_benchmark_run():
    """README.md's and docs/results.md's tables hold the figures a fresh run gives."""
    out = os.path.join(WS, 'results_tables')
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    run_logged([PYTHON, os.path.join(REPO, 'scripts', 'results_tables.py'), '--check', '--keep', out],
               out + '.log', env=workspace_env())
