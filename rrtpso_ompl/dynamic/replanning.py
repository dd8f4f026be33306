"""The replanning strategies' control loop: the robot drives its plan, senses, predicts, replans.

The robot drives its planned path (the differential-drive stop-and-turn motion of
:class:`~rrtpso_ompl.dynamic.motion.Motion`), the moving obstacles move at constant velocity
(eqs. 14-15, optionally with random heading changes), and every ``sample_time`` the robot

1. **senses** the moving obstacles whose disc comes within ``sensor_range`` of its centre and
   measures their position and velocity;
2. **predicts**, for each sensed obstacle, the *cross point*: the first time at which its remaining
   motion and the obstacle's constant-velocity extrapolation come closer than
   ``SR + SO + margin/2`` (exact, :func:`~rrtpso_ompl.dynamic.prediction.predict_threats`), and
   the collision zone (the stretch of its path during which they stay that close);
3. on a predicted collision, **replans** (:class:`~rrtpso_ompl.dynamic.manager.
   ReplanningManager`, as the strategy's :class:`~rrtpso_ompl.dynamic.manager.ReplanPolicy`
   asks: contour detours up and down, verified, or a verified wait or step aside).

:class:`ReplanningStrategy` is this loop as a strategy; ``contour``, ``global`` and ``none``
(:mod:`rrtpso_ompl.dynamic.strategies`) differ only in their policy.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

import numpy as np

from ..model.problem_types import Problem
from .manager import ReplanningManager, ReplanPolicy
from .motion import Motion, ObstacleTrack
from .options import MAX_REPLANS, DynamicOptions, RobotModel, default_margin
from .prediction import predict_threats
from .result import Replan, SimulationResult
from .world_view import (
    blocked,
    check_steps,
    measure,
    no_static_path,
    plan_static_path,
    sense,
    turn_at_random,
)

__all__ = ["RESHORTEN_PERIOD", "ReplanningStrategy"]

#: Least simulated time between two attempts to shortcut the rest of the plan, s.
RESHORTEN_PERIOD = 1.0


class ReplanningStrategy:
    """Drive the planned path; on a predicted collision, let the replanning manager react as
    :attr:`policy` asks (a base class: its subclasses set the class attributes).

    Attributes
    ----------
    name : str
        The strategy's registered name (and :attr:`ReplanPolicy.kind`).
    options : None
        A replanning strategy has no options of its own: :class:`DynamicOptions` holds them.
    policy : ReplanPolicy or None
        What a replan plans; None: never replan (drive the static path blindly).
    reshortens : bool
        Whether the rest of the plan is shortcut once no collision is predicted (when
        ``DynamicOptions.reshorten`` is on).
    """

    name: ClassVar[str] = ""
    options: ClassVar[type | None] = None
    policy: ClassVar[ReplanPolicy | None] = None
    reshortens: ClassVar[bool] = False

    def __init__(self, params: None = None) -> None:
        if params is not None:
            raise TypeError(f"strategy '{self.name}' takes no options of its own")

    def simulate(
        self,
        problem: Problem,
        options: DynamicOptions,
        *,
        seed: int | None = None,
        initial_path: np.ndarray | None = None,
        progress: Callable[[float, float], None] | None = None,
    ) -> SimulationResult:
        """Drive the robot from start to goal among the problem's moving obstacles (see
        :func:`~rrtpso_ompl.dynamic.simulate` for the arguments)."""
        robot = RobotModel.of(problem)
        margin = default_margin(problem, options.margin)
        label = (self.name, options.planner)
        plan_rng, world_rng = np.random.default_rng(seed).spawn(2)
        if initial_path is None:
            initial_path, _ = plan_static_path(problem, options, seed)
        static_path = np.asarray(initial_path, dtype=float).reshape(-1, 2)
        tracks = [ObstacleTrack.from_obstacle(m) for m in problem.moving_obstacles]
        if len(static_path) < 2:
            return no_static_path(problem, label, seed, robot, static_path, tracks)
        plan = Motion.from_path(static_path, 0.0, None, robot.speed, robot.turn_rate)
        t_max = options.max_time if options.max_time is not None else 4 * plan.t_end + 60.0
        check_steps(t_max, robot.sample_time)
        why = blocked(problem, tracks, robot)
        if why:
            return no_static_path(problem, label, seed, robot, static_path, tracks, why)
        manager = ReplanningManager(problem, options, robot.speed, robot.turn_rate, margin,
                                    plan_rng, policy=self.policy)  # fmt: skip
        plan, t, plans, replans = self._drive(
            plan, tracks, robot, manager, options, margin, t_max, world_rng, progress
        )
        reached = plan.t_end <= t_max + 1e-9
        executed = plan if reached else plan.until(min(t, plan.t_end))
        result = measure(problem, label, seed, robot, executed, reached, static_path, tracks,
                         replans, plans)  # fmt: skip
        if len(replans) >= MAX_REPLANS and not result.reached_goal:
            result.status = f"gave up after {MAX_REPLANS} replans"
        return result

    def _drive(self, plan, tracks, robot, manager, options, margin, t_max, world_rng, progress):
        """The control loop: every sample time sense, predict and react, until the plan ends or
        ``t_max``. Returns ``(plan, t, plans, replans)``."""
        plans = [(0.0, plan)]
        replans: list[Replan] = []
        busy_until = -math.inf
        last_short = -math.inf
        change_p = options.heading_changes * robot.sample_time
        reshorten = self.reshortens and options.reshorten
        t = 0.0
        k = 0
        while t < plan.t_end - 1e-9 and t <= t_max and len(replans) < MAX_REPLANS:
            obs = sense(plan.position(t), tracks, t, robot.sensor_range)
            threats = []
            if obs and self.policy is not None:
                threats = predict_threats(plan, t, obs, robot.radius, 0.5 * margin)
                rec = None
                if threats and t >= busy_until:
                    plan, rec = manager.react(t, plan, obs, threats)
                    busy_until = t + rec.budget
                elif threats and threats[0].t_enter <= busy_until + robot.sample_time:
                    # A new threat while the planner is busy and before it can help: react now.
                    plan, rec = manager.fallback(t, plan, obs, threats, t)
                if rec is not None:
                    replans.append(rec)
                    plans.append((t, plan))
            if not threats and reshorten and len(plans) > 1 and t - last_short >= RESHORTEN_PERIOD:
                # No collision predicted: the bends of an earlier detour may no longer be needed.
                last_short = t
                shorter = manager.reshorten(t, plan, obs)
                if shorter is not None:
                    plan = shorter
                    plans.append((t, plan))
            k += 1
            t = k * robot.sample_time
            if change_p > 0:
                turn_at_random(tracks, t, change_p, options.heading_change_deg, world_rng)
            if progress is not None:
                progress(min(t, plan.t_end), plan.t_end)
        return plan, t, plans, replans
