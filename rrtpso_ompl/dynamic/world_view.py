"""The simulated world as every control loop sees it: sensing the moving obstacles, their random
turns, the checks before a run, the initial static path and the measurement of the driven motion.

Shared by the replanning loop (:mod:`.replanning`) and the local controllers' harness
(:mod:`.local`), so that both sense, perturb and measure the same way for the same seed.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.geometry import path_length
from ..model.problem_types import Problem
from .motion import ObstacleTrack, closest_approach
from .options import MAX_STEPS, DynamicOptions, Observations, RobotModel, SimulationError
from .result import SimulationResult

__all__ = [
    "blocked",
    "check_steps",
    "measure",
    "no_static_path",
    "plan_static_path",
    "sense",
    "turn_at_random",
]


def check_steps(t_max: float, sample_time: float) -> None:
    """Refuse a run that would take more than MAX_STEPS control steps."""
    steps = t_max / sample_time
    if steps > MAX_STEPS:
        raise SimulationError(
            f"robot.sample_time {sample_time:g} s would take {steps:.3g} control steps to drive "
            f"the path (simulated time up to {t_max:.3g} s); at most {MAX_STEPS:,}: use a longer "
            "sample time or a higher speed"
        )


def blocked(problem: Problem, tracks: list[ObstacleTrack], robot: RobotModel) -> str:
    """Why the robot cannot set off: an obstacle on its start at t = 0, or one that never moves
    on its goal (empty when neither)."""
    for j, tr in enumerate(tracks):
        contact = robot.radius + tr.radius
        if math.dist(tr.position(0.0), problem.start) < contact:
            return f"start blocked: moving_obstacles[{j}] overlaps the robot at t = 0"
        if tr.speed == 0 and math.dist(tr.position(0.0), problem.goal) < contact:
            return f"goal blocked: moving_obstacles[{j}] stands still on the goal"
    return ""


def plan_static_path(
    problem: Problem, options: DynamicOptions, seed: int | None
) -> tuple[np.ndarray, float]:
    """The initial static path, planned with the options' planner for ``initial_time`` (empty
    when unsolved), and the time the planner took, s."""
    from ..planners import solve

    res = solve(
        problem,
        options.planner,
        time_limit=options.initial_time,
        seed=seed,
        params=dict(options.params),
    )
    return (res.path if res.solved else np.empty((0, 2))), res.time


def sense(
    p: np.ndarray, tracks: list[ObstacleTrack], t: float, sensor_range: float
) -> Observations:
    """The obstacles whose disc comes within the sensor range: index -> (position, velocity,
    radius), measured at time ``t``."""
    obs = {}
    for j, tr in enumerate(tracks):
        q = tr.position(t)
        if math.hypot(*(q - p)) - tr.radius <= sensor_range:
            obs[j] = (q, tr.velocity, tr.radius)
    return obs


def turn_at_random(tracks, t, probability, sigma_deg, rng) -> None:
    """Each obstacle turns with ``probability`` by a normal angle of ``sigma_deg`` degrees."""
    for tr in tracks:
        if rng.random() < probability:
            tr.turn(t, tr.heading + math.radians(rng.normal(0.0, sigma_deg)))


def measure(problem, label, seed, robot, executed, reached, static_path, tracks, replans,
             plans) -> SimulationResult:  # fmt: skip
    """Separations at every sample and exactly in between, collisions, arrival (``label``: the
    result's ``(strategy, planner)``)."""
    samples = executed.sample(robot.sample_time)
    contact = [robot.radius + tr.radius for tr in tracks]
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
    at_goal = np.allclose(executed.end, problem.goal, atol=1e-6 + problem.goal_tolerance)
    return SimulationResult(
        problem=problem.name,
        strategy=label[0],
        planner=label[1],
        seed=seed,
        reached_goal=bool(reached and at_goal),
        collisions=int(collisions.sum()),
        min_separation=min_sep,
        min_separation_continuous=min_cont,
        contact_distance=contact,
        total_time=executed.t_end,
        path_length=executed.path_length(),
        static_length=path_length(static_path),
        sample_time=robot.sample_time,
        motion=executed,
        static_path=static_path,
        tracks=tracks,
        replans=replans,
        plans=plans,
    )


def no_static_path(problem, label, seed, robot, static_path, tracks,
                    status: str = "no static path") -> SimulationResult:  # fmt: skip
    """The result when the robot cannot set off (no static path, a blocked start or goal);
    ``label``: its ``(strategy, planner)``."""
    n = len(tracks)
    return SimulationResult(
        problem=problem.name,
        strategy=label[0],
        planner=label[1],
        seed=seed,
        reached_goal=False,
        collisions=0,
        min_separation=[None] * n,
        min_separation_continuous=[None] * n,
        contact_distance=[robot.radius + tr.radius for tr in tracks],
        total_time=0.0,
        path_length=0.0,
        static_length=None,
        sample_time=robot.sample_time,
        motion=None,
        static_path=static_path,
        tracks=tracks,
        replans=[],
        plans=[],
        status=status,
    )
