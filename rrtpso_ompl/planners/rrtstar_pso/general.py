"""RRTstarPSO outside the plane: R^n, SE(2), Dubins and Reeds-Shepp, through the space
information alone.

The plane's stages that need its exact world (the vectorised segment checks, the inflation
cost's re-routing) do not apply here; what runs is

0. for a car-like robot's problem file only (its motion validator checks curves against our
   world): the corridor stage's route made poses, checked and repaired (:mod:`.car_seed`);
1. OMPL's RRT* (the planner's inner ``og.RRTstar``, grown by :func:`.rrtstar_stage.grow_rrtstar`:
   at most :data:`SPACE_RRT_SHARE` of the budget, its iteration cap, its stall test; BIT* looks
   for a first path in R^n and SE(2) when RRT* has none in time, and with no path and no
   corridor seed RRT* grows on for :data:`LATE_RRT_SHARE` of what is left);
2. OMPL's path simplifier on a copy of RRT*'s path (kept when shorter), every motion of the seed
   checked again at :data:`~rrtpso_ompl.planners.pso.space_path.FINAL_FINER` times the space's
   resolution, and a seed that fails repaired (:mod:`.repair`); the shorter of RRT*'s and the
   corridor's seeds goes on;
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
from .car_seed import car_corridor_seed
from .corridor import REPRODUCIBLE_CORRIDOR_CELLS
from .repair import repair_path
from .rrtstar_stage import RRTstarStatsMixin, grow_rrtstar, has_exact_solution

__all__ = ["SpaceStats", "solve_in_space", "space_of_planner"]

#: Share of the budget kept back for handing the path over (as in the plane).
FINISH_RESERVE = 0.03
#: RRT*'s share of the budget here, at most: the swarm's candidates cost motion checks through
#: the user's Python checker, so it needs far more of the budget than in the plane (tuned on
#: the benchmark's seeds 1-10, docs/spaces.md).
SPACE_RRT_SHARE = 0.4
#: With no path at the end of its share and no corridor seed, RRT* grows on for this share of
#: what is left: the rest is for checking its path (RRT*'s path in a plain Dubins space has
#: motions it checked the other way round) and the swarm.
LATE_RRT_SHARE = 0.8
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
    corridor_time: float = 0.0
    corridor_length: float | None = None
    corridor_reason: str = ""

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
    deadline = t0 + (1.0 - FINISH_RESERVE) * values["budget"] if values["budget"] > 0 else None
    corridor = _car_corridor(planner, adapter, values, ptc, deadline, rng, stats)
    _grow(planner, pdef, values, adapter.kind in _BITSTAR_SPACES, ptc, t0, stats,
          extend=corridor is None)  # fmt: skip
    stats.stages.append("RRTstar")
    if stats.first_solution != "RRTstar":
        stats.stages.append(stats.first_solution)
    seed, source = corridor, "corridor"
    if has_exact_solution(pdef):
        found, found_source = _rrt_seed(si, adapter, pdef, values, ptc, deadline, rng, stats)
        if found is not None and (seed is None or adapter.length(found) < adapter.length(seed)):
            seed, source = found, found_source
    if seed is None:
        if pdef.hasSolution() and not has_exact_solution(pdef):  # RRT* never reached the goal
            return ob.PlannerStatus(ob.PlannerStatus.APPROXIMATE_SOLUTION)
        pdef.clearSolutionPaths()  # none, or none that passes the fine check, even repaired
        if stats.rrt_length is not None:
            stats.stages.append("refused")
        return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
    stats.seed_source = source
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


def _rrt_seed(si, adapter: SpaceAdapter, pdef, values, ptc, deadline, rng,
              stats: SpaceStats) -> tuple[np.ndarray | None, str]:  # fmt: skip
    """RRT*'s path, simplified and checked (:func:`_checked_seed`), and whose it is."""
    raw = pdef.getSolutionPath()  # shared ownership: stays valid after clearSolutionPaths
    rows = adapter.path_to_array(raw)
    stats.rrt_length, stats.rrt_waypoints = adapter.length(rows), len(rows)
    stats.rrt_path = rows.tolist()
    simplified = None
    if values["simplify"]:
        simplified = _simplified(si, pdef, raw, rows, adapter, deadline, stats)
    seed, repaired = _checked_seed(si, adapter, simplified, rows, deadline, ptc, rng)
    if repaired:
        stats.stages.append("repair")
    return seed, stats.first_solution + ("+repair" if repaired else "")


def _car_corridor(planner, adapter: SpaceAdapter, values, ptc, deadline, rng,
                  stats: SpaceStats) -> np.ndarray | None:  # fmt: skip
    """For a car-like robot's problem (its curves checked against our world,
    :class:`~rrtpso_ompl.ompl_setup.car.CurveMotionValidator`): the corridor stage's route as a
    checked path of poses (:mod:`.car_seed`), within ``corridor_fraction`` of the budget; None
    elsewhere, with the corridor stage off, or without a route."""
    si = planner.getSpaceInformation()
    validator = si.getMotionValidator()
    if getattr(validator, "car", None) is None or values["corridor_cells"] <= 0:
        return None
    # The planner's input states (pdef.getStartState's state is freed with its Python wrapper).
    pis = planner.getPlannerInputStates()
    pis.restart()
    first, target = pis.nextStart(), pis.nextGoal(ob.plannerNonTerminatingCondition())
    pis.restart()
    if first is None or target is None:
        return None
    start, goal = adapter.row(first), adapter.row(target)
    t1 = time.perf_counter()
    seconds, cells = None, min(values["corridor_cells"], REPRODUCIBLE_CORRIDOR_CELLS)
    if values["budget"] > 0 and values["rrt_max_iterations"] <= 0:
        seconds = values["corridor_fraction"] * max(deadline - t1, 0.0)
        cells = values["corridor_cells"]
    until = None if seconds is None else t1 + seconds

    def stop() -> bool:
        return until is not None and (bool(ptc()) or time.perf_counter() >= until)

    check_stop = _stop(ptc, deadline, 0.5)  # the route's check and repair: half of what is left

    rows, reason = car_corridor_seed(si, adapter, validator, start, goal, seconds, cells, rng,
                                     stop, check_stop)  # fmt: skip
    stats.corridor_time = time.perf_counter() - t1
    stats.corridor_reason = reason
    stats.stages.append("corridor")
    if rows is None:
        return None
    stats.corridor_length = adapter.length(rows)
    if not values["simplify"]:
        return rows
    return _simplified_corridor(si, planner.getProblemDefinition(), rows, adapter, deadline,
                                check_stop, stats)  # fmt: skip


def _simplified_corridor(si, pdef, rows, adapter: SpaceAdapter, deadline, stop,
                         stats: SpaceStats):  # fmt: skip
    """OMPL's simplifier on the corridor's poses (``simplifyMax``; with a deadline, in small
    batches for a tenth of the time left), kept when shorter and when every motion passes the
    check again (until ``stop``)."""
    t1 = time.perf_counter()
    path = adapter.array_to_path(si, rows)
    if deadline is not None:
        simplify_until(si, path, t1 + 0.1 * max(deadline - t1, 0.0),
                       pdef.getOptimizationObjective())  # fmt: skip
    else:
        og.PathSimplifier(si).simplifyMax(path)
    candidate = adapter.path_to_array(path)
    stats.simplify_time += time.perf_counter() - t1
    if adapter.length(candidate) < adapter.length(rows) and bool(
        MotionChecker(si, adapter).path_free(candidate, stop, factor=FINAL_FINER)
    ):
        stats.corridor_length = adapter.length(candidate)
        return candidate
    return rows


def _grow(planner, pdef, values, bitstar: bool, ptc, t0: float, stats: SpaceStats,
          extend: bool = True) -> None:  # fmt: skip
    """RRT* for at most :data:`SPACE_RRT_SHARE` of the budget, and (``extend``: no corridor
    seed either) on for :data:`LATE_RRT_SHARE` of what is left when it has no path by then (the
    swarm has nothing to work on: a late answer rather than none).
    No corridor path waits here: where BIT* may not look for a first path (``bitstar`` False),
    RRT* does not stop looking at ``connect_after`` of its share."""
    grown = {**values, "rrt_time_fraction": min(values["rrt_time_fraction"], SPACE_RRT_SHARE),
             "connect_after": values["connect_after"] if bitstar else 1.0}  # fmt: skip
    grow_rrtstar(planner.inner, pdef, grown, ptc, t0, stats, inflation=False, fallback=bitstar)
    if extend and not has_exact_solution(pdef) and values["budget"] > 0 and not ptc():
        grow_rrtstar(planner.inner, pdef, {**grown, "rrt_time_fraction": LATE_RRT_SHARE},
                     ptc, t0, stats, inflation=False, fallback=bitstar)  # fmt: skip


def _checked_seed(si, adapter: SpaceAdapter, simplified, rows, deadline, ptc,
                  rng) -> tuple[np.ndarray | None, bool]:  # fmt: skip
    """The swarm's seed, and whether it was repaired: the simplifier's path when every motion of
    it passes ``si.checkMotion`` and the check at
    :data:`~rrtpso_ompl.planners.pso.space_path.FINAL_FINER` times the resolution, else RRT*'s
    when it does, each repaired by :func:`.repair.repair_path` when it fails; else None (no
    answer rather than one a denser check would refuse).

    The simplifier checks its shortcuts' motions, but the pieces it keeps of a motion are not
    the motion it checked (a shortcut from a point inside one segment to a point inside another
    leaves two part-segments, sampled at other states): measured, one simplified R^3 path in
    seven failed ``path.check()``. RRT*'s own path can fail too: OMPL checks it at the space's
    resolution (2 of 10 R^3 paths grazed a disc between those samples), and where the space's
    distance is not symmetric (plain Dubins) RRT* checks some motions the other way round.
    With a ``deadline``, a path is only checked (and used) when its first motion's check, timed,
    says the whole check fits in half of the time left. A repaired simplifier's path is used
    only when shorter than RRT*'s (its repair takes at most half of the time left when RRT*'s
    path passes as it is); the repair of RRT*'s path stops at the deadline."""
    checker = MotionChecker(si, adapter)
    if simplified is not None and _passes(checker, simplified, deadline):
        return simplified, False
    rrt_ok = _passes(checker, rows, deadline)
    if simplified is not None:
        # With RRT*'s path in hand the repair may take half of the time left, else all of it.
        repaired = repair_path(simplified, adapter, checker, rng,
                               _stop(ptc, deadline, 0.5 if rrt_ok else 1.0))  # fmt: skip
        if repaired is not None and (not rrt_ok or adapter.length(repaired) < adapter.length(rows)):
            return repaired, True
    if rrt_ok:
        return rows, False
    repaired = repair_path(rows, adapter, checker, rng, _stop(ptc, deadline, 1.0))
    return repaired, repaired is not None


def _passes(checker: MotionChecker, rows: np.ndarray, deadline: float | None) -> bool:
    """Whether every motion passes the check at ``FINAL_FINER`` times the resolution (False
    when that check would not fit in the time, :func:`_check_fits`)."""
    return _check_fits(checker, rows, deadline) and bool(
        checker.path_free(rows, factor=FINAL_FINER)
    )


def _stop(ptc, deadline: float | None, share: float):
    """A stop test at ``share`` of the time left before ``deadline`` (None without one: the
    outer condition has fired already, and the work is bounded by its counts)."""
    if deadline is None:
        return None
    until = time.perf_counter() + share * max(deadline - time.perf_counter(), 0.0)

    def stop() -> bool:
        return bool(ptc()) or time.perf_counter() >= until

    return stop


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
