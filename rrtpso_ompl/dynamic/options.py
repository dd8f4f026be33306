"""What every part of the dynamic stage shares: its options, the robot as it is driven, what the
robot senses, and the limits of one run.

This module imports nothing else of :mod:`rrtpso_ompl.dynamic`, so that the manager, the control
loops, the strategies and the registry all import it and each other one way only.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import RrtpsoError
from ..model.problem_types import Problem
from ..params import Rule, declared, param
from ..validation import MAX_STEPS as _MAX_STEPS

__all__ = [
    "MAX_REPLANS",
    "MAX_STEPS",
    "DynamicOptions",
    "Observations",
    "RobotModel",
    "RobotState",
    "SimulationError",
    "default_margin",
    "goal_tolerance",
]


class SimulationError(RrtpsoError):
    """A simulation that cannot be run as asked (the message says why)."""


#: Most control steps one simulation may take (simulated time / sample time): the limit every
#: sampled motion shares.
MAX_STEPS = _MAX_STEPS
#: Most reactions (detours and fallbacks) one simulation may make before it gives up: each one
#: plans or verifies, so this bounds the wall time of a run that can never get through.
MAX_REPLANS = 500

#: What the robot knows of an obstacle it senses: index -> (position, velocity, radius).
Observations = Mapping[int, tuple[np.ndarray, np.ndarray, float]]


@declared(rules=[Rule(("replan_time",), lambda t: t > 0, "replan_time > 0")])
class DynamicOptions:
    """Parameters of the simulation and of the replanning manager (every strategy reads the
    ones it uses; :mod:`rrtpso_ompl.dynamic.registry` lists the strategies)."""

    planner: str = param(
        "RRTstarPSO", "Planner of the initial path and of the detours (any registered name)."
    )
    strategy: str = param(
        "contour",
        "How the robot reacts (a registered strategy): `contour` detours around the collision "
        "zone, up and down, or waits (the paper's method); `global` replans the whole remaining "
        "path; `none` never replans; `dwa` is the Dynamic Window Approach peer.",
    )
    replan_time: float = param(
        0.1,
        "Simulated seconds one replan takes: the planners' total budget (the two contour "
        "detours share it) and a wall-clock budget. The robot drives its old plan meanwhile.",
        unit="s",
    )
    initial_time: float | None = param(
        None,
        "Budget of the initial static path (None: the problem's planner.time_limit, else 1.0). "
        "The robot waits for it at the start; it is not counted as driving time.",
        unit="s",
    )
    margin: float | None = param(
        None,
        "Extra separation kept beyond SR + SO (None: 10 % of SR + SO of the smallest obstacle). "
        "Detours are planned with the full margin; a collision is predicted when the separation "
        "would drop below SR + SO + margin / 2.",
        unit="length",
        low=0.0,
    )
    stretch: float = param(
        2.0,
        "How much longer than the straight line a detour may be when the relevant time windows "
        "of the obstacles' sweeps are computed.",
        low=1.0,
    )
    max_time: float | None = param(
        None, "Simulated time limit (None: four times the static path's duration plus 60 s).",
        unit="s",
    )  # fmt: skip
    heading_changes: float = param(
        0.0,
        "Mean number of random heading changes per obstacle per second (Poisson); 0 keeps the "
        "paper's constant velocity.",
        unit="1/s",
        low=0.0,
    )
    heading_change_deg: float = param(
        45.0, "Standard deviation of a random heading change.", unit="deg", low=0.0
    )
    reshorten: bool = param(
        True,
        "`contour`: while no collision is predicted, shortcut the rest of the plan in the static "
        "world (at most once a second, verified against the sensed obstacles), so that a "
        "detour's bends go once the obstacle has passed.",
    )
    params: dict[str, Any] = param({}, "Parameters for the planner (its own table checks them).")


@dataclass(frozen=True)
class RobotModel:
    """The robot as the simulation drives it (units, units/s, rad/s, s).

    Attributes
    ----------
    speed : float
        Top linear speed: the least of ``robot.speed``, ``max_speed`` and ``max_wheel_speed``.
    turn_rate : float or None
        Top turn rate in place, ``2 v_w / L`` (None without a track width: instantaneous turns).
    sample_time, radius, sensor_range : float
        The control period Ts, the safety radius SR and the sensor range.
    wheel_speed : float
        Top wheel speed ``v_w`` (``max_wheel_speed``, else ``speed``): a differential drive
        needs ``|v| + |w| L / 2 <= v_w``.
    track_width : float or None
        ``L``.
    """

    speed: float
    turn_rate: float | None
    sample_time: float
    radius: float
    sensor_range: float
    wheel_speed: float = math.inf
    track_width: float | None = None

    @classmethod
    def of(cls, problem: Problem) -> RobotModel:
        robot = problem.robot
        for key in ("speed", "sample_time", "sensor_range"):
            if getattr(robot, key) is None:
                raise ValueError(f"robot.{key} is required for a simulation")
        speed = min(
            v for v in (robot.speed, robot.max_speed, robot.max_wheel_speed) if v is not None
        )
        wheel = robot.max_wheel_speed or robot.speed
        turn_rate = None
        if robot.track_width:
            turn_rate = 2.0 * wheel / robot.track_width
        return cls(speed, turn_rate, float(robot.sample_time), robot.radius, robot.sensor_range,
                   float(wheel), robot.track_width or None)  # fmt: skip


@dataclass(frozen=True)
class RobotState:
    """What a local controller knows of the robot at a control instant.

    Attributes
    ----------
    xy : (2,) ndarray
        Position, units.
    theta : float
        Heading, rad (unwrapped).
    v, w : float
        Linear (units/s, negative backwards) and angular (rad/s) velocity of the last period.
    """

    xy: np.ndarray
    theta: float
    v: float
    w: float


def default_margin(problem: Problem, margin: float | None) -> float:
    """``margin``, or when None 10 % of ``SR + SO`` of the smallest moving obstacle, units."""
    if margin is not None:
        return float(margin)
    radii = [m.radius for m in problem.moving_obstacles]
    return 0.1 * (problem.robot.radius + min(radii, default=0.0))


def goal_tolerance(robot: RobotModel) -> float:
    """How near the goal a local controller's robot must be at a control instant for
    :func:`~rrtpso_ompl.dynamic.local.simulate_local` to drive the last chord in: one period's
    travel, at least SR/10."""
    return max(robot.speed * robot.sample_time, 0.1 * robot.radius)
