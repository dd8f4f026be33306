"""OMPL's seed: every seeded solve is reproducible, in a fresh process or after other solves."""

import json
import subprocess
import sys

import pytest
from helpers import PROBLEMS

from rrtpso_ompl import load_problem, solve

MAZE = PROBLEMS / "static" / "maze.yaml"
#: Bounded by iterations (and one swarm round) under a time limit no run comes near: the clock
#: never decides a path.
BOUNDED = {"RRTstarPSO": {"rrt_max_iterations": 300, "iterations": 20, "refine_rounds": 0,
                          "polish_rounds": 0}, "RRTConnect": {}}  # fmt: skip


def _path(planner: str, seed: int) -> list[list[float]]:
    result = solve(load_problem(MAZE), planner, time_limit=30.0, seed=seed,
                   params=BOUNDED[planner])  # fmt: skip
    assert result.solved and result.seed == seed
    return result.path.tolist()


@pytest.mark.parametrize("planner", sorted(BOUNDED))
def test_seeds_one_two_one_in_one_process_give_the_first_path_twice(planner):
    first, other, again = (_path(planner, seed) for seed in (1, 2, 1))
    assert first == again
    assert first != other


@pytest.mark.slow
def test_a_later_solve_gives_the_path_of_a_fresh_process():
    """Seed 1 after a solve with seed 2 in this process is seed 1 in a process of its own."""
    _path("RRTConnect", 2)
    here = _path("RRTConnect", 1)
    code = (
        "import json, sys; from rrtpso_ompl import load_problem, solve; "
        f"r = solve(load_problem({str(MAZE)!r}), 'RRTConnect', time_limit=30.0, seed=1); "
        "print(json.dumps(r.path.tolist()))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, check=True)  # fmt: skip
    assert json.loads(out.stdout) == here


def test_seed_zero_is_applied_as_one():
    """OMPL refuses 0 (takes 1 first, ignores it later): 0 means 1 whatever came before."""
    assert _path("RRTConnect", 0) == _path("RRTConnect", 1)
