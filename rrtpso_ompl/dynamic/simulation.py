"""The simulation: the robot drives from start to goal among moving obstacles, reacting as its
strategy does.

:func:`simulate` looks the strategy (``DynamicOptions.strategy``) up in the registry
(:mod:`.registry`) and lets it drive: the replanning loop of :mod:`.replanning` for ``contour``,
``global`` and ``none``, the local controllers' harness of :mod:`.local` for ``dwa``, or a
third-party strategy. Every strategy senses, perturbs and measures the same way for the same
seed (:mod:`.world_view`), so their results compare.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..model.problem_types import Problem
from .options import DynamicOptions
from .registry import default_strategies
from .result import SimulationResult

__all__ = ["simulate"]


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
        ``options.strategy`` names the strategy (a registered one, with its default options).
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

    Raises
    ------
    UnknownStrategyError
        When no strategy of that name is registered (a ``ValueError``).
    """
    options = options or DynamicOptions()
    strategy = default_strategies().make(options.strategy)
    return strategy.simulate(
        problem, options, seed=seed, initial_path=initial_path, progress=progress
    )
