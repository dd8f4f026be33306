"""Timed motions of the robot and of the moving obstacles, and exact closest approach between them.

Everything that moves in a simulation is *piecewise linear in time*: the robot drives its polyline
with the differential-drive model's stop-and-turn motion (straight at constant speed with both
wheels at ``v``, turns in place with the wheels at ``+-v_w``), and a moving obstacle moves at
constant velocity (paper eqs. 14-15) with, optionally, sudden changes of heading. Between two
breakpoints the *relative* position of robot and obstacle is then linear in time, so the smallest
distance and the first time the distance drops below a threshold are closed-form (a point-segment
distance and a quadratic). Collision prediction is exact, not sampled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.geometry import dedupe, wrap_angle

__all__ = ["Motion", "ObstacleTrack", "arc_position", "closest_approach", "first_entry"]


@dataclass(frozen=True)
class Motion:
    """A robot motion with knots ``t`` (s, increasing), ``xy`` (units) and ``theta`` (rad).

    Between consecutive knots the robot either translates (``theta`` constant) or turns in place
    (``xy`` constant, ``theta`` linear). Before ``t[0]`` and after ``t[-1]`` it rests at the first
    and last knot. ``theta`` is unwrapped (continuous), so linear interpolation is the turn.
    """

    t: np.ndarray
    xy: np.ndarray
    theta: np.ndarray

    # -- construction ---------------------------------------------------------------------------
    @classmethod
    def from_path(
        cls,
        path: np.ndarray,
        t0: float,
        theta0: float | None,
        speed: float,
        turn_rate: float | None,
        allow_reverse: bool = False,
    ) -> Motion:
        """Drive ``path`` from time ``t0``: turn in place towards each segment, then drive it.

        Parameters
        ----------
        path : (n, 2) array
            Waypoints, units; repeated points are skipped.
        t0 : float
            Start time, s.
        theta0 : float or None
            Heading at ``t0``, rad; None faces the first segment (no initial turn).
        speed : float
            Linear speed on straight pieces, units/s (both wheels at this speed).
        turn_rate : float or None
            Angular speed of a turn in place, rad/s (``2 v_w / L`` with the wheels at ``+-v_w``);
            None makes turns instantaneous.
        allow_reverse : bool
            Drive a segment backwards when that needs the smaller turn (a differential drive can:
            both wheels at ``-v``). Used by evasive manoeuvres; routes are driven forwards.
        """
        p = dedupe(np.asarray(path, dtype=float).reshape(-1, 2))
        heading = np.arctan2(np.diff(p[:, 1]), np.diff(p[:, 0]))
        th = float(theta0) if theta0 is not None else (float(heading[0]) if len(heading) else 0.0)
        ts, xs, ths = [float(t0)], [p[0]], [th]
        for i, h in enumerate(heading):
            turn = wrap_angle(h - th)
            if allow_reverse and abs(turn) > math.pi / 2:
                turn = wrap_angle(h + math.pi - th)
            if turn != 0.0:
                th = th + turn
                dt = abs(turn) / turn_rate if turn_rate else 0.0
                ts.append(ts[-1] + dt)
                xs.append(p[i])
                ths.append(th)
            ts.append(ts[-1] + float(np.hypot(*(p[i + 1] - p[i]))) / speed)
            xs.append(p[i + 1])
            ths.append(th)
        return cls(np.array(ts), np.array(xs), np.array(ths))

    @classmethod
    def rest(cls, xy: np.ndarray, theta: float, t0: float, t1: float) -> Motion:
        """Stand still at ``xy`` from ``t0`` to ``t1``."""
        xy = np.asarray(xy, dtype=float)
        return cls(np.array([t0, t1]), np.array([xy, xy]), np.array([theta, theta]))

    # -- queries ---------------------------------------------------------------------------------
    @property
    def t_end(self) -> float:
        """Time of the last knot (arrival), s."""
        return float(self.t[-1])

    @property
    def end(self) -> np.ndarray:
        """Final position."""
        return self.xy[-1]

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Positions at times ``t``, shape ``(..., 2)`` (resting outside the knot range)."""
        t = np.asarray(t, dtype=float)
        return np.stack(
            [np.interp(t, self.t, self.xy[:, 0]), np.interp(t, self.t, self.xy[:, 1])], -1
        )

    def heading(self, t: float | np.ndarray) -> np.ndarray:
        """Headings at times ``t``, rad (unwrapped)."""
        return np.interp(np.asarray(t, dtype=float), self.t, self.theta)

    def path_length(self, t0: float | None = None, t1: float | None = None) -> float:
        """Distance driven between ``t0`` and ``t1`` (default: all of it), units."""
        lo = self.t[0] if t0 is None else t0
        hi = self.t[-1] if t1 is None else t1
        inner = self.t[(self.t > lo) & (self.t < hi)]
        pts = self.position(np.concatenate([[lo], inner, [hi]]))
        return float(np.hypot(*np.diff(pts, axis=0).T).sum())

    def waypoints_after(self, t: float) -> np.ndarray:
        """The polyline still to drive after time ``t``: the position at ``t``, then the knots."""
        later = self.xy[self.t > t]
        return dedupe(np.vstack([self.position(t)[None], later]))

    def until(self, t: float) -> Motion:
        """This motion cut at time ``t`` (a knot is added there)."""
        keep = self.t < t
        return Motion(
            np.append(self.t[keep], t),
            np.vstack([self.xy[keep], self.position(t)[None]]),
            np.append(self.theta[keep], self.heading(t)),
        )

    def delayed(self, t: float, wait: float) -> Motion:
        """This motion with a stop of ``wait`` seconds inserted at time ``t`` (the rest is the
        same route, ``wait`` later)."""
        head = self.until(t)
        later = self.t > t
        return Motion(
            np.concatenate([head.t, [t + wait], self.t[later] + wait]),
            np.vstack([head.xy, head.xy[-1:], self.xy[later]]),
            np.concatenate([head.theta, head.theta[-1:], self.theta[later]]),
        )

    def then(self, other: Motion) -> Motion:
        """This motion followed by ``other``, which must start where and when this one ends.

        ``other``'s headings are shifted by a multiple of 2 pi so that the heading stays continuous.
        """
        if not math.isclose(other.t[0], self.t_end, rel_tol=0, abs_tol=1e-9) or not np.allclose(
            other.xy[0], self.end, rtol=0, atol=1e-7
        ):
            raise ValueError("motions must join in time and place")
        shift = 2 * math.pi * round((self.theta[-1] - other.theta[0]) / (2 * math.pi))
        return Motion(
            np.concatenate([self.t, other.t[1:]]),
            np.vstack([self.xy, other.xy[1:]]),
            np.concatenate([self.theta, other.theta[1:] + shift]),
        )

    def sample(self, sample_time: float) -> np.ndarray:
        """``[t, x, y, theta]`` rows every ``sample_time`` from ``t[0]``, plus the arrival."""
        n = math.floor((self.t_end - self.t[0]) / sample_time + 1e-9)
        ts = self.t[0] + sample_time * np.arange(n + 1)
        if ts[-1] < self.t_end - 1e-9:
            ts = np.append(ts, self.t_end)
        return np.column_stack([ts, self.position(ts), self.heading(ts)])

    def body_velocities(self) -> tuple[np.ndarray, np.ndarray]:
        """Linear speed ``v`` (units/s, negative backwards) and turn rate ``omega`` (rad/s) on
        each piece; 0 on a piece of no duration (an instantaneous turn)."""
        dt = np.diff(self.t)
        safe = np.where(dt > 0, dt, 1.0)
        d = np.diff(self.xy, axis=0)
        # Signed: the displacement along the heading (negative when driving backwards).
        along = d[:, 0] * np.cos(self.theta[:-1]) + d[:, 1] * np.sin(self.theta[:-1])
        v = np.where(dt > 0, along / safe, 0.0)
        w = np.where(dt > 0, np.diff(self.theta) / safe, 0.0)
        return v, w

    def wheel_speeds(self, track_width: float) -> tuple[np.ndarray, np.ndarray]:
        """Right and left wheel speeds on each piece (paper eqs. 9-10), units/s."""
        v, w = self.body_velocities()
        return v + 0.5 * track_width * w, v - 0.5 * track_width * w


@dataclass
class ObstacleTrack:
    """The true motion of one moving obstacle: constant velocity between heading changes.

    ``knots`` holds ``(t, x, y)`` rows where the heading changed (the first is ``t = 0``); after the
    last knot the obstacle moves with ``velocity``.
    """

    radius: float
    speed: float
    heading: float  # rad
    knots: list[tuple[float, float, float]]

    @classmethod
    def from_obstacle(cls, obstacle) -> ObstacleTrack:
        """Start the track of a :class:`~rrtpso_ompl.model.MovingObstacle` at t = 0."""
        x, y = obstacle.start
        return cls(
            obstacle.radius, obstacle.speed, math.radians(obstacle.heading_deg), [(0.0, x, y)]
        )

    @property
    def velocity(self) -> np.ndarray:
        """Current velocity vector, units/s."""
        return self.speed * np.array([math.cos(self.heading), math.sin(self.heading)])

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Positions at times ``t`` (s), including all heading changes so far."""
        t = np.asarray(t, dtype=float)
        k = np.asarray(self.knots)
        times = np.append(k[:, 0], k[-1, 0] + 1.0)
        last = k[-1, 1:] + self.velocity
        xs, ys = np.append(k[:, 1], last[0]), np.append(k[:, 2], last[1])
        # np.interp clamps beyond the last knot: extrapolate that part linearly by hand.
        beyond = np.maximum(t - times[-1], 0.0)
        v = self.velocity
        return np.stack(
            [np.interp(t, times, xs) + beyond * v[0], np.interp(t, times, ys) + beyond * v[1]], -1
        )

    def turn(self, t: float, heading: float) -> None:
        """Change heading (rad) at time ``t`` (s), from the current position."""
        x, y = self.position(t)
        self.knots.append((float(t), float(x), float(y)))
        self.heading = heading

    def breakpoints(self) -> np.ndarray:
        """Times at which the velocity changes."""
        return np.array([k[0] for k in self.knots])


def arc_position(x, theta, v, w, tau) -> np.ndarray:
    """Position after driving at linear speed ``v`` and turn rate ``w`` for ``tau`` from ``x``
    with heading ``theta`` (a differential drive at constant wheel speeds: an exact circular arc,
    or a straight line when ``w = 0``).

    Parameters
    ----------
    x : (2,) array
        Start position, units.
    theta : float or array
        Start heading, rad.
    v, w, tau : float or array
        Linear speed (units/s, negative backwards), turn rate (rad/s) and time (s); broadcast
        together with ``theta``.

    Returns
    -------
    ndarray of shape ``broadcast(theta, v, w, tau).shape + (2,)``
    """
    half = 0.5 * np.asarray(w, dtype=float) * tau
    # The chord of the arc: length v tau sinc(w tau / 2), direction theta + w tau / 2 (exact, and
    # stable as w -> 0, where it becomes the straight line).
    chord = np.asarray(v, dtype=float) * tau * np.sinc(half / math.pi)
    mid = np.asarray(theta, dtype=float) + half
    return np.stack([x[0] + chord * np.cos(mid), x[1] + chord * np.sin(mid)], axis=-1)


def _relative(
    motion: Motion, obstacle_at, t0: float, t1: float, extra: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoint times in ``[t0, t1]`` and the robot-minus-obstacle offsets there."""
    inner = motion.t[(motion.t > t0) & (motion.t < t1)]
    if extra is not None:
        inner = np.union1d(inner, extra[(extra > t0) & (extra < t1)])
    ts = np.concatenate([[t0], inner, [t1]])
    return ts, motion.position(ts) - obstacle_at(ts)


def closest_approach(motion: Motion, obstacle_at, t0: float, t1: float, breaks=None):
    """Smallest centre distance between the robot and an obstacle over ``[t0, t1]``, exactly.

    Parameters
    ----------
    motion : Motion
        The robot.
    obstacle_at : callable
        Obstacle centre at an array of times, piecewise linear with breakpoints ``breaks``.
    t0, t1 : float
        The time window, s.

    Returns
    -------
    (float, float)
        The distance (units) and a time (s) at which it is attained.
    """
    ts, rel = _relative(motion, obstacle_at, t0, t1, breaks)
    a, b = rel[:-1], rel[1:]
    d = b - a
    len2 = np.einsum("ij,ij->i", d, d)
    u = np.clip(-np.einsum("ij,ij->i", a, d) / np.where(len2 > 0, len2, 1.0), 0.0, 1.0)
    closest = a + u[:, None] * d
    dist = np.hypot(closest[:, 0], closest[:, 1])
    i = int(np.argmin(dist))
    return float(dist[i]), float(ts[i] + u[i] * (ts[i + 1] - ts[i]))


def first_entry(motion: Motion, obstacle_at, t0: float, t1: float, radius: float, breaks=None):
    """The first time in ``[t0, t1]`` at which the centre distance drops below ``radius``.

    Between breakpoints the offset is ``r0 + dv tau``; ``|r0 + dv tau| = radius`` is a quadratic in
    ``tau``, so entry and exit are exact.

    Returns
    -------
    tuple or None
        ``(t_enter, t_exit)`` in s (``t_exit`` is where the distance is back to ``radius``, or
        ``t1`` if it never is within the window), or None when the distance stays >= ``radius``.
    """
    ts, rel = _relative(motion, obstacle_at, t0, t1, breaks)
    r0, dv = rel[:-1], np.diff(rel, axis=0)  # per piece, with tau in [0, 1]
    a = np.einsum("ij,ij->i", dv, dv)
    b = np.einsum("ij,ij->i", r0, dv)
    c = np.einsum("ij,ij->i", r0, r0) - radius * radius
    disc = b * b - a * c
    ok = (disc > 0) & (a > 0)
    root = np.sqrt(np.where(ok, disc, 0.0))
    safe_a = np.where(a > 0, a, 1.0)
    lo = np.where(c < 0, 0.0, np.where(ok, (-b - root) / safe_a, np.inf))
    hi = np.where(ok, (-b + root) / safe_a, np.where(c < 0, 1.0, -np.inf))
    inside = (lo <= 1.0) & (hi >= 0.0) & (lo <= hi)
    if not inside.any():
        return None
    i = int(np.argmax(inside))
    dt = np.diff(ts)
    t_enter = ts[i] + max(lo[i], 0.0) * dt[i]
    # The zone lasts while consecutive pieces stay inside (the exit root lies beyond the piece).
    j = i
    while hi[j] >= 1.0 and j + 1 < len(dt) and inside[j + 1] and lo[j + 1] <= 0.0:
        j += 1
    t_exit = ts[j] + min(hi[j], 1.0) * dt[j]
    return float(t_enter), float(t_exit)
