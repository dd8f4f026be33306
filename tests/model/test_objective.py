"""The inflation objective against values computed by hand."""

import math

import numpy as np
import pytest

from rrtpso_ompl.model import World
from rrtpso_ompl.model.objective import InflationCost
from rrtpso_ompl.model.problem import problem_from_dict

WALL = {"type": "rectangle", "min": [0, 4], "max": [10, 5]}


def _world(robot, obstacles=(WALL,)):
    doc = {"bounds": [[0, 0], [10, 10]], "start": [1, 1], "goal": [9, 1], "robot": robot,
           "obstacles": list(obstacles)}  # fmt: skip
    problem = problem_from_dict(doc)
    return World.from_problem(problem), InflationCost.of(problem.robot)


def test_without_inflation_the_cost_is_the_length():
    world, cost = _world({"radius": 0.2})
    assert not cost.active
    path = [[1, 1], [5, 3.7], [9, 1]]
    assert cost.path_cost(world, path) == pytest.approx(
        math.dist(path[0], path[1]) + math.dist(path[1], path[2]), rel=1e-15
    )


def test_a_stretch_at_constant_distance_costs_one_plus_w_c_per_length():
    world, cost = _world({"radius": 0.2, "inflation_radius": 1.0, "cost_scaling_factor": 2.0})
    assert (cost.weight, cost.cost_scaling_factor) == (2.0, 2.0)  # w: Smac 2D's default
    # 0.5 below the wall, 8 long: c = exp(-2 (0.5 - 0.2)).
    expected = 8.0 * (1.0 + 2.0 * math.exp(-0.6))
    assert cost.path_cost(world, [[1, 3.5], [9, 3.5]]) == pytest.approx(expected, rel=1e-12)
    # Farther than the inflation radius: the length only.
    assert cost.path_cost(world, [[1, 2.9], [9, 2.9]]) == pytest.approx(8.0, rel=1e-15)
    assert cost.near_share(world, [[1, 3.5], [9, 3.5]]) == pytest.approx(1.0)
    assert cost.near_share(world, [[1, 2.9], [9, 2.9]]) == 0.0


def test_a_segment_leaving_the_wall_integrates_the_exponential():
    world, cost = _world({"radius": 0.2, "inflation_radius": 1.0, "cost_scaling_factor": 2.0,
                          "cost_travel_multiplier": 3.0})  # fmt: skip
    # From d = 0.2 (touching) straight away to d = 1.2: int_0.2^1.0 exp(-2 (d - 0.2)) dd.
    integral = (1.0 - math.exp(-1.6)) / 2.0
    got = cost.path_cost(world, [[5, 3.8], [5, 2.8]])
    assert got == pytest.approx(1.0 + 3.0 * integral, rel=2e-3)  # midpoint rule, step 0.1
    assert cost.near_share(world, [[5, 3.8], [5, 2.8]]) == pytest.approx(0.8, abs=1e-12)


def test_many_paths_at_once_equal_one_at_a_time():
    world, cost = _world({"radius": 0.1, "inflation_radius": 0.8},
                         [WALL, {"type": "circle", "center": [3, 2], "radius": 0.5}])  # fmt: skip
    rng = np.random.default_rng(4)
    paths = rng.uniform(0.5, 3.9, size=(5, 4, 2))
    together = cost.path_costs(world, paths)
    alone = [cost.path_cost(world, p) for p in paths]
    np.testing.assert_allclose(together, alone, rtol=1e-12)
    lengths = np.hypot(*np.diff(paths, axis=1).transpose(2, 0, 1)).sum(axis=1)
    assert np.all(together >= lengths) and np.any(together > lengths)


def test_the_cost_is_nav2s_normalised_inflation():
    cost = InflationCost(radius=0.2, inflation_radius=0.55, cost_scaling_factor=3.0)
    d = np.array([0.0, 0.2, 0.3, 0.55, 0.56])
    expected = [1.0, 1.0, math.exp(-0.3), math.exp(-3.0 * 0.35), 0.0]
    np.testing.assert_allclose(cost.cost(d), expected, rtol=1e-15)


def test_the_default_scaling_factor_is_nav2s_per_metre_in_the_problems_units():
    doc = {"bounds": [[0, 0], [500, 500]], "start": [20, 20], "goal": [450, 450],
           "robot": {"radius": 28.5, "inflation_radius": 60.0}}  # fmt: skip
    cm = problem_from_dict({**doc, "units": "cm"})
    assert cm.robot.cost_scaling_factor == pytest.approx(0.03)
    assert problem_from_dict(doc).robot.cost_scaling_factor == 3.0  # no units: metres
    given = problem_from_dict({**doc, "units": "cm",
                               "robot": {**doc["robot"], "cost_scaling_factor": 0.1}})  # fmt: skip
    assert given.robot.cost_scaling_factor == 0.1
    assert problem_from_dict({**doc, "robot": {"radius": 1}}).robot.cost_scaling_factor is None
