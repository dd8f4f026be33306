"""The limits a dynamic strategy is measured against (issue 14): how early the robot could
possibly arrive, and how early a robot that knew every obstacle's future would arrive by waiting.

- :func:`arrival_lower_bound`: the static world's exact shortest path driven at full speed with
  no turning time. No strategy can arrive earlier, whatever the obstacles do (they only add
  constraints).
- :func:`clairvoyant_wait`: a space-time baseline that knows the obstacles' future: wait at the
  start for the least multiple of the control period after which driving the static optimum
  (with the robot's real stop-and-turn motion) never comes within contact of any obstacle,
  checked exactly (:func:`~rrtpso_ompl.dynamic.motion.first_entry`). An achievable arrival time,
  so an upper bound on the space-time optimum; strategies that beat it dodge instead of waiting.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .motion import Motion, ObstacleTrack, first_entry

__all__ = ["ClairvoyantWait", "arrival_lower_bound", "clairvoyant_wait"]


def arrival_lower_bound(optimum_length: float, speed: float) -> float:
    """Earliest possible arrival, s: the static optimum (units) at full ``speed`` (units/s)."""
    return optimum_length / speed


@dataclass(frozen=True)
class ClairvoyantWait:
    """Result of :func:`clairvoyant_wait`: the wait at the start and the arrival time, s."""

    wait: float
    arrival: float


def clairvoyant_wait(
    path: np.ndarray,
    tracks: list[ObstacleTrack],
    robot_radius: float,
    speed: float,
    turn_rate: float | None,
    sample_time: float,
    max_wait: float,
) -> ClairvoyantWait | None:
    """Wait, then drive ``path``: the least wait (a multiple of ``sample_time``, at most
    ``max_wait``) for which no obstacle ever touches the robot, or None.

    Parameters
    ----------
    path : (n, 2) array
        The route (the static optimum), units.
    tracks : list of ObstacleTrack
        The obstacles' true motions (their whole future: this baseline is clairvoyant).
    robot_radius, speed, turn_rate, sample_time
        The robot's safety radius (units), speed (units/s), turn rate (rad/s, None: instant)
        and control period (s).
    max_wait : float
        Longest wait tried, s (bounds the search: at most ``max_wait / sample_time + 1`` tries).
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    d = p[1] - p[0] if len(p) > 1 else np.zeros(2)
    theta = math.atan2(d[1], d[0])
    n = int(max_wait / sample_time) + 1
    for k in range(n):
        wait = k * sample_time
        drive = Motion.from_path(p, wait, theta, speed, turn_rate)
        motion = Motion.rest(p[0], theta, 0.0, wait).then(drive) if wait > 0 else drive
        if all(
            first_entry(motion, tr.position, 0.0, motion.t_end, robot_radius + tr.radius,
                        tr.breakpoints()) is None
            for tr in tracks
        ):  # fmt: skip
            return ClairvoyantWait(wait, motion.t_end)
    return None
