"""The single entry point for solving a problem with a registered planner.

``solve(problem, "RRTstarPSO", time_limit=1.0, seed=1)`` builds the OMPL setup, creates the
planner by name with its parameters, runs it, validates the returned path exactly and returns a
:class:`~rrtpso_ompl.results.SolveResult`. The command line, the benchmark script and the tests all
go through here, so every planner is measured the same way.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..model.problem import Problem
from ..model.world import World
from ..ompl_setup.context import make_context, path_to_array, seed_ompl
from ..outputs import SolveResult
from .path_optimizer import path_length
from .registry import PlannerRegistry, default_registry

__all__ = ["DEFAULT_PLANNER", "DEFAULT_TIME_LIMIT", "PROGRESS_PERIOD", "solve"]

DEFAULT_PLANNER = "RRTstarPSO"
DEFAULT_TIME_LIMIT = 1.0
#: Seconds between progress samples (OMPL's ``Benchmark::Request::timeBetweenUpdates``).
PROGRESS_PERIOD = 0.05

#: The anytime planners whose termination condition is polled in the planning thread only.
_SINGLE_THREADED_ANYTIME = (og.RRTstar, og.InformedRRTstar, og.SORRTstar, og.BITstar)

_STATUS = {
    ob.PlannerStatus.EXACT_SOLUTION: "exact",
    ob.PlannerStatus.APPROXIMATE_SOLUTION: "approximate",
}


def solve(
    problem: Problem,
    planner: str | None = None,
    time_limit: float | None = None,
    seed: int | None = None,
    params: Mapping[str, Any] | None = None,
    *,
    simplify: bool = False,
    progress: bool = False,
    registry: PlannerRegistry | None = None,
    world: World | None = None,
) -> SolveResult:
    """Solve ``problem`` with the planner registered as ``planner``.

    Parameters
    ----------
    problem : Problem
        A validated problem.
    planner : str, optional
        Registered planner name or alias; the problem's ``planner.type``, else ``"RRTstarPSO"``.
    time_limit : float, optional
        Seconds; the problem's ``planner.time_limit``, else 1.0.
    seed : int, optional
        Seeds OMPL's RNG (once per process, before any OMPL object exists) and the planners'
        numpy generators; the problem's ``planner.seed`` when omitted.
    params : mapping, optional
        Planner parameters by name, on top of the problem's ``planner.params``.
    simplify : bool
        Run OMPL's path simplifier on an exact result, as OMPL's Benchmark does: after the
        planner's budget, with its time reported separately (``stages["simplification_time"]``).
    registry : PlannerRegistry, optional
        Where to look the planner up; the default registry when omitted.
    world : World, optional
        The problem's world, when the caller has built it already.

    Returns
    -------
    SolveResult
        ``solved`` is True only for an exact path that passed the exact validity check; a path that
        fails it is never returned as solved.

    Raises
    ------
    UnknownPlannerError, KeyError, ValueError
        For an unknown planner, parameter name or value (before anything is planned).
    """
    registry = registry or default_registry()
    cfg = problem.planner
    name = planner or cfg.type or DEFAULT_PLANNER
    entry = registry.get(name)
    if time_limit is None:
        time_limit = cfg.time_limit or DEFAULT_TIME_LIMIT
    time_limit = float(time_limit)
    if not (time_limit > 0 and math.isfinite(time_limit)):
        raise ValueError(f"time limit must be a positive number of seconds, got {time_limit}")
    seed = seed if seed is not None else cfg.seed
    values: dict[str, Any] = {**cfg.params, **(params or {})}
    # Planners that split their time (RRTstarPSO) need to know it: OMPL's termination condition
    # does not say how much is left.
    if any(p.name == "budget" for p in entry.params) and "budget" not in values:
        values["budget"] = time_limit
    if seed is not None and any(p.name == "seed" for p in entry.params) and "seed" not in values:
        values["seed"] = seed
    values = entry.validate(values)

    seed_ompl(seed)
    ctx = make_context(problem, world)
    instance = entry.make(ctx.si, values)
    ctx.ss.setPlanner(instance)
    ctx.ss.setup()

    sampler = _ProgressSampler(instance, time_limit) if progress else None
    t0 = time.perf_counter()
    if sampler is not None and sampler.polls:
        sampler.t0 = t0
        status = ctx.ss.solve(ob.PlannerTerminationCondition(sampler))
    else:
        status = ctx.ss.solve(ob.timedPlannerTerminationCondition(time_limit))
    elapsed = time.perf_counter() - t0
    pdef = ctx.ss.getProblemDefinition()
    simplification_time = None
    unsimplified: np.ndarray | None = None
    if pdef.hasSolution():
        unsimplified = path_to_array(pdef.getSolutionPath())
    if simplify and ctx.ss.haveExactSolutionPath():
        t1 = time.perf_counter()
        ctx.ss.simplifySolution()
        simplification_time = time.perf_counter() - t1

    code = status.getStatus()
    path = np.empty((0, 2))
    if pdef.hasSolution():
        path = path_to_array(pdef.getSolutionPath())
    valid = len(path) > 0 and ctx.world.path_valid(path)
    label = _STATUS.get(code, "none") if valid else "none"
    if label == "none":
        path = np.empty((0, 2))
    clearance = ctx.world.path_clearance(path) - ctx.world.robot_radius if valid else None

    stats = getattr(instance, "last_stats", None)
    stages = stats.to_dict() if stats is not None else {}
    applied = instance.param_values() if hasattr(instance, "param_values") else dict(values)
    if isinstance(instance, og.RRTstar | og.InformedRRTstar | og.SORRTstar):
        best = instance.bestCost().value()
        stages = {
            "iterations": instance.numIterations(),
            "best_cost": best if math.isfinite(best) else None,
        }
    if simplification_time is not None:
        stages["simplification_time"] = simplification_time
        stages["unsimplified_length"] = path_length(unsimplified)
        stages["unsimplified_valid"] = bool(ctx.world.path_valid(unsimplified))
    if sampler is not None:
        stages["progress"] = sampler.rows(stats, elapsed, unsimplified, code)
    return SolveResult(
        problem=problem.name,
        planner=entry.name,
        status=label,
        ompl_status=str(status),
        solved=label == "exact",
        length=path_length(path) if len(path) else None,
        time=elapsed,
        seed=seed,
        path=path,
        time_limit=time_limit,
        params=applied,
        stages=stages,
        clearance=clearance,
        valid=bool(valid),
    )


class _ProgressSampler:
    """A termination condition that also samples the planner's best cost every
    :data:`PROGRESS_PERIOD` seconds.

    OMPL polls the condition from the planning thread, so reading ``bestCost`` here is safe; a
    sampling thread could not run at all, since ``solve`` holds the GIL. Only planners with a
    ``bestCost`` are given this Python condition (:attr:`polls`): PRM and PRM* evaluate their
    condition in a second thread as well, which would wait for the GIL forever; the others run
    with OMPL's own timed condition and get their one progress row at the end.
    """

    def __init__(self, planner: Any, time_limit: float) -> None:
        self.time_limit = time_limit
        self.t0 = time.perf_counter()
        self._next = PROGRESS_PERIOD
        self._best = getattr(planner, "bestCost", None)
        #: Whether to poll this condition (only for single-threaded anytime planners).
        self.polls = self._best is not None and isinstance(planner, _SINGLE_THREADED_ANYTIME)
        self._rows: list[list[float]] = []

    def __call__(self) -> bool:
        t = time.perf_counter() - self.t0
        if t >= self._next and self._best is not None:
            self._next = (math.floor(t / PROGRESS_PERIOD) + 1) * PROGRESS_PERIOD
            cost = self._best().value()
            if math.isfinite(cost):
                self._rows.append([t, cost])
        return t >= self.time_limit

    def rows(
        self, stats: Any, elapsed: float, path: np.ndarray | None, code: Any
    ) -> list[list[float]]:
        """The best cost over time, ending with the returned path's length at ``elapsed``."""
        rows = list(self._rows)
        if stats is not None and hasattr(stats, "rrt_progress"):
            # RRTstarPSO: its RRT* samples, then OMPL's simplifier, then the swarm's result.
            rows = [list(r) for r in stats.rrt_progress]
            if stats.simplified_length is not None:
                rows.append([stats.rrt_time + stats.simplify_time, stats.simplified_length])
        exact = code == ob.PlannerStatus.EXACT_SOLUTION
        if exact and path is not None and len(path):
            rows.append([elapsed, path_length(path)])
        # Strictly increasing times: OMPL's database keys progress rows by (run, time).
        out: list[list[float]] = []
        for t, c in rows:
            if not out or t > out[-1][0]:
                out.append([float(t), float(c)])
        return out
