"""A path resampled into dense poses, the way Nav2's planners publish a plan.

Nav2's global planners publish one pose about every costmap cell, and its controllers (DWB,
Regulated Pure Pursuit, MPPI) look ahead along those poses; one pose per waypoint, metres apart,
starves them. :func:`dense_poses` places poses along every segment no farther apart than the
resolution, each with the heading of its segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["MAX_POSES", "Poses", "dense_poses"]

#: Bound on the poses of one path (an input-driven allocation): 10 million poses, 240 MB.
MAX_POSES = 10_000_000


@dataclass(frozen=True)
class Poses:
    """Poses along a path.

    Attributes
    ----------
    xy : (k, 2) ndarray
        Positions, in the units of the path given (metres for ROS outputs).
    yaw : (k,) ndarray
        Headings, radians, counter-clockwise from +x: the heading of the segment each pose lies
        on (the last pose: the goal heading when one is given, else the last segment's).
    """

    xy: np.ndarray
    yaw: np.ndarray

    def __len__(self) -> int:
        return len(self.xy)


def dense_poses(path: np.ndarray, resolution: float, goal_yaw: float | None = None) -> Poses:
    """Poses along ``path`` no farther apart than ``resolution``, waypoints included.

    Parameters
    ----------
    path : (m, 2) or (m, 3) array_like
        Waypoints, in any length unit (the result is in the same unit); with a third column,
        a car's headings there (radians): the poses between take them, turned the shorter
        way, and the last pose the last one (``goal_yaw`` is not used); else each pose faces
        along its segment.
    resolution : float
        Largest spacing between consecutive poses, same unit, > 0. Each segment of length ``L``
        gets ``ceil(L / resolution)`` equal steps.
    goal_yaw : float, optional
        Heading wanted at the goal, radians; the last pose takes it (the in-place turn there is
        the robot's, see :mod:`rrtpso_ompl.kinematics`).

    Returns
    -------
    Poses

    Raises
    ------
    ValueError
        ``resolution`` is not positive and finite, or the path would need more than
        :data:`MAX_POSES` poses.
    """
    given = np.asarray(path, dtype=float)
    headed = given.ndim == 2 and given.shape[1] == 3  # a car's poses: their own headings
    p = given[:, :2] if headed else given.reshape(-1, 2)
    if not (math.isfinite(resolution) and resolution > 0):
        raise ValueError(f"path resolution must be positive and finite, got {resolution!r}")
    if len(p) == 0:
        return Poses(np.zeros((0, 2)), np.zeros(0))
    d = np.diff(p, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    keep = length > 0.0  # repeated waypoints carry no heading
    d, length, starts = d[keep], length[keep], p[:-1][keep]
    if len(d) == 0:
        yaw0 = 0.0 if goal_yaw is None else goal_yaw
        return Poses(p[:1].copy(), np.array([yaw0]))
    steps = np.maximum(1, np.ceil(length / resolution - 1e-9)).astype(np.int64)
    total = int(steps.sum()) + 1
    if total > MAX_POSES:
        raise ValueError(
            f"{total} poses at resolution {resolution:g} exceed the bound of {MAX_POSES}; "
            "use a coarser path resolution"
        )
    seg = np.repeat(np.arange(len(d)), steps)
    first = np.cumsum(steps) - steps
    frac = (np.arange(total - 1) - first[seg]) / steps[seg]
    xy = np.empty((total, 2))
    xy[:-1] = starts[seg] + frac[:, None] * d[seg]
    xy[-1] = p[-1]
    if headed:
        return Poses(xy, _between(given[:, 2], keep, seg, frac))
    heading = np.arctan2(d[:, 1], d[:, 0])
    yaw = np.append(heading[seg], heading[-1] if goal_yaw is None else goal_yaw)
    return Poses(xy, yaw)


def _between(yaw: np.ndarray, keep: np.ndarray, seg: np.ndarray, frac: np.ndarray) -> np.ndarray:
    """Headings of the poses of :func:`dense_poses` from a car's headings at the waypoints: each
    step's between its segment's end poses' (turned the shorter way), the last the last."""
    yaw0, yaw1 = yaw[:-1][keep], yaw[1:][keep]
    turn = np.angle(np.exp(1j * (yaw1 - yaw0)))
    out = np.append(yaw0[seg] + frac * turn[seg], yaw[-1])
    return np.angle(np.exp(1j * out))
