"""RRTstarPSO and the swarm with a user's own validity checker (issue 17): the deadline is kept
with a slow checker, and the swarm does not mine the gaps of OMPL's discrete motion check.

The two environments are those of OMPL's own Python tests (ompl/ompl ``tests/pytests``):
``geo_env.py`` (a checker that sleeps 1 ms per state, always valid) and
``test_optimal_planning.py`` (the unit square with the obstacle (0.3, 0.7)^2, start (0.1, 0.1),
goal (0.9, 0.9), exact shortest path 1.26491), rewritten here with the same worlds.
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.ompl_setup import array_to_path, path_to_array
from rrtpso_ompl.planners import PSOPathOptimizer
from rrtpso_ompl.planners.base import SpaceInformationCollisionModel
from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSO

# The deadlines below are the conformance kit's, ``DEADLINE_FACTOR x budget + DEADLINE_SLACK``
# (1.5 x budget + 1 s): a loaded machine holds them. The 5 % is measured by
# ``benchmarks/foreign_checker.py`` (docs/foreign-checker.md), not by a test; what fails here is a
# stage that does not size itself to the checker (seconds to hours).
from rrtpso_ompl.testing import DEADLINE_FACTOR, DEADLINE_SLACK


def geo_env():
    """geo_env.py: [-1, 1]^2, a checker that takes 1 ms per state and accepts everything."""
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(-1)
    bounds.setHigh(1)
    space.setBounds(bounds)

    def is_valid(state):
        time.sleep(0.001)
        return True

    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(is_valid)
    si.setup()
    start, goal = si.allocState(), si.allocState()
    start[0], start[1], goal[0], goal[1] = -0.5, -0.5, 0.5, 0.5
    ss = og.SimpleSetup(si)
    ss.setStartAndGoalStates(start, goal)
    return ss, si


def square_env():
    """test_optimal_planning.py: the unit square with the obstacle (0.3, 0.7)^2."""
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0)
    bounds.setHigh(1)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)

    def is_valid(state):
        return not (0.3 < state[0] < 0.7 and 0.3 < state[1] < 0.7)

    si.setStateValidityChecker(is_valid)
    si.setup()
    ss = og.SimpleSetup(si)
    start, goal = si.allocState(), si.allocState()
    start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.9
    ss.setStartAndGoalStates(start, goal)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    return ss, si


def penetration(xy, n=20_000) -> float:
    """How deep the polyline goes into (0.3, 0.7)^2, measured densely (0 when it stays out)."""
    worst = 0.0
    xy = np.asarray(xy, dtype=float)
    for a, b in itertools.pairwise(xy):
        p = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
        depth = np.minimum.reduce([p[:, 0] - 0.3, 0.7 - p[:, 0], p[:, 1] - 0.3, 0.7 - p[:, 1]])
        worst = max(worst, float(depth.max()))
    return worst


def test_rrtstarpso_keeps_the_deadline_with_a_slow_checker():
    ss, si = geo_env()
    planner = RRTstarPSO(si, budget=0.5)
    ss.setPlanner(planner)
    t0 = time.perf_counter()
    status = ss.solve(0.5)
    elapsed = time.perf_counter() - t0
    assert status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    assert elapsed <= DEADLINE_FACTOR * 0.5 + DEADLINE_SLACK, elapsed


def test_the_optimizer_keeps_its_time_with_a_slow_checker():
    _ss, si = geo_env()
    path = array_to_path(si, np.array([[-0.5, -0.5], [0.4, -0.4], [0.5, 0.5]]))
    optimizer = PSOPathOptimizer(si, rng=np.random.default_rng(0))
    t0 = time.perf_counter()
    changed = optimizer.optimize(path, 0.2)
    elapsed = time.perf_counter() - t0
    assert elapsed <= DEADLINE_FACTOR * 0.2 + DEADLINE_SLACK, elapsed
    # Validating this path once at a tenth of the resolution takes about 0.5 s: no room.
    assert not changed and "validate" in optimizer.skipped
    assert path.getStateCount() == 3


def test_a_fast_checker_gets_a_swarm_sized_to_it():
    _ss, si = geo_env()
    # The same world without the sleep: a swarm runs and shortens the detour.
    si.setStateValidityChecker(lambda s: True)
    si.setup()
    path = array_to_path(si, np.array([[-0.5, -0.5], [0.4, -0.4], [0.5, 0.5]]))
    optimizer = PSOPathOptimizer(si, rng=np.random.default_rng(0))
    assert optimizer.optimize(path, 0.5) and optimizer.skipped == ""
    assert path.length() < math.hypot(0.9, 0.1) + math.hypot(0.1, 0.9)


@pytest.mark.parametrize("rep", range(3))
def test_rrtstarpso_does_not_go_deeper_than_its_rrt_path(rep):
    ss, si = square_env()
    planner = RRTstarPSO(si, budget=0.5)
    ss.setPlanner(planner)
    assert ss.solve(0.5).getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    out = path_to_array(ss.getSolutionPath())
    seed = np.array(planner.last_stats.seed_path)
    # No deeper than its RRT* path, give or take the most a segment can cut a corner between two
    # states a fine step h apart (h / 4; 0.00035 here, against RRT*'s 0.002-0.004): a point
    # checker tells nothing finer.
    h = SpaceInformationCollisionModel(si).step
    assert penetration(out) <= penetration(seed) + h / 4
    assert ss.getSolutionPath().length() <= planner.last_stats.rrt_length + 1e-9


def test_the_swarm_cannot_cut_the_corner_between_coarse_checks():
    _ss, si = square_env()
    model = SpaceInformationCollisionModel(si)
    resolution = si.getStateValidityCheckingResolution() * si.getMaximumExtent()
    assert model.step == pytest.approx(0.1 * resolution)
    # A segment that cuts the obstacle's corner (0.3, 0.7) 0.002 deep, over 0.006 of its length:
    # OMPL's discrete check (states 0.014 apart) may step over it; the fine one cannot.
    a, b = np.array([0.1, 0.496]), np.array([0.5, 0.896])
    assert penetration([a, b]) == pytest.approx(0.002, abs=1e-4)
    assert not model.segments_free(a[None], b[None])[0]
    # A path around the obstacle with a margin: the swarm shortens it, and stays out to within
    # a quarter of the fine step (the user's checker tells nothing finer).
    around = np.array([[0.1, 0.1], [0.29, 0.71], [0.9, 0.9]])
    path = array_to_path(si, around)
    optimizer = PSOPathOptimizer(si, rng=np.random.default_rng(2))
    optimizer.optimize(path, 0.5)
    out = path_to_array(path)
    assert penetration(out) <= model.step / 4
    assert path.length() <= math.hypot(0.19, 0.61) + math.hypot(0.61, 0.19) + 1e-12
