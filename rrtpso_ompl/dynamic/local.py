"""The harness of a local controller: every control period it chooses the velocities.

:func:`simulate_local` drives any :class:`LocalController` (such as the DWA peer of
:mod:`.dwa`) among the problem's moving obstacles, sensing, perturbing and measuring exactly as
the replanning loop (:mod:`.replanning`) does for the same seed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Protocol

import numpy as np

from ..model.geometry import path_length
from ..model.problem_types import Problem
from ..model.world import World
from .motion import Motion, ObstacleTrack, arc_position
from .options import (
    MAX_STEPS,
    DynamicOptions,
    Observations,
    RobotModel,
    RobotState,
    SimulationError,
    goal_tolerance,
)
from .result import SimulationResult
from .world_view import blocked, check_steps, measure, no_static_path, sense, turn_at_random

__all__ = ["SUBSTEPS", "LocalController", "simulate_local"]

#: Knots per control period of a local controller's executed motion (the arc between knots is
#: replaced by its chord: at most ``v w dt^2 / (8 SUBSTEPS^2)`` off, 0.001 cm for the paper's
#: robot).
SUBSTEPS = 5


class LocalController(Protocol):
    """A local planner that :func:`simulate_local` drives: every control period it gets the
    robot's state and the sensed obstacles and returns the velocities for the next period.

    ``name`` is what the result reports as its planner (its strategy in lower case).
    """

    name: str

    def reset(self, xy: np.ndarray, theta: float) -> None:
        """Start a new run at ``xy`` facing ``theta``."""

    def step(self, state: RobotState, obstacles: Observations, t: float) -> tuple[float, float]:
        """``(v, w)`` for the period from ``t``; ``obstacles`` as every strategy senses them
        (index -> (position, velocity, radius), measured at ``t``)."""


def simulate_local(
    problem: Problem,
    controller: LocalController,
    reference_path: np.ndarray,
    options: DynamicOptions | None = None,
    seed: int | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> SimulationResult:
    """Drive the robot with a local controller among the problem's moving obstacles.

    Every ``sample_time`` the robot senses as in :func:`~rrtpso_ompl.dynamic.simulate`, asks
    ``controller.step`` for ``(v, w)``, saturates them at the robot's limits (speed, turn rate,
    ``|v| + |w| L / 2 <= v_w``) and drives them for one period on an exact arc (knots every
    ``sample_time / SUBSTEPS``). Within one period's travel (or SR/10) of the goal, with the
    straight line free, it drives the last chord in. The result's ``status`` says when the
    executed motion clipped a static obstacle (checked exactly afterwards).

    Parameters
    ----------
    problem : Problem
        As for :func:`~rrtpso_ompl.dynamic.simulate`.
    controller : LocalController
    reference_path : (n, 2) array
        The path followed (units): its first point the start, its first segment the heading,
        its length the time limit (``4 L / v + 60`` s); under two points: "no static path".
    options : DynamicOptions, optional
        Only ``max_time``, ``heading_changes`` and ``heading_change_deg`` are used (the
        obstacles and their random turns of :func:`~rrtpso_ompl.dynamic.simulate`).
    seed : int, optional
        Seeds the obstacles' random heading changes as :func:`~rrtpso_ompl.dynamic.simulate`
        does.
    progress : callable, optional
        Called as ``progress(t, t_max)`` after every step.

    Returns
    -------
    SimulationResult
        ``planner`` is ``controller.name``, ``strategy`` its lower case; no replans.
    """
    options = options or DynamicOptions()
    robot = RobotModel.of(problem)
    label = (str(controller.name).lower(), str(controller.name))
    path = np.asarray(reference_path, dtype=float).reshape(-1, 2)
    tracks = [ObstacleTrack.from_obstacle(m) for m in problem.moving_obstacles]
    why = blocked(problem, tracks, robot) if len(path) >= 2 else "no static path"
    if why:
        return no_static_path(problem, label, seed, robot, path, tracks, why)
    _, world_rng = np.random.default_rng(seed).spawn(2)
    t_max = options.max_time
    t_max = 4.0 * path_length(path) / robot.speed + 60.0 if t_max is None else t_max
    check_steps(t_max, robot.sample_time)
    world = World.from_problem(problem)
    motion, reached = _drive_local(problem, controller, robot, world, path, tracks, options,
                                   t_max, world_rng, progress)  # fmt: skip
    # The driven motion is the only "plan" a local controller has (the animation draws it).
    result = measure(problem, label, seed, robot, motion, reached, path, tracks, [],
                     [(0.0, motion)])  # fmt: skip
    if not _statically_valid(world, motion):
        result.status = "clipped a static obstacle or left the bounds"
    return result


def _statically_valid(world: World, motion: Motion) -> bool:
    """Whether the executed motion's chords keep off the static world and in the bounds
    (checked exactly: unlike a planned path, a controller's arcs are not checked before)."""
    free = world.segments_free(motion.xy[:-1], motion.xy[1:])
    return bool(free.all() and world.points_in_bounds(motion.xy).all())


def _drive_local(problem, controller, robot, world, path, tracks, options, t_max, world_rng,
                 progress) -> tuple[Motion, bool]:  # fmt: skip
    """The control loop of :func:`simulate_local`: the executed motion and whether it arrived."""
    dt = robot.sample_time
    goal = np.asarray(problem.goal, dtype=float)
    x = path[0].copy()
    th = math.atan2(path[1, 1] - path[0, 1], path[1, 0] - path[0, 0])
    controller.reset(x.copy(), th)
    v = w = 0.0
    ts, xs, ths = [0.0], [x.copy()], [th]
    change_p = options.heading_changes * dt
    tol = goal_tolerance(robot)
    taus = dt * np.arange(1, SUBSTEPS + 1) / SUBSTEPS
    k = 0
    while k * dt <= t_max and k < MAX_STEPS:
        t = k * dt
        d = math.dist(x, goal)
        if d <= tol and world.motion_free(*x, *goal):
            ts.append(t + d / robot.speed)
            xs.append(goal.copy())
            ths.append(th)
            return Motion(np.array(ts), np.array(xs), np.array(ths)), True
        obs = sense(x, tracks, t, robot.sensor_range)
        v, w = _saturate(robot, *controller.step(RobotState(x.copy(), th, v, w), obs, t))
        xs.extend(arc_position(x, th, v, w, taus))
        ths.extend(th + w * taus)
        ts.extend(t + taus)
        x, th = xs[-1].copy(), float(ths[-1])
        k += 1
        if change_p > 0:
            turn_at_random(tracks, k * dt, change_p, options.heading_change_deg, world_rng)
        if progress is not None:
            progress(k * dt, t_max)
    return Motion(np.array(ts), np.array(xs), np.array(ths)), False


def _saturate(robot: RobotModel, v: float, w: float) -> tuple[float, float]:
    """The command the wheels can drive: speed and turn rate clipped, then both scaled down
    until ``|v| + |w| L / 2 <= v_w``."""
    if not (math.isfinite(v) and math.isfinite(w)):
        raise SimulationError(f"the local controller commanded v = {v}, w = {w}")
    v = min(max(v, -robot.speed), robot.speed)
    if robot.turn_rate is not None:
        w = min(max(w, -robot.turn_rate), robot.turn_rate)
        need = abs(v) + abs(w) * 0.5 * (robot.track_width or 0.0)
        if need > robot.wheel_speed:
            v, w = v * robot.wheel_speed / need, w * robot.wheel_speed / need
    return v, w
