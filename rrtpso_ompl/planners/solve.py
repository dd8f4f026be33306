"""The single entry point for solving a problem with a registered planner.

``solve(problem, "RRTstarPSO", time_limit=1.0, seed=1)`` builds the OMPL setup, creates the
planner by name with its parameters, runs it, validates the returned path exactly and returns a
:class:`~rrtpso_ompl.planners.result.SolveResult`. The command line, batches, benchmarks, the
dynamic replanner and the tests all go through here, so every planner is measured the same way.
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from ompl import base as ob

from ..model.geometry import path_length
from ..model.problem import Problem
from ..model.world import World
from ..ompl_setup import PlanningContext, make_context, path_to_array, seed_ompl
from ..validation import check_seconds, check_seed
from .post import POST_PARAMS, PostStep, parse_steps, run_post, split_params, split_spec
from .registry import PlannerEntry, PlannerRegistry, default_registry
from .result import BenchmarkRun, SolveResult

__all__ = [
    "DEFAULT_PLANNER",
    "DEFAULT_TIME_LIMIT",
    "PROGRESS_PERIOD",
    "PlannerRequest",
    "resolve_request",
    "solve",
]

DEFAULT_PLANNER = "RRTstarPSO"
DEFAULT_TIME_LIMIT = 1.0
#: Seconds between progress samples (OMPL's ``Benchmark::Request::timeBetweenUpdates``).
PROGRESS_PERIOD = 0.05

_STATUS = {
    ob.PlannerStatus.EXACT_SOLUTION: "exact",
    ob.PlannerStatus.APPROXIMATE_SOLUTION: "approximate",
}


@dataclass(frozen=True)
class PlannerRequest:
    """A planner, its budget, seed and validated parameters, resolved for one problem.

    Attributes
    ----------
    entry : PlannerEntry
        The registered planner.
    time_limit : float
        Seconds.
    seed : int or None
        OMPL's seed (and the planner's numpy seed when it takes one).
    values : dict
        Validated parameters: the file's ``planner.params`` under the caller's, plus ``budget``
        and ``seed`` for planners that take them.
    """

    entry: PlannerEntry
    time_limit: float
    seed: int | None
    values: dict[str, Any]


def resolve_request(
    problem: Problem,
    planner: str | None = None,
    time_limit: float | None = None,
    seed: int | None = None,
    params: Mapping[str, Any] | None = None,
    registry: PlannerRegistry | None = None,
) -> PlannerRequest:
    """What to run: the caller's choices over the problem's ``planner`` section over defaults.

    Raises
    ------
    UnknownPlannerError, ParameterError
        For an unknown planner, parameter name or value, or a time limit that is not a positive
        number of seconds.
    """
    from ..errors import ParameterError, ProblemError

    registry = registry or default_registry()
    cfg = problem.planner
    entry = registry.get(planner or cfg.type or DEFAULT_PLANNER)
    limit = time_limit if time_limit is not None else (cfg.time_limit or DEFAULT_TIME_LIMIT)
    try:
        limit = check_seconds(limit)
    except ValueError as exc:
        raise ParameterError(f"time limit {exc}", "time_limit") from None
    seed = seed if seed is not None else cfg.seed
    if seed is not None:
        try:
            seed = check_seed(seed)
        except ValueError as exc:
            raise ParameterError(f"seed {exc}", "seed") from None
    for key, value in cfg.params.items():
        # The file's values are typed YAML: "30" in quotes is text there, as everywhere in it.
        if entry.takes(key):
            try:
                entry.param(key).convert(value, entry.name, text=False)
            except ParameterError as exc:
                raise ProblemError(problem.source, f"planner.params.{key}", str(exc)) from None
    values: dict[str, Any] = {**cfg.params, **(params or {})}
    # Planners that split their time (RRTstarPSO) need to know it: OMPL's termination condition
    # does not say how much is left.
    if entry.takes("budget") and "budget" not in values:
        values["budget"] = limit
    if seed is not None and entry.takes("seed") and "seed" not in values:
        values["seed"] = seed
    return PlannerRequest(entry, limit, seed, entry.validate(values))


def solve(
    problem: Problem,
    planner: str | None = None,
    time_limit: float | None = None,
    seed: int | None = None,
    params: Mapping[str, Any] | None = None,
    *,
    post: Sequence[str] = (),
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
        A spec such as ``"BITstar+simplify+pso"`` adds post-passes (see ``post``).
    time_limit : float, optional
        Seconds; the problem's ``planner.time_limit``, else 1.0.
    seed : int, optional
        Seeds OMPL's RNG (once per process, before any OMPL object exists) and the planners'
        numpy generators; the problem's ``planner.seed`` when omitted.
    params : mapping, optional
        Planner parameters by name, on top of the problem's ``planner.params``.
    post : sequence of str, or str
        Post-passes after the planner (a string is a comma list), in order, within the same
        budget: ``"simplify"`` (OMPL's
        simplifier) and ``"pso"`` (:class:`~rrtpso_ompl.planners.post.PSOPathOptimizer`), after
        those of the spec. The planner then gets ``1 - post_fraction`` of the time
        (:data:`~rrtpso_ompl.planners.post.POST_PARAMS`, settable in ``params``); each step's
        lengths and time are in ``stages["post"]``.
    simplify : bool
        Run OMPL's path simplifier on an exact result, as OMPL's Benchmark does: after the
        planner's budget, with its time reported separately (``stages["simplification_time"]``).
        Ignored when there are post-passes (they say what follows the planner).
    progress : bool
        Sample the best cost over time (``result.benchmark.progress``), as OMPL's Benchmark does.
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
    ArgumentError
        For an argument of the wrong kind (a file name where the problem goes: load it with
        :func:`~rrtpso_ompl.model.load_problem` first).
    UnknownPlannerError, ParameterError
        For an unknown planner, parameter name or value (before anything is planned).
    ProblemError
        For a value of the problem's ``planner.params`` its planner cannot take.
    """
    post = _check_arguments(problem, planner, params, post, world)
    name, spec_steps = split_spec(planner) if planner else (None, ())
    steps = tuple(dict.fromkeys((*spec_steps, *parse_steps(post))))
    registry = registry or default_registry()
    entry = registry.get(name or problem.planner.type or DEFAULT_PLANNER)
    params, post_values = split_params(entry, params or {}, steps)
    request = resolve_request(problem, name, time_limit, seed, params, registry)
    planner_limit = request.time_limit
    if steps:
        fraction = post_values.get("post_fraction", POST_PARAMS["post_fraction"].default)
        planner_limit = request.time_limit * (1.0 - fraction)
        if request.entry.takes("budget") and "budget" not in params:
            request.values["budget"] = planner_limit
    seed_ompl(request.seed)
    ctx = make_context(problem, world)
    instance = request.entry.make(ctx.si, request.values)
    ctx.ss.setPlanner(instance)
    ctx.ss.setup()

    sampler = _ProgressSampler(instance, planner_limit, request) if progress else None
    t0 = time.perf_counter()
    if sampler is not None and sampler.polls:
        sampler.t0 = t0
        status = ctx.ss.solve(ob.PlannerTerminationCondition(sampler))
    else:
        status = ctx.ss.solve(ob.timedPlannerTerminationCondition(planner_limit))
    elapsed = time.perf_counter() - t0
    code = status.getStatus()

    pdef = ctx.ss.getProblemDefinition()
    raw = path_to_array(pdef.getSolutionPath()) if pdef.hasSolution() else None
    stats = request.entry.collect_stats(instance)
    stages = stats.to_dict()
    run = stats.benchmark_run(elapsed, _length(raw))
    spent = elapsed
    if steps and ctx.ss.haveExactSolutionPath():
        done = run_post(ctx.si, pdef.getSolutionPath(), steps, t0 + request.time_limit,
                        post_values)  # fmt: skip
        run = _with_post(run, done)
        spent += sum(d.time for d in done)
        stages["post"] = [d.to_dict() for d in done]
    elif simplify and ctx.ss.haveExactSolutionPath():
        run, simplification = _simplify(ctx, run, raw)
        stages.update(simplification)
    path, label, valid = _checked_path(ctx, pdef, code)
    if sampler is not None:
        # The last row is the planner's own path at the end of its budget (before any
        # simplification by the harness).
        final = _length(raw) if code == ob.PlannerStatus.EXACT_SOLUTION else None
        run = _with_progress(run, sampler.rows(), elapsed, final)
    return SolveResult(
        problem=problem.name,
        # The planner as asked: a spec keeps its post-passes in the name (a configuration of its
        # own in benchmarks); those of ``post`` are in ``stages["post"]`` only.
        planner=request.entry.name + "".join(f"+{step}" for step in spec_steps),
        status=label,
        ompl_status=str(status),
        solved=label == "exact",
        length=_length(path),
        time=spent,
        seed=request.seed,
        path=path,
        time_limit=request.time_limit,
        params=_applied(instance, request.values),
        stages=stages,
        clearance=ctx.world.path_clearance(path) - ctx.world.robot_radius if valid else None,
        valid=valid,
        benchmark=run,
    )


def _length(path: np.ndarray | None) -> float | None:
    return path_length(path) if path is not None and len(path) else None


def _applied(instance: Any, values: dict[str, Any]) -> dict[str, Any]:
    """The parameters as the planner applied them (ours report OMPL's choices, e.g. range)."""
    own = getattr(instance, "param_values", None)
    return own() if callable(own) else dict(values)


def _check_arguments(
    problem: Any, planner: Any, params: Any, post: Any, world: Any
) -> tuple[str, ...]:
    """Refuse arguments of the wrong kind with an :class:`ArgumentError` that says what goes
    there (a wrong *value* is the planners' business); ``post`` as a tuple of step names."""
    from ..errors import ArgumentError
    from ..validation import describe

    if not isinstance(problem, Problem):
        hint = ""
        if isinstance(problem, str | os.PathLike):
            hint = f"; load the file first: solve(load_problem({str(problem)!r}), ...)"
        raise ArgumentError(f"solve: problem must be a Problem (from load_problem or "
                            f"problem_from_dict), got {describe(problem)}{hint}")  # fmt: skip
    if planner is not None and not isinstance(planner, str):
        raise ArgumentError(f"solve: planner must be a planner name such as 'RRTstarPSO' (see "
                            f"'rrtpso planners'), got {describe(planner)}")  # fmt: skip
    if params is not None:
        if not isinstance(params, Mapping):
            raise ArgumentError(f"solve: params must be a mapping of parameter names to values, "
                                f"such as {{'range': 2.0}}, got {describe(params)}")  # fmt: skip
        for key in params:
            if not isinstance(key, str):
                raise ArgumentError(f"solve: params: parameter names are strings, got "
                                    f"{describe(key)}")  # fmt: skip
    if isinstance(post, str):
        post = [s for s in post.split(",") if s.strip()]
    if not isinstance(post, Sequence) or not all(isinstance(s, str) for s in post):
        raise ArgumentError(f"solve: post must be step names such as ('simplify', 'pso'), got "
                            f"{describe(post)}")  # fmt: skip
    if world is not None and not isinstance(world, World):
        raise ArgumentError(f"solve: world must be the problem's World, got {describe(world)}")
    return tuple(post)


def _simplify(
    ctx: PlanningContext, run: BenchmarkRun, raw: np.ndarray
) -> tuple[BenchmarkRun, dict[str, Any]]:
    """OMPL's simplifier after the planner, as in OMPL's Benchmark (timed separately)."""
    t1 = time.perf_counter()
    ctx.ss.simplifySolution()
    seconds = time.perf_counter() - t1
    length = path_length(path_to_array(ctx.ss.getProblemDefinition().getSolutionPath()))
    own = run.simplification_time or 0.0  # a planner's own simplification stage comes first
    run = BenchmarkRun(
        time=run.time,
        solution_length=run.solution_length,
        simplification_time=own + seconds,
        simplified_length=length,
        properties=run.properties,
        progress=run.progress,
    )
    stages = {
        "simplification_time": seconds,
        "unsimplified_length": path_length(raw),
        "unsimplified_valid": bool(ctx.world.path_valid(raw)),
    }
    return run, stages


def _with_post(run: BenchmarkRun, done: list[PostStep]) -> BenchmarkRun:
    """The run with the post-passes as OMPL's simplification: their time after the planner's
    own simplification stage, and the length they left."""
    own = run.simplification_time or 0.0
    return dataclasses.replace(
        run,
        simplification_time=own + sum(d.time for d in done),
        simplified_length=done[-1].length_after if done else run.simplified_length,
    )


def _checked_path(ctx: PlanningContext, pdef: Any, code: Any) -> tuple[np.ndarray, str, bool]:
    """The returned path if it passes the exact check, with its status label."""
    path = path_to_array(pdef.getSolutionPath()) if pdef.hasSolution() else np.empty((0, 2))
    valid = len(path) > 0 and bool(ctx.world.path_valid(path))
    label = _STATUS.get(code, "none") if valid else "none"
    if label == "none":
        return np.empty((0, 2)), label, False
    return path, label, valid


def _with_progress(
    run: BenchmarkRun, sampled: list[tuple[float, float]], elapsed: float, final: float | None
) -> BenchmarkRun:
    """The run with its progress rows: the planner's own or the sampled best costs, then the
    returned length at ``elapsed``; times strictly increasing (OMPL's database keys progress rows
    by run and time)."""
    rows = list(run.progress or sampled)
    if final is not None:
        rows.append((elapsed, final))
    out: list[tuple[float, float]] = []
    for t, c in rows:
        if not out or t > out[-1][0]:
            out.append((float(t), float(c)))
    return BenchmarkRun(
        time=run.time,
        solution_length=run.solution_length,
        simplification_time=run.simplification_time,
        simplified_length=run.simplified_length,
        properties=run.properties,
        progress=out,
    )


class _ProgressSampler:
    """A termination condition that also samples the planner's best cost every
    :data:`PROGRESS_PERIOD` seconds.

    OMPL polls the condition from the planning thread, so reading ``bestCost`` here is safe; a
    sampling thread could not run at all, since ``solve`` holds the GIL. Only planners whose
    registry entry says so (:attr:`Capabilities.progress_polling`) are given this Python
    condition: PRM and PRM* evaluate their condition in a second thread as well, which would
    wait for the GIL forever. The others run with OMPL's own timed condition and report their own
    progress, if any.
    """

    def __init__(self, planner: Any, time_limit: float, request: PlannerRequest) -> None:
        self.time_limit = time_limit
        self.t0 = time.perf_counter()
        self._next = PROGRESS_PERIOD
        #: Whether to poll this condition.
        self.polls = request.entry.capabilities.progress_polling
        self._best = planner.bestCost if self.polls else None
        self._rows: list[tuple[float, float]] = []

    def __call__(self) -> bool:
        t = time.perf_counter() - self.t0
        if t >= self._next and self._best is not None:
            self._next = (math.floor(t / PROGRESS_PERIOD) + 1) * PROGRESS_PERIOD
            cost = self._best().value()
            if math.isfinite(cost):
                self._rows.append((t, cost))
        return t >= self.time_limit

    def rows(self) -> list[tuple[float, float]]:
        """The sampled ``(time s, best cost)`` rows."""
        return list(self._rows)
