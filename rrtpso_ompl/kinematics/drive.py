"""Everything at once: from a planned path to a trajectory and how well the robot follows it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.problem_types import Robot
from ..model.world import World
from .diffdrive import integrate_wheels
from .profile import Trajectory, densify, time_parametrize
from .reference import ReferenceCurve, reference_curve, reference_polynomial, with_goal_heading
from .tracking import TrackingResult, track

__all__ = ["REQUIRED_ROBOT_KEYS", "DriveResult", "drive"]


@dataclass(frozen=True)
class DriveResult:
    """The kinematics of one path: reference, trajectory and how well the model follows it.

    ``goal_yaw`` is the heading wanted at the goal (radians, None: any); the curve's last
    ``turns`` entry is the in-place turn that reaches it.
    """

    polynomial: np.ndarray | None
    curve: ReferenceCurve
    trajectory: Trajectory
    open_loop_error: float
    tracking: TrackingResult
    goal_yaw: float | None = None

    def summary(self) -> dict:
        """JSON-ready figures (lengths in problem units, times in seconds, angles in radians).

        With a goal heading, ``goal_turn``: the in-place turn at the goal, ``{"angle": rad,
        counter-clockwise positive, "duration": s, "max_omega": rad/s, "max_wheel_speed":
        units/s}`` (the largest commands of the rows the turn takes part in); without a goal
        heading the key is absent.
        """
        tr = self.trajectory
        out = {
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
        if self.goal_yaw is not None:
            out["goal_turn"] = self._goal_turn()
        return out

    def _goal_turn(self) -> dict:
        """The in-place turn at the goal, from the trajectory's rows during it."""
        tr = self.trajectory
        t0, t1 = tr.goal_turn_times or (float(tr.t[-1]), float(tr.t[-1]))
        rows = (tr.t + tr.sample_time > t0) & (tr.t < t1)  # the steps the turn takes part in
        wheels = np.abs(np.concatenate([tr.v_right[rows], tr.v_left[rows]]))
        return {
            "angle": float(self.curve.turns[-1]),
            "duration": t1 - t0,
            "max_omega": float(np.abs(tr.omega[rows]).max()) if rows.any() else 0.0,
            "max_wheel_speed": float(wheels.max()) if rows.any() else 0.0,
        }


REQUIRED_ROBOT_KEYS = ("speed", "sample_time", "track_width", "wheel_radius")


def drive(
    path: np.ndarray,
    world: World,
    robot: Robot,
    profile: str = "auto",
    goal_yaw: float | None = None,
    slow_near_obstacles: bool = False,
) -> DriveResult:
    """Reference polynomial, certified reference curve, trajectory, open-loop replay and closed-loop
    tracking for a valid path (see the module docstring for each step).

    ``goal_yaw`` (radians, optional) is the heading wanted at the goal: the trajectory ends with
    the in-place turn to it, the shorter way round (:func:`~.reference.with_goal_heading`). With
    ``slow_near_obstacles`` (it needs ``robot.inflation_radius``) the speed is capped by the
    clearance along the curve (:func:`~rrtpso_ompl.kinematics.time_parametrize`).
    """
    curve = reference_curve(path, world)
    clearance = None
    if slow_near_obstacles:
        curve = densify(curve, curve.length / 200.0)
    curve = with_goal_heading(curve, goal_yaw)
    if slow_near_obstacles:
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
        goal_yaw=goal_yaw,
    )
