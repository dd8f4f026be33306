"""Slowing where clearance is small (``--slow-near-obstacles``): the cap, where it applies, and
nothing changed without it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rrtpso_ompl.kinematics import SLOW_FLOOR, clearance_speed_share, drive, time_parametrize
from rrtpso_ompl.kinematics.profile import densify
from rrtpso_ompl.kinematics.reference import reference_curve
from rrtpso_ompl.model.problem import Robot
from rrtpso_ompl.model.world import World

#: A robot in metres with an inflation band from 0.2 to 1.0 m.
ROBOT = Robot(radius=0.2, wheel_radius=0.05, track_width=0.3, speed=0.5, sample_time=0.1,
              inflation_radius=1.0)  # fmt: skip


def door_world(width: float = 0.8) -> World:
    """A wall across x = 5 of a 10 x 10 m room, with a door of ``width`` centred at y = 5."""
    lo, hi = 5 - width / 2, 5 + width / 2
    return World(((0, 0), (10, 10)), boxes=[(4.9, -1, 5.1, lo), (4.9, hi, 5.1, 11)],
                 robot_radius=ROBOT.radius)  # fmt: skip


#: Through the door's middle (clearance 0.4 m there), bending on either side of it.
PATH = np.array([[1.0, 2.0], [3.0, 4.5], [5.0, 5.0], [7.0, 5.5], [9.0, 8.0]])


def speed_at_door(traj) -> float:
    """The largest commanded speed within 0.1 m of the door's line."""
    return float(traj.v[np.abs(traj.x - 5.0) < 0.1].max())


@pytest.mark.parametrize("profile", ["constant", "limits"])
def test_slower_through_a_door_and_still_at_the_goal(profile):
    world = door_world()
    robot = replace(ROBOT, max_accel=0.5) if profile == "limits" else ROBOT
    fast = drive(PATH, world, robot, profile).trajectory
    slow = drive(PATH, world, robot, profile, slow_near_obstacles=True).trajectory
    assert slow.slow_near_obstacles and not fast.slow_near_obstacles
    # At the door the clearance is 0.4 m: (0.4 - 0.2) / 0.8 = 0.25 < the floor.
    assert speed_at_door(fast) == pytest.approx(0.5)
    assert speed_at_door(slow) <= SLOW_FLOOR * 0.5 + 1e-9
    assert slow.t[-1] > fast.t[-1]
    np.testing.assert_allclose([slow.x[-1], slow.y[-1]], PATH[-1], atol=1e-9)
    assert slow.v[-1] == 0.0
    # Far from the wall it still drives at full speed.
    assert slow.v[np.hypot(slow.x - 1.0, slow.y - 2.0) < 0.5][:-1].max() == pytest.approx(0.5)
    if profile == "limits":
        assert np.abs(np.diff(slow.v)).max() / robot.sample_time <= robot.max_accel + 1e-6


def test_the_cap_holds_at_every_sample():
    world = door_world()
    traj = drive(PATH, world, ROBOT, "constant", slow_near_obstacles=True).trajectory
    # Over a step the robot moves v Ts, so every point of it is within v Ts of both ends: the
    # step's mean speed is at most the cap at the larger clearance plus that.
    d = world.point_clearance(np.column_stack([traj.x, traj.y]))
    reach = np.maximum(d[:-1], d[1:]) + traj.v[:-1] * traj.sample_time
    cap = ROBOT.speed * clearance_speed_share(reach, ROBOT.radius, ROBOT.inflation_radius)
    assert np.all(traj.v[:-1] <= cap + 1e-9)


def test_speed_share_is_linear_in_the_band_and_floored():
    share = clearance_speed_share([0.0, 0.2, 0.44, 0.6, 1.0, 5.0, np.inf], 0.2, 1.0)
    np.testing.assert_allclose(share, [SLOW_FLOOR, SLOW_FLOOR, 0.3, 0.5, 1.0, 1.0, 1.0])


def test_without_the_option_nothing_changes():
    world = door_world()
    curve = reference_curve(PATH, world)
    plain = time_parametrize(curve, replace(ROBOT, inflation_radius=None), "constant")
    inflated = time_parametrize(curve, ROBOT, "constant")
    for name in ("t", "x", "y", "theta", "v", "omega", "v_right", "v_left"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(inflated, name))
    # Slowing with clearances all beyond the inflation radius: the same trajectory, too.
    far = time_parametrize(curve, ROBOT, "constant", np.full(len(curve.s), np.inf))
    np.testing.assert_array_equal(far.v, plain.v)


def test_slowing_needs_an_inflation_radius():
    curve = reference_curve(PATH, door_world())
    with pytest.raises(ValueError, match="inflation_radius"):
        time_parametrize(curve, replace(ROBOT, inflation_radius=None), "constant",
                         np.ones(len(curve.s)))  # fmt: skip


def test_a_densified_polyline_is_the_same_motion():
    world = door_world()
    curve = reference_curve(PATH, world, smooth=False)
    dense = densify(curve, 0.05)
    assert np.diff(dense.s).max() <= 0.05 + 1e-12 < np.diff(curve.s).max()
    for name in ("s", "x", "y"):
        np.testing.assert_allclose(np.interp(curve.s, dense.s, getattr(dense, name)),
                                   getattr(curve, name), atol=1e-12)  # fmt: skip
    assert np.abs(dense.turns).sum() == pytest.approx(np.abs(curve.turns).sum())
    a = time_parametrize(curve, ROBOT, "constant")
    b = time_parametrize(dense, ROBOT, "constant")
    np.testing.assert_allclose([b.x[-1], b.y[-1], b.theta[-1]], [a.x[-1], a.y[-1], a.theta[-1]])
    # The same polyline, with the same stops to turn (only the ramps to them are shorter).
    assert b.t[-1] <= a.t[-1] and np.abs(b.v).max() <= ROBOT.speed + 1e-9
    assert np.count_nonzero((b.v == 0) & (b.omega != 0)) > 0
