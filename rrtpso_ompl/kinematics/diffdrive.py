"""The differential-drive robot: wheel speeds from body velocities (eqs. 9-12) and back to poses
(eqs. 1-3, corrected).

Printed typos and their corrections (``docs/kinematics.md``): eq. 2 uses the *sum* of the wheel
speeds, like eq. 1; eq. 3 is ``theta(k) = theta(k-1) + (V_right - V_left) / L * Ts``.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["integrate_wheels", "step_wheels", "wheel_speeds"]


def wheel_speeds(
    v: np.ndarray, omega: np.ndarray, track_width: float, wheel_radius: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Wheel commands from the body velocities (paper eqs. 9-12).

    ``v_R = (2 v + L w) / 2`` (9), ``v_L = (2 v - L w) / 2`` (10), ``w_R = v_R / r`` (11),
    ``w_L = v_L / r`` (12).
    """
    v = np.asarray(v, dtype=float)
    omega = np.asarray(omega, dtype=float)
    v_r = (2.0 * v + track_width * omega) / 2.0
    v_l = (2.0 * v - track_width * omega) / 2.0
    return v_r, v_l, v_r / wheel_radius, v_l / wheel_radius


def integrate_wheels(
    pose0: tuple[float, float, float],
    v_right: np.ndarray,
    v_left: np.ndarray,
    track_width: float,
    sample_time: float,
) -> np.ndarray:
    """Replay wheel speeds on the differential-drive model (paper eqs. 1-3, corrected).

    ``theta(k) = theta(k-1) + (V_right - V_left) / L * Ts`` (3),
    ``x(k) = x(k-1) + (V_left + V_right) / 2 * cos(theta(k)) * Ts`` (1),
    ``y(k) = y(k-1) + (V_left + V_right) / 2 * sin(theta(k)) * Ts`` (2),
    with the wheel speeds of step k-1 held over the step (zero-order hold).

    Returns
    -------
    (n, 3) ndarray
        Poses ``(x, y, theta)``, the first being ``pose0``.
    """
    v_right = np.asarray(v_right, dtype=float)
    v_left = np.asarray(v_left, dtype=float)
    x0, y0, th0 = pose0
    # Eq. 3 accumulates the heading; eqs. 1-2 then move along the *new* heading of each step.
    dtheta = (v_right[:-1] - v_left[:-1]) / track_width * sample_time
    theta = th0 + np.concatenate([[0.0], np.cumsum(dtheta)])
    step = 0.5 * (v_right[:-1] + v_left[:-1]) * sample_time
    x = x0 + np.concatenate([[0.0], np.cumsum(step * np.cos(theta[1:]))])
    y = y0 + np.concatenate([[0.0], np.cumsum(step * np.sin(theta[1:]))])
    return np.column_stack([x, y, theta])


def step_wheels(
    pose: tuple[float, float, float],
    v_right: float,
    v_left: float,
    track_width: float,
    sample_time: float,
) -> tuple[float, float, float]:
    """One step of :func:`integrate_wheels` (the same eqs. 1-3) for scalars: the pose after
    holding the wheel speeds ``v_right``, ``v_left`` (units/s) for ``sample_time`` seconds.

    A closed loop needs the poses one at a time; this is a hundred times cheaper per step than
    the vectorised form on arrays of two."""
    x, y, theta = pose
    theta = theta + (v_right - v_left) / track_width * sample_time
    step = 0.5 * (v_right + v_left) * sample_time
    return x + step * math.cos(theta), y + step * math.sin(theta), theta
