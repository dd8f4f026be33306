"""RRTstarPSO's stage 1: OMPL's RRT* grown in slices, and BIT* when it finds no first path.

The C++ tree grows at full speed; only validity and motion checks call back into Python. It is
grown in short slices (repeated ``solve`` calls continue one tree) so that its best cost can be
sampled over time: OMPL's progress properties are not reachable from Python. The samples decide
when RRT* has stalled and the swarm should take the rest of the budget.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import asdict
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..result import BenchmarkRun

__all__ = [
    "INFLATION_RRT_MIN",
    "INFLATION_RRT_SHARE",
    "RRTstarStatsMixin",
    "connect_with_bitstar",
    "grow_rrtstar",
    "has_exact_solution",
    "stalled",
]

#: RRT*'s share of the budget under an inflation cost when the corridor stage has a path.
INFLATION_RRT_SHARE = 0.1
#: ... and none when that share is under this many seconds (``RRTstarPSO._rrt_futile``).
INFLATION_RRT_MIN = 0.05


class RRTstarStatsMixin:
    """What the statistics of RRTstarPSO, in the plane and outside it, report the same way:
    JSON, RRT*'s progress, and the run of OMPL's benchmark log (the swarm as its
    simplification). A class using it is a dataclass with the fields read here and names its
    own extra log properties in :meth:`log_properties`."""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        d = asdict(self)
        d["rrt_progress"] = [list(p) for p in self.rrt_progress]
        return d

    def progress(self) -> list[tuple[float, float]]:
        """RRT*'s best cost over time, then the length after OMPL's simplifier."""
        rows = list(self.rrt_progress)
        if self.simplified_length is not None:
            rows.append((self.rrt_time + self.simplify_time, self.simplified_length))
        return rows

    def log_properties(self) -> dict[str, tuple[str, Any]]:
        """The run's properties in OMPL's log: ``name -> (SQL type, value)``."""
        return {
            "rrt iterations": ("INTEGER", self.rrt_iterations),
            "pso iterations": ("INTEGER", self.pso_iterations),
            "pso evaluations": ("INTEGER", self.pso_evaluations),
            "pso rounds": ("INTEGER", self.pso_rounds),
        }

    def benchmark_run(self, elapsed: float, length: float | None) -> BenchmarkRun:
        """The run as OMPL's benchmark logs it: the swarm is the simplification."""
        swarm_ran = self.pso_length is not None
        return BenchmarkRun(
            time=elapsed - self.pso_time,
            solution_length=self.seed_length if self.seed_length is not None else self.rrt_length,
            simplification_time=self.pso_time if swarm_ran else None,
            simplified_length=length if swarm_ran else None,
            properties=self.log_properties(),
            progress=self.progress(),
        )


def grow_rrtstar(
    inner: og.RRTstar,
    pdef: ob.ProblemDefinition,
    values: Mapping[str, Any],
    ptc: ob.PlannerTerminationCondition,
    t0: float,
    stats: Any,
    *,
    inflation: bool,
    resume: bool = False,
    fallback: bool = True,
) -> None:
    """Grow RRT* until its share of the budget, its iteration cap or the outer condition, or
    until its best cost stalls (the swarm gets the rest); with no path at ``connect_after`` of
    its share (and ``fallback``: no corridor path either), BIT* looks for the first one.

    Parameters
    ----------
    inner, pdef : og.RRTstar, ob.ProblemDefinition
        The planner's RRT*, set up on ``pdef``, the problem BIT* solves too.
    values : mapping
        RRTstarPSO's parameter values (``budget`` in seconds, ``rrt_time_fraction``,
        ``rrt_max_iterations``, ``connect_after``, ``stall_fraction``).
    ptc : ob.PlannerTerminationCondition
        The outer condition: the stage stops when it fires.
    t0 : float
        ``time.perf_counter()`` at the start of the solve, s.
    stats : RRTstarPSOStats
        Receives ``rrt_time``, ``rrt_iterations``, ``rrt_progress`` and ``first_solution``.
    inflation : bool
        Whether the problem has an inflation cost (each motion cost is then a Python call, and
        with the corridor's path in hand RRT* gets only :data:`INFLATION_RRT_SHARE`).
    resume : bool
        Grow the tree on after a swarm run, for at most 70 % of the time left.
    fallback : bool
        Whether BIT* may look for a first path (False when the corridor stage has one).
    """
    budget = values["budget"]
    t_begin = time.perf_counter()
    share = values["rrt_time_fraction"]  # of what the corridor stage left
    if inflation and not fallback:
        # With the corridor's path in hand and every motion's cost a Python call (10-30 times
        # fewer vertices a second), the cost route and the swarm make better use of it.
        share = min(share, INFLATION_RRT_SHARE)
    rrt_end = t_begin + share * max(t0 + budget - t_begin, 0.0) if budget > 0 else None
    if resume:  # grown on after a swarm run: until a stall again, or 70 % of what is left
        rrt_end = t_begin + 0.7 * max(t0 + budget - t_begin, 0.0)
    start_iter = inner.numIterations()
    if values["rrt_max_iterations"] > 0:
        _grow_bounded(inner, values["rrt_max_iterations"], ptc, rrt_end)
    else:
        connect_at = None
        if rrt_end is not None and values["connect_after"] < 1.0 and not resume:
            connect_at = t_begin + values["connect_after"] * (rrt_end - t_begin)
        slice_s = 0.05 if budget <= 0 else max(0.01, values["rrt_time_fraction"] * budget / 20)
        _grow_in_slices(inner, pdef, values, ptc, t0, t_begin, stats,
                        (rrt_end, connect_at, slice_s), fallback)  # fmt: skip
    stats.rrt_time += time.perf_counter() - t_begin
    stats.rrt_iterations += inner.numIterations() - start_iter


def _grow_bounded(inner: og.RRTstar, max_iter: int, ptc, rrt_end: float | None) -> None:
    """Iteration-bounded: one call with a Python condition that RRT* polls once per iteration
    (no period, so no checker thread and no GIL deadlock)."""
    start_iter = inner.numIterations()

    def stop() -> bool:
        return (
            inner.numIterations() - start_iter >= max_iter
            or ptc()
            or (rrt_end is not None and time.perf_counter() >= rrt_end)
        )

    inner.solve(ob.PlannerTerminationCondition(stop))


def _grow_in_slices(inner, pdef, values, ptc, t0, t_begin, stats, timing, fallback) -> None:
    """Time-bounded: slices of ``slice_s`` seconds until ``rrt_end``, a stall, or the hand-over
    to BIT* at ``connect_at`` with no exact path yet (``timing = (rrt_end, connect_at,
    slice_s)``); each slice's best cost is appended to ``stats.rrt_progress``."""
    rrt_end, connect_at, slice_s = timing
    budget = values["budget"]
    while not ptc():
        now = time.perf_counter()
        if rrt_end is not None and now >= rrt_end:
            break
        if connect_at is not None and now >= connect_at and not has_exact_solution(pdef):
            if fallback:
                connect_with_bitstar(inner.getSpaceInformation(), pdef, ptc, rrt_end, stats)
            break  # with the corridor's path in hand, the swarm gets the time instead
        since = t_begin - t0
        if stalled(stats.rrt_progress, now - t0, budget, since, values["stall_fraction"]):
            break
        step = slice_s if rrt_end is None else min(slice_s, rrt_end - now)
        inner.solve(ob.plannerOrTerminationCondition(
            ptc, ob.timedPlannerTerminationCondition(max(step, 1e-4))))  # fmt: skip
        cost = inner.bestCost().value()
        if np.isfinite(cost):
            stats.rrt_progress.append((time.perf_counter() - t0, float(cost)))


def has_exact_solution(pdef: ob.ProblemDefinition) -> bool:
    """Whether ``pdef`` holds a path that reaches the goal (not only an approximate one)."""
    return pdef.hasSolution() and not pdef.hasApproximateSolution()


def stalled(
    progress: list[tuple[float, float]],
    elapsed: float,
    budget: float,
    since: float,
    stall_fraction: float,
) -> bool:
    """Whether RRT*'s best cost fell by less than 0.1 % over the last ``stall_fraction`` of the
    budget (relative, so the same on every scale), looking no further back than ``since``.

    Parameters
    ----------
    progress : list of (float, float)
        ``(seconds into the solve, best cost)`` samples, in order.
    elapsed, budget, since : float
        Seconds into the solve now, the budget, and the start of the current growth, s.
    stall_fraction : float
        The share of the budget the cost must have fallen over.
    """
    window = stall_fraction * budget
    if window <= 0 or not progress or elapsed < max(progress[0][0], since) + window:
        return False
    then = [c for t, c in progress if t <= elapsed - window]
    if not then:
        return False
    now = progress[-1][1]
    return then[-1] - now <= 1e-3 * now


def connect_with_bitstar(
    si: ob.SpaceInformation, pdef: ob.ProblemDefinition, ptc, end: float, stats: Any
) -> None:
    """OMPL's BIT* on the same problem until ``end`` (a ``perf_counter`` time) or its first path:
    through narrow passages that RRT*'s single tree has not crossed yet.

    Measured on narrow unique-solution mazes (point robot, corridors 1-2 % of the width):
    RRTConnect found no path in 4 s where BIT*, whose batches of samples are searched as a graph,
    found one in under a second (docs/benchmarking.md).
    """
    pdef.clearSolutionPaths()  # RRT*'s approximate path, if any
    connect = og.BITstar(si)
    connect.setStopOnSolnImprovement(True)  # the first path is all it is asked for
    connect.setProblemDefinition(pdef)
    connect.setup()
    left = max(end - time.perf_counter(), 1e-4)
    connect.solve(ob.plannerOrTerminationCondition(
        ptc, ob.timedPlannerTerminationCondition(left)))  # fmt: skip
    stats.first_solution = "BITstar"
