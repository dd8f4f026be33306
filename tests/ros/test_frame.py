"""The frame of a problem's ROS outputs: its units in metres and its goal heading."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers import SINGLE_CIRCLE

from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.ros import RosFrame, units_fields


def test_the_goal_yaw_of_the_problem_faces_the_last_pose():
    problem = problem_from_dict({**SINGLE_CIRCLE, "units": "cm", "goal_yaw": 270}, source="mem")
    frame = RosFrame.for_problem(problem)
    assert frame.scale == 0.01 and frame.goal_yaw == pytest.approx(-math.pi / 2)
    poses = frame.poses([[20.0, 20.0], [20.0, 120.0]])
    assert np.allclose(poses.xy[[0, -1]], [[0.2, 0.2], [0.2, 1.2]])
    assert poses.yaw[-1] == pytest.approx(-math.pi / 2)
    assert poses.yaw[0] == pytest.approx(math.pi / 2)
    plain = RosFrame.for_problem(problem_from_dict(SINGLE_CIRCLE, source="mem"))
    assert plain.goal_yaw is None


@pytest.mark.parametrize(
    ("units", "fields"),
    [("cm", {"units": "cm", "metres_per_unit": 0.01}), ("", {"units": "", "metres_per_unit": 1.0}),
     ("furlong", {"units": "furlong"})],
)  # fmt: skip
def test_json_outputs_name_their_units_and_metres_when_known(units, fields):
    assert units_fields(units) == fields
