"""The single entry point for solving a problem with a registered planner.

``solve(problem, "RRTstarPSO", time_limit=1.0, seed=1)`` resolves the request
(:func:`~rrtpso_ompl.planners.request.resolve`), builds the OMPL setup, creates the planner by
name with its parameters, runs it and its post-passes, validates the returned path exactly and
returns a :class:`~rrtpso_ompl.planners.result.SolveResult`. The command line, batches,
benchmarks, the dynamic replanner and the tests all go through here, so every planner is measured
the same way.

The steps that use OMPL import it themselves, so that importing this module (and
:mod:`rrtpso_ompl.planners`, which names :func:`solve`) loads no OMPL.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ArgumentError
from ..model.geometry import path_length
from ..model.problem_types import Problem
from ..model.world import World
from ..validation import describe
from .registry import PlannerRegistry
from .request import PlannerRequest, check_arguments, resolve
from .result import BenchmarkRun, SolveResult

if TYPE_CHECKING:
    from ..ompl_setup import PlanningContext
    from .post import PostStep

__all__ = ["PROGRESS_PERIOD", "solve"]

#: Seconds between progress samples (OMPL's ``Benchmark::Request::timeBetweenUpdates``).
PROGRESS_PERIOD = 0.05


def solve(
    problem: Problem | PlannerRequest,
    planner: str | None = None,
    *,
    time_limit: float | None = None,
    seed: int | None = None,
    params: Mapping[str, Any] | None = None,
    post: Sequence[str] | str = (),
    simplify: bool = False,
    progress: bool = False,
    registry: PlannerRegistry | None = None,
    world: World | None = None,
) -> SolveResult:
    """Solve ``problem`` with the planner registered as ``planner``.

    Parameters
    ----------
    problem : Problem or PlannerRequest
        A validated problem; or a request resolved for one (:func:`.request.resolve`), and then
        none of ``planner``, ``time_limit``, ``seed``, ``params``, ``post`` and ``registry``.
    planner, time_limit, seed, params, post, registry
        What to run, resolved by :func:`.request.resolve` (the caller's choices over the
        problem's ``planner`` section over the defaults): a planner spec such as
        ``"BITstar+simplify+pso"``; seconds for the planner and its post-passes; OMPL's and the
        planner's seed; parameters by name; post-passes after those of the spec (a string is a
        comma list), which get ``post_fraction`` of the time and report each step in
        ``stages["post"]``; the registry to look the planner up in.
    simplify : bool
        Run OMPL's path simplifier on an exact result after the planner's budget, timed
        separately (``stages["simplification_time"]``), as OMPL's Benchmark does; ignored with
        post-passes.
    progress : bool
        Sample the best cost over time (``result.benchmark.progress``), as OMPL's Benchmark does.
    world : World, optional
        The problem's world, when the caller has built it already.

    Returns
    -------
    SolveResult
        ``solved`` only for an exact path that passed the exact check; a path that fails it is
        never returned.

    Raises
    ------
    ArgumentError
        For an argument of the wrong kind (a file name where the problem goes).
    UnknownPlannerError, ParameterError, ProblemError
        As :func:`.request.resolve`, before anything is planned.
    """
    request = _request(problem, planner, time_limit, seed, params, post, registry)
    if world is not None and not isinstance(world, World):
        raise ArgumentError(f"solve: world must be the problem's World, got {describe(world)}")
    ctx, instance = _build(request, world)
    run = _run_planner(ctx, instance, request, progress)
    _post_passes(ctx, request, run, simplify)
    path, status = _validated_path(ctx, run.code)
    if ctx.car is not None and len(path):
        run.stages.update(_car_path(ctx))
    return _result(request, ctx, instance, run, path, status)


@dataclass
class _Run:
    """One solve as it goes: what the planner returned, and the figures so far."""

    status: Any  # ob.PlannerStatus
    t0: float  # time.perf_counter() when the planner started
    elapsed: float  # the planner's seconds
    raw: np.ndarray | None  # the planner's own path
    benchmark: BenchmarkRun
    stages: dict[str, Any] = field(default_factory=dict)
    spent: float = 0.0  # the planner's and the post-passes' seconds

    @property
    def code(self) -> Any:
        return self.status.getStatus()


def _request(
    problem: Any,
    planner: Any,
    time_limit: float | None,
    seed: int | None,
    params: Any,
    post: Any,
    registry: PlannerRegistry | None,
) -> PlannerRequest:
    """Step 1: the request, given or resolved from the arguments."""
    if isinstance(problem, PlannerRequest):
        given = [name for name, value in (("planner", planner), ("time_limit", time_limit),
                 ("seed", seed), ("params", params), ("post", post), ("registry", registry))
                 if value not in (None, ())]  # fmt: skip
        if given:
            raise ArgumentError(f"solve: give a PlannerRequest or the arguments to resolve one, "
                                f"not both (got {', '.join(given)})")  # fmt: skip
        if problem.problem is None:
            raise ArgumentError("solve: the request was resolved without a problem")
        return problem
    steps = check_arguments("solve", problem, planner, params, post, problem_required=True)
    return resolve(problem, planner, params=params, time_limit=time_limit, seed=seed, post=steps,
                   registry=registry)  # fmt: skip


def _build(request: PlannerRequest, world: World | None) -> tuple[PlanningContext, Any]:
    """Step 2: OMPL seeded, the problem's setup and the planner in it."""
    from ..ompl_setup import make_context, seed_ompl

    seed_ompl(request.seed)
    ctx = make_context(request.problem, world)
    instance = request.entry.make(ctx.si, request.values)
    ctx.ss.setPlanner(instance)
    ctx.ss.setup()
    return ctx, instance


def _run_planner(
    ctx: PlanningContext, instance: Any, request: PlannerRequest, progress: bool
) -> _Run:
    """Step 3: the planner for its share of the time, sampled when asked; its own figures."""
    from ompl import base as ob

    limit = request.planner_time
    sampler = _ProgressSampler(instance, limit, request) if progress else None
    t0 = time.perf_counter()
    if sampler is not None and sampler.polls:
        sampler.t0 = t0
        status = ctx.ss.solve(ob.PlannerTerminationCondition(sampler))
    else:
        status = ctx.ss.solve(ob.timedPlannerTerminationCondition(limit))
    elapsed = time.perf_counter() - t0
    pdef = ctx.ss.getProblemDefinition()
    raw = ctx.polyline(pdef.getSolutionPath()) if pdef.hasSolution() else None
    stats = request.entry.collect_stats(instance)
    run = _Run(status, t0, elapsed, raw, stats.benchmark_run(elapsed, _length(raw)),
               _car_stages(ctx, stats.to_dict()), elapsed)  # fmt: skip
    if sampler is not None:
        # The last row is the planner's own path at the end of its budget (before any
        # simplification by the harness).
        final = _length(raw) if run.code == ob.PlannerStatus.EXACT_SOLUTION else None
        run.benchmark = _with_progress(run.benchmark, sampler.rows(), elapsed, final)
    return run


def _car_stages(ctx: PlanningContext, stages: dict[str, Any]) -> dict[str, Any]:
    """A car's stage paths as the plane's are read: ``rrt_path`` and ``seed_path`` (poses
    ``x, y, yaw`` outside the plane) become their curves' chord polylines, the poses kept as
    ``rrt_poses`` and ``seed_poses``."""
    if ctx.car is None:
        return stages
    for key in ("rrt_path", "seed_path"):
        poses = np.asarray(stages.get(key) or [], dtype=float).reshape(-1, 3)
        if len(poses):
            stages[key.replace("_path", "_poses")] = poses.tolist()
            stages[key] = ctx.car.polyline(poses)[:, :2].tolist()
    return stages


def _car_path(ctx: PlanningContext) -> dict[str, Any]:
    """A car's returned path as what drives it: its waypoint poses ``(x, y, yaw)`` (units,
    rad), the heading at each point of the reported polyline (``path_yaw``, rad) and its
    curves' figures (the curve's length by the space's distance, its turning
    radius, whether it backs, the chords' sagitta)."""
    path = ctx.ss.getProblemDefinition().getSolutionPath()
    car = ctx.car
    poses = car.path_poses(path)
    return {"poses": poses.tolist(), "path_yaw": car.polyline(poses)[:, 2].tolist(),
            "car": {"space": "Reeds-Shepp" if car.reverse else "Dubins",
                    "turning_radius": car.rho, "curve_length": float(path.length()),
                    "sagitta": car.sagitta}}  # fmt: skip


def _post_passes(ctx: PlanningContext, request: PlannerRequest, run: _Run, simplify: bool) -> None:
    """Step 4: the post-passes on an exact path, within the time limit (or OMPL's simplifier
    after it, as OMPL's Benchmark does, when asked and there are none)."""
    from .post import run_post

    if not ctx.ss.haveExactSolutionPath():
        return
    if request.post:
        path = ctx.ss.getProblemDefinition().getSolutionPath()
        deadline = run.t0 + request.time_limit
        done = run_post(ctx.si, path, request.post, deadline, values=dict(request.post_params),
                        objective=_inflation_objective(ctx))  # fmt: skip
        run.benchmark = _with_post(run.benchmark, done)
        run.spent += sum(d.time for d in done)
        run.stages["post"] = [d.to_dict() for d in done]
    elif simplify:
        run.benchmark, simplification = _simplify(ctx, run.benchmark, run.raw)
        run.stages.update(simplification)


def _inflation_objective(ctx: PlanningContext) -> Any:
    """The problem's objective when it is more than the length (None: the length)."""
    from ..ompl_setup import InflationObjective

    return ctx.objective if isinstance(ctx.objective, InflationObjective) else None


def _validated_path(ctx: PlanningContext, code: Any) -> tuple[np.ndarray, str]:
    """Step 5: the returned path if it passes the exact check, with its status; no path and
    ``"none"`` otherwise (a path that fails the check is never returned)."""
    from ompl import base as ob

    verdicts = {ob.PlannerStatus.EXACT_SOLUTION: "exact",
                ob.PlannerStatus.APPROXIMATE_SOLUTION: "approximate"}  # fmt: skip
    pdef = ctx.ss.getProblemDefinition()
    path = ctx.polyline(pdef.getSolutionPath()) if pdef.hasSolution() else np.empty((0, 2))
    if code not in verdicts or not (len(path) and ctx.polyline_valid(path)):
        return np.empty((0, 2)), "none"
    return path, verdicts[code]


def _result(
    request: PlannerRequest,
    ctx: PlanningContext,
    instance: Any,
    run: _Run,
    path: np.ndarray,
    status: str,
) -> SolveResult:
    """Step 6: the typed result."""
    return SolveResult(
        problem=request.problem.name,
        planner=request.label,
        status=status,
        ompl_status=str(run.status),
        length=_length(path),
        time=run.spent,
        seed=request.seed,
        path=path,
        time_limit=request.time_limit,
        params=_applied(instance, request.values),
        stages=run.stages,
        clearance=ctx.world.path_clearance(path) - ctx.world.robot_radius if len(path) else None,
        cost=request.problem.objective.path_cost(ctx.world, path) if len(path) else None,
        benchmark=run.benchmark,
    )


def _length(path: np.ndarray | None) -> float | None:
    return path_length(path) if path is not None and len(path) else None


def _applied(instance: Any, values: dict[str, Any]) -> dict[str, Any]:
    """The parameters as the planner holds them (ours: every one, defaults included)."""
    own = getattr(instance, "get_params", None)
    return own() if callable(own) else dict(values)


def _simplify(
    ctx: PlanningContext, run: BenchmarkRun, raw: np.ndarray
) -> tuple[BenchmarkRun, dict[str, Any]]:
    """OMPL's simplifier after the planner, as in OMPL's Benchmark (timed separately)."""
    from ..ompl_setup import assign_path, path_to_array
    from ..ompl_setup.objective import path_cost

    t1 = time.perf_counter()
    path = ctx.ss.getProblemDefinition().getSolutionPath()
    objective = _inflation_objective(ctx)
    if objective is not None:
        before = path_to_array(path), path_cost(objective, path)
    ctx.ss.simplifySolution()
    if objective is not None and path_cost(objective, path) > before[1]:
        assign_path(ctx.si, path, before[0])  # the simplifier raised the objective: undone
    seconds = time.perf_counter() - t1
    length = path_length(ctx.polyline(path))
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
        "unsimplified_valid": bool(ctx.polyline_valid(raw)),
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
