"""How a problem's path becomes ROS poses: the unit, the spacing and the frame, decided once."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .poses import Poses, dense_poses
from .units import metres_per_unit

__all__ = ["DEFAULT_PATH_RESOLUTION", "RosFrame"]

#: Spacing of a plan's poses without a map, metres: a typical Nav2 costmap resolution.
DEFAULT_PATH_RESOLUTION = 0.05


@dataclass(frozen=True)
class RosFrame:
    """The conversion of one problem's outputs for ROS.

    Attributes
    ----------
    scale : float
        Metres per problem unit (REP 103: ROS lengths are metres).
    resolution : float
        Largest spacing of a plan's poses, metres.
    frame_id : str
        ``header.frame_id`` of every message in the map frame.
    goal_yaw : float or None
        Heading wanted at the goal, radians (the problem's ``goal_yaw``, degrees), or None.
    """

    scale: float
    resolution: float
    frame_id: str = "map"
    goal_yaw: float | None = None

    @classmethod
    def for_problem(
        cls, problem: Any, resolution: float | None = None, frame_id: str = "map"
    ) -> RosFrame:
        """The frame of ``problem``'s ROS outputs.

        Parameters
        ----------
        problem : Problem
            Its ``units`` give the scale (a :class:`~rrtpso_ompl.errors.ProblemError` naming
            the file and ``units`` when unknown); its map, the default resolution.
        resolution : float, optional
            Pose spacing, metres (default: the map's resolution, else
            :data:`DEFAULT_PATH_RESOLUTION`).
        frame_id : str
            The frame the plan is expressed in.
        """
        scale = metres_per_unit(problem.units, problem.source)
        if resolution is None:
            grid = getattr(problem, "map", None)
            resolution = grid.resolution if grid is not None else DEFAULT_PATH_RESOLUTION
        if not (math.isfinite(resolution) and resolution > 0):
            raise ValueError(f"path resolution must be positive and finite, got {resolution!r}")
        yaw_deg = getattr(problem, "goal_yaw", None)
        yaw = None if yaw_deg is None else math.radians(yaw_deg)
        return cls(scale=scale, resolution=float(resolution), frame_id=frame_id, goal_yaw=yaw)

    def metres(self, xy: Any) -> np.ndarray:
        """Problem-unit coordinates (any shape) in metres."""
        return np.asarray(xy, dtype=float) * self.scale

    def poses(self, path: Any) -> Poses:
        """The path's dense poses in metres, the goal heading on the last one; a car's path
        ``(m, 3)`` keeps its own headings (:func:`~.poses.dense_poses`)."""
        p = np.array(path, dtype=float)
        if p.ndim == 2 and p.shape[1] == 3:
            p[:, :2] *= self.scale
        else:
            p = self.metres(p)
        return dense_poses(p, self.resolution, self.goal_yaw)
