"""Certificates of solvability: a grid path the exact checker accepts, or none."""

from __future__ import annotations

import numpy as np

from rrtpso_ompl.groundtruth.generate import grid_path, is_solvable
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.model.world import World


def test_grid_path_finds_no_route_into_a_closed_box():
    box = [
        {"type": "rectangle", "min": [6, 6], "max": [9, 6.5]},
        {"type": "rectangle", "min": [6, 8.5], "max": [9, 9]},
        {"type": "rectangle", "min": [6, 6], "max": [6.5, 9]},
        {"type": "rectangle", "min": [8.5, 6], "max": [9, 9]},
    ]
    data = {
        "bounds": [[0, 0], [10, 10]],
        "start": [1, 1],
        "goal": [7.5, 7.5],
        "robot": {"radius": 0.2},
        "obstacles": box,
    }
    problem = problem_from_dict(data)
    assert grid_path(problem) is None and not is_solvable(problem)
    # With a goal tolerance that reaches outside the box, a grid point near the goal will do.
    reachable = problem_from_dict({**data, "goal_tolerance": 2.0})
    path = grid_path(reachable)
    assert path is not None and World.from_problem(reachable).path_valid(path)
    assert np.hypot(*(path[-1] - reachable.goal)) <= 2.0


def test_grid_path_straight_line_when_free():
    problem = problem_from_dict(
        {"bounds": [[0, 0], [10, 10]], "start": [1, 1], "goal": [9, 2], "robot": {"radius": 0}}
    )
    np.testing.assert_array_equal(grid_path(problem), [[1, 1], [9, 2]])
