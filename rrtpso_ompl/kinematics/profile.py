"""Time along the reference curve: the paper's constant speed or a profile within the robot's
limits, sampled every ``Ts`` with the body velocities (eqs. 7-8) and wheel speeds (eqs. 9-12).

Eq. 8 as printed has a typo; along a planar curve with time derivatives it is
``omega = (x' y'' - y' x'') / (x'^2 + y'^2)`` (``docs/kinematics.md``).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import RrtpsoError
from ..model.problem_types import Robot
from ..validation import MAX_STEPS
from .diffdrive import wheel_speeds
from .reference import ReferenceCurve

__all__ = [
    "CSV_HEADER",
    "SLOW_FLOOR",
    "Trajectory",
    "TrajectoryError",
    "check_samples",
    "clearance_speed_share",
    "densify",
    "time_parametrize",
    "turn_limits",
]

CSV_HEADER = (
    "t", "x", "y", "theta", "v", "omega", "v_right", "v_left", "omega_right", "omega_left",
)  # fmt: skip


class TrajectoryError(RrtpsoError, ValueError):
    """A trajectory that cannot be sampled as asked (more than
    :data:`~rrtpso_ompl.validation.MAX_STEPS` samples)."""


def check_samples(duration: float, sample_time: float, what: str = "the path") -> None:
    """Refuse to sample ``duration`` seconds every ``sample_time`` seconds in more than
    :data:`~rrtpso_ompl.validation.MAX_STEPS` samples.

    Raises
    ------
    TrajectoryError
        Naming ``robot.sample_time``, the number of samples and what to change.
    """
    samples = duration / sample_time
    if samples > MAX_STEPS:
        raise TrajectoryError(
            f"robot.sample_time {sample_time:g} s would take {samples:.3g} samples to drive "
            f"{what} ({duration:.3g} s); at most {MAX_STEPS:,}: use a longer sample time or a "
            "higher speed"
        )


#: Lowest share of the top speed near obstacles (``--slow-near-obstacles``): at the robot's radius
#: from an obstacle the robot still drives at 30 % of its speed, so that it never stops short of a
#: door it must pass.
SLOW_FLOOR = 0.3


def clearance_speed_share(clearance, radius: float, inflation_radius: float,
                          floor: float = SLOW_FLOOR) -> np.ndarray:  # fmt: skip
    """Share of the top speed allowed at a clearance (``--slow-near-obstacles``):
    ``clamp((d - r) / (R_i - r), floor, 1)``.

    Full speed from the inflation radius ``R_i`` on, falling linearly to ``floor`` at the robot
    radius ``r``: the band where the inflation cost is charged (:mod:`rrtpso_ompl.model.objective`)
    is also where a careful robot slows.

    Parameters
    ----------
    clearance : array_like
        Distances from the robot's centre to the nearest obstacle (``inf`` allowed), length units.
    radius, inflation_radius : float
        ``r < R_i``, length units.
    floor : float
        The share at ``d <= r``, in (0, 1].
    """
    d = np.asarray(clearance, dtype=float)
    return np.clip((d - radius) / (inflation_radius - radius), floor, 1.0)


def densify(curve: ReferenceCurve, spacing: float) -> ReferenceCurve:
    """The polyline fallback (:func:`~rrtpso_ompl.kinematics.reference_curve`) with samples at
    most ``spacing`` apart along its straight segments (a speed cap needs samples where it
    changes; the polyline has them only at its waypoints). A spline is returned as it is."""
    if curve.kind != "polyline" or len(curve.s) < 2 or spacing <= 0:
        return curve
    return _subdivide(curve, np.ceil(np.diff(curve.s) / spacing))[0]


def _subdivide(curve: ReferenceCurve, parts: np.ndarray) -> tuple[ReferenceCurve, np.ndarray]:
    """The curve with segment ``k`` cut into ``parts[k]`` equal pieces (straight segments: the
    polyline fallback's, whose samples other than the waypoints turn nowhere and drive on with
    the heading the waypoint leaves with). Also returns, for each new sample, the old sample it
    is (index ``>= 0``) or ``-1 - k`` when it lies inside segment ``k``."""
    parts = np.maximum(1, np.asarray(parts)).astype(np.int64)
    seg = np.repeat(np.arange(len(parts)), parts)
    f = (np.arange(int(parts.sum())) - np.repeat(np.cumsum(parts) - parts, parts)) / parts[seg]
    node = f == 0.0
    leave = curve.theta[seg] + curve.turns[seg]

    def lerp(v: np.ndarray) -> np.ndarray:
        return np.append(v[seg] + f * (v[seg + 1] - v[seg]), v[-1])

    out = ReferenceCurve(
        s=lerp(curve.s), x=lerp(curve.x), y=lerp(curve.y),
        theta=np.append(np.where(node, curve.theta[seg], leave), curve.theta[-1]),
        kappa=np.append(np.where(node, curve.kappa[seg], 0.0), curve.kappa[-1]),
        turns=np.append(np.where(node, curve.turns[seg], 0.0), curve.turns[-1]),
        kind=curve.kind, knots=curve.knots,
    )  # fmt: skip
    origin = np.append(np.where(node, seg, -1 - seg), len(curve.s) - 1)
    return out, origin


def _split_rests(
    curve: ReferenceCurve, profile: str, clearance: np.ndarray | None
) -> tuple[ReferenceCurve, np.ndarray | None]:
    """Split each segment between two samples where the robot is at rest at its middle.

    The robot rests where it turns in place and, with ``"limits"``, at both ends; speed is
    interpolated between samples, so a segment between two rests would be crossed at zero speed
    in zero time: a jump (the polyline fallback of a straight path from start to goal, or two
    turning waypoints in a row). Its middle sample lets the robot speed up and brake again. A
    clearance there is the lower bound ``max(d_i, d_j) - ds / 2`` (clearance changes by at most
    the distance moved).
    """
    rest = curve.turns != 0.0
    if profile == "limits":
        rest[0] = rest[-1] = True
    ds = np.diff(curve.s)
    jump = rest[:-1] & rest[1:] & (ds > 0.0)
    if not jump.any():
        return curve, clearance
    out, origin = _subdivide(curve, np.where(jump, 2, 1))
    if clearance is not None:
        k = np.where(origin < 0, -1 - origin, 0)  # the segment an inserted sample halves
        bound = np.maximum(clearance[k], clearance[k + 1]) - 0.5 * ds[k]
        clearance = np.where(origin >= 0, clearance[np.maximum(origin, 0)], bound)
    return out, clearance


#: Rows formatted at a time when writing the CSV (bounds the memory the text takes).
_CSV_CHUNK = 10_000


@dataclass(frozen=True)
class Trajectory:
    """Poses and commands sampled every ``sample_time`` from the start to the goal.

    All arrays have one entry per sample; lengths in problem units, angles in radians, times in
    seconds, linear speeds in units/s, angular speeds in rad/s. The velocities of a row are the
    commands to hold until the next row (the mean velocities over that step); the last row is the
    goal, at rest. ``goal_turn_times`` is when the in-place turn to a goal heading starts and
    ends (s), None without one.
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
    goal_turn_times: tuple[float, float] | None = None
    slow_near_obstacles: bool = False

    def columns(self) -> np.ndarray:
        """``(n, 10)`` array in the order of :data:`CSV_HEADER`."""
        return np.column_stack([getattr(self, name) for name in CSV_HEADER])

    def write_csv(self, path: str | Path) -> None:
        """Write the CSV with exactly the header ``t,x,y,theta,v,omega,...`` (published whole, see
        :func:`rrtpso_ompl.outputs.publish`)."""
        from ..outputs import atomic_path

        columns = self.columns()
        with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(CSV_HEADER)
            for i in range(0, len(columns), _CSV_CHUNK):  # the text of a chunk at a time
                chunk = columns[i : i + _CSV_CHUNK].tolist()  # floats format faster than numpy's
                writer.writerows([f"{v:.9g}" for v in row] for row in chunk)

    @property
    def path_length(self) -> float:
        """Length of the sampled (x, y) polyline."""
        return float(np.hypot(np.diff(self.x), np.diff(self.y)).sum())


def time_parametrize(
    curve: ReferenceCurve, robot: Robot, profile: str = "auto", clearance: np.ndarray | None = None
) -> Trajectory:
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
    clearance : (len(curve.s),) array_like, optional
        Distance from each curve sample to the nearest obstacle (``inf`` beyond the inflation
        radius will do). When given, the robot slows where clearance is small: its speed is at
        most the profile's top speed times :func:`clearance_speed_share` (``robot.radius`` and
        ``robot.inflation_radius``, which must exceed it) of the least clearance the curve can
        have on either side of a sample (clearance changes by at most the distance moved, so
        the cap holds between samples too); accelerations stay within ``max_accel``.

    Returns
    -------
    Trajectory
        Poses at every sample; v and omega (eqs. 7-8) and the wheel speeds (eqs. 9-12) of row k
        are the mean velocities from row k to row k + 1, i.e. the commands to hold for one sample.
        Turns in place (the polyline fallback's at the waypoints, and the turn to a goal heading
        at the end, :func:`~.reference.with_goal_heading`) run with the wheels at opposite speeds
        within the limits (:func:`turn_limits`).

    Raises
    ------
    TrajectoryError
        When the trajectory would have more than :data:`~rrtpso_ompl.validation.MAX_STEPS`
        samples.
    """
    profile, clearance = _checked_inputs(curve, robot, profile, clearance)
    curve, clearance = _split_rests(curve, profile, clearance)
    L, ts = robot.track_width, robot.sample_time
    v, v_top = _speeds(curve, robot, profile, clearance)
    turn = turn_limits(robot, profile, v_top)
    dt, turn_dt, t_nodes = _node_times(curve, v, turn)
    t_end = t_nodes[-1] + turn_dt[-1]
    check_samples(t_end, ts)
    n = max(1, math.ceil(t_end / ts - 1e-9))
    t = np.arange(n + 1) * ts
    out = _states_at(curve, v, dt, turn_dt, t_nodes, turn, np.minimum(t, t_end))
    # The commands of row k are held until row k + 1 (what a controller does with them), so they
    # are the *mean* velocities over that step (eqs. 7-8 integrated over Ts): the heading then
    # matches the reference exactly at every sample, and means of limited speeds stay within the
    # limits. The last row is the goal, at rest.
    v_out = np.append(np.diff(out["s"]) / ts, 0.0)
    w_out = np.append(np.diff(out["theta"]) / ts, 0.0)
    v_r, v_l, w_r, w_l = wheel_speeds(v_out, w_out, L, robot.wheel_radius)
    return Trajectory(
        t=t, x=out["x"], y=out["y"], theta=out["theta"], v=v_out, omega=w_out,
        v_right=v_r, v_left=v_l, omega_right=w_r, omega_left=w_l, sample_time=ts,
        track_width=L, wheel_radius=robot.wheel_radius, profile=profile,
        goal_turn_times=(float(t_nodes[-1]), float(t_end)) if turn_dt[-1] > 0 else None,
        slow_near_obstacles=clearance is not None,
    )  # fmt: skip


def _checked_inputs(curve: ReferenceCurve, robot: Robot, profile: str, clearance):
    """:func:`time_parametrize`'s inputs checked (ValueError naming what is missing or wrong):
    the profile resolved, and ``clearance`` as a flat array of one value per curve sample."""
    for key in ("speed", "sample_time", "track_width", "wheel_radius"):
        if getattr(robot, key) is None:
            raise ValueError(f"robot.{key} is required to compute velocities")
    profile = _resolve_profile(robot, profile)
    if clearance is None:
        return profile, None
    if not robot.inflation_radius or robot.inflation_radius <= robot.radius:
        raise ValueError("robot.inflation_radius (above robot.radius) is required to slow "
                         "near obstacles")  # fmt: skip
    clearance = np.asarray(clearance, dtype=float).reshape(-1)
    if len(clearance) != len(curve.s):
        raise ValueError(f"{len(clearance)} clearances for {len(curve.s)} curve samples")
    return profile, clearance


def turn_limits(robot: Robot, profile: str, v_top: float) -> tuple[float, float | None]:
    """How fast a turn in place runs: its top angular speed and angular acceleration.

    In place (``v = 0``) eqs. 9-10 give opposite wheel speeds ``v_R = -v_L = L omega / 2``.
    The wheels run at ``max_wheel_speed`` when it is given, else at ``v_top``, the speed the
    robot drives at (both wheels' speed on a straight line): ``omega = 2 v_wheel / L``. In the
    ``limits`` profile with ``max_accel`` each wheel also speeds up and slows down at most at
    ``max_accel``: the turn is a trapezoid in omega with ``alpha = 2 max_accel / L``.

    Parameters
    ----------
    robot : Robot
        Its ``track_width`` (units) and the optional limits.
    profile : {"constant", "limits"}
        The resolved profile (``max_accel`` only shapes ``limits``, as it does for driving).
    v_top : float
        The profile's top linear speed, units/s.

    Returns
    -------
    omega : float
        Top angular speed of a turn, rad/s.
    alpha : float or None
        Angular acceleration, rad/s^2; None: the turn starts and stops at full speed (the
        paper's constant-speed assumption).
    """
    L = robot.track_width
    omega = 2.0 * (robot.max_wheel_speed or v_top) / L
    limited = profile == "limits" and robot.max_accel is not None
    return omega, (2.0 * robot.max_accel / L if limited else None)


def _turn_time(angle: np.ndarray, turn: tuple[float, float | None]) -> np.ndarray:
    """Seconds to turn in place by ``|angle|`` (rad) within ``turn`` (:func:`turn_limits`):
    ``|angle| / omega``, plus ``omega / alpha`` for the ramps (a triangle when the turn is too
    short to reach ``omega``)."""
    angle = np.abs(angle)
    omega, alpha = turn
    if alpha is None:
        return angle / omega
    peak = np.minimum(omega, np.sqrt(angle * alpha))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(angle > 0.0, angle / peak + peak / alpha, 0.0)


def _turned(tau: np.ndarray, angle: np.ndarray, turn: tuple[float, float | None]) -> np.ndarray:
    """Radians turned ``tau`` seconds into a turn in place by ``|angle|`` (:func:`_turn_time`)."""
    angle = np.abs(angle)
    omega, alpha = turn
    if alpha is None:
        return np.minimum(omega * tau, angle)
    peak = np.minimum(omega, np.sqrt(angle * alpha))
    total = _turn_time(angle, turn)
    ramp = peak / alpha
    tau = np.clip(tau, 0.0, total)
    rise = 0.5 * alpha * tau**2
    fall = angle - 0.5 * alpha * (total - tau) ** 2
    cruise = peak * (tau - 0.5 * ramp)
    return np.where(tau < ramp, rise, np.where(tau > total - ramp, fall, cruise))


def _resolve_profile(robot: Robot, profile: str) -> str:
    """``"auto"`` is ``"limits"`` when the robot declares any limit, else ``"constant"``."""
    if profile == "auto":
        has_limits = any(
            getattr(robot, k) is not None for k in ("max_speed", "max_wheel_speed", "max_accel")
        )
        profile = "limits" if has_limits else "constant"
    if profile not in ("constant", "limits"):
        raise ValueError(f"unknown profile '{profile}' (constant or limits)")
    return profile


def _speeds(
    curve: ReferenceCurve, robot: Robot, profile: str, clearance: np.ndarray | None = None
) -> tuple[np.ndarray, float]:
    """The speed at each curve sample (units/s) and the top speed of the profile."""
    L = robot.track_width
    v_top = robot.max_speed if profile == "limits" and robot.max_speed else robot.speed
    if robot.max_speed is not None:
        v_top = min(v_top, robot.max_speed)
    v = np.full(len(curve.s), float(v_top))
    if robot.max_wheel_speed is not None:
        # |v| (1 + L |kappa| / 2) is the faster wheel's speed in a turn of curvature kappa.
        # Between samples v and kappa are interpolated, so cap each sample by the larger
        # curvature of the intervals on either side: then the limit holds in between too.
        k = np.abs(curve.kappa)
        k_int = np.maximum(k[:-1], k[1:]) if len(k) > 1 else k
        k_worst = np.maximum(
            np.concatenate([k_int[:1], k_int]), np.concatenate([k_int, k_int[-1:]])
        )
        v = np.minimum(v, robot.max_wheel_speed / (1.0 + 0.5 * L * k_worst))
    if clearance is not None:
        v = np.minimum(v, v_top * _clearance_caps(curve, robot, clearance))
    stops = curve.turns != 0.0
    if profile == "limits":
        v[0] = v[-1] = 0.0
        v[stops] = 0.0
        if robot.max_accel is not None:
            _limit_acceleration(v, np.diff(curve.s), robot.max_accel)
    elif stops.any():
        v[stops] = 0.0  # the polyline fallback must stop to turn, whatever the profile
    return v, float(v_top)


def _clearance_caps(curve: ReferenceCurve, robot: Robot, clearance: np.ndarray) -> np.ndarray:
    """The speed share at each sample (:func:`clearance_speed_share`) of the least clearance on
    the intervals either side of it: a point ``t`` along an interval of length ``ds`` has at least
    ``max(d_i - t, d_j - (ds - t)) >= (d_i + d_j - ds) / 2``. The speed between two samples lies
    between theirs, so it keeps the cap of the interval everywhere."""
    if len(clearance) < 2:
        low = clearance
    else:
        ds = np.diff(curve.s)
        with np.errstate(invalid="ignore"):  # inf + inf is inf; never inf - inf here
            between = 0.5 * (clearance[:-1] + clearance[1:] - ds)
        low = np.minimum(np.concatenate([between[:1], between]),
                         np.concatenate([between, between[-1:]]))  # fmt: skip
    return clearance_speed_share(low, robot.radius, robot.inflation_radius)


def _node_times(
    curve: ReferenceCurve, v: np.ndarray, turn: tuple[float, float | None]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time along the curve at speeds ``v`` (units/s) with turns in place within ``turn``
    (:func:`turn_limits`).

    Returns
    -------
    dt : ndarray
        Seconds from each curve sample to the next (exact for constant acceleration between
        samples); one fewer than the samples.
    turn_dt : ndarray
        Seconds of each sample's turn in place (0 where there is none).
    t_nodes : ndarray
        When each sample is reached, before its turn (s).
    """
    ds = np.diff(curve.s)
    dv = v[:-1] + v[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = np.where(dv > 0, 2.0 * ds / dv, 0.0)
    turn_dt = _turn_time(curve.turns, turn)
    t_nodes = np.concatenate([[0.0], np.cumsum(turn_dt[:-1] + dt)])
    return dt, turn_dt, t_nodes


def _limit_acceleration(v: np.ndarray, ds: np.ndarray, a: float) -> None:
    """Lower ``v`` in place so that no step accelerates or brakes faster than ``a``.

    A forward pass, then a backward one; each step depends on the one before, so these are
    sequential recurrences (O(n), once per trajectory).
    """
    for i in range(1, len(v)):  # forward: accelerate at most a
        v[i] = min(v[i], math.sqrt(v[i - 1] ** 2 + 2 * a * ds[i - 1]))
    for i in range(len(v) - 2, -1, -1):  # backward: brake at most a
        v[i] = min(v[i], math.sqrt(v[i + 1] ** 2 + 2 * a * ds[i]))


def _states_at(curve, v, dt, turn_dt, t_nodes, turn, tk) -> dict[str, np.ndarray]:
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
    turned = curve.theta[i] + np.sign(curve.turns[i]) * _turned(local, curve.turns[i], turn)
    return {
        "x": curve.x[i] + f * (curve.x[j] - curve.x[i]),
        "y": curve.y[i] + f * (curve.y[j] - curve.y[i]),
        "theta": np.where(turning, turned, th0 + f * (curve.theta[j] - th0)),
        "s": curve.s[i] + f * seg,
    }
