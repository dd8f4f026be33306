"""The PSO post-optimiser: valid, never longer, end points fixed, input returned when it cannot
improve, and close to a known optimum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers import SINGLE_CIRCLE_OPTIMUM

from rrtpso_ompl.model.geometry import path_length, shortcut
from rrtpso_ompl.model.world import World
from rrtpso_ompl.planners.pso.path_optimizer import (
    PathOptimizerOptions,
    optimize_path,
    turning_angles,
)

BOUNDS = ((0.0, 0.0), (500.0, 500.0))
CIRCLE_WORLD = World(BOUNDS, [(250, 250, 80)], [], robot_radius=28.5)
ZIGZAG = np.array([[20, 20], [150, 330], [300, 420], [450, 450]], dtype=float)


def analytic_single_circle() -> float:
    """Tangent + arc + tangent around the grown circle (radius 80 + 28.5). Start and goal lie
    on opposite sides of the centre at distances d_s and d_g; each tangent meets the circle at
    the angle acos(r / d) from its own direction, and the arc spans what is left of pi."""
    r = 80 + 28.5
    d_s = math.dist((20, 20), (250, 250))
    d_g = math.dist((450, 450), (250, 250))
    tangents = math.sqrt(d_s**2 - r**2) + math.sqrt(d_g**2 - r**2)
    arc = r * (math.pi - math.acos(r / d_s) - math.acos(r / d_g))
    return tangents + arc


def test_analytic_optimum_is_647_45():
    # The issue quotes 647.45; the closed form is 647.4596.
    assert analytic_single_circle() == pytest.approx(SINGLE_CIRCLE_OPTIMUM, abs=0.01)


def test_reaches_the_known_optimum_from_a_zigzag():
    assert CIRCLE_WORLD.path_valid(ZIGZAG)
    res = optimize_path(ZIGZAG, CIRCLE_WORLD, rng=np.random.default_rng(0))
    assert CIRCLE_WORLD.path_valid(res.path)
    optimum = analytic_single_circle()
    assert optimum - 1e-6 <= res.length <= optimum * 1.005
    assert res.improved and res.length < res.input_length
    assert np.array_equal(res.path[0], ZIGZAG[0]) and np.array_equal(res.path[-1], ZIGZAG[-1])


def random_world(rng):
    circles = np.column_stack([rng.uniform(60, 440, (10, 2)), rng.uniform(10, 40, 10)])
    square = np.array([[200, 60], [260, 60], [260, 120], [200, 120]], float)
    return World(BOUNDS, circles, [square], robot_radius=10)


def random_valid_path(world, rng):
    """A random walk of free waypoints joined by free segments, from (5, 5) to (495, 495)."""
    for _ in range(200):
        k = rng.integers(2, 8)
        mid = rng.uniform(0, 500, (k, 2))
        path = np.vstack([[5, 5], mid[np.argsort(mid.sum(axis=1))], [495, 495]])
        if world.path_valid(path):
            return path
    return None


@pytest.mark.parametrize("seed", range(12))
def test_never_longer_never_invalid(seed):
    rng = np.random.default_rng(seed)
    world = random_world(rng)
    path = random_valid_path(world, rng)
    if path is None:
        pytest.skip("no random valid path in this world")
    res = optimize_path(path, world, rng=np.random.default_rng(seed))
    assert world.path_valid(res.path)
    assert res.length <= res.input_length + 1e-9
    assert np.array_equal(res.path[0], path[0]) and np.array_equal(res.path[-1], path[-1])
    if not res.improved:
        assert res.path is not None and np.array_equal(res.path, path)


def test_invalid_input_is_returned_unchanged():
    through = np.array([[20, 20], [450, 450]], dtype=float)
    res = optimize_path(through, CIRCLE_WORLD, rng=np.random.default_rng(0))
    assert not res.improved and np.array_equal(res.path, through)


def test_nothing_shorter_returns_the_input_itself():
    empty = World(BOUNDS, [], [], 5)
    line = np.array([[20, 20], [100, 100], [450, 450]], dtype=float)
    res = optimize_path(line, empty, rng=np.random.default_rng(0))
    assert not res.improved and res.path is not line and np.array_equal(res.path, line)
    assert res.length == pytest.approx(math.dist((20, 20), (450, 450)))


def test_same_seed_same_path():
    a = optimize_path(ZIGZAG, CIRCLE_WORLD, rng=np.random.default_rng(4))
    b = optimize_path(ZIGZAG, CIRCLE_WORLD, rng=np.random.default_rng(4))
    assert np.array_equal(a.path, b.path)


def test_smoothness_weight_keeps_the_guarantees():
    opts = PathOptimizerOptions(smoothness_weight=50.0)
    res = optimize_path(ZIGZAG, CIRCLE_WORLD, opts, rng=np.random.default_rng(1))
    assert CIRCLE_WORLD.path_valid(res.path) and res.length <= res.input_length


def test_shortcut_keeps_a_subset_and_never_lengthens():
    res = shortcut(ZIGZAG, CIRCLE_WORLD.segments_free)
    assert np.array_equal(res[0], ZIGZAG[0]) and np.array_equal(res[-1], ZIGZAG[-1])
    assert all(any(np.array_equal(p, q) for q in ZIGZAG) for p in res)
    assert path_length(res) <= path_length(ZIGZAG) and CIRCLE_WORLD.path_valid(res)


def test_turning_angles():
    straight = np.array([[0, 0], [1, 1], [2, 2]], dtype=float)
    corner = np.array([[0, 0], [1, 0], [1, 1]], dtype=float)
    assert turning_angles(straight) == pytest.approx([0.0])
    assert turning_angles(corner) == pytest.approx([math.pi / 2])


def test_terminate_stops_the_swarm_but_keeps_the_guarantees():
    res = optimize_path(ZIGZAG, CIRCLE_WORLD, rng=np.random.default_rng(0), terminate=lambda: True)
    assert res.n_iterations == 0
    assert CIRCLE_WORLD.path_valid(res.path) and res.length <= res.input_length


@pytest.mark.parametrize("window", [0, 2])
def test_the_best_cost_curve_is_the_path_s_own_never_below_what_was_kept(window):
    """The curve the picture draws (issue 36): every value a cost of a path the swarm had, so
    never below the returned path's, and ending at it; with windows too (whose swarms see their
    window's cost only)."""
    for seed in range(4):
        res = optimize_path(ZIGZAG, CIRCLE_WORLD, PathOptimizerOptions(window=window,
                            iterations=30), rng=np.random.default_rng(seed))  # fmt: skip
        assert len(res.history) and res.history.min() >= res.cost - 1e-9
        assert res.history.max() <= res.input_cost + 1e-9
        if res.improved:
            assert res.history[-1] == pytest.approx(res.cost, abs=1e-9)
