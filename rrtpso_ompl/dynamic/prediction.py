"""Collision prediction: where and when the robot's plan would meet a moving obstacle.

The robot drives stop-and-turn motions and the obstacles move at constant velocity (eqs. 14-15),
so both are piecewise linear in time and the cross point is an exact root of a quadratic
(:func:`~rrtpso_ompl.dynamic.motion.first_entry`), not a sample. A disc's sweep over a time window
is exactly a capsule (circle + rectangle + circle).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from ..model.problem_types import Circle, Polygon
from .motion import Motion, first_entry

__all__ = ["Threat", "capsule", "extrapolate", "predict_threats", "true_runs"]


@dataclass(frozen=True)
class Threat:
    """A predicted collision with one obstacle.

    ``t_enter`` is the cross-point time, ``t_exit`` the end of the collision zone (s);
    ``cross_point`` is the robot's planned position at ``t_enter`` and ``obstacle_point`` the
    obstacle's predicted centre then (units).
    """

    obstacle: int
    t_enter: float
    t_exit: float
    cross_point: np.ndarray
    obstacle_point: np.ndarray


def predict_threats(
    plan: Motion,
    t_now: float,
    observations: Mapping[int, tuple[np.ndarray, np.ndarray, float]],
    robot_radius: float,
    margin: float,
) -> list[Threat]:
    """Predicted collisions of the remaining plan with each observed obstacle, earliest first.

    Parameters
    ----------
    plan : Motion
        The robot's current plan.
    t_now : float
        Now, s.
    observations : mapping
        ``obstacle index -> (position, velocity, radius)`` measured at ``t_now``.
    robot_radius : float
        SR, units.
    margin : float
        A collision is predicted below ``SR + SO + margin``.
    """
    threats = []
    t_end = max(plan.t_end, t_now)
    for j, (pos, vel, radius) in observations.items():
        at = extrapolate(pos, vel, t_now)
        hit = first_entry(plan, at, t_now, t_end, robot_radius + radius + margin)
        if hit is not None:
            te, tx = hit
            threats.append(Threat(j, te, tx, plan.position(te), at(np.array([te]))[0]))
    return sorted(threats, key=lambda th: th.t_enter)


def extrapolate(pos: np.ndarray, vel: np.ndarray, t0: float) -> Callable[[np.ndarray], np.ndarray]:
    """Constant-velocity extrapolation (eqs. 14-15) from ``pos`` at ``t0``."""
    pos = np.asarray(pos, dtype=float)
    vel = np.asarray(vel, dtype=float)
    return lambda ts: pos + (np.asarray(ts, dtype=float)[..., None] - t0) * vel


def capsule(a: np.ndarray, b: np.ndarray, radius: float) -> list[Circle | Polygon]:
    """The area swept by a disc of ``radius`` moving from ``a`` to ``b``, exactly.

    Two circles and the rectangle between them (the rectangle is omitted when ``a == b``).
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    parts: list[Circle | Polygon] = [Circle((float(a[0]), float(a[1])), radius)]
    d = b - a
    n = float(np.hypot(*d))
    if n > 0:
        perp = np.array([-d[1], d[0]]) / n * radius
        ring = [a - perp, b - perp, b + perp, a + perp]  # counter-clockwise
        parts.append(Polygon(tuple((float(x), float(y)) for x, y in ring)))
        parts.append(Circle((float(b[0]), float(b[1])), radius))
    return parts


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``(first, last)`` of the True runs in ``mask``."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]
