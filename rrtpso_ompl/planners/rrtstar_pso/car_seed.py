"""A car's first path from the corridor stage: the plane's workspace route, made poses.

A car-like robot's problem file (:mod:`rrtpso_ompl.ompl_setup.car`) is planned in OMPL's Dubins
or Reeds-Shepp space, where RRT* grows slowly (every motion is a curve checked through Python)
and on a map often finds no path in a real-time budget at all. The plane's corridor stage
(:func:`.corridor.find_corridor_path`) finds a workspace route in milliseconds to a second on
such maps. Here it runs on the world with the robot's radius grown by up to the turning radius
(a route that keeps that much room leaves the car room to turn; less where the start or the goal
is closer to an obstacle; with the robot's own radius when that closes every route), and its
vertices become poses: each faces along the bisector of its
two segments (the start and the goal keep their own headings), with poses added along long
segments every :data:`SPACING` turning radii. Each motion between those poses is then checked as
the car's curve (``si.checkMotion``), and a failing one repaired
(:func:`.repair.repair_path`: a state beside it). The result is a seed for the swarm, used
when RRT* has none or a longer one.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ...ompl_setup.spaces import SpaceAdapter
from ..pso.space_path import MotionChecker
from .corridor import find_corridor_path
from .repair import repair_path

__all__ = ["SPACING", "car_corridor_seed", "route_poses"]

#: Most arc between consecutive poses along a route's straight stretch, in turning radii.
SPACING = 4.0
#: The room kept from obstacles by the route, in turning radii (at most; the start's and the
#: goal's own clearance bound it too).
ROOM = 1.0


def route_poses(route: np.ndarray, start: np.ndarray, goal: np.ndarray,
                rho: float) -> np.ndarray:  # fmt: skip
    """Poses ``(x, y, yaw)`` along a workspace route: its vertices facing along the bisector of
    their segments, poses along segments longer than ``SPACING * rho``, none within ``2 rho``
    of the start or the goal, and those as given (their headings too).

    Parameters
    ----------
    route : ndarray, shape (k, 2)
        From the start's position to the goal's.
    start, goal : ndarray, shape (3,)
        The end poses.
    rho : float
        The turning radius.
    """
    pts = np.asarray(route, dtype=float)
    keep = np.concatenate([[True], np.hypot(*np.diff(pts, axis=0).T) > 1e-12])
    pts = pts[keep]
    if len(pts) < 2:
        return np.array([start, goal], dtype=float)
    direction = np.arctan2(*np.diff(pts, axis=0)[:, ::-1].T)
    rows = [np.asarray(start, dtype=float)]
    for k in range(len(pts) - 1):
        a, b = pts[k], pts[k + 1]
        n = max(1, math.ceil(math.hypot(*(b - a)) / (SPACING * rho)))
        for i in range(1, n):
            rows.append(np.array([*(a + (b - a) * i / n), direction[k]]))
        if k + 1 < len(pts) - 1:
            turn = math.remainder(direction[k + 1] - direction[k], 2 * math.pi)
            rows.append(np.array([*b, direction[k] + 0.5 * turn]))
    rows.append(np.asarray(goal, dtype=float))
    rows = np.array(rows)
    # A car turns round in a circle of radius rho: no pose within 2 rho of an end, where the
    # curve to it would have to turn in too little room.
    near = np.minimum(np.hypot(*(rows[:, :2] - rows[0, :2]).T),
                      np.hypot(*(rows[:, :2] - rows[-1, :2]).T)) < 2.0 * rho  # fmt: skip
    near[[0, -1]] = False
    return rows[~near]


def car_corridor_seed(si: Any, adapter: SpaceAdapter, validator: Any, start: np.ndarray,
                      goal: np.ndarray, seconds: float | None, max_cells: int,
                      rng: np.random.Generator, stop: Callable[[], bool] | None,
                      check_stop: Callable[[], bool] | None,
                      ) -> tuple[np.ndarray | None, str]:  # fmt: skip
    """The corridor stage's route as a checked path of car poses, or None, and why.

    Parameters
    ----------
    si : ob.SpaceInformation
        Its motion validator is ``validator``.
    adapter : SpaceAdapter
        The car space's rows.
    validator : CurveMotionValidator
        Gives the world and the car (:mod:`rrtpso_ompl.ompl_setup.car`).
    start, goal : ndarray, shape (3,)
        The problem's end poses.
    seconds : float or None
        The corridor stage's time (None: bounded by ``max_cells`` only).
    max_cells : int
        The corridor lattice's cells, at most.
    rng : numpy.random.Generator
        The repair's randomness.
    stop, check_stop : callable, optional
        The stop tests of the corridor search and of the check and repair of its route.

    Returns
    -------
    (ndarray or None, str)
        The poses, every motion checked, the ends exactly ``start`` and ``goal``; or None with
        the reason (``"no route"``, ``"not repaired"``).
    """
    world, car = validator.world, validator.car
    ends = np.array([start[:2], goal[:2]])
    room = float(world.point_clearance(ends).min() - world.robot_radius)
    extra = max(0.0, min(ROOM * car.rho, 0.9 * room))
    t0 = time.perf_counter()
    result = find_corridor_path(world.with_robot_radius(world.robot_radius + extra), start[:2],
                                goal[:2], seconds, max_cells, stop)  # fmt: skip
    if result.path is None and extra > 0:  # the room closes a passage: the robot's own radius
        left = None if seconds is None else seconds - (time.perf_counter() - t0)
        if left is None or left > 0:
            result = find_corridor_path(world, start[:2], goal[:2], left, max_cells, stop)
    if result.path is None:
        return None, f"no route ({result.reason})"
    rows = route_poses(result.path, start, goal, car.rho)
    checker = MotionChecker(si, adapter)
    free = checker.path_free(rows, check_stop)
    if free:
        return rows, ""
    if free is None:
        return None, "out of time checking the route"
    repaired = repair_path(rows, adapter, checker, rng, check_stop)
    return (repaired, "") if repaired is not None else (None, "not repaired")
