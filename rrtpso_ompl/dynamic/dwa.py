"""A Dynamic Window Approach (DWA) local planner: the peer robots use today, in the same harness.

Fox, Burgard & Thrun's DWA (IEEE RAM 1997), as in ROS ``dwa_local_planner``: every control period
the robot picks a pair of linear and angular velocities ``(v, w)`` from the *dynamic window*, the
velocities reachable within one period under its acceleration limits (and its wheel-speed limit
``|v| + |w| L / 2 <= v_w``). Each pair is rolled out as a circular arc over a horizon; arcs that
come too close to a static obstacle or to a sensed moving obstacle's constant-velocity
prediction (the same prediction the replanning manager uses) are inadmissible; among the rest the
robot takes the best of

- **path**: how close the arc's end comes to a *carrot*, the point of the guide path (the static
  path) a fixed look-ahead beyond the robot's progress along it;
- **clearance**: the least distance to any obstacle along the arc, capped;

an arc is admissible when the robot can brake to a stop before it meets a static obstacle
(classic DWA; it then rests at the last free point) and no sensed obstacle's prediction comes
within the contact distance over the horizon;
- **speed**: closeness to the wanted speed (full speed, slowing down to stop at the goal).

When no arc is admissible (an obstacle will hit the robot whatever it does within the horizon) it
takes the arc that comes least close (the one that gets out of the way most). Everything is
vectorised over all arcs and horizon steps. The executed motion is integrated exactly on arcs
(knots every ``sample_time / SUBSTEPS``), then measured by the same code as the replanning
strategies, and its static validity is checked exactly (DWA, unlike a planner, can clip a static
obstacle).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields

import numpy as np

from ..model.problem import PlannerConfig, Problem
from ..model.world import World
from .motion import Motion, ObstacleTrack
from .simulation import (
    MAX_STEPS,
    DynamicOptions,
    SimulationResult,
    _check_steps,
    _measure,
    _no_static_path,
    _Robot,
    _sense,
    _turn_at_random,
)

__all__ = ["CARROT_SAMPLES", "SUBSTEPS", "DWAParams", "guide_path", "simulate_dwa"]

#: Knots per control period of the executed motion (the arc between knots is replaced by its
#: chord: at most ``v dt^2 w / 8`` off, 0.003 cm for the paper's robot).
SUBSTEPS = 5

#: Points of the guide path tried as the carrot, every control period.
CARROT_SAMPLES = 16


@dataclass(frozen=True)
class DWAParams:
    """The DWA's parameters (units of the problem, seconds, radians).

    Attributes
    ----------
    horizon : float
        Roll-out time of each arc, s.
    v_samples, w_samples : int
        Linear and angular velocities sampled across the dynamic window.
    accel_time : float
        Time to reach full speed (or full turn rate) from rest, s: sets the acceleration limits
        ``v_max / accel_time`` and ``w_max / accel_time``.
    lookahead : float
        Carrot distance along the guide path beyond the robot's progress, in robot radii beyond
        the longest arc (``v_max * horizon``).
    weight_path, weight_clearance, weight_speed : float
        Weights of the three terms (each normalised to [0, 1]).
    clearance_cap : float
        Clearance beyond which it no longer scores, in robot radii.
    """

    horizon: float = 4.0
    v_samples: int = 7
    w_samples: int = 15
    accel_time: float = 0.3
    lookahead: float = 1.0
    weight_path: float = 1.0
    weight_clearance: float = 0.4
    weight_speed: float = 0.3
    clearance_cap: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"DWAParams.{f.name} must be a finite number >= 0, got {value}")
        if self.v_samples < 2 or self.w_samples < 2 or self.v_samples * self.w_samples > 10_000:
            raise ValueError("DWAParams: 2 to 10,000 samples per axis product are needed")
        if not (self.horizon > 0 and self.accel_time > 0):
            raise ValueError("DWAParams.horizon and accel_time must be > 0")


def simulate_dwa(
    problem: Problem,
    guide_path: np.ndarray,
    params: DWAParams | None = None,
    options: DynamicOptions | None = None,
    seed: int | None = None,
) -> SimulationResult:
    """Drive the robot with the DWA along ``guide_path`` among the problem's moving obstacles.

    Parameters
    ----------
    problem : Problem
        As for :func:`~rrtpso_ompl.dynamic.simulate` (``robot.speed``, ``sample_time``,
        ``sensor_range``; the turn rate from ``track_width``).
    guide_path : (n, 2) array
        The static path to follow (units).
    params : DWAParams, optional
    options : DynamicOptions, optional
        Only ``margin``, ``max_time``, ``heading_changes`` and ``heading_change_deg`` are used
        (the same obstacles, the same random turns as :func:`simulate` with the same seed).
    seed : int, optional
        Seeds the obstacles' random heading changes exactly as :func:`simulate` does.

    Returns
    -------
    SimulationResult
        ``strategy="dwa"``; ``status`` says when the robot clipped a static obstacle.
    """
    params = params or DWAParams()
    options = options or DynamicOptions()
    robot = _Robot.of(problem)
    options_dwa = dataclasses.replace(options, strategy="none", planner="DWA")
    path = np.asarray(guide_path, dtype=float).reshape(-1, 2)
    tracks = [ObstacleTrack.from_obstacle(m) for m in problem.moving_obstacles]
    if len(path) < 2:
        return _no_static_path(problem, options_dwa, seed, robot, path, tracks)
    radii = [m.radius for m in problem.moving_obstacles]
    margin = options.margin
    if margin is None:
        margin = 0.1 * (robot.radius + min(radii, default=0.0))
    _, world_rng = np.random.default_rng(seed).spawn(2)
    seg = np.hypot(*np.diff(path, axis=0).T)
    t_max = options.max_time if options.max_time is not None else 4 * seg.sum() / robot.speed + 60
    _check_steps(t_max, robot.sample_time)
    world = World.from_problem(problem)
    dwa = _DWA(problem, robot, params, world, path, margin)
    motion, reached = dwa.drive(tracks, options, t_max, world_rng)
    # The driven motion is the only "plan" a local planner has (the animation draws it ahead).
    plans = [(0.0, motion)]
    result = _measure(problem, options_dwa, seed, robot, motion, reached, path, tracks, [], plans)
    result.strategy = "dwa"
    result.planner = "DWA"
    # Unlike a planned path, DWA's arcs are not checked exactly before they are driven.
    free = world.segments_free(motion.xy[:-1], motion.xy[1:])
    if not (free.all() and world.points_in_bounds(motion.xy).all()):
        result.status = "clipped a static obstacle or left the bounds"
    return result


def guide_path(
    problem: Problem,
    static_path: np.ndarray,
    planner: str = "RRTstarPSO",
    time_limit: float = 1.0,
    params: dict | None = None,
) -> np.ndarray:
    """The path the DWA follows: the static problem re-planned (with ``planner`` for
    ``time_limit`` s) for a robot larger by 10 % of SR plus half a control period's travel
    (``v_max * sample_time / 2``); ``static_path`` when that problem has no solution.

    A shortest path touches obstacles (zero clearance): a DWA, whose sampled arcs and clearance
    term keep it off the obstacles, cannot follow it there and crawls. OMPL is not reseeded here
    (give ``params={"seed": ...}``).
    """
    from ..planners import solve

    robot = problem.robot
    grown = 1.1 * robot.radius + 0.5 * (robot.speed or 0.0) * (robot.sample_time or 0.1)
    # The problem file's planner section (its seed above all) is not for this plan.
    bigger = dataclasses.replace(
        problem, robot=dataclasses.replace(robot, radius=grown), planner=PlannerConfig()
    )
    res = solve(bigger, planner, time_limit=time_limit, params=params)
    return res.path if res.solved else np.asarray(static_path, dtype=float)


class _DWA:
    """The controller's state: the robot's velocities and its progress along the guide path."""

    def __init__(self, problem, robot, params: DWAParams, world, path, margin) -> None:
        self.p = params
        self.robot = robot
        self.world = world
        self.path = path
        self.goal = np.asarray(problem.goal, dtype=float)
        self.margin = margin
        seg = np.diff(path, axis=0)
        self.seg = seg
        self.seg_len = np.hypot(*seg.T)
        self.s_at = np.concatenate([[0.0], np.cumsum(self.seg_len)])
        self.v_max = robot.speed
        self.w_max = robot.turn_rate if robot.turn_rate else 4.0 * math.pi
        self.wheel = problem.robot.max_wheel_speed or problem.robot.speed
        self.half_track = 0.5 * (problem.robot.track_width or 0.0)
        self.progress = 0.0
        # The carrot lies beyond the longest arc, so that the heading term never asks a fast
        # arc to turn back to a carrot it has already passed.
        self.carrot_distance = self.v_max * params.horizon + params.lookahead * robot.radius
        dt = robot.sample_time
        self.n_steps = max(1, math.ceil(params.horizon / dt))
        self.t_roll = dt * np.arange(1, self.n_steps + 1)
        # Samples are h = v dt apart along an arc: passing a convex obstacle of radius >= SR
        # between two of them, the disc can go deeper than at either by at most the sagitta
        # (h/2)^2 / (2 SR). (Relative to a moving obstacle the relative motion is what counts:
        # half of both speeds times dt, see _dynamic_clearance.)
        self.static_pad = (0.5 * self.v_max * dt) ** 2 / (2.0 * robot.radius)

    # -- the control loop --------------------------------------------------------------------------
    def drive(self, tracks, options, t_max, world_rng) -> tuple[Motion, bool]:
        dt = self.robot.sample_time
        x = self.path[0].copy()
        th = math.atan2(*self.seg[0][::-1])
        v = w = 0.0
        ts, xs, ths = [0.0], [x.copy()], [th]
        change_p = options.heading_changes * dt
        tol = max(self.v_max * dt, 0.1 * self.robot.radius)
        reached = False
        k = 0
        while k * dt <= t_max and k < MAX_STEPS:
            t = k * dt
            if math.dist(x, self.goal) <= tol and self._straight_free(x, self.goal):
                # Within one control period (or SR/10) of the goal: drive the last chord in.
                d = math.dist(x, self.goal)
                ts.append(t + d / self.v_max)
                xs.append(self.goal.copy())
                ths.append(th)
                reached = True
                break
            obs = _sense(x, tracks, t, self.robot.sensor_range)
            v, w = self.choose(x, th, v, w, obs)
            for j in range(1, SUBSTEPS + 1):
                tau = dt * j / SUBSTEPS
                xs.append(_arc(x, th, v, w, tau))
                ths.append(th + w * tau)
                ts.append(t + tau)
            x, th = xs[-1].copy(), ths[-1]
            self._advance(x)
            k += 1
            if change_p > 0:
                _turn_at_random(tracks, k * dt, change_p, options.heading_change_deg, world_rng)
        return Motion(np.array(ts), np.array(xs), np.array(ths)), reached

    def choose(self, x, th, v, w, obs) -> tuple[float, float]:
        """The best admissible ``(v, w)`` of the dynamic window (see the module doc)."""
        p = self.p
        dt = self.robot.sample_time
        dv = self.v_max / p.accel_time * dt
        dw = self.w_max / p.accel_time * dt
        vs = np.linspace(max(0.0, v - dv), min(self.v_max, v + dv), p.v_samples)
        ws = np.linspace(max(-self.w_max, w - dw), min(self.w_max, w + dw), p.w_samples)
        V, W = (a.ravel() for a in np.meshgrid(vs, ws))
        ok = np.abs(V) + np.abs(W) * self.half_track <= self.wheel * (1 + 1e-9)
        if not ok.any():  # the window lies beyond the wheel limit: slow down
            ok = np.isclose(V, V.min())
        V, W = V[ok], W[ok]
        n = self.n_steps
        pts = _arc(x, th, V[:, None], W[:, None], self.t_roll[None, :])  # (m, n, 2)
        static = self._static_clearance(pts)  # (m, n): distance beyond contact, units
        s_hit = static < 0
        k_s = np.where(s_hit.any(axis=1), s_hit.argmax(axis=1), n)
        # Classic DWA admissibility towards static obstacles: the robot can still brake to a
        # stop before the first contact after one more control period (t_free >= V/2a + dt),
        # and then stays at the last free roll-out point, where a moving obstacle may still
        # reach it.
        a = self.v_max / p.accel_time
        t_free = np.where(k_s == n, np.inf, np.where(k_s > 0, self.t_roll[k_s - 1], 0.0))
        static_ok = (k_s == n) | (t_free >= V / (2.0 * a) + dt - 1e-12)
        idx = np.minimum(np.arange(n)[None, :], k_s[:, None] - 1)
        held = np.take_along_axis(pts, np.maximum(idx, 0)[..., None], axis=1)
        pts = np.where((idx >= 0)[..., None], held, x)
        static = np.where(idx >= 0, np.take_along_axis(static, np.maximum(idx, 0), axis=1),
                          self._static_clearance(x[None, None])[0, 0])  # fmt: skip
        dyn = self._dynamic_clearance(pts, obs)
        clear = np.minimum(static, dyn)
        hit = dyn < 0
        safe = static_ok & ~hit.any(axis=1)
        first_hit = np.where(hit.any(axis=1), hit.argmax(axis=1), n)
        cap = p.clearance_cap * self.robot.radius
        carrot = self._carrot(x)
        # How near the arc comes to the carrot (not where it ends: an arc through the goal at
        # full speed is as good as one that stops on it).
        reach = self.v_max * p.horizon + 1e-9
        near = np.hypot(*(pts - carrot).transpose(2, 0, 1)).min(axis=1)
        # ... and whether it ends facing the carrot (the classic DWA heading term), which is
        # what turns the robot back after it has dodged away.
        end = pts[:, -1]
        bearing = np.arctan2(carrot[1] - end[:, 1], carrot[0] - end[:, 0])
        heading = th + W * np.minimum(t_free, p.horizon)
        off = np.abs(np.angle(np.exp(1j * (bearing - heading))))
        off = np.where(np.hypot(*(carrot - end).T) < self.robot.radius, 0.0, off)
        path_term = 0.5 * (1.0 - np.minimum(near / reach, 1.0)) + 0.5 * (1.0 - off / math.pi)
        clear_term = np.minimum(clear.min(axis=1), cap) / cap
        d_goal = math.dist(x, self.goal)
        # Slow down over the last second to the goal (arriving at full speed, the robot orbits it).
        v_want = min(self.v_max, d_goal / 1.0)
        speed_term = 1.0 - np.abs(V - v_want) / self.v_max
        score = p.weight_path * path_term + p.weight_clearance * clear_term
        score = score + p.weight_speed * speed_term
        if safe.any():
            i = int(np.argmax(np.where(safe, score, -np.inf)))
        else:
            # Every arc meets something within the horizon: the one that comes least close (the
            # one that moves out of the way most), on a tie the one whose contact comes latest.
            least = np.round(clear.min(axis=1), 6)
            i = int(np.lexsort((-first_hit, -least, ~static_ok))[0])
        return float(V[i]), float(W[i])

    # -- pieces ------------------------------------------------------------------------------------
    def _static_clearance(self, pts) -> np.ndarray:
        """Margin left to the static obstacles and the bounds at each point (negative: too
        close), units; ``pts`` is ``(..., 2)``."""
        sr = self.robot.radius
        flat = pts.reshape(-1, 2)
        static = self.world.point_clearance(flat, cap=sr + self.static_pad + 1.0)
        clear = static - sr - self.static_pad
        (xmin, ymin), (xmax, ymax) = self.world.bounds
        out = (flat[:, 0] < xmin) | (flat[:, 0] > xmax) | (flat[:, 1] < ymin)
        out |= flat[:, 1] > ymax
        return np.where(out, -1.0, clear).reshape(pts.shape[:-1])

    def _dynamic_clearance(self, pts, obs) -> np.ndarray:
        """Margin left to the sensed obstacles' constant-velocity predictions at each roll-out
        point ``(m, n, 2)`` (inf when none is sensed), units."""
        clear = np.full(pts.shape[:-1], np.inf)
        sr = self.robot.radius
        for pos, vel, radius in obs.values():
            o = pos[None, :] + self.t_roll[:, None] * vel[None, :]  # (n, 2)
            pad = 0.5 * (self.v_max + float(np.hypot(*vel))) * self.robot.sample_time
            d = np.hypot(*(pts - o[None]).transpose(2, 0, 1))
            clear = np.minimum(clear, d - (sr + radius + 0.5 * self.margin + pad))
        return clear

    def _advance(self, x) -> None:
        """Progress along the guide path: the nearest point ahead of the last progress (never
        back, never more than a look-ahead at once)."""
        rel = x[None, :] - self.path[:-1]
        L2 = np.maximum(self.seg_len**2, 1e-12)
        u = np.clip(np.einsum("ij,ij->i", rel, self.seg) / L2, 0.0, 1.0)
        s = self.s_at[:-1] + u * self.seg_len
        d = np.hypot(*(self.path[:-1] + u[:, None] * self.seg - x).T)
        window = (s >= self.progress - 1e-9) & (s <= self.progress + self.carrot_distance)
        if window.any():
            self.progress = max(self.progress, float(s[window][np.argmin(d[window])]))

    def _carrot(self, x) -> np.ndarray:
        """The farthest point of the guide path within the carrot distance beyond the robot's
        progress that the robot sees (the straight line to it is free): a carrot behind a wall
        pulls a DWA into the wall, the classic local minimum at a door."""
        s = np.linspace(self.progress, min(self.progress + self.carrot_distance, self.s_at[-1]),
                        CARROT_SAMPLES)  # fmt: skip
        pts = np.column_stack([np.interp(s, self.s_at, self.path[:, 0]),
                               np.interp(s, self.s_at, self.path[:, 1])])  # fmt: skip
        seen = self.world.segments_free(np.broadcast_to(x, pts.shape), pts)
        return pts[int(np.flatnonzero(seen)[-1])] if seen.any() else pts[0]

    def _straight_free(self, a, b) -> bool:
        return bool(self.world.motion_free(*a, *b))


def _arc(x, th, v, w, tau):
    """Position after driving ``(v, w)`` for ``tau`` from ``x`` with heading ``th`` (exact arc;
    broadcasts over arrays of ``v``, ``w``, ``tau``)."""
    v = np.asarray(v, dtype=float)
    w = np.asarray(w, dtype=float)
    small = np.abs(w) < 1e-9
    ws = np.where(small, 1.0, w)
    a = th + w * tau
    dx = np.where(small, v * tau * np.cos(th), v / ws * (np.sin(a) - math.sin(th)))
    dy = np.where(small, v * tau * np.sin(th), -v / ws * (np.cos(a) - math.cos(th)))
    return np.stack([x[0] + dx, x[1] + dy], axis=-1)
