"""The replanning manager: on a predicted collision, plan contour detours, verify them, splice one.

It keeps driving the old plan while the planner runs (the planning budget is simulated time), so
the detour starts where the robot will be when it is ready; the detour's goal is the first point
of the old path safely past the collision zone; the obstacles' predicted sweeps over the detour's
time window become static obstacles (capsules); a thin wall on one side of the cross point makes
the planner pass on the other side, and both detours, "contour path up" (left of the direction of
travel) and "down" (right), are planned with the static planner (RRTstarPSO by default). A third
candidate is *waiting*: the least stop (a multiple of the control period) after which the old plan
passes every obstacle. Every candidate is *verified* in space and time against all sensed
obstacles; the verified one that arrives first is spliced in (on a tie the shorter, so a wait
beats an equally fast detour). Without a verified candidate the robot waits or steps aside (also
verified); it never drives into a predicted collision. The planning budget (``replan_time``) is
simulated time and also a wall-clock budget: the detours share what is left of it, less what a
solve costs beyond its own time limit (measured as the manager goes). Once no collision is
predicted, :meth:`ReplanningManager.reshorten` shortcuts the rest of the plan in the static
world, so a detour's bends go when the obstacle has passed.

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
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.geometry import shortcut
from ..model.problem_types import Circle, PlannerConfig, Polygon, Problem
from ..model.world import World
from .motion import Motion, closest_approach
from .options import DynamicOptions, Observations
from .prediction import Threat, capsule, extrapolate, true_runs
from .result import Replan

__all__ = [
    "BUDGET_RESERVE",
    "FALLBACK_KINDS",
    "MAX_WAIT_STEPS",
    "Detour",
    "Replan",
    "ReplanPolicy",
    "ReplanningManager",
]

#: Least planner budget of one detour, s (below it a solve cannot even set up).
MIN_DETOUR_TIME = 0.01
#: Share of the replanning budget kept back for the bookkeeping after the last solve (choosing,
#: recording) and for the scatter of a solve's overrun around the measured estimate.
BUDGET_RESERVE = 0.05
#: The kinds of a :class:`Replan` that planned nothing (the others are the strategy's name).
FALLBACK_KINDS = ("wait", "evade", "unavoidable")
#: Most waits one replan verifies (each is an exact check against every sensed obstacle).
MAX_WAIT_STEPS = 400


@dataclass(frozen=True)
class ReplanPolicy:
    """What a replanning strategy asks of the manager (the defaults are the paper's contour).

    Attributes
    ----------
    kind : str
        The :attr:`Replan.kind` of a planned reaction (the strategy's name).
    sides : tuple of str or None
        The detours planned per replan: ``"up"`` (left of the direction of travel) and
        ``"down"``, each behind a wall that closes the other side, or ``(None,)``: one plan
        with no wall.
    wait : bool
        Whether waiting for the obstacles to pass is a candidate too.
    rejoin_at_goal : bool
        Whether the detour goes to the goal (the whole remaining path replanned) instead of the
        first free point of the old plan past the collision zone.
    """

    kind: str = "contour"
    sides: tuple[str | None, ...] = ("up", "down")
    wait: bool = True
    rejoin_at_goal: bool = False


@dataclass
class Detour:
    """One planned detour (a candidate of a replan).

    Attributes
    ----------
    side : str or None
        ``"up"``, ``"down"``, ``"wait"`` (let the obstacle pass, then drive on) or None
        (whole-path replanning).
    record : dict
        Its JSON record in :attr:`Replan.candidates` (side, validity, length, predicted arrival
        in s, reason...).
    motion : Motion or None
        The spliced plan when the detour was planned and verified, else None.
    goal : ndarray or None
        Where it rejoins the old plan.
    length : float or None
        Length of the planned detour, units.
    path : ndarray or None
        The planner's path.
    """

    side: str | None
    record: dict[str, Any]
    motion: Motion | None = None
    goal: np.ndarray | None = None
    length: float | None = None
    path: np.ndarray | None = None

    def refuse(self, reason: str) -> Detour:
        """Mark the detour as not usable, for ``reason``."""
        self.record["reason"] = reason
        return self


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
    policy : ReplanPolicy, optional
        What the strategy asks of a replan (default: the paper's contour detours).
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
        *,
        policy: ReplanPolicy | None = None,
    ) -> None:
        from ..planners import default_registry, solve

        self.problem = problem
        self.options = options
        self.policy = policy or ReplanPolicy()
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
        # Detours do not reseed OMPL (that would restart its sequence at every replan, so every
        # detour would sample alike): planners that take a seed get one as a parameter instead.
        self._seed_param = default_registry().get(options.planner).takes("seed")
        # What a solve costs beyond its own budget (set-up, verification), s; measured per call.
        self._overrun = 0.005

    # -- entry points ----------------------------------------------------------------------------
    def react(
        self, t_now: float, plan: Motion, obs: Observations, threats: list[Threat]
    ) -> tuple[Motion, Replan]:
        """A new plan for the predicted ``threats`` (verified when at all possible)."""
        budget = self.options.replan_time
        t_s = t_now + budget
        if threats[0].t_enter <= t_s + 1e-9:
            # No time to plan: fall back at once (no planning, so nothing is charged).
            return self.fallback(t_now, plan, obs, threats, t_now)
        clock = time.perf_counter()
        deadline = clock + (1.0 - BUDGET_RESERVE) * budget
        detours = self._candidates(t_now, plan, obs, threats, t_s, deadline)
        elapsed = time.perf_counter() - clock
        candidates = [d.record for d in detours]
        usable = [d for d in detours if d.motion is not None]
        if not usable:
            # Planning failed after its budget: the robot has driven on until t_s; fall back there.
            new, rec = self.fallback(t_now, plan, obs, threats, t_s)
            rec.planning_time, rec.budget = elapsed, budget
            rec.candidates = candidates + rec.candidates
            return new, rec
        # The first to arrive; on a tie the shorter (a wait adds no length).
        best = min(usable, key=lambda d: (round(d.motion.t_end, 6), d.length or 0.0))
        rec = Replan(
            t=t_now,
            kind=self.policy.kind,
            side=best.side,
            start=plan.position(t_s),
            goal=best.goal,
            planning_time=elapsed,
            budget=budget,
            length=best.length,
            obstacles=[th.obstacle for th in threats],
            cross_point=threats[0].cross_point,
            t_cross=threats[0].t_enter,
            candidates=candidates,
            detour=best.path,
        )
        return best.motion, rec

    def fallback(
        self,
        t_now: float,
        plan: Motion,
        obs: Observations,
        threats: list[Threat],
        t_act: float,
    ) -> tuple[Motion, Replan]:
        """Wait, or step aside and wait, from time ``t_act``: the first verified option that
        arrives soonest; the safest one when none verifies."""
        p = plan.position(t_act)
        th = float(plan.heading(t_act))
        head = plan.until(t_act) if t_act > plan.t[0] else None
        rest_path = plan.waypoints_after(t_act)
        best_ok: tuple[float, Motion, str, np.ndarray | None, float] | None = None
        best_bad: tuple[float, Motion, str, np.ndarray | None, float] | None = None
        for kind, x, w in self._fallback_options(p, th, obs):
            m = self._fallback_motion(head, p, th, t_act, rest_path, x, w)
            sep = self._worst_separation(m, obs, t_now)
            if sep >= 0:
                if best_ok is None or m.t_end < best_ok[1].t_end:
                    best_ok = (sep, m, kind, x, w)
            elif best_bad is None or sep > best_bad[0]:
                best_bad = (sep, m, kind, x, w)
        chosen = best_ok or best_bad
        assert chosen is not None  # waiting is always an option
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

    def reshorten(self, t_now: float, plan: Motion, obs: Observations) -> Motion | None:
        """The rest of ``plan`` shortcut in the static world once no collision is predicted
        (a detour's bends are no longer needed after the obstacle has passed), or None when that
        does not arrive earlier or would meet a sensed obstacle.

        The shortcut takes effect one control period from now (the time it is computed in).
        """
        t_a = t_now + (self.problem.robot.sample_time or 0.1)
        if t_a >= plan.t_end:
            return None
        rest = plan.waypoints_after(t_a)
        if len(rest) < 3:
            return None
        short = shortcut(rest, self.world.segments_free)
        if len(short) == len(rest):
            return None
        new = plan.until(t_a).then(
            Motion.from_path(short, t_a, float(plan.heading(t_a)), self.speed, self.turn_rate)
        )
        if new.t_end >= plan.t_end - 1e-6:
            return None
        if obs and self._worst_separation(new, obs, t_now) < 0:
            return None
        return new

    # -- pieces ------------------------------------------------------------------------------------
    def _candidates(self, t_now, plan, obs, threats, t_s, deadline) -> list[Detour]:
        """The policy's candidates from ``t_s``: the wait (when it is one) and a detour per side,
        planned until the wall-clock ``deadline`` (``time.perf_counter`` s)."""
        p_s = plan.position(t_s)
        th_s = float(plan.heading(t_s))
        t_exit = max(th.t_exit for th in threats)
        sides = self.policy.sides
        # The wall of a side is set along the direction of travel at the first threat.
        tangent = _direction(plan, threats[0].t_enter) if sides != (None,) else None
        detours = []
        if self.policy.wait:
            # Waiting: let the obstacle pass, then drive on (cheap: exact checks of the old plan
            # delayed, no planning).
            detours.append(self._wait(t_now, plan, obs, t_s, t_exit))
        for i, side in enumerate(sides):
            # Wall-clock budgeting: what is left, shared among the detours still to plan, less the
            # set-up and verification a solve costs beyond its own budget (measured as we go).
            share = (deadline - time.perf_counter()) / (len(sides) - i) - self._overrun
            share = max(share, MIN_DETOUR_TIME)
            started = time.perf_counter()
            d = self._detour(t_now, plan, obs, p_s, th_s, t_s, t_exit, side, share, threats[0],
                             tangent)  # fmt: skip
            self._overrun = max(0.75 * self._overrun, time.perf_counter() - started - share)
            detours.append(d)
        return detours

    def _wait(self, t_now, plan, obs, t_s, t_exit) -> Detour:
        """The least wait at ``p_s`` (a multiple of the control period) after which driving on
        along ``plan`` passes every sensed obstacle, verified exactly.

        The search is bounded: waits up to ``2 (t_exit - t_now) + 4 s`` and at most
        :data:`MAX_WAIT_STEPS` tries.
        """
        detour = Detour("wait", {"side": "wait", "valid": False, "length": 0.0, "reason": ""})
        ts = self.problem.robot.sample_time or 0.1
        longest = 2.0 * (t_exit - t_now) + 4.0
        n = min(int(longest / ts), MAX_WAIT_STEPS)
        for k in range(1, n + 1):
            motion = plan.delayed(t_s, k * ts)
            sep = self._worst_separation(motion, obs, t_now)
            if sep >= 0:
                detour.record.update(valid=True, wait=k * ts, margin_left=sep, arrival=motion.t_end)
                detour.motion, detour.goal, detour.length = motion, None, 0.0
                return detour
        return detour.refuse(f"no wait of up to {n * ts:.3g} s passes every obstacle")

    def _fallback_options(
        self, p: np.ndarray, th: float, obs: Observations
    ) -> list[tuple[str, np.ndarray | None, float]]:
        """Waits of growing length, and steps aside in 16 directions at three distances, each
        followed by the same waits: ``(kind, step-aside point or None, wait s)``."""
        d_contact = self.sr + max(r for _, _, r in obs.values()) + self.margin
        ts = self.problem.robot.sample_time or 0.1
        waits = [0.0] + [ts * 2**k for k in range(0, 9)]
        options: list[tuple[str, np.ndarray | None, float]] = [("wait", None, w) for w in waits[1:]]
        for ang in np.linspace(0, 2 * math.pi, 16, endpoint=False):
            for dist in (d_contact, 2 * d_contact, 3 * d_contact):
                x = p + dist * np.array([math.cos(th + ang), math.sin(th + ang)])
                if self.world.in_bounds(*x) and self.world.motion_free(*p, *x):
                    options.extend(("evade", x, w) for w in waits)
        return options

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

    def _worst_separation(self, motion: Motion, obs: Observations, t_now: float) -> float:
        """Smallest ``distance - (SR + SO + margin/2)`` over the observed obstacles."""
        worst = math.inf
        for pos, vel, radius in obs.values():
            d, _ = closest_approach(motion, extrapolate(pos, vel, t_now), t_now, motion.t_end)
            worst = min(worst, d - (self.sr + radius + 0.5 * self.margin))
        return worst

    def _detour(self, t_now, plan, obs, p_s, th_s, t_s, t_exit, side, budget, first, tangent):
        """Plan and verify one detour from ``p_s`` at ``t_s`` (on ``side`` of the cross point)."""
        detour = Detour(side, {"side": side, "valid": False, "length": None, "reason": ""})
        wall = [] if side is None else [self._side_wall(first.cross_point, tangent, side)]
        found = self._rejoin(t_now, plan, obs, p_s, t_s, t_exit, wall)
        if found is None:
            return detour.refuse("no free rejoin point past the collision zone")
        t_g, goal, obstacles, world = found
        if not world.point_free(*p_s):
            return detour.refuse("the detour start lies in a predicted sweep")
        res = self._plan(t_now, side, p_s, goal, obstacles, world, budget)
        detour.record["planning_time"] = res.time
        if not res.solved:
            return detour.refuse(f"planner found no detour ({res.ompl_status})")
        route = np.vstack([res.path, plan.waypoints_after(float(t_g))[1:]])
        motion = plan.until(t_s).then(
            Motion.from_path(route, t_s, th_s, self.speed, self.turn_rate)
        )
        sep = self._worst_separation(motion, obs, t_now)
        detour.record["length"] = res.length
        detour.record["margin_left"] = sep
        if sep < 0:
            return detour.refuse("verification failed: the detour meets a predicted obstacle")
        detour.record["valid"] = True
        detour.record["arrival"] = motion.t_end
        detour.motion, detour.goal, detour.length, detour.path = motion, goal, res.length, res.path
        return detour

    def _side_wall(self, cross_point: np.ndarray, tangent: np.ndarray, side: str) -> Polygon:
        """The wall that closes the side the detour must not take."""
        normal = np.array([-tangent[1], tangent[0]])  # left of the direction of travel
        away = -normal if side == "up" else normal  # block the other side
        width = max(1e-3 * self.diagonal, 0.05 * self.sr)
        return _wall(cross_point, away, self.diagonal, width)

    def _rejoin(self, t_now, plan, obs, p_s, t_s, t_exit, wall):
        """The first point of the old plan past the collision zone that is free among the
        relevant sweeps: ``(t_g, goal, obstacles, world)``, or None.

        With ``policy.rejoin_at_goal`` the only candidate is the plan's end (the goal).
        """
        if self.policy.rejoin_at_goal:
            goal_times = np.array([plan.t_end])
        else:
            step = max(self.sr, 1e-6) / self.speed
            goal_times = np.append(np.arange(t_exit + step, plan.t_end, step), plan.t_end)
        for t_g in goal_times:
            goal = plan.position(t_g)
            horizon = self._horizon(plan, t_s, float(t_g))
            obstacles = [
                *self.problem.obstacles,
                *wall,
                *self._sweeps(obs, t_now, p_s, t_s, horizon),
            ]
            world = World.from_problem(self.problem, obstacles, self.sr, lattice=False)
            if world.point_free(*goal):
                return t_g, goal, obstacles, world
        return None

    def _plan(self, t_now, side, p_s, goal, obstacles, world, budget):
        """The static planner on the detour problem (the sweeps and the wall as obstacles)."""
        detour_problem = dataclasses.replace(
            self.problem,
            name=f"{self.problem.name}@{t_now:.2f}s" + (f"/{side}" if side else ""),
            start=(float(p_s[0]), float(p_s[1])),
            goal=(float(goal[0]), float(goal[1])),
            goal_tolerance=0.0,
            obstacles=tuple(obstacles),
            moving_obstacles=(),
            planner=PlannerConfig(),
        )
        params = dict(self.options.params)
        if self._seed_param:
            params.setdefault("seed", int(self.rng.integers(2**31 - 1)))
        return self.solve(
            detour_problem, self.options.planner, time_limit=budget, params=params, world=world
        )

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
            at = extrapolate(pos, vel, t_now)
            speed_o = float(np.hypot(*vel))
            dt = min(0.25 * r / speed_o if speed_o > 0 else math.inf, max(t_end - t_s, 1e-6) / 50)
            ts = np.arange(t_s, t_end + dt, dt)
            d = np.hypot(*(at(ts) - p_s).T)
            earliest = t_s + (d - reach) / v
            latest = t_s + self.options.stretch * (d + reach) / v + self.turn_slack
            relevant = (ts + dt >= earliest) & (ts - dt <= latest)
            for lo, hi in true_runs(relevant):
                # One grid step of padding either side: the window's ends are between samples.
                a = at(np.array([max(ts[lo] - dt, t_s)]))[0]
                b = at(np.array([ts[hi] + dt]))[0]
                out.extend(capsule(a, b, r))
        return out


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
