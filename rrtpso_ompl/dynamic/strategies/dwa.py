"""``dwa``: the Dynamic Window Approach peer, a DWB-like local controller (:mod:`..dwa`)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...model.problem_types import Problem
from ...params import declared, param
from ..dwa_params import DWAParams
from ..options import DynamicOptions
from ..result import SimulationResult
from ..world_view import plan_static_path

__all__ = ["DWA", "DWAOptions"]


@declared
class DWAOptions(DWAParams):
    """The DWA strategy's options: the controller's (:class:`~rrtpso_ompl.dynamic.dwa.
    DWAParams`) and the budget of its guide path."""

    guide_time: float | None = param(
        None,
        "Budget of the guide path (None: the time the static path took, or DynamicOptions."
        "initial_time, else 1.0, when the static path is given).",
        unit="s",
        low=0.0,
    )


class DWA:
    """A Dynamic Window Approach local planner following the static path (Nav2's DWB).

    It follows a guide path: the static path re-planned with clearance for it
    (``DynamicOptions.planner``, seeded with the run's seed when the planner takes one).
    """

    name = "dwa"
    options = DWAOptions

    def __init__(self, params: DWAOptions | None = None) -> None:
        self.params = params or DWAOptions()

    def simulate(
        self,
        problem: Problem,
        options: DynamicOptions,
        *,
        seed: int | None = None,
        initial_path: np.ndarray | None = None,
        progress: Callable[[float, float], None] | None = None,
    ) -> SimulationResult:
        """The static path (planned when not given), the guide path, then the DWA's drive in
        :func:`~rrtpso_ompl.dynamic.local.simulate_local` (see :class:`Strategy`)."""
        from ...planners import default_registry
        from ..dwa import guide_path, simulate_dwa

        budget = self.params.guide_time
        if initial_path is None:
            initial_path, took = plan_static_path(problem, options, seed)
            budget = took if budget is None else budget
        if budget is None:
            budget = options.initial_time or 1.0
        path = np.asarray(initial_path, dtype=float).reshape(-1, 2)
        guide = path
        if len(path) >= 2:
            params = dict(options.params)
            if seed is not None and default_registry().get(options.planner).takes("seed"):
                # The guide's planner takes the run's seed (OMPL is not reseeded here).
                params.setdefault("seed", seed)
            guide = guide_path(problem, path, options.planner, budget, params)
        return simulate_dwa(problem, guide, self.params, options, seed, progress)
