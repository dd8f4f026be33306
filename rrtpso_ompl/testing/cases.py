"""The conformance kit's shared machinery: the simple problem and the budgets, a planner's
case (its entry, problem, budget, seed and registry), its memoised solves, and the path checks
the checks share."""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..model.geometry import path_length
from ..model.problem import Problem, problem_from_dict
from ..planners.registry import PlannerEntry, PlannerRegistry, default_registry
from ..planners.request import resolve
from ..planners.result import SolveResult
from ..planners.solve import solve

#: The simple problem: a 500 x 500 cm room, a disc robot (radius 28.5 cm) and one round
#: obstacle across the straight line from start to goal (the paper's single-obstacle case;
#: shortest path 647.45 cm). Every planner of this package solves it in a few milliseconds.
SIMPLE_PROBLEM = {
    "name": "conformance",
    "units": "cm",
    "bounds": [[0, 0], [500, 500]],
    "start": [20, 20],
    "goal": [450, 450],
    "robot": {"radius": 28.5},
    "obstacles": [{"type": "circle", "center": [250, 250], "radius": 80}],
}


#: Seconds per solve (generous for :data:`SIMPLE_PROBLEM`).
BUDGET = 0.5


#: Seconds of the deadline check's smallest budget.
TINY_BUDGET = 0.01


#: A solve may take ``DEADLINE_FACTOR x budget + DEADLINE_SLACK`` seconds, one with an expired
#: termination condition ``DEADLINE_SLACK`` (see the module's docstring for why so much: a
#: loaded machine must hold it).
DEADLINE_FACTOR = 1.5


DEADLINE_SLACK = 1.0


#: Round-off allowed when comparing lengths and costs (relative).
RTOL = 1e-9


@functools.cache
def simple_problem() -> Problem:
    """:data:`SIMPLE_PROBLEM` as a :class:`~rrtpso_ompl.model.Problem` (one per process)."""
    return problem_from_dict(SIMPLE_PROBLEM, source="<conformance>")


# ----------------------------------------------------------------------------------------------
# The runs the checks share
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Case:
    """A planner on a problem with a budget and a seed, and the registry it is found in."""

    entry: PlannerEntry
    problem: Problem
    budget: float
    seed: int
    registry: PlannerRegistry

    @property
    def name(self) -> str:
        return self.entry.name

    @property
    def key(self) -> tuple[Any, ...]:
        return (id(self.entry), id(self.problem), self.budget, self.seed)


@dataclass(frozen=True)
class Direct:
    """The planner run in OMPL directly: each ``ss.solve``'s status text, the path it left
    (``(n, 2)``, empty for none) and the seconds it took (the two timed solves, then the one
    with an expired condition)."""

    statuses: tuple[str, ...]
    paths: tuple[np.ndarray, ...]
    times: tuple[float, ...]


#: Runs already made in this process: key -> (entry, problem, value); the entry and problem are
#: kept so that their ids, part of the key, cannot be reused by other objects.
RUNS: dict[tuple[Any, ...], tuple[Any, Any, Any]] = {}


def memo(kind: str, case: Case, make: Callable[[], Any]) -> Any:
    key = (kind, *case.key)
    if key not in RUNS:
        RUNS[key] = (case.entry, case.problem, make())
    return RUNS[key][2]


def entry_of(item: PlannerEntry | str, registry: PlannerRegistry | None) -> PlannerEntry:
    if isinstance(item, PlannerEntry):
        return item
    return (registry or default_registry()).get(item)


def case_of(
    item: PlannerEntry | str,
    problem: Problem | None,
    budget: float,
    seed: int,
    registry: PlannerRegistry | None,
) -> Case:
    entry = entry_of(item, registry)
    registry = registry or default_registry()
    if entry.name not in registry or registry.get(entry.name) is not entry:
        registry = own_registry(entry)
    return Case(entry, problem or simple_problem(), budget, seed, registry)


@functools.cache
def own_registry(entry: PlannerEntry) -> PlannerRegistry:
    """A registry of one planner that is not registered (a plugin under test)."""
    registry = PlannerRegistry()
    registry.register(entry)
    return registry


def run_result(case: Case) -> SolveResult:
    """The solve through :func:`~rrtpso_ompl.planners.solve`, with progress, simplified after
    the budget when benchmarks would simplify it (as ``rrtpso bench`` runs it)."""

    def run() -> SolveResult:
        return solve(case.problem, case.name, time_limit=case.budget, seed=case.seed,
                     simplify=case.entry.capabilities.simplify_in_benchmark, progress=True,
                     registry=case.registry)  # fmt: skip

    return memo("solve", case, run)


def solved_result(case: Case) -> SolveResult:
    result = run_result(case)
    said_exact = result.ompl_status == "Exact solution"
    rejected = ", but the path failed the exact check" if said_exact else ""
    assert result.solved, (
        f"{case.name} found no exact path in {case.budget:g} s on {case.problem.name!r} (status "
        f"{result.status!r}; OMPL said {result.ompl_status!r}{rejected})"
    )
    return result


def direct_run(case: Case) -> Direct:
    """OMPL's ``PlannerTest`` sequence in a setup of this package: solve; clear, solve; clear,
    solve with an expired condition."""

    def run() -> Direct:
        from ompl import base as ob

        from ..ompl_setup import make_context, path_to_array, seed_ompl

        request = resolve(case.problem, case.name, time_limit=case.budget, seed=case.seed,
                          registry=case.registry)  # fmt: skip
        seed_ompl(request.seed)
        ctx = make_context(case.problem)
        ctx.ss.setPlanner(request.entry.make(ctx.si, request.values))
        ctx.ss.setup()
        statuses, paths, times = [], [], []
        for condition in ("timed", "timed", "expired"):
            ctx.ss.clear()
            ptc = (ob.timedPlannerTerminationCondition(case.budget) if condition == "timed"
                   else ob.plannerAlwaysTerminatingCondition())  # fmt: skip
            t0 = time.perf_counter()
            try:
                status = ctx.ss.solve(ptc)
            except Exception as exc:  # the check reports it
                raise AssertionError(f"{case.name}: solve() raised {exc!r}") from exc
            times.append(time.perf_counter() - t0)
            pdef = ctx.ss.getProblemDefinition()
            paths.append(path_to_array(pdef.getSolutionPath()) if pdef.hasSolution()
                         else np.empty((0, 2)))  # fmt: skip
            statuses.append(str(status))
        return Direct(tuple(statuses), tuple(paths), tuple(times))

    return memo("direct", case, run)


def fmt(xs: Iterable[float]) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in xs) + ")"


def check_path(case: Case, xy: np.ndarray, which: str) -> None:
    from ..model.world import World

    problem, name = case.problem, case.name
    world = World.from_problem(problem)
    assert len(xy) >= 2, f"{name}: {which}: the path has {len(xy)} waypoint(s)"
    assert world.path_valid(xy), (f"{name}: {which}: the path collides or leaves the bounds "
                                  f"(exact check with the robot's radius)")  # fmt: skip
    assert np.allclose(xy[0], problem.start, rtol=0, atol=world.tol), (
        f"{name}: {which}: the path starts at {xy[0].tolist()}, not at the start {problem.start}"
    )
    reach = max(problem.goal_tolerance, world.tol)
    assert math.dist(xy[-1], problem.goal) <= reach * (1 + RTOL), (
        f"{name}: {which}: the path ends at {xy[-1].tolist()}, not within {reach:g} of the goal "
        f"{problem.goal}"
    )
    straight = math.dist(problem.start, problem.goal) - problem.goal_tolerance
    assert path_length(xy) >= straight * (1 - RTOL), (
        f"{name}: {which}: the path ({path_length(xy):.6g}) is shorter than the straight line"
    )


def out_of_range(spec: Any) -> list[Any]:
    """Values the declaration of ``spec`` refuses: below and above its range, or not one of its
    choices."""
    if spec.type is bool:
        return ["maybe"]
    if spec.type is str:
        return [] if spec.choices is None else ["not-one-of-the-choices"]
    out = []
    if spec.low is not None:
        out.append(spec.low - 1)
    if spec.high is not None and math.isfinite(spec.high):
        out.append(spec.high + 1)
    return [spec.type(v) if spec.type is int else float(v) for v in out]


def planner_with_params(case: Case) -> tuple[Any, Any]:
    """The planner made in a setup of the problem when it has ``set_params`` (else None), and
    the setup."""
    from ..ompl_setup import make_context

    ctx = make_context(case.problem)
    planner = case.entry.make(ctx.si)
    return (planner if callable(getattr(planner, "set_params", None)) else None), ctx


def refused(case: Case, what: str, name: str, call: Callable[[], Any]) -> None:
    try:
        call()
    except ParameterError as exc:
        assert name in str(exc), f"{case.name}: {what} was refused without naming {name!r}: {exc}"
        return
    raise AssertionError(f"{case.name}: {what} was accepted; it must raise ParameterError")
