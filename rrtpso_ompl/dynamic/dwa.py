"""A Dynamic Window Approach local planner in the manner of Nav2's DWB controller: the peer.

Robots in the field mostly avoid moving obstacles with a local planner that follows a global
path, not by replanning it. :class:`DWAController` is that planner, built as Nav2's DWB
(``dwb_core`` + ``dwb_critics``) is, on exact geometry:

- **the plan**: a *guide path* from the project's static planner, planned with clearance
  (:func:`guide_path`), of which every period only a *local plan* is used: from a little behind
  the robot's progress along it to ``prune_distance`` ahead (DWB's pruned, shortened plan);
- **the trajectories**: ``(v, w)`` pairs sampled across the *dynamic window* (the velocities
  reachable within one period under the acceleration limits; ``|v| + |w| L / 2 <= v_w``; up to
  ``reverse * v_max`` backwards), each rolled out as an exact arc over ``sim_time``;
- **admissibility** (hard, classic DWA): the robot must be able to brake to a stop after the
  period along the arc (both velocities ramped down together, so it stays on the arc) before it
  meets a static obstacle or leaves the bounds, checked exactly on chords padded by the arc's
  sagitta. The command that brakes along the current arc is always among the samples, and its
  stop lies on the stop the last command was admitted with: some command is always admissible,
  and the robot is never driven into a static obstacle that a stop could avoid;
- **safety** against the sensed moving obstacles, predicted at constant velocity over
  ``obstacle_time`` (longer than ``sim_time``: an obstacle overtaking the robot is seen coming):
  a trajectory is safe when stopping, or driving on (straight at full speed after ``sim_time``),
  keeps ``SR + SO + margin / 2`` from every prediction, exactly on each chord of the relative
  motion;
- **critics** (lower is better, weighted; distances in robot radii), over the safe
  trajectories, at the trajectory's end (the last free point when it meets a static obstacle)
  and at a point ``forward_point`` ahead of it: ``PathDist`` and ``PathAlign`` (distance to the
  local plan), ``GoalDist`` and ``GoalAlign`` (distance to the local plan's end), all measured
  through free space round the static world and the obstacles sensed now (Nav2's costmap with
  its obstacle layer; :class:`~rrtpso_ompl.dynamic.navgrid.NavGrid`, DWB's map-grid critics,
  exact where nothing is in the way), the align critics off near the goal, and ``GoalDist``
  rewarding an early arrival when the local plan ends at the goal; ``Obstacle``: an
  inflation-like cost of the least clearance to the static world and to the predicted moving
  obstacles; ``PreferForward``: a penalty for driving backwards; ``Oscillation``: after the sign
  of ``v`` (or of ``w`` while nearly stopped) flipped, commands flipping it back are refused
  until the robot has moved ``oscillation_distance`` or turned ``oscillation_angle``;
- **rotate to the path**: nearly stopped and facing more than ``rotate_threshold_deg`` away from
  the local plan, the robot turns in place first (Nav2's rotation shim); the problems have no goal
  heading, so there is no rotation at the goal;
- **recovery** (Nav2's behaviour tree): when the robot has not moved ``progress_distance`` in
  ``progress_time`` (the progress checker) it re-plans the guide path from where it stands on
  the grid (Nav2's NavFn) and backs up for ``backup_time``; when it has left the reach of the
  local plan's field it re-plans; at most ``max_recoveries`` times;
- **no safe trajectory** (a predicted obstacle will come too close whatever the robot does):
  the admissible command whose better continuation (stop or drive on) comes least close, of
  those the one that meets the obstacle last.

Everything is vectorised over samples, horizon steps and obstacles (the static checks through
the :class:`~rrtpso_ompl.model.world.World`'s spatial index). :func:`simulate_dwa` runs it in
:func:`~rrtpso_ompl.dynamic.local.simulate_local`, the harness of every local controller.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..model.geometry import cumulative_length, point_segment_distance, wrap_angle
from ..model.problem_types import PlannerConfig, Problem
from ..model.world import World
from .dwa_params import DWAParams
from .local import simulate_local
from .motion import arc_position
from .navgrid import NavGrid
from .options import (
    DynamicOptions,
    Observations,
    RobotModel,
    RobotState,
    default_margin,
    goal_tolerance,
)
from .result import SimulationResult

__all__ = ["DWAController", "DWAParams", "guide_path", "simulate_dwa"]

#: Least cost of an inadmissible-by-prediction drive, as a multiple of the obstacle weight:
#: the exponential obstacle cost is capped there.
_MAX_OBSTACLE_COST = 20.0


def simulate_dwa(
    problem: Problem,
    guide_path: np.ndarray,
    params: DWAParams | None = None,
    options: DynamicOptions | None = None,
    seed: int | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> SimulationResult:
    """Drive the robot with the DWA along ``guide_path`` among the problem's moving obstacles.

    Parameters
    ----------
    problem : Problem
        As for :func:`~rrtpso_ompl.dynamic.simulate` (``robot.speed``, ``sample_time``,
        ``sensor_range``; the turn rate from ``track_width``).
    guide_path : (n, 2) array
        The path to follow (units), e.g. from :func:`guide_path`.
    params : DWAParams, optional
    options : DynamicOptions, optional
        ``margin``, ``max_time``, ``heading_changes`` and ``heading_change_deg`` are used (the
        same obstacles, the same random turns as :func:`~rrtpso_ompl.dynamic.simulate` with
        the same seed).
    seed : int, optional
        Seeds the obstacles' random heading changes as :func:`~rrtpso_ompl.dynamic.simulate`
        does.
    progress : callable, optional
        Called as ``progress(t, t_max)`` after every step.

    Returns
    -------
    SimulationResult
        ``strategy="dwa"``, ``planner="DWA"``; ``status`` says when the robot clipped a static
        obstacle.
    """
    options = options or DynamicOptions()
    path = np.asarray(guide_path, dtype=float).reshape(-1, 2)
    controller = None
    if len(path) >= 2:
        controller = DWAController(problem, path, params, options.margin)
    return simulate_local(problem, controller or _NoController(), path, options, seed, progress)


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

    A shortest path touches obstacles (zero clearance), and a local planner that keeps off the
    obstacles cannot follow it there; the inflation is Nav2's inflated costmap under the global
    planner. OMPL is not reseeded here (give ``params={"seed": ...}``).
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


class _NoController:
    """Stands in when there is no guide path: the harness reports "no static path"."""

    name = "DWA"

    def reset(self, xy, theta) -> None:  # pragma: no cover - never driven
        pass

    def step(self, state, obstacles, t) -> tuple[float, float]:  # pragma: no cover
        return 0.0, 0.0


@dataclass
class _Trend:
    """The sign history of one velocity (DWB's oscillation critic): after a flip, the other
    sign is refused until the robot has moved or turned enough."""

    sign: int = 0
    refused: int = 0  # the sign refused since the last flip (0: none)

    def update(self, value: float) -> bool:
        s = int(np.sign(value))
        flipped = s != 0 and self.sign != 0 and s != self.sign
        if flipped:
            self.refused = self.sign
        if s != 0:
            self.sign = s
        return flipped

    def refuses(self, values: np.ndarray) -> np.ndarray:
        return np.sign(values) == self.refused if self.refused else np.zeros(len(values), bool)


@dataclass
class Evaluation:
    """The scored samples of one control period (kept for tests and diagnostics).

    ``v``, ``w``: the sampled commands; ``admissible``: a stop after the period keeps off the
    static world; ``safe``: admissible and not heading into a predicted moving obstacle;
    ``cost``: the critics' total (``inf`` where not scored); ``d_go``, ``d_stop``: the least
    margin to the predicted moving obstacles driving on and stopping; ``chosen``: the index taken;
    ``mode``: ``"critics"``, ``"rotate"``, ``"backup"`` or ``"unavoidable"``.
    """

    v: np.ndarray
    w: np.ndarray
    admissible: np.ndarray
    safe: np.ndarray
    cost: np.ndarray
    d_go: np.ndarray
    d_stop: np.ndarray
    chosen: int
    mode: str


class _StaticCheck(NamedTuple):
    """The static world's verdict on the sampled commands (see :meth:`DWAController.
    _static_check`)."""

    admissible: np.ndarray  # (m,) a stop after the period keeps off the static world
    k_s: np.ndarray  # (m,) index of the first roll-out step that meets it (n: none)
    go: np.ndarray  # (m, n, 2) the roll-outs, held at their last free point
    reached: np.ndarray  # (m,) how long each roll-out drives, s
    clear_static: np.ndarray  # (m,) least clearance to the static world, units


class DWAController:
    """The DWB-like controller (see the module doc); a :class:`~rrtpso_ompl.dynamic.local.
    LocalController`.

    Parameters
    ----------
    problem : Problem
        The robot's limits, the static world, the goal.
    guide : (n, 2) array
        The guide path (units), from the start to the goal.
    params : DWAParams, optional
    margin : float or None
        Extra separation kept from moving obstacles beyond ``SR + SO`` (half of it is the
        prediction's threshold, as for the replanning strategies); default 10 % of ``SR + SO``
        of the smallest obstacle.
    """

    name = "DWA"

    def __init__(
        self,
        problem: Problem,
        guide: np.ndarray,
        params: DWAParams | None = None,
        margin: float | None = None,
    ) -> None:
        self.p = p = params or DWAParams()
        self.robot = robot = RobotModel.of(problem)
        self.world = World.from_problem(problem)
        self.goal = np.asarray(problem.goal, dtype=float)
        self.margin = default_margin(problem, margin)
        sr = robot.radius
        self.sr = sr
        self.dt = dt = robot.sample_time
        self.v_max = robot.speed
        self.w_max = robot.turn_rate if robot.turn_rate else 4.0 * math.pi
        self.half_track = 0.5 * (robot.track_width or 0.0)
        self.acc = self.v_max / p.accel_time
        self.alpha = self.w_max / p.accel_time
        self.v_min = -p.reverse * self.v_max
        # Every braking arc (one period, then at most accel_time ramping down) lies within the
        # roll-out, so admissibility is decided on it.
        horizon = max(p.sim_time, dt + 0.5 * p.accel_time)
        self.t_roll = dt * np.arange(1, math.ceil(horizon / dt - 1e-9) + 1)
        ahead = max(horizon, p.obstacle_time)
        self.t_pred = dt * np.arange(1, math.ceil(ahead / dt - 1e-9) + 1)
        self.forward = p.forward_point * sr
        self.goal_tolerance = goal_tolerance(robot)
        self.grid = NavGrid(self.world, sr, p.resolution * sr)
        reach = self.v_max * self.t_roll[-1] + self.forward
        #: How far beyond the local plan the distance fields are computed.
        self.path_limit = reach + 4.0 * sr
        self.goal_limit = p.prune_distance * sr + reach + 4.0 * sr
        self.recoveries: list[tuple[float, str]] = []
        self.last: Evaluation | None = None
        self._set_guide(np.asarray(guide, dtype=float).reshape(-1, 2))
        self.reset(self.guide[0], 0.0)

    # -- LocalController ------------------------------------------------------------------------
    def reset(self, xy: np.ndarray, theta: float) -> None:
        """Start a run at ``xy``: progress, oscillation, progress checker and recoveries."""
        self.progress = 0.0
        self._v_trend, self._w_trend = _Trend(), _Trend()
        self._flip_pose = (np.asarray(xy, dtype=float).copy(), float(theta))
        self._checkpoint: tuple[float, np.ndarray] | None = None
        self._backup_until = -math.inf
        self._track(np.asarray(xy, dtype=float))

    def step(self, state: RobotState, obstacles: Observations, t: float) -> tuple[float, float]:
        """The command for the period from ``t`` (see the module doc)."""
        x = np.asarray(state.xy, dtype=float)
        self._track(x)
        self._check_progress(x, t)
        pd, gd = self._fields(obstacles)
        if self._off_plan(x) and self._recover(t, x, "left the plan"):
            pd, gd = self._fields(obstacles)
        ev = self._evaluate(x, state.theta, state.v, state.w, obstacles, pd, gd, t)
        self.last = ev
        v, w = float(ev.v[ev.chosen]), float(ev.w[ev.chosen])
        self._debrief(v, w, x, state.theta)
        return v, w

    # -- the plan -------------------------------------------------------------------------------
    def _set_guide(self, path: np.ndarray) -> None:
        self.guide = path
        seg = np.diff(path, axis=0)
        self.seg = seg
        self.seg_len = np.hypot(*seg.T)
        self.s_at = cumulative_length(path)
        self.progress = 0.0
        self._guide_version = getattr(self, "_guide_version", -1) + 1
        self._field_key: tuple | None = None

    def _point_at(self, s: np.ndarray) -> np.ndarray:
        return np.column_stack([np.interp(s, self.s_at, self.guide[:, 0]),
                                np.interp(s, self.s_at, self.guide[:, 1])])  # fmt: skip

    def _track(self, x: np.ndarray) -> None:
        """Progress along the guide: its point nearest the robot, never back and never more than
        a little beyond one period's travel ahead at once (a point of the path behind a wall
        must not pull the progress through it)."""
        rel = x[None, :] - self.guide[:-1]
        u = np.clip(np.einsum("ij,ij->i", rel, self.seg) / np.maximum(self.seg_len**2, 1e-300),
                    0.0, 1.0)  # fmt: skip
        ahead = 2.0 * self.v_max * self.dt + 2.0 * self.sr
        # Each segment's nearest point, moved into the window where the window cuts the
        # segment (along a segment the distance is convex, so that is the window's nearest).
        s = np.clip(self.s_at[:-1] + u * self.seg_len, self.progress, self.progress + ahead)
        d = np.hypot(*(self._point_at(s) - x).T)
        self.progress = max(self.progress, float(s[np.argmin(d)]))

    def _fields(self, obstacles: Observations) -> tuple[np.ndarray, np.ndarray]:
        """The distance fields of the local plan (PathDist) and of its end (GoalDist), round
        the static world and the sensed obstacles where they are now (Nav2's costmap with its
        obstacle layer)."""
        # Recomputed once the progress has moved on by SR (every few periods), or when
        # obstacles are sensed: the local plan starts up to 3 SR behind the progress and ends
        # up to SR short of prune_distance.
        sr = self.sr
        q = math.floor(self.progress / sr)
        discs = None
        if obstacles:
            discs = np.array([(*o[0], sr + o[2] + 0.5 * self.margin) for o in obstacles.values()])
        key = (q, self._guide_version, None if discs is None else discs.tobytes())
        if key != self._field_key:
            lo = max(0.0, (q - 2) * sr)
            hi = min(self.s_at[-1], (q + self.p.prune_distance) * sr)
            s = np.linspace(lo, hi, max(2, math.ceil((hi - lo) / (0.5 * self.grid.h)) + 1))
            local = self._point_at(s)
            self._pd = self.grid.field(local, self.path_limit, discs)
            self._gd = self.grid.field(local[-1:], self.goal_limit, discs)
            inner = (self.s_at > lo) & (self.s_at < hi)
            self._local = np.vstack([local[:1], self.guide[inner], local[-1:]])
            self._local_end = hi
            self._field_key = key
        return self._pd, self._gd

    def _off_plan(self, x: np.ndarray) -> bool:
        """Whether the robot is beyond the reach of the PathDist field."""
        a, b = self._local[:-1], self._local[1:]
        near = float(point_segment_distance(x[None], a, b).min())
        return near > self.path_limit - self.v_max * self.t_roll[-1] - self.forward

    def _path_distance(self, pd: np.ndarray, pts: np.ndarray) -> np.ndarray:
        """PathDist at ``pts``: distance to the local plan through free space, units."""
        a, b = self._local[:-1], self._local[1:]
        direct = point_segment_distance(pts[:, None], a[None], b[None]).min(axis=1)
        return self.grid.value(pd, pts, direct)

    def _goal_distance(self, gd: np.ndarray, pts: np.ndarray) -> np.ndarray:
        """GoalDist at ``pts``: distance to the local plan's end through free space, units."""
        return self.grid.value(gd, pts, np.hypot(*(pts - self._local[-1]).T))

    # -- scoring --------------------------------------------------------------------------------
    def _window(self, v0: float, w0: float) -> tuple[np.ndarray, np.ndarray]:
        """The sampled commands: a grid over the dynamic window plus zero, the current
        velocities and the command that brakes along the current arc."""
        p, dt = self.p, self.dt
        vlo, vhi = max(self.v_min, v0 - self.acc * dt), min(self.v_max, v0 + self.acc * dt)
        wlo, whi = max(-self.w_max, w0 - self.alpha * dt), min(self.w_max, w0 + self.alpha * dt)
        vs = np.linspace(vlo, vhi, p.v_samples)
        ws = np.linspace(wlo, whi, p.w_samples)
        vs = np.unique(np.concatenate([vs, [min(max(0.0, vlo), vhi), min(max(v0, vlo), vhi)]]))
        ws = np.unique(np.concatenate([ws, [min(max(0.0, wlo), whi), min(max(w0, wlo), whi)]]))
        V, W = (a.ravel() for a in np.meshgrid(vs, ws))
        ok = np.abs(V) + np.abs(W) * self.half_track <= self.robot.wheel_speed * (1 + 1e-9)
        V, W = V[ok], W[ok]
        t_b = max(abs(v0) / self.acc, abs(w0) / self.alpha)
        keep = max(0.0, 1.0 - dt / t_b) if t_b > 0 else 0.0
        return np.append(V, v0 * keep), np.append(W, w0 * keep)

    def _evaluate(self, x, th, v0, w0, obstacles, pd, gd, t) -> Evaluation:
        """Roll out the dynamic window's commands, check them against the static world and the
        predicted moving obstacles, score the safe ones and choose (see the module doc)."""
        V, W = self._window(v0, w0)
        go, stop, tau_stop = self._rollouts(x, th, V, W)
        static = self._static_check(x, V, W, go, tau_stop)
        # Moving obstacles, predicted at constant velocity: the first predicted contact and the
        # least margin, driving on (straight on after the roll-out, unless it met the static
        # world) and stopping.
        heading = th + W * static.reached
        drive = self._drive_on(static.go, heading, V, static.k_s)
        (ttc_go, d_go), (ttc_stop, d_stop) = (
            self._dynamic_clearance(x, traj, V, obstacles) for traj in (drive, stop)
        )
        safe = static.admissible & (np.isinf(ttc_go) | np.isinf(ttc_stop))
        cost = self._critics(x, V, static, heading, d_go, pd, gd)
        choice, mode = self._choose(x, th, v0, t, V, W, safe, cost, static, (ttc_go, ttc_stop),
                                    (d_go, d_stop))  # fmt: skip
        return Evaluation(V, W, static.admissible, safe, np.where(safe, cost, np.inf), d_go,
                          d_stop, choice, mode)  # fmt: skip

    def _rollouts(self, x, th, V, W) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(go, stop, tau_stop)``: driving on, the arc for the whole roll-out (``(m, n, 2)``);
        stopping, the period then both velocities ramped down together in ``t_b`` (the same
        arc, at the position reached by then), over the prediction's horizon; and the time
        from now to the stop, s."""
        dt = self.dt
        go = arc_position(x, th, V[:, None], W[:, None], self.t_roll[None, :])
        t_b = np.maximum(np.abs(V) / self.acc, np.abs(W) / self.alpha)
        tb = t_b[:, None]
        after = np.clip(self.t_pred[None, :] - dt, 0.0, tb)
        ramp = np.where(tb > 0, after - after**2 / (2.0 * np.where(tb > 0, tb, 1.0)), 0.0)
        tau = np.minimum(self.t_pred[None, :], dt) + ramp
        stop = arc_position(x, th, V[:, None], W[:, None], tau)
        return go, stop, dt + 0.5 * t_b

    def _static_check(self, x, V, W, go, tau_stop) -> _StaticCheck:
        """Admissibility (a stop keeps off the static world and in the bounds), each roll-out
        cut at its last free point, and the least clearance to the static world."""
        p, dt, sr, t_roll = self.p, self.dt, self.sr, self.t_roll
        m, n = len(V), len(t_roll)
        # Static world: exact distance of each chord of the roll-out, less the arc's sagitta
        # (once for the chord of the roll-out, once for the executed motion's own chords).
        pad = 0.25 * np.abs(V) * np.abs(W) * dt**2 + self.world.tol
        start = np.concatenate([np.broadcast_to(x, (m, 1, 2)), go[:, :-1]], axis=1)
        # One query for the chords and the robot's own position (beyond the cap the obstacle
        # cost is below exp(-3)).
        cap = sr + 3.0 * p.inflation * sr
        a = np.concatenate([start.reshape(-1, 2), x[None]])
        b = np.concatenate([go.reshape(-1, 2), x[None]])
        d_all = self.world.segment_distance(a, b, cap=cap)
        d_static, here = d_all[:-1].reshape(m, n), d_all[-1] - sr
        # The centre's bounds, shrunk by the pad: between two samples an arc bulges out.
        (xmin, ymin), (xmax, ymax) = self.world.bounds
        lo, hi = np.array([xmin, ymin]), np.array([xmax, ymax])
        inside = ((go >= lo + pad[:, None, None]) & (go <= hi - pad[:, None, None])).all(axis=2)
        clear_s = np.where(inside, d_static - sr - pad[:, None], -1.0)
        hit = clear_s < 0
        k_s = np.where(hit.any(axis=1), hit.argmax(axis=1), n)
        t_free = np.where(k_s == n, np.inf, np.where(k_s > 0, t_roll[np.maximum(k_s - 1, 0)], 0))
        still = (V == 0) & (W == 0)
        admissible = (tau_stop <= t_free + 1e-12) | still
        if not admissible.any():  # round-off at a contact: braking is what is left
            admissible[-1] = True
        # Driving on ends at the last free point before a static contact.
        idx = np.minimum(np.arange(n)[None, :], k_s[:, None] - 1)
        held = np.take_along_axis(go, np.maximum(idx, 0)[..., None], axis=1)
        go = np.where((idx >= 0)[..., None], held, x)
        clear_static = np.where(np.arange(n)[None, :] < k_s[:, None], clear_s, np.inf).min(axis=1)
        return _StaticCheck(admissible, k_s, go, np.minimum(t_free, t_roll[-1]),
                            np.minimum(clear_static, here))  # fmt: skip

    def _drive_on(self, go, heading, V, k_s) -> np.ndarray:
        """The roll-outs continued over the prediction's horizon: straight on at full speed
        (a turn in place is how the robot starts to get out of the way), or standing where a
        roll-out met the static world."""
        n = len(self.t_roll)
        extra = self.t_pred[n:] - self.t_roll[-1]
        onward = np.where(V < 0, -self.v_max, self.v_max)
        onward = np.where(k_s == n, onward, 0.0)[:, None, None] * extra[None, :, None]
        direction = np.column_stack([np.cos(heading), np.sin(heading)])
        return np.concatenate([go, go[:, -1:] + onward * direction[:, None, :]], axis=1)

    def _critics(self, x, V, static, heading, d_go, pd, gd) -> np.ndarray:
        """The critics' total per command (lower is better; ``inf`` where not finite); the
        weighted scores, one row per critic, are kept in :attr:`parts`."""
        p, sr, go = self.p, self.sr, static.go
        m, t_roll = len(V), self.t_roll
        end = go[:, -1]
        front = end + self.forward * np.column_stack([np.cos(heading), np.sin(heading)])
        path_d = self._path_distance(pd, end) / sr
        goal_d = self._goal_distance(gd, end) / sr
        if self._local_end >= self.s_at[-1]:
            # The local plan ends at the goal, where the run ends: a trajectory that gets there
            # (within the harness's tolerance, at a control instant) scores the distance it
            # could still have driven, so that arriving early beats creeping up to the goal.
            near = np.hypot(*(go - self.goal).transpose(2, 0, 1)) <= self.goal_tolerance
            arrive = np.where(near.any(axis=1), t_roll[near.argmax(axis=1)], np.inf)
            goal_d = np.where(np.isfinite(arrive), -self.v_max * (t_roll[-1] - arrive) / sr, goal_d)
        align_path = align_goal = np.zeros(m)
        if math.dist(x, self.goal) > self.forward:
            # A point ahead in a wall or off the field does not veto a trajectory (as in DWB,
            # the align critics only score): it counts as far as the field reaches.
            far = self.goal_limit / sr
            align_path = p.path_align * np.minimum(self._path_distance(pd, front) / sr, far)
            align_goal = p.goal_align * np.minimum(self._goal_distance(gd, front) / sr, far)
        lam = p.inflation * sr
        obstacle = np.exp(-np.maximum(static.clear_static, 0.0) / lam)
        obstacle += np.minimum(np.exp(-d_go / lam), _MAX_OBSTACLE_COST)
        #: The critics' weighted scores, one row each (kept for diagnostics).
        self.parts = np.array([
            p.path_dist * path_d,
            p.goal_dist * goal_d,
            align_path,
            align_goal,
            p.obstacle * obstacle,
            p.prefer_forward * np.maximum(-V, 0.0) / self.v_max,
        ])  # fmt: skip
        cost = self.parts.sum(axis=0)
        return np.where(np.isfinite(cost), cost, np.inf)

    def _choose(self, x, th, v0, t, V, W, safe, cost, static, ttc, d) -> tuple[int, str]:
        """``(index, mode)`` of the command taken: a recovery's back-up, the rotation shim, the
        cheapest safe command the oscillation critic allows, or when nothing is safe the
        admissible one that meets the predicted obstacle last (``ttc``, ``d``: driving on and
        stopping)."""
        if t < self._backup_until:
            choice, mode = self._backup(V, W, safe), "backup"
        else:
            choice = self._rotate(x, th, v0, V, W, safe)
            mode = "critics" if choice is None else "rotate"
        if choice is not None:
            return choice, mode
        osc = self._v_trend.refuses(V)
        osc |= (np.abs(V) <= 0.1 * self.v_max) & self._w_trend.refuses(W)
        legal = safe & np.isfinite(cost)
        if legal.any() and (legal & ~osc).any():
            legal &= ~osc
        if legal.any():
            return int(np.argmin(np.where(legal, cost, np.inf))), mode
        if safe.any():
            # Off the fields' reach: the safe command nearest the local plan's end.
            end = static.go[:, -1]
            near = np.hypot(*(end - self._local[-1]).T)
            return int(np.argmin(np.where(safe, near, np.inf))), mode
        # Whatever it does, a predicted obstacle comes too close: the admissible command whose
        # better continuation meets it last, and of those the one that comes least close.
        admissible = static.admissible
        late = np.where(admissible, np.maximum(*ttc), -np.inf)
        least = np.where(admissible, np.maximum(*d), -np.inf)
        return int(np.lexsort((-late, -np.round(least, 9)))[0]), "unavoidable"

    def _dynamic_clearance(self, x, traj, V, obstacles) -> tuple[np.ndarray, np.ndarray]:
        """First predicted contact (s; ``inf`` when none) and least margin (units) to the sensed
        obstacles' constant-velocity predictions along ``traj`` (``(m, len(t_pred), 2)``), per
        sample: exact on each chord of the relative motion (linear in time up to the arc's
        sagitta, which the margin is padded with)."""
        m = len(V)
        if not obstacles:
            return np.full(m, np.inf), np.full(m, np.inf)
        pos = np.array([o[0] for o in obstacles.values()], dtype=float)  # (J, 2)
        vel = np.array([o[1] for o in obstacles.values()], dtype=float)
        rad = np.array([o[2] for o in obstacles.values()], dtype=float)
        ts = np.concatenate([[0.0], self.t_pred])
        pred = pos[:, None, :] + ts[None, :, None] * vel[:, None, :]  # (J, n + 1, 2)
        contact = self.sr + rad + 0.5 * self.margin  # (J,)
        pad = 0.25 * np.abs(V) * self.w_max * self.dt**2  # the arc's sagitta, over-estimated
        full = np.concatenate([np.broadcast_to(x, (m, 1, 2)), traj], axis=1)  # (m, n + 1, 2)
        rel = full[:, None] - pred[None]  # (m, J, n + 1, 2)
        a, d = rel[:, :, :-1], np.diff(rel, axis=2)
        dd = np.einsum("...k,...k->...", d, d)
        u = np.clip(-np.einsum("...k,...k->...", a, d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
        closest = np.hypot(*(a + u[..., None] * d).transpose(3, 0, 1, 2))  # (m, J, n)
        margin = (closest - contact[None, :, None]).min(axis=1) - pad[:, None]  # (m, n)
        hit = margin < 0
        ttc = np.where(hit.any(axis=1), ts[hit.argmax(axis=1)], np.inf)
        return ttc, margin.min(axis=1)

    # -- behaviours -----------------------------------------------------------------------------
    def _rotate(self, x, th, v0, V, W, safe) -> int | None:
        """Nav2's rotation shim: nearly stopped and facing away from the local plan, turn in
        place towards it (when turning in place is safe)."""
        if abs(v0) > self.acc * self.dt + 1e-12:
            return None
        ahead = self._point_at(np.array([min(self.s_at[-1], self.progress + 2.0 * self.sr)]))[0]
        if math.dist(ahead, x) < 0.5 * self.sr:
            return None
        err = wrap_angle(math.atan2(ahead[1] - x[1], ahead[0] - x[0]) - th)
        if abs(err) <= math.radians(self.p.rotate_threshold_deg):
            return None
        turning = safe & (V == 0)
        if not turning.any():
            return None
        want = math.copysign(min(self.w_max, abs(err) / self.dt), err)
        return int(np.argmin(np.where(turning, np.abs(W - want), np.inf)))

    def _backup(self, V, W, safe) -> int | None:
        """A recovery's back-up: the safe command nearest half the reverse speed, straight."""
        if not safe.any() or self.v_min >= 0:
            return None
        want = 0.5 * self.v_min
        return int(np.argmin(np.where(safe, np.abs(V - want) + np.abs(W), np.inf)))

    def _debrief(self, v: float, w: float, x: np.ndarray, th: float) -> None:
        """The oscillation critic's memory (DWB's debrief): a sign flip starts a refusal that
        moving or turning enough forgets."""
        flipped = self._v_trend.update(v)
        if abs(v) <= 0.1 * self.v_max:
            flipped |= self._w_trend.update(w)
        if flipped:
            self._flip_pose = (x.copy(), th)
        elif self._v_trend.refused or self._w_trend.refused:
            fx, fth = self._flip_pose
            if (math.dist(x, fx) > self.p.oscillation_distance * self.sr
                    or abs(th - fth) > self.p.oscillation_angle):  # fmt: skip
                self._v_trend, self._w_trend = (
                    _Trend(self._v_trend.sign),
                    _Trend(self._w_trend.sign),
                )

    def _check_progress(self, x: np.ndarray, t: float) -> None:
        """Nav2's progress checker: no progress for ``progress_time`` starts a recovery."""
        if self._checkpoint is None or math.dist(x, self._checkpoint[1]) >= (
            self.p.progress_distance * self.sr
        ):
            self._checkpoint = (t, x.copy())
        elif t - self._checkpoint[0] >= self.p.progress_time:
            self._recover(t, x, "no progress")
            self._checkpoint = (t, x.copy())

    def _recover(self, t: float, x: np.ndarray, why: str) -> bool:
        """Re-plan the guide path from ``x`` on the grid and back up a little; False when the
        recoveries are used up or no route exists."""
        if len(self.recoveries) >= self.p.max_recoveries:
            return False
        self.recoveries.append((t, why))
        if why == "no progress":
            self._backup_until = t + self.p.backup_time
        route = self.grid.route(x, self.goal)
        if route is None or len(route) < 2:
            return False
        self._set_guide(route)
        self._v_trend, self._w_trend = _Trend(), _Trend()
        self._track(x)
        return True
