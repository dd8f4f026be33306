"""Moving obstacles: collision prediction and the replanning manager (paper section 4.2).

The robot drives its planned path (the differential-drive stop-and-turn motion of
:class:`~rrtpso_ompl.motion.Motion`), the moving obstacles move at constant velocity (eqs. 14-15,
optionally with random heading changes), and every ``sample_time`` the robot

1. **senses** the moving obstacles whose disc comes within ``sensor_range`` of its centre and
   measures their position and velocity;
2. **predicts**, for each sensed obstacle, the *cross point*: the first time at which its remaining
   motion and the obstacle's constant-velocity extrapolation come closer than
   ``SR + SO + margin/2`` (exact, see :func:`~rrtpso_ompl.motion.first_entry`), and the
   collision zone (the stretch of its path during which they stay that close);
3. on a predicted collision, **replans** (:class:`ReplanningManager`): it keeps driving its old
   plan while the planner runs (the planning budget is simulated time), so the detour starts where
   the robot will be when it is ready; the detour's goal is the first point of the old path safely
   past the collision zone; the obstacles' predicted sweeps over the detour's time window become
   static obstacles (a disc's sweep is exactly a capsule: circle + rectangle + circle); a thin wall
   on one side of the cross point makes the planner pass on the other side, and both detours,
   "contour path up" (left of the direction of travel) and "down" (right), are planned with
   RRTstarPSO. Every candidate is then *verified* in space and time against all sensed
   obstacles; the verified one that arrives first is spliced in. Without a verified detour the
   robot waits or steps aside (also verified); it never drives into a predicted collision.

Only the time windows in which the robot could actually meet an obstacle become static
obstacles: the robot, driving at speed ``v`` from ``p_s`` at ``t_s`` on a detour at most
``stretch`` times longer than the straight line, reaches a point ``x`` between
``t_s + |x - p_s| / v`` and ``t_s + stretch |x - p_s| / v`` (plus turning time), so an obstacle
position outside that window is irrelevant. This is what lets a robot step aside from an
obstacle coming head-on, whose whole sweep covers the robot's own position. The assumption is
checked by the exact verification, never trusted.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model.problem import Circle, PlannerConfig, Polygon, Problem
from ..model.world import World
from .motion import Motion, ObstacleTrack, closest_approach, first_entry

__all__ = [
    "DynamicOptions",
    "Replan",
    "ReplanningManager",
    "SimulationResult",
    "Threat",
    "capsule",
    "predict_threats",
    "simulate",
]

#: The strategies: the paper's contour detours, replanning the whole remaining path (baseline),
#: or driving the static path blindly (baseline).
STRATEGIES = ("contour", "global", "none")


@dataclass(frozen=True)
class DynamicOptions:
    """Parameters of the simulation and of the replanning manager.

    Attributes
    ----------
    planner : str
        Planner of the initial path and of the detours (any registered name).
    strategy : {"contour", "global", "none"}
        ``contour``: detours around the collision zone, up and down (the paper's method);
        ``global``: replan the whole remaining path to the goal (one plan); ``none``: never replan.
    replan_time : float
        Simulated seconds one replan takes: the planners' total budget (the two contour detours
        get half each). The robot keeps driving its old plan meanwhile.
    initial_time : float or None
        Budget for the initial static path, s (default: the problem's ``planner.time_limit``,
        else 1.0). The robot waits for it at the start; it is not counted as driving time.
    margin : float or None
        Extra separation kept beyond ``SR + SO``, units (default 10 % of ``SR + SO`` of the
        smallest obstacle). Detours are planned with the full margin; a collision is *predicted*
        when the separation would drop below ``SR + SO + margin / 2``.
    stretch : float
        How much longer than the straight line a detour may be (>= 1) when the relevant time
        windows are computed.
    max_time : float or None
        Simulated time limit, s (default: four times the static path's duration plus 60 s).
    heading_changes : float
        Mean number of random heading changes per obstacle per second (Poisson); 0 keeps the
        paper's constant velocity.
    heading_change_deg : float
        Standard deviation of a heading change, degrees.
    params : mapping
        Parameters for the planner.
    """

    planner: str = "RRTstarPSO"
    strategy: str = "contour"
    replan_time: float = 0.5
    initial_time: float | None = None
    margin: float | None = None
    stretch: float = 2.0
    max_time: float | None = None
    heading_changes: float = 0.0
    heading_change_deg: float = 45.0
    params: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.strategy not in STRATEGIES:
            raise ValueError(
                f"strategy must be one of {', '.join(STRATEGIES)}, got {self.strategy!r}"
            )
        for name in ("replan_time",):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0")
        if not self.stretch >= 1.0:
            raise ValueError("stretch must be >= 1")
        if self.heading_changes < 0 or self.heading_change_deg < 0:
            raise ValueError("heading_changes and heading_change_deg must be >= 0")
        if self.margin is not None and self.margin < 0:
            raise ValueError("margin must be >= 0")


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


@dataclass
class Replan:
    """One reaction of the manager (JSON-ready through :meth:`to_dict`).

    ``kind`` is ``"contour"``/``"global"`` for a planned detour, ``"wait"`` or ``"evade"`` for a
    fallback, ``"unavoidable"`` when nothing verified. ``planning_time`` is the measured wall-clock
    time of the planners, ``budget`` the simulated time it was charged.
    """

    t: float
    kind: str
    side: str | None
    start: np.ndarray
    goal: np.ndarray | None
    planning_time: float
    budget: float
    length: float | None
    obstacles: list[int]
    cross_point: np.ndarray
    t_cross: float
    candidates: list[dict[str, Any]] = field(default_factory=list)
    detour: np.ndarray | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "t": self.t,
            "kind": self.kind,
            "side": self.side,
            "start": self.start.tolist(),
            "goal": None if self.goal is None else self.goal.tolist(),
            "planning_time": self.planning_time,
            "budget": self.budget,
            "length": self.length,
            "obstacles": self.obstacles,
            "cross_point": self.cross_point.tolist(),
            "t_cross": self.t_cross,
            "candidates": self.candidates,
            "detour": None if self.detour is None else self.detour.tolist(),
        }


@dataclass
class SimulationResult:
    """The outcome of one simulation; :meth:`to_dict` is the ``rrtpso simulate --json`` output.

    Distances are centre to centre (units): the robot and obstacle ``k`` touch at
    ``SR + SO_k``. ``collisions`` counts the sample instants at which any separation was below
    that; ``min_separation_continuous`` is exact between samples too.
    """

    problem: str
    strategy: str
    planner: str
    seed: int | None
    reached_goal: bool
    collisions: int
    min_separation: list[float | None]
    min_separation_continuous: list[float | None]
    contact_distance: list[float]
    total_time: float
    path_length: float
    static_length: float | None
    sample_time: float
    motion: Motion | None
    static_path: np.ndarray
    tracks: list[ObstacleTrack]
    replans: list[Replan]
    plans: list[tuple[float, Motion]]
    status: str = "ok"

    @property
    def trajectory(self) -> np.ndarray:
        """``[t, x, y, theta]`` every sample time from the start to the goal (or the end)."""
        if self.motion is None:
            return np.empty((0, 4))
        return self.motion.sample(self.sample_time)

    @property
    def success(self) -> bool:
        """Goal reached without any collision."""
        return self.reached_goal and self.collisions == 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "problem": self.problem,
            "status": self.status,
            "strategy": self.strategy,
            "planner": self.planner,
            "seed": self.seed,
            "reached_goal": self.reached_goal,
            "collisions": self.collisions,
            "min_separation": self.min_separation,
            "min_separation_continuous": self.min_separation_continuous,
            "contact_distance": self.contact_distance,
            "total_time": self.total_time,
            "path_length": self.path_length,
            "static_length": self.static_length,
            "replans": [r.to_dict() for r in self.replans],
            "trajectory": self.trajectory.tolist(),
            "static_path": self.static_path.tolist(),
        }


# ----------------------------------------------------------------------------------------------
# Prediction
# ----------------------------------------------------------------------------------------------
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
        at = _linear(pos, vel, t_now)
        hit = first_entry(plan, at, t_now, t_end, robot_radius + radius + margin)
        if hit is not None:
            te, tx = hit
            threats.append(Threat(j, te, tx, plan.position(te), at(np.array([te]))[0]))
    return sorted(threats, key=lambda th: th.t_enter)


def _linear(pos: np.ndarray, vel: np.ndarray, t0: float) -> Callable[[np.ndarray], np.ndarray]:
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


# ----------------------------------------------------------------------------------------------
# The replanning manager
# ----------------------------------------------------------------------------------------------
class ReplanningManager:
    """Reacts to predicted collisions: plans, verifies and splices detours (see the module doc).

    Parameters
    ----------
    problem : Problem
        The static problem (its moving obstacles are not used here: the manager only knows what
        the robot senses).
    options : DynamicOptions
    speed, turn_rate : float
        The robot's driving speed (units/s) and turn-in-place rate (rad/s, None for instant).
    margin : float
        Extra separation, units.
    rng : numpy.random.Generator
        Seeds the planners.
    solve_fn : callable
        ``solve``-compatible function (injectable for tests).
    """

    def __init__(
        self,
        problem: Problem,
        options: DynamicOptions,
        speed: float,
        turn_rate: float | None,
        margin: float,
        rng: np.random.Generator,
        solve_fn: Callable[..., Any] | None = None,
    ) -> None:
        from ..planners.solve import solve

        self.problem = problem
        self.options = options
        self.speed = speed
        self.turn_rate = turn_rate
        self.margin = margin
        self.rng = rng
        self.solve = solve_fn or solve
        self.world = World.from_problem(problem)
        (xmin, ymin), (xmax, ymax) = problem.bounds
        self.diagonal = math.hypot(xmax - xmin, ymax - ymin)
        self.sr = problem.robot.radius
        # Slack for turning in place on a detour: one half turn in all (verified, not trusted).
        self.turn_slack = math.pi / turn_rate if turn_rate else 0.0
        # Detours must not reseed OMPL (once per process): planners that take a seed get one as
        # a parameter instead.
        from ..planners.registry import default_registry

        entry = default_registry().get(options.planner)
        self._seed_param = any(p.name == "seed" for p in entry.params)

    # -- entry points ----------------------------------------------------------------------------
    def react(
        self, t_now: float, plan: Motion, obs: Mapping[int, Any], threats: list[Threat]
    ) -> tuple[Motion, Replan]:
        """A new plan for the predicted ``threats`` (verified when at all possible)."""
        budget = self.options.replan_time
        t_s = t_now + budget
        first = threats[0]
        if first.t_enter <= t_s + 1e-9:
            # No time to plan: fall back at once (no planning, so nothing is charged).
            return self.fallback(t_now, plan, obs, threats, t_now)
        p_s = plan.position(t_s)
        th_s = float(plan.heading(t_s))
        t_exit = max(th.t_exit for th in threats)
        candidates: list[dict[str, Any]] = []
        best: tuple[float, Motion, dict[str, Any]] | None = None
        clock = time.perf_counter()
        if self.options.strategy == "contour":
            tangent = _direction(plan, first.t_enter)
            sides = ("up", "down")
            share = budget / len(sides)
        else:
            sides, share, tangent = (None,), budget, None
        for side in sides:
            cand = self._detour(
                t_now, plan, obs, p_s, th_s, t_s, t_exit, side, share, first, tangent
            )
            candidates.append(cand["record"])
            if cand["motion"] is not None and (best is None or cand["motion"].t_end < best[0]):
                best = (cand["motion"].t_end, cand["motion"], cand)
        elapsed = time.perf_counter() - clock
        if best is None:
            # Planning failed after its budget: the robot has driven on until t_s; fall back there.
            new, rec = self.fallback(t_now, plan, obs, threats, t_s)
            rec.planning_time, rec.budget = elapsed, budget
            rec.candidates = candidates + rec.candidates
            return new, rec
        _, motion, cand = best
        rec = Replan(
            t=t_now,
            kind=self.options.strategy,
            side=cand["side"],
            start=p_s,
            goal=cand["goal"],
            planning_time=elapsed,
            budget=budget,
            length=cand["length"],
            obstacles=[th.obstacle for th in threats],
            cross_point=first.cross_point,
            t_cross=first.t_enter,
            candidates=candidates,
            detour=cand["path"],
        )
        return motion, rec

    def fallback(
        self,
        t_now: float,
        plan: Motion,
        obs: Mapping[int, Any],
        threats: list[Threat],
        t_act: float,
    ) -> tuple[Motion, Replan]:
        """Wait, or step aside and wait, from time ``t_act``: the first verified option that
        arrives soonest; the safest one when none verifies."""
        p = plan.position(t_act)
        th = float(plan.heading(t_act))
        head = plan.until(t_act) if t_act > plan.t[0] else None
        rest_path = plan.waypoints_after(t_act)
        d_contact = self.sr + max(r for _, _, r in obs.values()) + self.margin
        ts = self.problem.robot.sample_time or 0.1
        waits = [0.0] + [ts * 2**k for k in range(0, 9)]
        options: list[tuple[str, np.ndarray | None, float]] = [("wait", None, w) for w in waits[1:]]
        for ang in np.linspace(0, 2 * math.pi, 16, endpoint=False):
            for dist in (d_contact, 2 * d_contact, 3 * d_contact):
                x = p + dist * np.array([math.cos(th + ang), math.sin(th + ang)])
                if self.world.in_bounds(*x) and self.world.motion_free(*p, *x):
                    options.extend(("evade", x, w) for w in waits)
        best_ok: tuple[float, Motion, str, np.ndarray | None, float] | None = None
        best_bad: tuple[float, Motion, str, np.ndarray | None, float] | None = None
        for kind, x, w in options:
            m = self._fallback_motion(head, p, th, t_act, rest_path, x, w)
            sep = self._worst_separation(m, obs, t_now)
            if sep >= 0:
                if best_ok is None or m.t_end < best_ok[1].t_end:
                    best_ok = (sep, m, kind, x, w)
            elif best_bad is None or sep > best_bad[0]:
                best_bad = (sep, m, kind, x, w)
        chosen = best_ok or best_bad
        assert chosen is not None
        sep, m, kind, x, w = chosen
        rec = Replan(
            t=t_now,
            kind=kind if best_ok else "unavoidable",
            side=None,
            start=p,
            goal=x,
            planning_time=0.0,
            budget=0.0,
            length=None if x is None else float(2 * np.hypot(*(x - p))),
            obstacles=[t.obstacle for t in threats],
            cross_point=threats[0].cross_point,
            t_cross=threats[0].t_enter,
            candidates=[{"kind": kind, "wait": w, "margin_left": sep}],
        )
        return m, rec

    # -- pieces ------------------------------------------------------------------------------------
    def _fallback_motion(self, head, p, th, t_act, rest_path, x, wait) -> Motion:
        if x is None:
            out = Motion.rest(p, th, t_act, t_act + wait)
        else:
            # Stepping aside may be done backwards: no time lost turning away from the threat.
            out = Motion.from_path(np.array([p, x]), t_act, th, self.speed, self.turn_rate, True)
            out = out.then(Motion.rest(x, float(out.theta[-1]), out.t_end, out.t_end + wait))
        back = rest_path
        if x is not None:
            # Rejoin the old path at its next waypoint when the straight line there is free.
            skip = len(rest_path) > 1 and self.world.motion_free(*x, *rest_path[1])
            back = np.vstack([x[None], rest_path[1:] if skip else rest_path])
        if len(back) > 1:
            out = out.then(
                Motion.from_path(back, out.t_end, float(out.theta[-1]), self.speed, self.turn_rate)
            )
        return out if head is None else head.then(out)

    def _worst_separation(self, motion: Motion, obs: Mapping[int, Any], t_now: float) -> float:
        """Smallest ``distance - (SR + SO + margin/2)`` over the observed obstacles."""
        worst = math.inf
        for pos, vel, radius in obs.values():
            d, _ = closest_approach(motion, _linear(pos, vel, t_now), t_now, motion.t_end)
            worst = min(worst, d - (self.sr + radius + 0.5 * self.margin))
        return worst

    def _detour(self, t_now, plan, obs, p_s, th_s, t_s, t_exit, side, budget, first, tangent):
        record: dict[str, Any] = {"side": side, "valid": False, "length": None, "reason": ""}
        out = {"motion": None, "record": record, "side": side, "goal": None, "length": None,
               "path": None}  # fmt: skip
        goal_final = self.options.strategy == "global"
        wall = []
        if side is not None:
            normal = np.array([-tangent[1], tangent[0]])  # left of the direction of travel
            away = -normal if side == "up" else normal  # block the other side
            wall = [
                _wall(
                    first.cross_point,
                    away,
                    self.diagonal,
                    max(1e-3 * self.diagonal, 0.05 * self.sr),
                )
            ]
        # The goal: the first point of the old path past the zone that is free in the detour world.
        if goal_final:
            goal_times = np.array([plan.t_end])
        else:
            step = max(self.sr, 1e-6) / self.speed
            goal_times = np.append(np.arange(t_exit + step, plan.t_end, step), plan.t_end)
        world = None
        t_g = None
        for t_g in goal_times:
            g = plan.position(t_g)
            horizon = self._horizon(plan, t_s, float(t_g))
            obstacles = (
                list(self.problem.obstacles) + wall + self._sweeps(obs, t_now, p_s, t_s, horizon)
            )
            world = World(self.problem.bounds, *_split(obstacles), self.sr)
            if world.point_free(*g):
                break
            world = None
        if world is None:
            record["reason"] = "no free rejoin point past the collision zone"
            return out
        if not world.point_free(*p_s):
            record["reason"] = "the detour start lies in a predicted sweep"
            return out
        detour_problem = dataclasses.replace(
            self.problem,
            name=f"{self.problem.name}@{t_now:.2f}s" + (f"/{side}" if side else ""),
            start=(float(p_s[0]), float(p_s[1])),
            goal=(float(g[0]), float(g[1])),
            goal_tolerance=0.0,
            obstacles=tuple(obstacles),
            moving_obstacles=(),
            planner=PlannerConfig(),
        )
        params = dict(self.options.params)
        if self._seed_param:
            params.setdefault("seed", int(self.rng.integers(2**31 - 1)))
        res = self.solve(detour_problem, self.options.planner, budget, None, params, world=world)
        record["planning_time"] = res.time
        if not res.solved:
            record["reason"] = f"planner found no detour ({res.ompl_status})"
            return out
        tail = plan.waypoints_after(float(t_g))
        route = np.vstack([res.path, tail[1:]])
        motion = plan.until(t_s).then(
            Motion.from_path(route, t_s, th_s, self.speed, self.turn_rate)
        )
        sep = self._worst_separation(motion, obs, t_now)
        record["length"] = res.length
        record["margin_left"] = sep
        if sep < 0:
            record["reason"] = "verification failed: the detour meets a predicted obstacle"
            return out
        record["valid"] = True
        out.update(motion=motion, goal=g, length=res.length, path=res.path)
        return out

    def _horizon(self, plan: Motion, t_s: float, t_g: float) -> float:
        """Latest time the detour to the old plan's point at ``t_g`` may still be under way."""
        length = plan.path_length(t_s, t_g)
        return t_s + (self.options.stretch * length + 2 * self.sr) / self.speed + self.turn_slack

    def _sweeps(self, obs, t_now, p_s, t_s, t_end) -> list[Circle | Polygon]:
        """Capsules for the parts of each observed obstacle's predicted motion in ``[t_s, t_end]``
        that the robot, starting at ``p_s`` at ``t_s``, could meet (see the module docstring)."""
        out: list[Circle | Polygon] = []
        v = self.speed
        for pos, vel, radius in obs.values():
            r = radius + self.margin
            reach = self.sr + r
            speed_o = float(np.hypot(*vel))
            dt = min(0.25 * r / speed_o if speed_o > 0 else math.inf, max(t_end - t_s, 1e-6) / 50)
            ts = np.arange(t_s, t_end + dt, dt)
            q = _linear(pos, vel, t_now)(ts)
            d = np.hypot(*(q - p_s).T)
            earliest = t_s + (d - reach) / v
            latest = t_s + self.options.stretch * (d + reach) / v + self.turn_slack
            relevant = (ts + dt >= earliest) & (ts - dt <= latest)
            for lo, hi in _runs(relevant):
                # One grid step of padding either side: the window's ends are between samples.
                a = _linear(pos, vel, t_now)(np.array([max(ts[lo] - dt, t_s)]))[0]
                b = _linear(pos, vel, t_now)(np.array([ts[hi] + dt]))[0]
                out.extend(capsule(a, b, r))
        return out


# ----------------------------------------------------------------------------------------------
# The simulation loop
# ----------------------------------------------------------------------------------------------
def simulate(
    problem: Problem,
    options: DynamicOptions | None = None,
    seed: int | None = None,
    initial_path: np.ndarray | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> SimulationResult:
    """Drive the robot from start to goal among the problem's moving obstacles.

    Parameters
    ----------
    problem : Problem
        Needs ``robot.speed``, ``robot.sample_time`` and ``robot.sensor_range``; the turn rate
        comes from ``robot.track_width`` and ``max_wheel_speed`` (else ``speed``), with
        instantaneous turns when there is no track width.
    options : DynamicOptions, optional
    seed : int, optional
        Seeds the planners and the obstacles' random heading changes (numpy ``Generator``).
    initial_path : (n, 2) array, optional
        The static path to start from (planned with ``options.planner`` when omitted); passing it
        lets several strategies start from the same path.
    progress : callable, optional
        Called as ``progress(t, t_estimate)`` after every step.

    Returns
    -------
    SimulationResult
    """
    from ..planners.solve import solve

    options = options or DynamicOptions()
    robot = problem.robot
    for key in ("speed", "sample_time", "sensor_range"):
        if getattr(robot, key) is None:
            raise ValueError(f"robot.{key} is required for a simulation")
    speed = min(v for v in (robot.speed, robot.max_speed, robot.max_wheel_speed) if v is not None)
    turn_rate = None
    if robot.track_width:
        wheel = robot.max_wheel_speed or robot.speed
        turn_rate = 2.0 * wheel / robot.track_width
    ts = float(robot.sample_time)
    sr = robot.radius
    moving = problem.moving_obstacles
    radii = [m.radius for m in moving]
    margin = options.margin
    if margin is None:
        margin = 0.1 * (sr + min(radii, default=0.0))
    rng = np.random.default_rng(seed)
    plan_rng, world_rng = rng.spawn(2)

    if initial_path is None:
        res = solve(problem, options.planner, options.initial_time, seed, dict(options.params))
        initial_path = res.path if res.solved else np.empty((0, 2))
    static_path = np.asarray(initial_path, dtype=float).reshape(-1, 2)
    tracks = [ObstacleTrack.from_obstacle(m) for m in moving]
    contact = [sr + r for r in radii]
    if len(static_path) < 2:
        return SimulationResult(
            problem.name, options.strategy, options.planner, seed, False, 0,
            [None] * len(moving), [None] * len(moving), contact, 0.0, 0.0, None, ts, None,
            static_path, tracks, [], [], status="no static path",
        )  # fmt: skip

    plan = Motion.from_path(static_path, 0.0, None, speed, turn_rate)
    static_length = float(np.hypot(*np.diff(static_path, axis=0).T).sum())
    t_max = options.max_time if options.max_time is not None else 4 * plan.t_end + 60.0
    manager = ReplanningManager(problem, options, speed, turn_rate, margin, plan_rng)
    plans = [(0.0, plan)]
    replans: list[Replan] = []
    busy_until = -math.inf
    change_p = options.heading_changes * ts
    t = 0.0
    k = 0
    while t < plan.t_end - 1e-9 and t <= t_max:
        p = plan.position(t)
        obs = {}
        for j, tr in enumerate(tracks):
            q = tr.position(t)
            if math.hypot(*(q - p)) - tr.radius <= robot.sensor_range:
                obs[j] = (q, tr.velocity, tr.radius)
        if obs and options.strategy != "none":
            threats = predict_threats(plan, t, obs, sr, 0.5 * margin)
            if threats and t >= busy_until:
                plan, rec = manager.react(t, plan, obs, threats)
                busy_until = t + rec.budget
                replans.append(rec)
                plans.append((t, plan))
            elif threats and threats[0].t_enter <= busy_until + ts:
                # A new threat while the planner is busy and before it can help: react at once.
                plan, rec = manager.fallback(t, plan, obs, threats, t)
                replans.append(rec)
                plans.append((t, plan))
        k += 1
        t = k * ts
        if change_p > 0:
            for tr in tracks:
                if world_rng.random() < change_p:
                    tr.turn(
                        t,
                        tr.heading
                        + math.radians(world_rng.normal(0.0, options.heading_change_deg)),
                    )
        if progress is not None:
            progress(min(t, plan.t_end), plan.t_end)

    reached = plan.t_end <= t_max + 1e-9
    executed = plan if reached else plan.until(min(t, plan.t_end))
    samples = executed.sample(ts)
    min_sep: list[float | None] = []
    min_cont: list[float | None] = []
    collisions = np.zeros(len(samples), dtype=bool)
    for tr, c in zip(tracks, contact, strict=True):
        d = np.hypot(*(samples[:, 1:3] - tr.position(samples[:, 0])).T)
        collisions |= d < c * (1 - 1e-9)
        min_sep.append(float(d.min()))
        dc, _ = closest_approach(
            executed, tr.position, executed.t[0], executed.t_end, tr.breakpoints()
        )
        min_cont.append(dc)
    return SimulationResult(
        problem=problem.name,
        strategy=options.strategy,
        planner=options.planner,
        seed=seed,
        reached_goal=bool(
            reached and np.allclose(executed.end, problem.goal, atol=1e-6 + problem.goal_tolerance)
        ),
        collisions=int(collisions.sum()),
        min_separation=min_sep,
        min_separation_continuous=min_cont,
        contact_distance=contact,
        total_time=executed.t_end,
        path_length=executed.path_length(),
        static_length=static_length,
        sample_time=ts,
        motion=executed,
        static_path=static_path,
        tracks=tracks,
        replans=replans,
        plans=plans,
    )


# ----------------------------------------------------------------------------------------------
# Small helpers
# ----------------------------------------------------------------------------------------------
def _direction(plan: Motion, t: float) -> np.ndarray:
    """Unit direction of travel at time ``t`` (the heading; robust inside turns)."""
    h = float(plan.heading(t))
    return np.array([math.cos(h), math.sin(h)])


def _wall(origin: np.ndarray, direction: np.ndarray, length: float, width: float) -> Polygon:
    """A thin rectangle from ``origin`` along ``direction``: it closes one side to the planner."""
    side = np.array([-direction[1], direction[0]]) * (0.5 * width)
    far = origin + direction * length
    ring = [origin - side, far - side, far + side, origin + side]
    return Polygon(tuple((float(x), float(y)) for x, y in ring))


def _split(obstacles) -> tuple[list[tuple[float, float, float]], list[np.ndarray]]:
    circles = [(*o.center, o.radius) for o in obstacles if isinstance(o, Circle)]
    polygons = [np.asarray(o.points) for o in obstacles if isinstance(o, Polygon)]
    return circles, polygons


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``(first, last)`` of the True runs in ``mask``."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(m))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]
