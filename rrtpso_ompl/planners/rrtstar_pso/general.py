"""RRTstarPSO outside the plane: R^n, SE(2), Dubins and Reeds-Shepp, through the space
information alone.

The plane's stages that need its exact world (the corridor lattice, the vectorised segment
checks, the inflation cost's re-routing) do not apply here; what runs is

1. OMPL's RRT* (the planner's inner ``og.RRTstar``, grown by :func:`.rrtstar_stage.grow_rrtstar`
   exactly as in the plane: its share of the budget, its iteration cap, its stall test; BIT*
   looks for a first path in R^n and SE(2) when RRT* has none in time);
2. OMPL's path simplifier on a copy of RRT*'s path (kept when shorter): every motion it keeps
   passed ``si.checkMotion``;
3. the swarm over the waypoints (:func:`~rrtpso_ompl.planners.pso.space_path.optimize_space_path`:
   the length by the space's distance, every accepted candidate checked with ``si.checkMotion``);
4. the result replaces RRT*'s path in the problem definition (under the planner's name).

``stats.stages`` says which of them ran. A problem objective other than the path length (a
user's own) is respected: the swarm's path is kept only when it does not raise that objective.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ...ompl_setup.objective import path_cost
from ...ompl_setup.spaces import SpaceAdapter, space_adapter, unsupported_space
from ..base import PlannerStats
from ..post import simplify_until
from ..pso.path_optimizer import PathOptimizerOptions
from ..pso.space_path import FINAL_FINER, MotionChecker, optimize_space_path
from .rrtstar_stage import RRTstarStatsMixin, grow_rrtstar, has_exact_solution

__all__ = ["SpaceStats", "solve_in_space", "space_of_planner"]

#: Share of the budget kept back for handing the path over (as in the plane).
FINISH_RESERVE = 0.03
#: The spaces where BIT* may look for RRT*'s first path (its informed sampling assumes a metric
#: space; Dubins is not one).
_BITSTAR_SPACES = ("R^n", "SE(2)")


@dataclass
class SpaceStats(RRTstarStatsMixin, PlannerStats):
    """The figures of one RRTstarPSO solve outside the plane (the ``stages`` of a solve result).

    Lengths are by the space's distance (units; SE(2) adds weighted radians), times in seconds.
    ``stages`` lists what ran, in order (``"RRTstar"``, ``"BITstar"``, ``"simplify"``,
    ``"pso"``); ``rrt_path`` / ``seed_path`` are RRT*'s path and the swarm's seed as rows
    (:mod:`rrtpso_ompl.ompl_setup.spaces`).
    """

    space: str = ""
    stages: list[str] = field(default_factory=list)
    range_used: float = 0.0
    first_solution: str = "RRTstar"
    rrt_length: float | None = None
    rrt_time: float = 0.0
    rrt_iterations: int = 0
    rrt_waypoints: int = 0
    rrt_progress: list[tuple[float, float]] = field(default_factory=list)
    rrt_path: list[list[float]] = field(default_factory=list)
    simplified_length: float | None = None
    simplify_time: float = 0.0
    seed_source: str = ""
    seed_length: float | None = None
    seed_path: list[list[float]] = field(default_factory=list)
    pso_length: float | None = None
    pso_time: float = 0.0
    pso_iterations: int = 0
    pso_evaluations: int = 0
    pso_rounds: int = 0
    pso_motion_checks: int = 0
    pso_waypoints: int = 0
    pso_improved: bool = False
    pso_history: list[float] = field(default_factory=list)

    def log_properties(self) -> dict[str, tuple[str, Any]]:
        """RRT*'s and the swarm's figures, and the swarm's motion checks."""
        return {**super().log_properties(),
                "pso motion checks": ("INTEGER", self.pso_motion_checks)}  # fmt: skip


def space_of_planner(si: ob.SpaceInformation, name: str) -> tuple[SpaceAdapter | None, str | None]:
    """The adapter RRTstarPSO plans through outside the plane, or why it refuses.

    Returns
    -------
    (SpaceAdapter, None) or (None, str)
        The refusal is one sentence naming the planner and the space (``planner.unsupported``).
    """
    problem = unsupported_space(si)
    if problem is not None:
        return None, (f"{name} refuses to plan: {problem}; OMPL's own planners (e.g. og.RRTstar) "
                      f"plan in it")  # fmt: skip
    return space_adapter(si, name), None


def solve_in_space(planner: Any, adapter: SpaceAdapter, ptc: ob.PlannerTerminationCondition,
                   t0: float, rng: np.random.Generator) -> ob.PlannerStatus:  # fmt: skip
    """RRTstarPSO's solve outside the plane (see the module docstring).

    Parameters
    ----------
    planner : RRTstarPSO
        Set up (its inner RRT* shares its problem definition); ``last_stats`` receives a
        :class:`SpaceStats`.
    adapter : SpaceAdapter
        The space's rows and distances.
    ptc : ob.PlannerTerminationCondition
        The outer condition.
    t0 : float
        ``time.perf_counter()`` at the start of the solve, s.
    rng : numpy.random.Generator
        The swarm's randomness.
    """
    pdef, si = planner.getProblemDefinition(), planner.getSpaceInformation()
    values = planner.get_params()
    stats = SpaceStats(space=adapter.kind, range_used=planner.inner.getRange())
    planner.last_stats = stats
    grow_rrtstar(planner.inner, pdef, values, ptc, t0, stats, inflation=False,
                 fallback=adapter.kind in _BITSTAR_SPACES)  # fmt: skip
    stats.stages.append("RRTstar")
    if stats.first_solution != "RRTstar":
        stats.stages.append(stats.first_solution)
    if not has_exact_solution(pdef):
        if pdef.hasSolution():  # RRT*'s tree never reached the goal
            return ob.PlannerStatus(ob.PlannerStatus.APPROXIMATE_SOLUTION)
        return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
    raw = pdef.getSolutionPath()  # shared ownership: stays valid after clearSolutionPaths
    rows = adapter.path_to_array(raw)
    stats.rrt_length, stats.rrt_waypoints = adapter.length(rows), len(rows)
    stats.rrt_path = rows.tolist()
    deadline = t0 + (1.0 - FINISH_RESERVE) * values["budget"] if values["budget"] > 0 else None
    simplified = None
    if values["simplify"]:
        simplified = _simplified(si, pdef, raw, rows, adapter, deadline, stats)
    seed = _checked_seed(si, adapter, simplified, rows, deadline)
    if seed is None:  # RRT*'s own path fails checkMotion (asymmetric spaces): no answer
        pdef.clearSolutionPaths()
        stats.stages.append("refused")
        return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
    stats.seed_source = stats.first_solution
    stats.seed_length, stats.seed_path = adapter.length(seed), seed.tolist()
    best = _swarm(si, adapter, seed, values, rng, ptc, deadline, stats)
    path = adapter.array_to_path(si, best)
    objective = pdef.getOptimizationObjective()
    if objective is not None and not isinstance(objective, ob.PathLengthOptimizationObjective):
        fallback = adapter.array_to_path(si, seed)
        if path_cost(objective, path) > path_cost(objective, fallback):
            path = fallback  # shorter, but dearer by the user's own objective
    pdef.clearSolutionPaths()
    pdef.addSolutionPath(path, False, 0.0, planner.getName())
    return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


def _checked_seed(si, adapter: SpaceAdapter, simplified, rows, deadline) -> np.ndarray | None:
    """The swarm's seed: the simplifier's path when every motion of it passes ``si.checkMotion``
    and the check at :data:`~rrtpso_ompl.planners.pso.space_path.FINAL_FINER` times the
    resolution, else RRT*'s when it does, else None (no answer rather than one a denser check
    would refuse: measured, RRT*'s own path failed a check of 4,000 states along it in 1 of 10
    R^3 runs).

    The simplifier checks its shortcuts' motions, but the pieces it keeps of a motion are not
    the motion it checked (a shortcut from a point inside one segment to a point inside another
    leaves two part-segments, sampled at other states): measured, one simplified R^3 path in
    seven failed ``path.check()``. RRT*'s own path can fail too where the space's distance is
    not symmetric (plain Dubins: RRT* checks some motions the other way round; OMPL warns).
    With a ``deadline``, a path is only checked (and used) when its first motion's check, timed,
    says the whole check fits in half of the time left."""
    checker = MotionChecker(si, adapter)
    for candidate in (simplified, rows):
        if candidate is None or not _check_fits(checker, candidate, deadline):
            continue
        if checker.path_free(candidate, factor=FINAL_FINER):
            return candidate
    return None


def _check_fits(checker: MotionChecker, rows: np.ndarray, deadline: float | None) -> bool:
    """Whether checking every motion of ``rows`` finely fits in half of the time left (timed on
    its first motion: a user's checker may take a millisecond a state)."""
    if deadline is None:
        return True
    if not checker.motion_free(rows[0], rows[1]):
        return False
    need = checker.final_check_seconds(len(rows) - 1)
    return need <= 0.5 * (deadline - time.perf_counter())


def _simplified(si, pdef, raw, rows, adapter: SpaceAdapter, deadline, stats: SpaceStats):
    """OMPL's simplifier on a copy of RRT*'s path, as rows when shorter (else None).

    ``simplifyMax`` without a budget; with one, its steps in small batches for at most half of
    what is left (:func:`~rrtpso_ompl.planners.post.simplify_until`)."""
    t1 = time.perf_counter()
    copy = og.PathGeometric(raw)
    if deadline is not None:
        simplify_until(si, copy, t1 + max(0.5 * (deadline - t1), 1e-4),
                       pdef.getOptimizationObjective())  # fmt: skip
    else:
        og.PathSimplifier(si).simplifyMax(copy)
    candidate = adapter.path_to_array(copy)
    stats.simplify_time += time.perf_counter() - t1
    stats.stages.append("simplify")
    if adapter.length(candidate) < adapter.length(rows):
        stats.simplified_length = adapter.length(candidate)
        return candidate
    stats.simplified_length = adapter.length(rows)
    return None


def _swarm(si, adapter: SpaceAdapter, seed: np.ndarray, values, rng, ptc, deadline,
           stats: SpaceStats) -> np.ndarray:  # fmt: skip
    """The swarm over the seed's waypoints until the budget's end and the outer condition;
    without a budget that condition has already fired (RRT* ran until it), so the swarm is
    bounded by its iterations only, as in the plane."""
    terminate = None
    if deadline is not None:

        def terminate() -> bool:
            return bool(ptc()) or time.perf_counter() >= deadline

    options = PathOptimizerOptions.from_values(values)
    result = optimize_space_path(seed, adapter, si, options, rng, terminate, deadline)
    stats.stages.append("pso")
    stats.pso_time += result.time
    stats.pso_iterations += result.n_iterations
    stats.pso_evaluations += result.n_evaluations
    stats.pso_rounds += result.rounds
    stats.pso_motion_checks += result.motion_checks
    stats.pso_history.extend(result.history.tolist())
    stats.pso_length, stats.pso_waypoints = result.length, len(result.path)
    stats.pso_improved = result.improved
    return result.path
