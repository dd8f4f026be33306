"""The velocity profile: closed forms on lines and arcs, turns in place, the sample bound."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from helpers import BOUNDS, PAPER_ROBOT, arc_curve

from rrtpso_ompl.kinematics import TrajectoryError, reference_curve, time_parametrize
from rrtpso_ompl.model.problem import Robot
from rrtpso_ompl.model.world import World
from rrtpso_ompl.validation import MAX_STEPS


def test_straight_line_has_no_rotation_and_equal_wheels():
    curve = reference_curve(np.array([[10, 10], [200, 150], [390, 290]]), World(BOUNDS))
    traj = time_parametrize(curve, PAPER_ROBOT, "constant")
    full = slice(0, -2)  # full steps (the last one arrives part-way through it)
    assert np.allclose(traj.omega, 0.0, atol=1e-9)
    assert np.allclose(traj.v_right, traj.v_left)
    assert np.allclose(traj.v[full], 20.0)


def test_circular_arc_gives_the_closed_forms():
    R, v, L, r = 100.0, 20.0, 38.0, 7.6
    traj = time_parametrize(arc_curve(R, math.pi / 2), PAPER_ROBOT, "constant")
    k = slice(0, -2)  # full steps: the last one arrives part-way, the last row is at rest
    assert np.allclose(traj.omega[k], v / R)
    assert np.allclose(traj.v_right[k], v * (1 + L / (2 * R)))
    assert np.allclose(traj.v_left[k], v * (1 - L / (2 * R)))
    assert np.allclose(traj.omega_right[k], traj.v_right[k] / r)
    assert np.allclose(traj.omega_left[k], traj.v_left[k] / r)


def test_polyline_fallback_turns_in_place():
    corner = np.array([[0, 0], [100, 0], [100, 100]], dtype=float)
    curve = reference_curve(corner, World(BOUNDS), smooth=False)
    robot = replace(PAPER_ROBOT, max_wheel_speed=20.0)
    traj = time_parametrize(curve, robot, "constant")
    at_corner = np.flatnonzero(np.hypot(traj.x - 100, traj.y) < 1e-9)
    assert len(at_corner) >= 3  # it stays at the corner while it turns
    turning = at_corner[:-1]  # the last of these steps already drives on
    assert np.allclose(traj.v[turning], 0.0)
    assert np.allclose(traj.omega[turning], 2 * 20.0 / 38.0)  # a left turn at full wheel speed
    assert traj.theta[-1] == pytest.approx(math.pi / 2)


def test_a_trajectory_has_at_most_max_steps_samples():
    """A tiny sample time would build and write tens of millions of rows: refused with the key
    to change (``rrtpso solve --trajectory`` refuses it before planning, see test_hostile)."""
    world = World(((0.0, 0.0), (500.0, 500.0)), [], [], 28.5)
    curve = reference_curve(np.array([[20.0, 20.0], [450.0, 450.0]]), world)
    fine = replace(PAPER_ROBOT, sample_time=608.0 / 20.0 / (0.9 * MAX_STEPS))
    assert len(time_parametrize(curve, fine).t) <= MAX_STEPS + 1
    with pytest.raises(TrajectoryError, match=r"robot\.sample_time .* at most 1,000,000"):
        time_parametrize(curve, replace(PAPER_ROBOT, sample_time=1e-6))


@pytest.mark.parametrize(
    "path,profile",
    [
        # The polyline fallback of a straight path, at rest at both ends with "limits".
        ([[1.0, 5.0], [9.0, 5.0]], "limits"),
        # Two turning waypoints in a row: at rest at both ends of the segment between them.
        ([[1.0, 2.0], [3.0, 4.5], [5.0, 5.2], [7.0, 5.5], [9.0, 8.0]], "constant"),
        ([[1.0, 2.0], [3.0, 4.5], [5.0, 5.2], [7.0, 5.5], [9.0, 8.0]], "limits"),
    ],
)
def test_a_segment_between_two_rests_is_driven_not_jumped(path, profile):
    """A segment whose both ends are at rest used to be crossed in no time: the robot jumped
    (8 m in one 0.1 s step, straight to the goal) instead of speeding up and braking."""
    robot = Robot(radius=0.2, wheel_radius=0.05, track_width=0.3, speed=0.5, sample_time=0.1,
                  max_accel=0.5 if profile == "limits" else None)  # fmt: skip
    p = np.array(path)
    curve = reference_curve(p, World(((0.0, 0.0), (10.0, 10.0))), smooth=False)
    traj = time_parametrize(curve, robot, profile)
    step = np.hypot(np.diff(traj.x), np.diff(traj.y)) / robot.sample_time
    assert step.max() <= robot.speed + 1e-9
    assert traj.t[-1] >= curve.length / robot.speed
    np.testing.assert_allclose([traj.x[-1], traj.y[-1]], p[-1])
    if robot.max_accel:
        assert np.abs(np.diff(traj.v)).max() / robot.sample_time <= robot.max_accel + 1e-6
