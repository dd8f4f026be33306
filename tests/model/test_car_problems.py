"""Car-like robots in problem files (issue 35): the keys, their checks, and the JSON Schema."""

from __future__ import annotations

import math

import pytest

from rrtpso_ompl.errors import ProblemError
from rrtpso_ompl.model.format import json_schema
from rrtpso_ompl.model.problem import problem_from_dict

BASE = {
    "bounds": [[0, 0], [20, 12]],
    "start": [2, 2],
    "goal": [18, 10],
    "robot": {"radius": 0.4, "turning_radius": 1.5},
}


def _problem(**changes):
    doc = {**BASE, **changes}
    return problem_from_dict(doc, source="car.yaml")


def test_a_turning_radius_makes_the_robot_car_like_with_headings_towards_the_goal():
    problem = _problem()
    assert problem.car and problem.robot.turning_radius == 1.5 and problem.robot.reverse is False
    toward = math.atan2(8, 16)
    assert problem.end_yaws() == pytest.approx((toward, toward))
    problem = _problem(start_yaw=90, goal_yaw=-450, robot={**BASE["robot"], "reverse": True})
    assert problem.robot.reverse is True
    assert problem.end_yaws() == pytest.approx((math.pi / 2, -math.pi / 2))
    # OMPL's SO(2) bounds are [-pi, pi): a heading of 180 degrees is -pi there.
    assert _problem(start_yaw=180).end_yaws()[0] == -math.pi
    assert not _problem(robot={"radius": 0.4}).car


@pytest.mark.parametrize(
    ("changes", "key", "words"),
    [
        ({"robot": {"radius": 0.4, "reverse": True}}, "robot.reverse", "car-like robot only"),
        ({"robot": {"radius": 0.4}, "start_yaw": 10}, "start_yaw", "car-like robot only"),
        ({"robot": {"radius": 0.4, "turning_radius": 1.0, "reverse": "yes"}}, "robot.reverse",
         "must be true or false"),
        ({"robot": {"radius": 0.4, "turning_radius": 0}}, "robot.turning_radius", ""),
        ({"robot": {"radius": 0.4, "turning_radius": 1.0, "inflation_radius": 1.0}},
         "robot.inflation_radius", "not supported for a car-like robot"),
        ({"start_yaw": "north"}, "start_yaw", "number"),
    ],
)  # fmt: skip
def test_car_keys_in_the_wrong_company_are_refused_naming_the_key(changes, key, words):
    with pytest.raises(ProblemError) as info:
        _problem(**changes)
    assert info.value.key == key and words in info.value.message
    assert "car.yaml" in str(info.value)


def test_the_schema_knows_the_car_keys():
    schema = json_schema()
    robot = schema["$defs"]["robot"]["properties"]
    assert {"type": "boolean"} in robot["reverse"]["anyOf"]
    assert robot["turning_radius"]["anyOf"][0]["exclusiveMinimum"] == 0
    assert "start_yaw" in schema["properties"]
