"""The seed under an inflation cost: the cheapest route in a band round the corridor's path."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import INFLATED_DOOR, PROBLEMS

from rrtpso_ompl.groundtruth import shortest_path
from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.model.objective import InflationCost
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.planners.rrtstar_pso.costroute import cost_route, drop_waypoints

DOOR = INFLATED_DOOR


def _setup(problem):
    world = World.from_problem(problem)
    return world, InflationCost.of(problem.robot), shortest_path(problem).valid_polyline(world)


def test_the_route_is_valid_cheaper_than_the_shortest_path_and_passes_the_door():
    world, cost, taut = _setup(problem_from_dict(DOOR))
    route = cost_route(world, cost, taut)
    assert route is not None and world.path_valid(route)
    assert np.array_equal(route[0], taut[0]) and np.array_equal(route[-1], taut[-1])
    assert cost.path_cost(world, route) < cost.path_cost(world, taut)
    assert cost.near_share(world, route) < cost.near_share(world, taut)
    i = np.flatnonzero((route[:-1, 0] < 5) & (route[1:, 0] >= 5))[0]
    t = (5 - route[i, 0]) / (route[i + 1, 0] - route[i, 0])
    assert 4.8 <= route[i, 1] + t * (route[i + 1, 1] - route[i, 1]) <= 5.2  # the door's middle


def test_on_a_map_the_route_keeps_off_the_walls(tmp_path):
    import yaml

    doc = yaml.safe_load((PROBLEMS / "maps" / "office_rooms.yaml").read_text())
    doc["map"] = str(PROBLEMS / "maps" / doc["map"])
    doc["robot"]["inflation_radius"] = 0.8
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(doc))
    world, cost, taut = _setup(load_problem(path))
    route = cost_route(world, cost, taut)
    assert route is not None and world.path_valid(route)
    assert cost.path_cost(world, route) < cost.path_cost(world, taut)
    assert cost.near_share(world, route) < 0.5 * cost.near_share(world, taut)


def test_dropping_waypoints_never_raises_the_cost():
    problem = problem_from_dict(DOOR)
    world, cost, taut = _setup(problem)
    dense = np.vstack([np.linspace(taut[k], taut[k + 1], 9)[:-1] for k in range(len(taut) - 1)]
                      + [taut[-1:]])  # fmt: skip
    fewer = drop_waypoints(world, cost, dense)
    assert len(fewer) < len(dense) and world.path_valid(fewer)
    assert cost.path_cost(world, fewer) <= cost.path_cost(world, dense) + 1e-12
    # Back to about the taut path (the midpoint rule's steps fall differently: 1e-4 apart).
    assert cost.path_cost(world, fewer) == pytest.approx(cost.path_cost(world, taut), rel=1e-3)
