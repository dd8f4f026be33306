"""Issue 13: scale-free refinement, the whole budget used, a first path in narrow mazes."""

from __future__ import annotations

import time

import numpy as np
from helpers import PROBLEMS

from rrtpso_ompl.groundtruth.generate import generate
from rrtpso_ompl.model import World, load_problem, problem_from_dict
from rrtpso_ompl.model.geometry import path_length, shortcut
from rrtpso_ompl.planners import solve
from rrtpso_ompl.planners.pso.path_optimizer import PathOptimizerOptions, _refine, optimize_path
from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSO


def test_refinement_fires_for_a_point_robot():
    """A chord passing close to a circle is 'along the obstacle' for a point robot too: before,
    the test was r (1 + margin), always false for r = 0."""
    world = World(((0, 0), (10, 10)), np.array([[5.0, 5.0, 1.0]]), robot_radius=0.0)
    path = np.array([[1.0, 6.1], [9.0, 6.1]])  # 0.1 above the circle, a segment of length 8
    refined = _refine(path, world, margin=0.05, max_waypoints=10)
    assert len(refined) == 3
    far = np.array([[1.0, 8.0], [9.0, 8.0]])  # 2.0 clear: not along it
    assert len(_refine(far, world, margin=0.05, max_waypoints=10)) == 2


def test_a_budget_is_used_by_further_rounds_while_they_pay():
    rng = np.random.default_rng(0)
    world = World.from_problem(load_problem(PROBLEMS / "static" / "cluttered_circles.yaml"))
    problem = load_problem(PROBLEMS / "static" / "cluttered_circles.yaml")
    from rrtpso_ompl.groundtruth.certify import grid_path

    seed = grid_path(problem, shortcut=False)
    polled = []

    def terminate() -> bool:  # a deadline far away: only the rounds' own rule stops them
        polled.append(1)
        return False

    opts = PathOptimizerOptions(refine_rounds=0)
    once = optimize_path(seed, world, PathOptimizerOptions(refine_rounds=0, polish_rounds=0), rng)
    more = optimize_path(seed, world, opts, np.random.default_rng(0), terminate)
    assert more.rounds > 1 and polled
    assert world.path_valid(more.path) and more.length <= path_length(seed)
    assert once.rounds == 1


def test_shortcut_stops_when_told_and_stays_valid():
    world = World(((0, 0), (10, 10)), np.array([[5.0, 5.0, 1.0]]), robot_radius=0.1)
    path = np.column_stack([np.linspace(0.5, 9.5, 50), np.full(50, 1.0)])
    stopped = shortcut(path, world.segments_free, lambda: True)
    assert np.array_equal(stopped, path)  # told to stop at once: the path as it was
    full = shortcut(path, world.segments_free, lambda: False)
    assert len(full) == 2 and world.path_valid(full)


def test_stall_is_relative_and_looks_back_only_since_a_resume():
    from rrtpso_ompl.planners.rrtstar_pso.rrtstar_stage import stalled

    flat = [(0.1, 100.0), (0.2, 99.99), (0.4, 99.98)]
    assert stalled(flat, 0.4, 1.0, 0.0, 0.25)  # less than 0.1 % over the last quarter
    assert not stalled(flat, 0.4, 1.0, 0.3, 0.25)  # resumed at 0.3: not a quarter yet
    falling = [(0.1, 100.0), (0.2, 95.0), (0.4, 90.0)]
    assert not stalled(falling, 0.4, 1.0, 0.0, 0.25)
    scaled = [(t, c * 1e-3) for t, c in flat]  # the same world at another scale
    assert stalled(scaled, 0.4, 1.0, 0.0, 0.25)
    assert not stalled(flat, 0.4, 1.0, 0.0, 0.0)  # stall_fraction 0: never


#: Issue 13's narrow maze: corridors 1.3 % of the width, a point robot (RRT* alone finds no path
#: in 2 s). Work-bounded runs below: what they find does not depend on the machine's speed.
NARROW_MAZE = {"kind": "maze", "seed": 1, "cells": 12, "robot_radius": 0.0, "wall": 7.0}
#: An iteration-bounded RRTstarPSO: its corridor stage's lattice is fixed (no clock sizes it) and
#: its swarm runs one bounded round; the time limit is only a cap, far from reached.
BOUNDED = {"rrt_max_iterations": 50, "iterations": 5, "refine_rounds": 0, "polish_rounds": 0}


def _narrow_maze():
    kind, seed = NARROW_MAZE["kind"], NARROW_MAZE["seed"]
    options = {k: v for k, v in NARROW_MAZE.items() if k not in ("kind", "seed")}
    return problem_from_dict(generate(kind, seed, **options))


def test_the_corridor_stage_finds_a_path_through_a_narrow_maze():
    maze = _narrow_maze()
    r = solve(maze, "RRTstarPSO", time_limit=60.0, seed=1, params=BOUNDED)
    assert r.solved and r.stages["seed_source"] == "corridor"
    assert World.from_problem(maze).path_valid(np.array(r.path))


def test_without_a_corridor_path_bitstar_finds_the_first_path_through_a_narrow_maze():
    """The fallback itself (``connect_with_bitstar``), bounded by its first path (BIT* stops
    there), not by seconds: the end it is given is a cap two orders of magnitude away."""
    from ompl import base as ob

    from rrtpso_ompl.ompl_setup import make_context, path_to_array, seed_ompl
    from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSOStats
    from rrtpso_ompl.planners.rrtstar_pso.rrtstar_stage import connect_with_bitstar

    maze = _narrow_maze()
    seed_ompl(1)
    ctx = make_context(maze)
    planner = RRTstarPSO(ctx.si, corridor_cells=0)
    ctx.ss.setPlanner(planner)
    ctx.ss.setup()
    stats = RRTstarPSOStats()
    pdef = ctx.ss.getProblemDefinition()
    connect_with_bitstar(ctx.si, pdef, ob.PlannerTerminationCondition(lambda: False),
                         time.perf_counter() + 120, stats)  # fmt: skip
    assert stats.first_solution == "BITstar" and pdef.hasExactSolution()
    assert World.from_problem(maze).path_valid(path_to_array(pdef.getSolutionPath()))


def test_rrtstar_without_a_path_hands_over_to_bitstar_at_connect_after():
    """The hand-over, whatever the machine: with ``connect_after`` 0 and no corridor stage RRT*
    has no exact path when its first slice would start, so BIT* looks for one; whether it finds
    one in this short budget is not the point (the test above is)."""
    maze = _narrow_maze()
    r = solve(maze, "RRTstarPSO", time_limit=0.2, seed=1,
              params={"corridor_cells": 0, "connect_after": 0.0})  # fmt: skip
    assert r.stages["first_solution"] == "BITstar" and r.stages["rrt_iterations"] == 0
    if r.solved:
        assert World.from_problem(maze).path_valid(np.array(r.path))


def test_rrtstarpso_gives_its_swarm_the_rest_of_the_budget(monkeypatch):
    """With a budget, the swarm gets a termination condition (so its further rounds may run while
    they pay: ``test_a_budget_is_used_by_further_rounds_while_they_pay``) and a deadline at the
    budget's end less the reserve for handing the path over, both from the planner's own start."""
    from rrtpso_ompl.planners import post
    from rrtpso_ompl.planners.rrtstar_pso.planner import FINISH_RESERVE

    calls = []
    original = post.PSOPathOptimizer.optimize_array

    def spy(self, xy, terminate=None, deadline=None):
        calls.append((time.perf_counter(), terminate, deadline))
        return original(self, xy, terminate, deadline)

    monkeypatch.setattr(post.PSOPathOptimizer, "optimize_array", spy)
    before = time.perf_counter()
    easy = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    r = solve(easy, "RRTstarPSO", time_limit=0.3, seed=1)
    assert r.solved and calls
    for called, terminate, deadline in calls:
        assert terminate is not None and deadline is not None
        # t0 + (1 - reserve) x budget, t0 between ``before`` and the call
        assert before + (1 - FINISH_RESERVE) * 0.3 <= deadline <= called + 0.3
