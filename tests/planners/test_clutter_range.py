"""RRTstarPSO's automatic RRT* range: OMPL's default unless the world is cluttered."""

from __future__ import annotations

import math

import numpy as np
from helpers import PROBLEMS

from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.planners.rrtstar_pso.planner import RANGE_PER_CLEARANCE, clutter_range


def _lattice(n: int) -> World:
    rng = np.random.default_rng(0)
    k = math.ceil(math.sqrt(n))
    cell = 1000.0 / k
    ij = np.array([(i, j) for i in range(k) for j in range(k)])[:n]
    c = (ij + 0.5 + rng.uniform(-0.25, 0.25, (n, 2))) * cell
    r = rng.uniform(0.15, 0.3, n) * cell
    return World(((0, 0), (1000, 1000)), np.column_stack([c, r]), robot_radius=0.05 * cell)


def test_sparse_worlds_keep_omplss_default():
    for name in ("single_circle", "paper_static", "cluttered_circles", "dense_circles"):
        problem = load_problem(PROBLEMS / "static" / f"{name}.yaml")
        (x0, y0), (x1, y1) = problem.bounds
        default = 0.2 * math.hypot(x1 - x0, y1 - y0)
        assert clutter_range(World.from_problem(problem), default) == default


def test_cluttered_worlds_get_a_range_of_a_few_gaps_and_it_is_deterministic():
    world = _lattice(10_000)
    default = 0.2 * math.hypot(1000, 1000)
    r = clutter_range(world, default)
    assert 5.0 < r < 40.0  # the lattice cell is 10
    assert r == clutter_range(world, default)
    assert r <= RANGE_PER_CLEARANCE * 10.0
