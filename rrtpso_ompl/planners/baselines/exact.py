"""Exact: the shortest path itself, as a planner (:func:`~rrtpso_ompl.groundtruth.optimum`'s
tangent-graph search), so that the reference can be selected by name, benchmarked and
batch-solved like any planner.

It needs the explicit geometry: the :class:`~rrtpso_ompl.model.World` that this package's
validity checker carries (every setup built by :mod:`rrtpso_ompl.ompl_setup`). With a user's own
validity checker there is no geometry to search (only yes/no answers for states), and the
planner refuses: it logs why and returns ``ABORT``.

What it reports: the exact length (the path is the optimum's tangent segments, with its arcs as
circumscribed polygons, so the exact checker accepts it and it is longer by a relative ``1e-4`` at
most); ``INFEASIBLE`` when the search proves that no path exists; ``TIMEOUT`` when it is stopped
at the time limit before it knows (a partial search proves nothing, so it returns no path). In
OMPL's benchmark terms the whole solve is planning time, with no iterations and no
simplification; the size of the searched graph is logged as run properties.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Any

from ompl import base as ob

from ...model.geometry import path_length
from ...ompl_setup import array_to_path
from ...params import ParamTable
from ..base import BUDGET, PlannerStats, PythonPlanner
from ..result import BenchmarkRun

__all__ = ["EXACT_PARAMS", "ExactPlanner", "ExactStats"]

log = logging.getLogger(__name__)

#: Its only parameter: the budget (the search itself has nothing to tune).
EXACT_PARAMS = ParamTable(BUDGET)


@dataclass
class ExactStats(PlannerStats):
    """Figures of one Exact solve (length in problem units, time in seconds).

    Attributes
    ----------
    optimum_length : float or None
        Length of the exact shortest path (the returned polyline is at most ``1e-4`` longer).
    graph_nodes, graph_edges : int
        Tangent nodes and edges of the search's last round.
    rounds : int
        Rounds of growing bounds.
    stopped : bool
        The time limit cut the search before it knew.
    infeasible : bool
        The search proved that no path exists.
    search_time : float
    """

    optimum_length: float | None = None
    graph_nodes: int = 0
    graph_edges: int = 0
    rounds: int = 0
    stopped: bool = False
    infeasible: bool = False
    search_time: float = 0.0

    def benchmark_run(self, elapsed: float, length: float | None) -> BenchmarkRun:
        return BenchmarkRun(
            time=elapsed,
            solution_length=length,
            properties={
                "graph nodes": ("INTEGER", self.graph_nodes),
                "graph edges": ("INTEGER", self.graph_edges),
                "bound rounds": ("INTEGER", self.rounds),
            },
        )


class ExactPlanner(PythonPlanner):
    """The exact shortest path for the disc robot (module docstring).

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        A 2-D real vector space whose validity checker carries the world (as
        :func:`~rrtpso_ompl.ompl_setup.make_context` builds it); in any other space it refuses
        (:class:`~rrtpso_ompl.planners.base.PythonPlanner`).
    name : str
        Planner name.
    **params
        Any of :data:`EXACT_PARAMS` by name.
    """

    PARAMS = EXACT_PARAMS

    def __init__(self, si: ob.SpaceInformation, name: str = "Exact", **params: Any) -> None:
        super().__init__(si, name, **params)

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        from ...groundtruth.optimum import shortest_path_in_world

        t0 = time.perf_counter()
        stats = ExactStats()
        self.last_stats = stats
        si = self.getSpaceInformation()
        world = getattr(si.getStateValidityChecker(), "world", None)
        if world is None:
            log.error(
                "%s needs the explicit geometry (the World of this package's validity checker); "
                "a user's own validity checker answers only yes or no per state, which no exact "
                "search can use: plan with another planner, or build the setup with "
                "rrtpso_ompl.ompl_setup.make_context",
                self.getName(),
            )
            return ob.PlannerStatus(ob.PlannerStatus.ABORT)
        start, goal = self._start_and_goal(ptc)
        if start is None or not (world.in_bounds(*start) and world.point_free(*start)):
            return ob.PlannerStatus(ob.PlannerStatus.INVALID_START)
        if goal is None or not (world.in_bounds(*goal) and world.point_free(*goal)):
            return ob.PlannerStatus(ob.PlannerStatus.INVALID_GOAL)
        budget = self._values["budget"]
        deadline = t0 + budget if budget > 0 else math.inf

        def terminate() -> bool:
            return time.perf_counter() >= deadline or bool(ptc())

        result = shortest_path_in_world(world, start, goal, terminate=terminate,
                                        name=self.getName(), source=self.getName())  # fmt: skip
        stats.search_time = time.perf_counter() - t0
        stats.graph_nodes, stats.graph_edges = result.n_nodes, result.n_edges
        stats.rounds, stats.stopped = result.rounds, result.stopped
        if result.stopped:
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        if not result.found:
            stats.infeasible = True
            return ob.PlannerStatus(ob.PlannerStatus.INFEASIBLE)
        stats.optimum_length = result.length
        path = result.valid_polyline(world)
        if not world.path_valid(path):  # never return an invalid path (module docstring)
            log.error("%s: the optimum's polyline failed the exact check", self.getName())
            return ob.PlannerStatus(ob.PlannerStatus.CRASH)
        pdef = self.getProblemDefinition()
        pdef.clearSolutionPaths()
        pdef.addSolutionPath(array_to_path(si, path), False, 0.0, self.getName())
        log.debug("%s: length %.6f (optimum %.6f)", self.getName(), path_length(path),
                  result.length)  # fmt: skip
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)
