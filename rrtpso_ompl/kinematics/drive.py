"""Everything at once: from a planned path to a trajectory and how well the robot follows it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.problem import Robot
from ..model.world import World
from .diffdrive import integrate_wheels
from .profile import Trajectory, densify, time_parametrize
from .reference import ReferenceCurve, reference_curve, reference_polynomial
from .tracking import TrackingResult, track

__all__ = ["REQUIRED_ROBOT_KEYS", "DriveResult", "drive"]


@dataclass(frozen=True)
class DriveResult:
    """The kinematics of one path: reference, trajectory and how well the model follows it."""

    polynomial: np.ndarray | None
    curve: ReferenceCurve
    trajectory: Trajectory
    open_loop_error: float
    tracking: TrackingResult

    def summary(self) -> dict:
        """JSON-ready figures (lengths in problem units, times in seconds)."""
        tr = self.trajectory
        return {
            "reference_polynomial": None if self.polynomial is None else self.polynomial.tolist(),
            "curve": self.curve.kind,
            "curve_length": self.curve.length,
            "profile": tr.profile,
            "slow_near_obstacles": tr.slow_near_obstacles,
            "duration": float(tr.t[-1]),
            "samples": len(tr.t),
            "max_v": float(np.abs(tr.v).max()),
            "max_omega": float(np.abs(tr.omega).max()),
            "max_wheel_speed": float(max(np.abs(tr.v_right).max(), np.abs(tr.v_left).max())),
            "open_loop_max_error": self.open_loop_error,
            "tracking_max_error": self.tracking.max_error,
        }


REQUIRED_ROBOT_KEYS = ("speed", "sample_time", "track_width", "wheel_radius")


def drive(
    path: np.ndarray,
    world: World,
    robot: Robot,
    profile: str = "auto",
    slow_near_obstacles: bool = False,
) -> DriveResult:
    """Reference polynomial, certified reference curve, trajectory, open-loop replay and closed-loop
    tracking for a valid path (see the module docstring for each step).

    With ``slow_near_obstacles`` (it needs ``robot.inflation_radius``) the speed is capped by the
    clearance along the curve (:func:`~rrtpso_ompl.kinematics.time_parametrize`)."""
    curve = reference_curve(path, world)
    clearance = None
    if slow_near_obstacles:
        curve = densify(curve, curve.length / 200.0)
        xy = np.column_stack([curve.x, curve.y])
        # Beyond the inflation radius the robot drives at full speed: farther needs no number.
        clearance = world.point_clearance(xy, cap=robot.inflation_radius)
    traj = time_parametrize(curve, robot, profile, clearance)
    poses = integrate_wheels(
        (traj.x[0], traj.y[0], traj.theta[0]), traj.v_right, traj.v_left,
        traj.track_width, traj.sample_time,
    )  # fmt: skip
    open_loop = float(np.hypot(poses[:, 0] - traj.x, poses[:, 1] - traj.y).max())
    tracking = track(traj, max_wheel_speed=robot.max_wheel_speed)
    return DriveResult(
        polynomial=reference_polynomial(path),
        curve=curve,
        trajectory=traj,
        open_loop_error=open_loop,
        tracking=tracking,
    )
