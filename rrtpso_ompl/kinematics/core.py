"""From a planned path to wheel commands of a differential-drive robot (paper section 5.1).

Stages, each a pure function:

1. :func:`reference_polynomial`: the paper's cubic fit ``y_ref(x_ref)`` (eq. 6), where the path is a
   function of x.
2. :func:`reference_curve`: a smooth, arc-length-parametrised curve through the waypoints (a C2
   cubic spline in chord-length parameter), certified collision-free with the robot's safety
   radius (see below), tightened with extra knots where needed; when it cannot be certified the
   robot drives the polyline itself, stopping to turn in place at each waypoint.
3. :func:`time_parametrize`: the paper's constant speed, or a profile that respects ``max_speed``,
   ``max_wheel_speed`` and ``max_accel``: slower in tight turns, from rest to rest.
4. :func:`wheel_speeds`: eqs. 7-12 (v_ref, omega_ref, wheel linear and angular speeds).
5. :func:`integrate_wheels` (the corrected eqs. 1-3) and :func:`track` (Kanayama's kinematic
   controller) replay the commands on the robot model.

Printed typos and their corrections (``docs/kinematics.md``): eq. 2 uses the *sum* of the wheel
speeds, like eq. 1; eq. 3 is ``theta(k) = theta(k-1) + (V_right - V_left) / L * Ts``; eq. 8 is
``omega = (x' y'' - y' x'') / (x'^2 + y'^2)`` along a planar curve with time derivatives.

Certification of the spline: on a parameter interval of length ``h`` a curve ``C`` stays within
``h^2 / 8 * max|C''|`` of its chord; ``C''`` is linear on each spline piece, so its maximum is at an
end point. Every dense chord is checked exactly against the obstacles with the robot radius *plus*
that bound, so the curve itself keeps the radius everywhere.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from ..model.problem import Robot
from ..model.world import World

__all__ = [
    "CSV_HEADER",
    "REQUIRED_ROBOT_KEYS",
    "DriveResult",
    "ReferenceCurve",
    "TrackingResult",
    "Trajectory",
    "drive",
    "integrate_wheels",
    "reference_curve",
    "reference_polynomial",
    "time_parametrize",
    "track",
    "wheel_speeds",
]

CSV_HEADER = (
    "t", "x", "y", "theta", "v", "omega", "v_right", "v_left", "omega_right", "omega_left",
)  # fmt: skip


# ----------------------------------------------------------------------------------------------
# 1. The paper's reference path equation (eq. 6)
# ----------------------------------------------------------------------------------------------
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


# ----------------------------------------------------------------------------------------------
# 2. A smooth reference curve, certified collision-free
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ReferenceCurve:
    """A reference curve sampled densely along its arc length.

    Attributes
    ----------
    s, x, y, theta, kappa : ndarray
        Arc length (units), position, heading (rad, unwrapped) and signed curvature (1/units).
    turns : ndarray
        Heading change to make *in place* at each sample before moving on (rad); non-zero only for
        the polyline fallback, at the waypoints.
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
    p = _dedupe(np.asarray(path, dtype=float).reshape(-1, 2))
    total = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    if len(p) < 3 or total == 0.0 or not smooth:
        return _polyline_curve(p)
    spacing = spacing or total / 200.0
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
    return _polyline_curve(p)


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


def _dedupe(p: np.ndarray) -> np.ndarray:
    keep = np.concatenate([[True], np.linalg.norm(np.diff(p, axis=0), axis=1) > 1e-12])
    return p[keep]


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


def _polyline_curve(p: np.ndarray) -> ReferenceCurve:
    """Drive the polyline: straight segments (zero curvature), turning in place at waypoints."""
    seg = np.diff(p, axis=0)
    heading = np.unwrap(np.arctan2(seg[:, 1], seg[:, 0])) if len(seg) else np.zeros(0)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(seg, axis=1))])
    theta = np.concatenate([heading[:1], heading]) if len(heading) else np.zeros(len(p))
    turns = np.zeros(len(p))
    turns[1:-1] = np.diff(heading) if len(heading) > 1 else 0.0
    # At waypoint i the robot arrives with heading[i-1] and leaves with heading[i].
    return ReferenceCurve(
        s=s, x=p[:, 0], y=p[:, 1], theta=theta, kappa=np.zeros(len(p)), turns=turns,
        kind="polyline", knots=p,
    )  # fmt: skip


# ----------------------------------------------------------------------------------------------
# 3. Time parametrisation and 4. velocities (eqs. 7-12)
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Trajectory:
    """Poses and commands sampled every ``sample_time`` from the start to the goal.

    All arrays have one entry per sample; lengths in problem units, angles in radians, times in
    seconds, linear speeds in units/s, angular speeds in rad/s. The velocities of a row are the
    commands to hold until the next row (the mean velocities over that step); the last row is the
    goal, at rest.
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    v_right: np.ndarray
    v_left: np.ndarray
    omega_right: np.ndarray
    omega_left: np.ndarray
    sample_time: float
    track_width: float
    wheel_radius: float
    profile: str

    def columns(self) -> np.ndarray:
        """``(n, 10)`` array in the order of :data:`CSV_HEADER`."""
        return np.column_stack([getattr(self, name) for name in CSV_HEADER])

    def write_csv(self, path: str | Path) -> None:
        """Write the CSV with exactly the header ``t,x,y,theta,v,omega,...``."""
        from ..outputs import publish_atomic

        path = Path(path)
        tmp = path.with_name(f".{path.name}.tmp")
        with tmp.open("w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(CSV_HEADER)
            writer.writerows([[f"{v:.9g}" for v in row] for row in self.columns()])
        publish_atomic(tmp, path)

    @property
    def path_length(self) -> float:
        """Length of the sampled (x, y) polyline."""
        return float(np.hypot(np.diff(self.x), np.diff(self.y)).sum())


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


def time_parametrize(curve: ReferenceCurve, robot: Robot, profile: str = "auto") -> Trajectory:
    """Sample the curve in time every ``robot.sample_time``.

    Parameters
    ----------
    curve : ReferenceCurve
        From :func:`reference_curve`.
    robot : Robot
        Needs ``speed``, ``sample_time``, ``track_width`` and ``wheel_radius``; optional limits
        ``max_speed``, ``max_wheel_speed`` (both units/s) and ``max_accel`` (units/s^2).
    profile : {"auto", "constant", "limits"}
        ``"constant"``: the paper's constant speed ``robot.speed`` along the curve (capped where a
        wheel limit would be exceeded). ``"limits"``: as fast as ``max_speed`` (else ``speed``)
        allows, slower where a wheel would exceed ``max_wheel_speed`` in a turn, accelerating
        from rest and braking to rest within ``max_accel``. ``"auto"`` picks ``"limits"`` when any
        limit is given.

    Returns
    -------
    Trajectory
        Poses at every sample; v and omega (eqs. 7-8) and the wheel speeds (eqs. 9-12) of row k
        are the mean velocities from row k to row k + 1, i.e. the commands to hold for one sample.
        Turns in place (the polyline fallback) run at the largest angular speed the wheel limit
        allows.
    """
    for key in ("speed", "sample_time", "track_width", "wheel_radius"):
        if getattr(robot, key) is None:
            raise ValueError(f"robot.{key} is required to compute velocities")
    if profile == "auto":
        has_limits = any(
            getattr(robot, k) is not None for k in ("max_speed", "max_wheel_speed", "max_accel")
        )
        profile = "limits" if has_limits else "constant"
    if profile not in ("constant", "limits"):
        raise ValueError(f"unknown profile '{profile}' (constant or limits)")
    L, ts = robot.track_width, robot.sample_time
    v_top = robot.max_speed if profile == "limits" and robot.max_speed else robot.speed
    if robot.max_speed is not None:
        v_top = min(v_top, robot.max_speed)
    cap = np.full(len(curve.s), float(v_top))
    if robot.max_wheel_speed is not None:
        # |v| (1 + L |kappa| / 2) is the faster wheel's speed in a turn of curvature kappa.
        # Between samples v and kappa are interpolated, so cap each sample by the larger
        # curvature of the intervals on either side: then the limit holds in between too.
        k = np.abs(curve.kappa)
        k_int = np.maximum(k[:-1], k[1:]) if len(k) > 1 else k
        k_worst = np.maximum(
            np.concatenate([k_int[:1], k_int]), np.concatenate([k_int, k_int[-1:]])
        )
        cap = np.minimum(cap, robot.max_wheel_speed / (1.0 + 0.5 * L * k_worst))
    ds = np.diff(curve.s)
    v = cap.copy()
    stops = curve.turns != 0.0
    if profile == "limits":
        v[0] = v[-1] = 0.0
        v[stops] = 0.0
        if robot.max_accel is not None:
            a = robot.max_accel
            for i in range(1, len(v)):  # forward: accelerate at most a
                v[i] = min(v[i], math.sqrt(v[i - 1] ** 2 + 2 * a * ds[i - 1]))
            for i in range(len(v) - 2, -1, -1):  # backward: brake at most a
                v[i] = min(v[i], math.sqrt(v[i + 1] ** 2 + 2 * a * ds[i]))
    elif stops.any():
        v[stops] = 0.0  # the polyline fallback must stop to turn, whatever the profile
    # Time along the curve: exact for constant acceleration between samples.
    dv = v[:-1] + v[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = np.where(dv > 0, 2.0 * ds / dv, 0.0)
    # Turns in place: as fast as the wheels allow (w = 2 v_wheel / L), else at the speed the
    # robot would drive.
    w_turn = 2.0 * (robot.max_wheel_speed or v_top) / L
    turn_dt = np.abs(curve.turns) / w_turn

    # Event list: (time, s index, in-place turn progress).
    t_nodes = [0.0]
    for i in range(len(ds)):
        t_nodes.append(t_nodes[-1] + turn_dt[i] + dt[i])
    t_end = t_nodes[-1] + turn_dt[-1]
    n = max(1, math.ceil(t_end / ts - 1e-9))
    t = np.arange(n + 1) * ts
    out = _states_at(curve, v, dt, turn_dt, np.asarray(t_nodes), w_turn, np.minimum(t, t_end))
    # The commands of row k are held until row k + 1 (what a controller does with them), so they
    # are the *mean* velocities over that step (eqs. 7-8 integrated over Ts): the heading then
    # matches the reference exactly at every sample, and means of limited speeds stay within the
    # limits. The last row is the goal, at rest.
    v_out = np.append(np.diff(out["s"]) / ts, 0.0)
    w_out = np.append(np.diff(out["theta"]) / ts, 0.0)
    out["v"], out["omega"] = v_out, w_out
    v_r, v_l, w_r, w_l = wheel_speeds(v_out, w_out, L, robot.wheel_radius)
    return Trajectory(
        t=t, x=out["x"], y=out["y"], theta=out["theta"], v=out["v"], omega=out["omega"],
        v_right=v_r, v_left=v_l, omega_right=w_r, omega_left=w_l, sample_time=ts,
        track_width=L, wheel_radius=robot.wheel_radius, profile=profile,
    )  # fmt: skip


def _states_at(curve, v, dt, turn_dt, t_nodes, w_turn, tk) -> dict[str, np.ndarray]:
    """Poses and arc lengths at the times ``tk`` (constant acceleration between curve samples;
    a turn in place, if any, before leaving sample i)."""
    last = len(curve.s) - 1
    i = np.clip(np.searchsorted(t_nodes, tk, side="right") - 1, 0, last)
    local = tk - t_nodes[i]
    turning = (turn_dt[i] > 0) & (local < turn_dt[i])
    th0 = curve.theta[i] + curve.turns[i]
    # Driving from sample i to i + 1 after the turn: constant acceleration from v[i] to v[i+1].
    j = np.minimum(i + 1, last)
    drive_t = np.maximum(local - turn_dt[i], 0.0)
    dt_i = np.append(dt, 0.0)[i]
    moving = ~turning & (i < last) & (dt_i > 0)
    acc = np.where(moving, (v[j] - v[i]) / np.where(dt_i > 0, dt_i, 1.0), 0.0)
    ds = np.where(moving, v[i] * drive_t + 0.5 * acc * drive_t**2, 0.0)
    seg = curve.s[j] - curve.s[i]
    f = np.clip(np.where(seg > 0, ds / np.where(seg > 0, seg, 1.0), 0.0), 0.0, 1.0)
    turned = curve.theta[i] + np.sign(curve.turns[i]) * w_turn * local
    return {
        "x": curve.x[i] + f * (curve.x[j] - curve.x[i]),
        "y": curve.y[i] + f * (curve.y[j] - curve.y[i]),
        "theta": np.where(turning, turned, th0 + f * (curve.theta[j] - th0)),
        "s": curve.s[i] + f * seg,
    }


# ----------------------------------------------------------------------------------------------
# 5. The robot model (corrected eqs. 1-3) and a tracking controller
# ----------------------------------------------------------------------------------------------
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
    poses[0] = pose0 if pose0 is not None else (traj.x[0], traj.y[0], traj.theta[0])
    v_cmd = np.zeros(n)
    w_cmd = np.zeros(n)
    L, ts = traj.track_width, traj.sample_time
    for k in range(n):
        x, y, th = poses[k]
        dx, dy = traj.x[k] - x, traj.y[k] - y
        ex = math.cos(th) * dx + math.sin(th) * dy
        ey = -math.sin(th) * dx + math.cos(th) * dy
        eth = math.atan2(math.sin(traj.theta[k] - th), math.cos(traj.theta[k] - th))
        v = traj.v[k] * math.cos(eth) + kx * ex
        w = traj.omega[k] + traj.v[k] * (ky * ey + kth * math.sin(eth))
        vr, vl = v + 0.5 * L * w, v - 0.5 * L * w
        if max_wheel_speed is not None:
            scale = max(abs(vr), abs(vl)) / max_wheel_speed
            if scale > 1.0:
                vr, vl = vr / scale, vl / scale
        v_cmd[k], w_cmd[k] = 0.5 * (vr + vl), (vr - vl) / L
        if k + 1 < n:
            poses[k + 1] = integrate_wheels(poses[k], [vr, vr], [vl, vl], L, ts)[1]
    err = np.hypot(poses[:, 0] - traj.x, poses[:, 1] - traj.y)
    return TrackingResult(poses=poses, v=v_cmd, omega=w_cmd, position_error=err)


# ----------------------------------------------------------------------------------------------
# Everything at once
# ----------------------------------------------------------------------------------------------
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
            "duration": float(tr.t[-1]),
            "samples": len(tr.t),
            "max_v": float(np.abs(tr.v).max()),
            "max_omega": float(np.abs(tr.omega).max()),
            "max_wheel_speed": float(max(np.abs(tr.v_right).max(), np.abs(tr.v_left).max())),
            "open_loop_max_error": self.open_loop_error,
            "tracking_max_error": self.tracking.max_error,
        }


REQUIRED_ROBOT_KEYS = ("speed", "sample_time", "track_width", "wheel_radius")


def drive(path: np.ndarray, world: World, robot: Robot, profile: str = "auto") -> DriveResult:
    """Reference polynomial, certified reference curve, trajectory, open-loop replay and closed-loop
    tracking for a valid path (see the module docstring for each step)."""
    curve = reference_curve(path, world)
    traj = time_parametrize(curve, robot, profile)
    poses = integrate_wheels(
        (traj.x[0], traj.y[0], traj.theta[0]), traj.v_right, traj.v_left,
        traj.track_width, traj.sample_time,
    )  # fmt: skip
    open_loop = float(np.hypot(poses[:, 0] - traj.x, poses[:, 1] - traj.y).max())
    tracking = track(traj, max_wheel_speed=robot.max_wheel_speed)
    return DriveResult(reference_polynomial(path), curve, traj, open_loop, tracking)
