"""The reference path: the paper's polynomial (eq. 6) and a smooth curve certified collision-free.

:func:`reference_polynomial` is the paper's cubic fit ``y_ref(x_ref)`` (eq. 6), where the path is a
function of x. :func:`reference_curve` is what the robot drives: a C2 cubic spline in chord-length
parameter through the waypoints, arc-length sampled, certified collision-free with the robot's
safety radius and tightened with extra knots where needed; when it cannot be certified the robot
drives the polyline itself, stopping to turn in place at each waypoint.

Certification of the spline: on a parameter interval of length ``h`` a curve ``C`` stays within
``h^2 / 8 * max|C''|`` of its chord; ``C''`` is linear on each spline piece, so its maximum is at an
end point. Every dense chord is checked exactly against the obstacles with the robot radius *plus*
that bound, so the curve itself keeps the radius everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import CubicSpline

from ..model.geometry import dedupe, wrap_angle
from ..model.world import World

__all__ = ["ReferenceCurve", "reference_curve", "reference_polynomial", "with_goal_heading"]


def reference_polynomial(path: np.ndarray, degree: int = 3) -> np.ndarray | None:
    """Least-squares polynomial ``y_ref(x_ref)`` through the waypoints (paper eq. 6).

    Returns the coefficients, highest power first (``a3, a2, a1, a0`` for a cubic, as the paper
    prints them), or None where the path is not a function of x (x not strictly monotonic).
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    dx = np.diff(p[:, 0])
    if len(p) < 2 or not (np.all(dx > 0) or np.all(dx < 0)):
        return None
    deg = min(degree, len(p) - 1)
    return np.polyfit(p[:, 0], p[:, 1], deg)


@dataclass(frozen=True)
class ReferenceCurve:
    """A reference curve sampled densely along its arc length.

    Attributes
    ----------
    s, x, y, theta, kappa : ndarray
        Arc length (units), position, heading (rad, unwrapped) and signed curvature (1/units).
    turns : ndarray
        Heading change to make *in place* at each sample before moving on (rad); non-zero only at
        the waypoints of the polyline fallback, and at the last sample for a goal heading
        (:func:`with_goal_heading`).
    kind : str
        ``"spline"`` or ``"polyline"`` (stop and turn in place at each waypoint).
    knots : ndarray
        The points the spline passes through (the waypoints plus tightening knots).
    """

    s: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    kappa: np.ndarray
    turns: np.ndarray
    kind: str
    knots: np.ndarray = field(repr=False)

    @property
    def length(self) -> float:
        """Total arc length."""
        return float(self.s[-1])


def reference_curve(
    path: np.ndarray,
    world: World,
    spacing: float | None = None,
    max_rounds: int = 12,
    smooth: bool = True,
) -> ReferenceCurve:
    """A smooth curve through the waypoints that keeps the robot radius from every obstacle.

    Parameters
    ----------
    path : (n, 2) array_like
        A valid polyline (e.g. a planner's result).
    world : World
        Obstacles and robot radius for the certification.
    spacing : float, optional
        Length of the dense chords; 1/200 of the path length by default.
    max_rounds : int
        Tightening rounds: each adds the mid-point of every polyline segment whose part of the
        curve could not be certified, which pulls the spline onto the (valid) polyline.

    Returns
    -------
    ReferenceCurve
        A ``"spline"`` when certified; otherwise the ``"polyline"`` itself, driven with stops to
        turn in place at the waypoints (always valid for a valid path).
    """
    p = dedupe(np.asarray(path, dtype=float).reshape(-1, 2), tol=1e-12)
    total = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    spacing = spacing or total / 200.0
    if len(p) < 3 or total == 0.0 or not smooth:
        return _polyline_curve(p, spacing)
    # Tightening only inserts mid-points between consecutive knots, and consecutive knots always
    # lie on one polyline segment, so every knot stays on the (valid) polyline.
    knots = _graded_knots(p)
    for _ in range(max_rounds + 1):
        curve, bad_intervals = _spline_curve(knots, world, spacing)
        if curve is not None:
            return curve
        bad = np.unique(bad_intervals)
        mids = 0.5 * (knots[bad] + knots[bad + 1])
        knots = np.insert(knots, bad + 1, mids, axis=0)
    return _polyline_curve(p, spacing)


def _graded_knots(p: np.ndarray, ratio: float = 2.0) -> np.ndarray:
    """Add knots on long segments so that neighbouring knot spacings differ by at most ``ratio``.

    A natural spline through a long segment followed by short ones (the optimiser's waypoints
    hugging an obstacle's corner) rings: its curvature, hence omega, oscillates. Knots placed on
    the long segment at geometrically growing distances from its short neighbours grade the
    spacing. They lie on the polyline, so they keep the certification argument intact.
    """
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    out = [p[0]]
    for i, length in enumerate(seg):
        ts = []
        for end, neighbour in ((0, seg[i - 1] if i > 0 else length),
                               (1, seg[i + 1] if i + 1 < len(seg) else length)):  # fmt: skip
            d = neighbour * ratio
            while d < 0.5 * length:
                ts.append(d / length if end == 0 else 1.0 - d / length)
                d *= ratio
        out.extend(p[i] + t * (p[i + 1] - p[i]) for t in sorted(ts))
        out.append(p[i + 1])
    return np.array(out)


def _spline_curve(
    knots: np.ndarray, world: World, spacing: float
) -> tuple[ReferenceCurve | None, np.ndarray]:
    """The chord-length C2 spline through ``knots``; (curve, []) when certified, else
    (None, indices of knot intervals that failed)."""
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(knots, axis=0), axis=1))])
    spline = CubicSpline(u, knots, bc_type="natural")
    # Dense parameter grid that contains every knot, so C'' is linear on each interval.
    pieces = [
        np.linspace(u[i], u[i + 1], max(2, math.ceil((u[i + 1] - u[i]) / spacing) + 1))[:-1]
        for i in range(len(u) - 1)
    ]
    grid = np.concatenate([*pieces, [u[-1]]])
    pts = spline(grid)
    d1 = spline(grid, 1)
    d2 = spline(grid, 2)
    h = np.diff(grid)
    c2 = np.linalg.norm(d2, axis=1)
    bound = h**2 / 8.0 * np.maximum(c2[:-1], c2[1:])
    clearance = world.segment_distance(pts[:-1], pts[1:])
    inside = world.points_in_bounds(pts)
    ok = (clearance >= world.threshold + bound) & inside[:-1] & inside[1:]
    if not ok.all():
        interval = np.searchsorted(u, grid[:-1][~ok], side="right") - 1
        return None, np.clip(interval, 0, len(u) - 2)
    speed2 = np.einsum("ij,ij->i", d1, d1)
    kappa = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / speed2**1.5
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    theta = np.unwrap(np.arctan2(d1[:, 1], d1[:, 0]))
    curve = ReferenceCurve(
        s=s, x=pts[:, 0], y=pts[:, 1], theta=theta, kappa=kappa,
        turns=np.zeros_like(s), kind="spline", knots=knots,
    )  # fmt: skip
    return curve, np.empty(0, dtype=int)


def _polyline_curve(p: np.ndarray, spacing: float) -> ReferenceCurve:
    """Drive the polyline: straight segments (zero curvature), turning in place at waypoints.

    Each segment is sampled at most ``spacing`` apart and in at least two steps: the profile
    takes constant acceleration between samples, and the robot stops at both ends of a segment
    (to turn, or at the goal), so a segment of one step would have a mean speed of 0 and take
    no time at all.
    """
    seg = np.diff(p, axis=0)
    length = np.linalg.norm(seg, axis=1)
    if len(seg) == 0:
        z = np.zeros(len(p))
        return ReferenceCurve(s=z, x=p[:, 0], y=p[:, 1], theta=z, kappa=z, turns=z.copy(),
                              kind="polyline", knots=p)  # fmt: skip
    heading = np.unwrap(np.arctan2(seg[:, 1], seg[:, 0]))
    # Bounded: at most total / spacing + 2 per segment samples (200 + 2 n by default).
    steps = np.maximum(2, np.ceil(length / spacing - 1e-9)).astype(np.int64)
    k = np.repeat(np.arange(len(seg)), steps)  # the segment of each sample but the last
    first = np.cumsum(steps) - steps
    frac = (np.arange(int(steps.sum())) - first[k]) / steps[k]
    xy = np.vstack([p[:-1][k] + frac[:, None] * seg[k], p[-1:]])
    s = np.append(np.cumsum(np.append(0.0, length))[:-1][k] + frac * length[k], length.sum())
    # A waypoint sample keeps the heading it is reached with (the segment before it) and turns
    # there to the next one; the start faces its first segment.
    theta = np.append(heading[0], heading[k[1:] - (frac[1:] == 0.0)])
    theta = np.append(theta, heading[-1])
    turns = np.zeros(len(xy))
    turns[first[1:]] = np.diff(heading)
    return ReferenceCurve(
        s=s, x=xy[:, 0], y=xy[:, 1], theta=theta, kappa=np.zeros(len(xy)), turns=turns,
        kind="polyline", knots=p,
    )  # fmt: skip


def with_goal_heading(curve: ReferenceCurve, goal_yaw: float | None) -> ReferenceCurve:
    """The curve with the in-place turn a differential drive makes at its end to face
    ``goal_yaw``.

    Parameters
    ----------
    curve : ReferenceCurve
        From :func:`reference_curve`.
    goal_yaw : float or None
        Heading wanted at the goal, radians counter-clockwise from +x (any value: read modulo
        2 pi); None leaves the curve as it is.

    Returns
    -------
    ReferenceCurve
        The same curve whose last sample turns in place by the shorter way round,
        ``wrap_angle(goal_yaw - theta[-1])`` in [-pi, pi] (half a turn: either way, both as
        short).
        The robot is a disc, so turning in place sweeps nothing new: the certification stands.
    """
    if goal_yaw is None:
        return curve
    turns = curve.turns.copy()
    turns[-1] = wrap_angle(goal_yaw - float(curve.theta[-1]))
    return replace(curve, turns=turns)
