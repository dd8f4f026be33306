"""Closed-loop tracking of a trajectory: Kanayama's kinematic controller on the robot model."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .diffdrive import step_wheels
from .profile import Trajectory

__all__ = ["TrackingResult", "track"]


@dataclass(frozen=True)
class TrackingResult:
    """A closed-loop run: the robot's poses, its commands and the tracking error."""

    poses: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    position_error: np.ndarray

    @property
    def max_error(self) -> float:
        """Largest distance between the robot and its reference, in units."""
        return float(self.position_error.max())


def track(
    traj: Trajectory,
    natural_frequency: float = 1.5,
    damping: float = 0.7,
    max_wheel_speed: float | None = None,
    pose0: tuple[float, float, float] | None = None,
) -> TrackingResult:
    """Follow the trajectory with Kanayama's kinematic controller on the corrected eqs. 1-3.

    With the error in the robot frame ``(e_x, e_y, e_theta)``:
    ``v = v_r cos(e_theta) + K_x e_x`` and ``w = w_r + v_r (K_y e_y + K_theta sin(e_theta))``
    (Kanayama, Kimura, Miyazaki, Noguchi: "A stable tracking control method for an autonomous
    mobile robot", ICRA 1990). Linearised about the reference at speed ``V`` the lateral error obeys
    ``e'' + V K_theta e' + V^2 K_y e = 0``, so the gains follow from a natural frequency ``a``
    (rad/s) and damping ``zeta`` independently of the problem's unit:
    ``K_x = 2 zeta a``, ``K_y = a^2 / V^2``, ``K_theta = 2 zeta a / V`` with ``V`` the largest
    reference speed. Keep ``a * sample_time`` well below 1 (the default 1.5 rad/s suits 0.15 s).
    Wheel commands are scaled down together to ``max_wheel_speed`` when given. The robot starts
    at ``pose0`` (default: the reference's first pose).
    """
    v_nom = max(float(np.abs(traj.v).max()), 1e-9)
    kx = 2.0 * damping * natural_frequency
    ky = natural_frequency**2 / v_nom**2
    kth = 2.0 * damping * natural_frequency / v_nom
    n = len(traj.t)
    poses = np.empty((n, 3))
    pose = pose0 if pose0 is not None else (traj.x[0], traj.y[0], traj.theta[0])
    v_cmd = np.zeros(n)
    w_cmd = np.zeros(n)
    L, ts = traj.track_width, traj.sample_time
    # Python floats, not numpy scalars: the loop is sequential (each pose depends on the last).
    ref = zip(traj.x.tolist(), traj.y.tolist(), traj.theta.tolist(), traj.v.tolist(),
              traj.omega.tolist(), strict=True)  # fmt: skip
    for k, (xr, yr, thr, vref, wref) in enumerate(ref):
        poses[k] = pose
        x, y, th = pose
        dx, dy = xr - x, yr - y
        ex = math.cos(th) * dx + math.sin(th) * dy
        ey = -math.sin(th) * dx + math.cos(th) * dy
        eth = math.atan2(math.sin(thr - th), math.cos(thr - th))
        v = vref * math.cos(eth) + kx * ex
        w = wref + vref * (ky * ey + kth * math.sin(eth))
        vr, vl = v + 0.5 * L * w, v - 0.5 * L * w
        if max_wheel_speed is not None:
            scale = max(abs(vr), abs(vl)) / max_wheel_speed
            if scale > 1.0:
                vr, vl = vr / scale, vl / scale
        v_cmd[k], w_cmd[k] = 0.5 * (vr + vl), (vr - vl) / L
        pose = step_wheels(pose, vr, vl, L, ts)
    err = np.hypot(poses[:, 0] - traj.x, poses[:, 1] - traj.y)
    return TrackingResult(poses=poses, v=v_cmd, omega=w_cmd, position_error=err)
