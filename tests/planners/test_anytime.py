"""Issue 13: scale-free refinement, the whole budget used, a first path in narrow mazes."""

from __future__ import annotations

import numpy as np
from helpers import PROBLEMS

from rrtpso_ompl.groundtruth.generate import generate
from rrtpso_ompl.model import World, load_problem, problem_from_dict
from rrtpso_ompl.model.geometry import path_length, shortcut
from rrtpso_ompl.planners import solve
from rrtpso_ompl.planners.path_optimizer import PathOptimizerOptions, _refine, optimize_path
from rrtpso_ompl.planners.rrtstar_pso import RRTstarPSO


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
    p = RRTstarPSO.__new__(RRTstarPSO)
    p._values = {"stall_fraction": 0.25}
    flat = [(0.1, 100.0), (0.2, 99.99), (0.4, 99.98)]
    assert p._stalled(flat, 0.4, 1.0, 0.0)  # less than 0.1 % over the last quarter
    assert not p._stalled(flat, 0.4, 1.0, 0.3)  # resumed at 0.3: not a quarter yet
    falling = [(0.1, 100.0), (0.2, 95.0), (0.4, 90.0)]
    assert not p._stalled(falling, 0.4, 1.0, 0.0)
    scaled = [(t, c * 1e-3) for t, c in flat]  # the same world at another scale
    assert p._stalled(scaled, 0.4, 1.0, 0.0)


def test_rrtstarpso_uses_its_budget_and_finds_a_path_through_a_narrow_maze():
    # A perfect maze with corridors 1.3 % of the width and a point robot: RRT* alone finds no
    # path in 2 s. The corridor stage finds one at once; without it, BIT*, started a fifth of
    # the way through RRT*'s share, does.
    maze = problem_from_dict(generate("maze", 1, cells=12, robot_radius=0.0, wall=7.0))
    world = World.from_problem(maze)
    r = solve(maze, "RRTstarPSO", time_limit=2.0, seed=1)
    assert r.solved and r.stages["seed_source"] == "corridor"
    assert world.path_valid(np.array(r.path))
    r = solve(maze, "RRTstarPSO", time_limit=2.0, seed=1, params={"corridor_cells": 0})
    assert r.solved and r.stages["first_solution"] == "BITstar"
    assert world.path_valid(np.array(r.path))
    easy = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    r = solve(easy, "RRTstarPSO", time_limit=0.5, seed=1)
    assert r.stages["pso_rounds"] > 1
