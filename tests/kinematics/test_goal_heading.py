"""The turn in place at the goal to a goal heading (``goal_yaw``), and the polyline fallback's
timing that the turn relies on."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from helpers import BOUNDS, PAPER_ROBOT

from rrtpso_ompl.kinematics import (
    drive,
    integrate_wheels,
    reference_curve,
    time_parametrize,
    turn_limits,
    with_goal_heading,
)
from rrtpso_ompl.model.world import World

#: The paper's robot with every limit of the velocity profile.
LIMITED = replace(PAPER_ROBOT, max_speed=30.0, max_wheel_speed=25.0, max_accel=20.0)
PATH = np.array([[20.0, 20.0], [200.0, 150.0], [450.0, 450.0]])


def _heading_error(a: float, b: float) -> float:
    """|a - b| modulo a full turn, radians."""
    return abs(math.remainder(a - b, 2 * math.pi))


def _turn_rows(traj):
    """The rows of the turn at the goal: the robot at the goal with the wheels turning."""
    at_goal = np.hypot(traj.x - traj.x[-1], traj.y - traj.y[-1]) < 1e-9
    return at_goal & (np.abs(traj.omega) > 0)


@pytest.mark.parametrize(("robot", "profile"), [(PAPER_ROBOT, "constant"), (LIMITED, "limits")])
@pytest.mark.parametrize("smooth", [True, False], ids=["spline", "polyline"])
@pytest.mark.parametrize("goal_deg", [-135.0, 0.0, 100.0, 179.0, 540.0])
def test_the_trajectory_ends_facing_the_goal_heading(robot, profile, smooth, goal_deg):
    curve = reference_curve(PATH, World(BOUNDS, [], [], 28.5), smooth=smooth)
    arrive = float(curve.theta[-1])
    goal = math.radians(goal_deg)
    traj = time_parametrize(with_goal_heading(curve, goal), robot, profile)
    assert _heading_error(traj.theta[-1], goal) < 1e-9
    assert np.allclose([traj.x[-1], traj.y[-1]], PATH[-1])
    assert traj.v[-1] == 0.0 and traj.omega[-1] == 0.0  # at rest, facing it
    # The shorter way round: never more than half a turn, in the direction of the difference.
    turned = traj.theta[-1] - arrive
    assert abs(turned) <= math.pi + 1e-12
    assert turned == pytest.approx(math.remainder(goal - arrive, 2 * math.pi), abs=1e-12)
    rows = _turn_rows(traj)
    assert rows.any() and np.all(np.sign(traj.omega[rows]) == np.sign(turned))


@pytest.mark.parametrize(("robot", "profile"), [(PAPER_ROBOT, "constant"), (LIMITED, "limits")])
def test_the_turn_in_place_has_opposite_wheels_within_the_limits(robot, profile):
    curve = reference_curve(PATH, World(BOUNDS, [], [], 28.5))
    traj = time_parametrize(with_goal_heading(curve, math.radians(-100.0)), robot, profile)
    omega, alpha = turn_limits(robot, profile, robot.max_speed or robot.speed)
    turning = _turn_rows(traj) & (traj.v == 0.0)  # the steps wholly in the turn
    assert turning.sum() >= 3
    assert np.allclose(traj.v[turning], 0.0)
    assert np.allclose(traj.v_right[turning], -traj.v_left[turning])  # eqs. 9-10 with v = 0
    assert np.allclose(traj.omega_right[turning], -traj.omega_left[turning])  # eqs. 11-12
    wheel = robot.max_wheel_speed or robot.speed  # the documented default: the driving speed
    assert omega == pytest.approx(2 * wheel / robot.track_width)
    assert np.abs(traj.v_right).max() <= (robot.max_wheel_speed or np.inf) + 1e-9
    assert np.abs(traj.v_right[turning]).max() == pytest.approx(wheel)  # as fast as allowed
    if alpha is not None:  # each wheel speeds up and slows down within max_accel
        ts = robot.sample_time
        for w in (traj.v_right, traj.v_left):
            assert np.abs(np.diff(w[_turn_rows(traj) | np.roll(_turn_rows(traj), 1)])).max() / ts \
                <= robot.max_accel + 1e-6  # fmt: skip


def test_a_short_turn_ramps_up_and_down_within_max_accel():
    """A turn too short to reach the top angular speed is a triangle: it takes
    ``2 sqrt(angle / alpha)`` seconds, ``alpha = 2 max_accel / L``."""
    curve = reference_curve(np.array([[20.0, 20.0], [450.0, 20.0]]), World(BOUNDS))
    angle = 0.05
    traj = time_parametrize(with_goal_heading(curve, angle), LIMITED, "limits")
    t0, t1 = traj.goal_turn_times
    alpha = 2 * LIMITED.max_accel / LIMITED.track_width
    assert t1 - t0 == pytest.approx(2 * math.sqrt(angle / alpha))
    assert _heading_error(traj.theta[-1], angle) < 1e-12


def test_without_a_goal_heading_nothing_changes():
    world = World(BOUNDS, [], [], 28.5)
    plain = drive(PATH, world, LIMITED)
    none = drive(PATH, world, LIMITED, goal_yaw=None)
    assert np.array_equal(plain.trajectory.columns(), none.trajectory.columns())
    assert "goal_turn" not in plain.summary() and plain.trajectory.goal_turn_times is None
    # Facing the goal heading already: no turn, the same trajectory, a turn of 0 reported.
    facing = drive(PATH, world, LIMITED, goal_yaw=float(plain.curve.theta[-1]))
    assert np.array_equal(facing.trajectory.columns(), plain.trajectory.columns())
    assert facing.summary()["goal_turn"] == pytest.approx(
        {"angle": 0.0, "duration": 0.0, "max_omega": 0.0, "max_wheel_speed": 0.0}
    )


def test_drive_reports_the_goal_turn_and_replays_it():
    world = World(BOUNDS, [], [], 28.5)
    result = drive(PATH, world, LIMITED, goal_yaw=math.radians(-90.0))
    turn = result.summary()["goal_turn"]
    arrive = float(result.curve.theta[-1])
    assert turn["angle"] == pytest.approx(math.remainder(-math.pi / 2 - arrive, 2 * math.pi))
    t0, t1 = result.trajectory.goal_turn_times
    assert turn["duration"] == pytest.approx(t1 - t0) and turn["duration"] > 0
    assert turn["max_wheel_speed"] <= LIMITED.max_wheel_speed + 1e-9
    # Eqs. 1-3 replayed turn the robot in place to the goal heading.
    tr = result.trajectory
    poses = integrate_wheels((tr.x[0], tr.y[0], tr.theta[0]), tr.v_right, tr.v_left,
                             tr.track_width, tr.sample_time)  # fmt: skip
    assert _heading_error(poses[-1, 2], -math.pi / 2) < 1e-9


@pytest.mark.parametrize("path", [PATH[[0, 2]], PATH], ids=["two-waypoints", "corner"])
def test_the_polyline_fallback_drives_within_the_limits(path):
    """The polyline was timed between its waypoints only: stopping at both ends of a segment
    (the limits profile always does) gave it a mean speed of 0 and no time at all, so the robot
    jumped along it (2,600 cm/s against a limit of 25)."""
    curve = reference_curve(path, World(BOUNDS), smooth=False)
    traj = time_parametrize(curve, LIMITED, "limits")
    wheels = np.abs(np.concatenate([traj.v_right, traj.v_left]))
    assert wheels.max() <= LIMITED.max_wheel_speed + 1e-9
    assert np.abs(traj.v).max() <= LIMITED.max_speed + 1e-9
    length = np.hypot(*np.diff(path, axis=0).T).sum()
    assert traj.t[-1] >= length / LIMITED.max_speed
    assert traj.path_length == pytest.approx(length)
