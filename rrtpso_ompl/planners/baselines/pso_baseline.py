"""PSO: the paper's particle-swarm-only baseline (Table 3), as an OMPL planner.

Each particle is a path with ``n_waypoints`` free interior waypoints between the fixed start and
goal, initialised uniformly at random in the bounds (paper step 1), and scored with the same cost as
RRT*PSO's optimiser (length, optional smoothness, exact collision penalty). Colliding paths are
ranked after every collision-free one (Deb's feasibility rule), so the swarm's best is a valid path
as soon as one particle has found one. When the swarm has found no valid path at the end of its
iterations and time remains, it restarts from a new random swarm.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from ompl import base as ob

from ...model.geometry import path_length, shortcut
from ...ompl_setup import array_to_path
from ...params import ParamSpec, ParamTable
from ..base import BUDGET, SEED, PlannerStats, PythonPlanner, collision_model_for
from ..pso import swarm as pso
from ..pso.path_optimizer import OPTIMIZER_PARAMS, PathCost
from ..pso.swarm import SWARM_PARAMS, PSOOptions
from ..result import BenchmarkRun

__all__ = ["PSO_PARAMS", "PSOPlanner", "PSOPlannerStats"]

#: The baseline's parameters. Its particles roam the whole workspace, so its velocity clamp is
#: relative to the workspace (not to a seed path's segments, as in RRTstarPSO's optimiser), and it
#: runs a fixed number of iterations per swarm, as in the paper.
PSO_PARAMS = (
    ParamTable(
        ParamSpec("n_waypoints", int, 5, "Free interior waypoints per candidate path.",
                  low=1, high=1000),
        BUDGET,
        ParamSpec("restarts", bool, True,
                  "Start a new random swarm when one ends without a valid path and time remains."),
        SEED,
        ParamSpec("v_max_workspace_fraction", float, 0.1,
                  "Velocity clamp per coordinate, as a fraction of the workspace's larger side.",
                  low=1e-6, high=10.0),
    )
    + SWARM_PARAMS.replace(
        iterations={"default": 200, "low": 1, "doc": "PSO iterations per swarm (eqs. 4-5)."},
        tolerance={"default": 0.0},
    )
    + OPTIMIZER_PARAMS.subset("smoothness_weight", "violation_weight")
)  # fmt: skip


@dataclass
class PSOPlannerStats(PlannerStats):
    """Figures of one PSO-baseline solve (lengths in problem units, times in seconds).

    The whole solve is planning in OMPL's benchmark terms: the baseline has no separate
    simplification stage.
    """

    pso_length: float | None = None
    pso_time: float = 0.0
    pso_iterations: int = 0
    pso_evaluations: int = 0
    swarms: int = 0
    pso_history: list[float] = field(default_factory=list)

    def benchmark_run(self, elapsed: float, length: float | None) -> BenchmarkRun:
        return BenchmarkRun(
            time=elapsed,
            solution_length=length,
            properties={
                "swarms": ("INTEGER", self.swarms),
                "pso iterations": ("INTEGER", self.pso_iterations),
                "pso evaluations": ("INTEGER", self.pso_evaluations),
            },
        )


class PSOPlanner(PythonPlanner):
    """Particle swarm over random waypoints (the paper's "PSO" baseline).

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        A 2-D real vector space; in any other it refuses (see
        :class:`~rrtpso_ompl.planners.RRTstarPSO`).
    name : str
        Planner name.
    **params
        Any of :data:`PSO_PARAMS` by name.
    """

    PARAMS = PSO_PARAMS

    def __init__(self, si: ob.SpaceInformation, name: str = "PSO", **params: Any) -> None:
        super().__init__(si, name, **params)

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        values = self._values
        stats = PSOPlannerStats()
        self.last_stats = stats
        start, goal = self._start_and_goal(ptc)
        if start is None:
            return ob.PlannerStatus(ob.PlannerStatus.INVALID_START)
        if goal is None:
            return ob.PlannerStatus(ob.PlannerStatus.INVALID_GOAL)
        model = collision_model_for(self.getSpaceInformation())
        cost_model = PathCost(start, goal, model, values["smoothness_weight"])
        k = values["n_waypoints"]
        (xmin, ymin), (xmax, ymax) = model.bounds
        lower = np.tile([xmin, ymin], k)
        upper = np.tile([xmax, ymax], k)
        # Any path of k+1 segments in the box is shorter than this, so adding it to a colliding
        # path's cost ranks it after every collision-free one.
        diagonal = math.hypot(xmax - xmin, ymax - ymin)
        offset = (k + 1) * diagonal * (1.0 + values["smoothness_weight"])

        def cost(x: np.ndarray) -> np.ndarray:
            c, v = cost_model.terms(x)
            return np.where(v > 0.0, c + offset + values["violation_weight"] * v, c)

        budget = values["budget"]
        deadline = t0 + budget if budget > 0 else math.inf

        def terminate() -> bool:
            return ptc() or time.perf_counter() >= deadline

        options = PSOOptions.from_values(values)
        v_max = values["v_max_workspace_fraction"] * max(xmax - xmin, ymax - ymin)
        rng = self._rng()
        best: np.ndarray | None = None
        while not terminate():
            res = pso.minimize(cost, lower, upper, options, rng, v_max=v_max, terminate=terminate)
            stats.swarms += 1
            stats.pso_iterations += res.n_iterations
            stats.pso_evaluations += res.n_evaluations
            stats.pso_history.extend(res.history.tolist())
            path = np.vstack([start, res.position.reshape(k, 2), goal])
            if res.cost < offset and model.path_valid(path):
                best = path
                break
            if not values["restarts"]:
                break
        stats.pso_time = time.perf_counter() - t0
        if best is None:
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        best = shortcut(
            best, model.segments_free
        )  # drop waypoints the swarm left redundant; never longer
        stats.pso_length = path_length(best)
        pdef = self.getProblemDefinition()
        pdef.clearSolutionPaths()
        pdef.addSolutionPath(
            array_to_path(self.getSpaceInformation(), best), False, 0.0, self.getName()
        )
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)
