"""The closed-loop tracking controller."""

from __future__ import annotations

import math

import pytest
from helpers import PAPER_ROBOT, arc_curve

from rrtpso_ompl.kinematics import time_parametrize, track


def test_tracking_controller_recovers_from_an_offset():
    traj = time_parametrize(arc_curve(120.0, math.pi), PAPER_ROBOT, "constant")
    start = (traj.x[0] + 5.0, traj.y[0], traj.theta[0])  # 5 units off its reference
    res = track(traj, pose0=start)
    assert res.position_error[0] == pytest.approx(5.0)
    assert res.position_error[len(traj.t) // 2] < 1.0
