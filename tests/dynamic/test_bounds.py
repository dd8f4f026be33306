"""The limits of the dynamic benchmark: the lower bound and the clairvoyant wait."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rrtpso_ompl.dynamic import (
    Motion,
    ObstacleTrack,
    arrival_lower_bound,
    clairvoyant_wait,
    closest_approach,
)
from rrtpso_ompl.model.problem import MovingObstacle

PATH = np.array([[0.0, 0.0], [100.0, 0.0]])


def test_lower_bound_is_the_optimum_at_full_speed():
    assert arrival_lower_bound(610.0, 20.0) == pytest.approx(30.5)


def test_no_obstacles_means_no_wait():
    got = clairvoyant_wait(PATH, [], 5.0, 10.0, None, 0.1, 60.0)
    assert got.wait == 0.0 and got.arrival == pytest.approx(10.0)


def test_waits_exactly_until_a_crossing_obstacle_has_passed():
    # Crossing the route at x = 50 from below at t = 5 s, exactly when the robot would be there.
    obs = MovingObstacle(radius=5.0, start=(50.0, -50.0), speed=10.0, heading_deg=90.0)
    track = ObstacleTrack.from_obstacle(obs)
    got = clairvoyant_wait(PATH, [track], 5.0, 10.0, None, 0.1, 60.0)
    assert got is not None and got.wait > 0.0
    drive = Motion.from_path(PATH, got.wait, 0.0, 10.0, None)
    motion = Motion.rest(PATH[0], 0.0, 0.0, got.wait).then(drive)
    d, _ = closest_approach(motion, track.position, 0.0, motion.t_end)
    assert d >= 10.0 - 1e-9  # never within contact
    # One period less would touch it: the wait is the least one.
    shorter = got.wait - 0.1
    drive = Motion.from_path(PATH, shorter, 0.0, 10.0, None)
    early = Motion.rest(PATH[0], 0.0, 0.0, shorter).then(drive) if shorter > 0 else drive
    assert closest_approach(early, track.position, 0.0, early.t_end)[0] < 10.0
    assert got.arrival == pytest.approx(got.wait + 10.0)
    assert got.arrival > arrival_lower_bound(100.0, 10.0)


def test_an_obstacle_parked_on_the_route_has_no_wait():
    obs = MovingObstacle(radius=5.0, start=(50.0, 0.0), speed=0.0, heading_deg=0.0)
    track = ObstacleTrack.from_obstacle(obs)
    assert clairvoyant_wait(PATH, [track], 5.0, 10.0, None, 0.5, 20.0) is None
    assert math.isfinite(arrival_lower_bound(100.0, 10.0))
