"""The interface of a strategy: how the robot reacts to the moving obstacles it senses.

A strategy is a class with a ``name`` (what ``rrtpso simulate --strategy`` and
``DynamicOptions.strategy`` take), a docstring (its description in listings), ``options`` (the
option set of its own, a class declared with :func:`~rrtpso_ompl.params.declared`, or
None when :class:`~rrtpso_ompl.dynamic.options.DynamicOptions` says all it needs) and one method,
:meth:`Strategy.simulate`, that drives one run. Its constructor takes an instance of ``options``
(or None for the defaults). The registry (:mod:`rrtpso_ompl.dynamic.registry`) holds the
classes.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from ...model.problem_types import Problem
from ..options import DynamicOptions
from ..result import SimulationResult

__all__ = ["Strategy"]


@runtime_checkable
class Strategy(Protocol):
    """How the robot gets from start to goal among moving obstacles (see the module doc)."""

    name: ClassVar[str]
    options: ClassVar[type | None]

    def __init__(self, params: Any = None) -> None: ...

    def simulate(
        self,
        problem: Problem,
        options: DynamicOptions,
        *,
        seed: int | None = None,
        initial_path: np.ndarray | None = None,
        progress: Callable[[float, float], None] | None = None,
    ) -> SimulationResult:
        """Drive the robot from ``problem.start`` to ``problem.goal``.

        Parameters
        ----------
        problem : Problem
            Needs ``robot.speed``, ``robot.sample_time`` and ``robot.sensor_range``.
        options : DynamicOptions
            The run's options (planner, margin, time limit, random turns ...).
        seed : int, optional
            Seeds the planners and the obstacles' random heading changes: the same seed gives
            every strategy the same obstacles (use
            :func:`~rrtpso_ompl.dynamic.world_view.turn_at_random` on the second of
            ``numpy.random.default_rng(seed).spawn(2)``, as the first-party strategies do).
        initial_path : (n, 2) array, optional
            The static path to start from (planned with ``options.planner`` when omitted).
        progress : callable, optional
            ``progress(t, t_estimate)`` after every control step, simulated seconds.

        Returns
        -------
        SimulationResult
            Its ``strategy`` is the strategy's ``name``.
        """
        ...
