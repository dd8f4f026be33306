"""The planner conformance kit: the checks every planner must pass, whoever wrote it.

As scikit-learn ships ``check_estimator`` and ``parametrize_with_checks`` and OMPL tests each of
its planners with ``tests/base/PlannerTest.h``, this module checks a planner's registry entry
(:class:`~rrtpso_ompl.planners.PlannerEntry`, or a registered name) on a simple problem with real
OMPL, one property per check:

========================  =================================================================
:func:`check_solves`      an exact path within the budget (a planner that never finds one
                          fails: no check passes by skipping)
:func:`check_valid_path`  the planner's own path (before any check of the harness) is valid by
                          the exact world check and runs from the start to the goal (also
                          after an expired termination condition, if it reports one)
:func:`check_cost_never_rises`
                          the best-cost samples never increase, and the returned path is no
                          longer than the planner's own first path (RRTstarPSO: its RRT* path)
                          or the seed path its stats name
:func:`check_deadline`    every solve returns within ``1.5 x budget + 1 s``, and one whose
                          termination condition has already fired within ``1 s``
:func:`check_clear_and_solve_again`
                          ``solve``, ``clear()``, ``solve`` again: exact both times; an already
                          expired termination condition returns without a crash
:func:`check_parameters`  defaults within their declared ranges; an unknown name and every
                          value out of range refused with a ``ParameterError``, by the entry,
                          by :func:`~rrtpso_ompl.planners.request.resolve` and by the planner's
                          own ``set_params`` (which then changes nothing)
:func:`check_benchmark_run`
                          the stats' run in OMPL's terms is well formed: its times and lengths
                          add up to the solve's, its properties are typed, it survives JSON
:func:`check_other_spaces`
                          never a wrong answer in a user's own ``og.SimpleSetup`` on spaces the
                          planner may not support (R^3, R^6, SE(2), Reeds-Shepp): it
                          refuses (an exception before ``solve``, or a status without a path),
                          or every path it leaves starts at the start, is valid by the user's
                          checker along every motion and, if exact, ends in the goal (and
                          is no longer than the seed its stats name, as RRTstarPSO's do)
========================  =================================================================

Each check is a plain function ``check(entry_or_name, *, problem=None, budget=BUDGET, seed=1,
registry=None)`` that raises ``AssertionError`` with a message naming the planner and the
property. :func:`check_planner` runs them all; :func:`parametrize_with_checks` makes them pytest
cases::

    from rrtpso_ompl.testing import parametrize_with_checks

    @parametrize_with_checks(["MyPlanner"])
    def test_my_planner(entry, check):
        check(entry)

The deadline's tolerance is generous on purpose: the project's promise is 5 % (measured by the
benchmarks on a quiet machine, never by a test); a test on a shared, loaded machine can be
descheduled for a good part of a second, and the planner's last iteration and the exact check
after it stretched with it. ``1.5 x budget + 1 s`` absorbs that, and still fails a planner that
ignores its termination condition: one that runs a fixed amount of work, or waits for a solution
that does not come. The mechanism itself is checked as OMPL's ``PlannerTest`` does: a solve
whose condition has already fired must return at once (within the same ``1 s``). Solves the
checks share (the same entry, problem, budget and seed) run once per process.
"""

from __future__ import annotations

import functools
import itertools
import json
import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import ParameterError
from .model.geometry import path_length
from .model.problem import Problem, problem_from_dict
from .planners.registry import PlannerEntry, PlannerRegistry, default_registry
from .planners.request import resolve
from .planners.result import BenchmarkRun, SolveResult
from .planners.solve import solve

__all__ = [
    "BUDGET",
    "CHECKS",
    "DEADLINE_FACTOR",
    "DEADLINE_SLACK",
    "OTHER_SPACES",
    "OTHER_SPACES_BUDGET",
    "SIMPLE_PROBLEM",
    "TINY_BUDGET",
    "check_benchmark_run",
    "check_clear_and_solve_again",
    "check_cost_never_rises",
    "check_deadline",
    "check_other_spaces",
    "check_parameters",
    "check_planner",
    "check_solves",
    "check_valid_path",
    "parametrize_with_checks",
    "simple_problem",
]

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
_RTOL = 1e-9
#: The spaces of :func:`check_other_spaces`: a user's own ``og.SimpleSetup`` in each. Not
#: Dubins: there OMPL's own BKPIECE1, LBKPIECE1, KPIECE1, PRM and PRMstar return paths that
#: OMPL's own ``PathGeometric.check()`` rejects (measured: up to 10 of 10 runs; they check some
#: motions in the other direction, or end a motion part-way, which on a Dubins curve is another
#: curve), so the check would report OMPL's fault, not the planner's under test.
OTHER_SPACES = ("R^3", "R^6", "SE(2)", "Reeds-Shepp")
#: Seconds per solve in :func:`check_other_spaces`: OMPL's planners find a path in each of its
#: spaces in milliseconds; one that finds none in time passes all the same (the property is
#: "never a wrong answer", not speed).
OTHER_SPACES_BUDGET = 0.1


@functools.cache
def simple_problem() -> Problem:
    """:data:`SIMPLE_PROBLEM` as a :class:`~rrtpso_ompl.model.Problem` (one per process)."""
    return problem_from_dict(SIMPLE_PROBLEM, source="<conformance>")


# ----------------------------------------------------------------------------------------------
# The checks
# ----------------------------------------------------------------------------------------------
def check_solves(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """An exact, valid path for the problem within ``budget`` seconds (through
    :func:`~rrtpso_ompl.planners.solve`)."""
    case = _case(entry, problem, budget, seed, registry)
    _solved(case)


def check_valid_path(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """The paths the planner itself leaves in the problem definition (before the harness checks
    them) pass the exact world check, start at the start and end at the goal, and are no
    shorter than the straight line."""
    case = _case(entry, problem, budget, seed, registry)
    direct = _direct(case)
    for i, (status, xy) in enumerate(zip(direct.statuses[:2], direct.paths[:2], strict=True)):
        which = ("first solve", "solve after clear()")[i]
        assert status == "Exact solution", f"{case.name}: {which}: no exact path ({status})"
        _check_path(case, xy, which)
    if direct.statuses[2] == "Exact solution":  # no time at all is no excuse for a wrong path
        _check_path(case, direct.paths[2], "solve with an expired termination condition")


def check_cost_never_rises(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """The best-cost samples of the solve (the planner's own or sampled, then its final path)
    never increase; the returned path is no longer than the planner's own path before its
    simplification stage (RRTstarPSO: RRT*'s path) nor than the seed path its stats name."""
    case = _case(entry, problem, budget, seed, registry)
    result = _solved(case)
    rows = result.benchmark.progress
    assert rows, f"{case.name}: a solved run has no progress rows (the final path is one)"
    for (t0, c0), (t1, c1) in itertools.pairwise(rows):
        assert c1 <= c0 * (1 + _RTOL), (f"{case.name}: the best cost rose from {c0:.6g} at "
                                        f"{t0:.3f} s to {c1:.6g} at {t1:.3f} s")  # fmt: skip
    own = result.benchmark.solution_length
    assert own is not None, f"{case.name}: the benchmark run has no solution length"
    assert result.length <= own * (1 + _RTOL), (
        f"{case.name}: the returned path ({result.length:.6g}) is longer than the planner's own "
        f"({own:.6g})"
    )
    seed_path = result.stages.get("seed_path")
    if seed_path:  # a planner that optimises a seed path (RRTstarPSO) names it
        start = path_length(np.asarray(seed_path, dtype=float))
        assert result.length <= start * (1 + _RTOL), (
            f"{case.name}: the returned path ({result.length:.6g}) is longer than the seed path "
            f"it was made from ({start:.6g})"
        )


def check_deadline(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """Every solve returns within ``DEADLINE_FACTOR x budget + DEADLINE_SLACK`` seconds: the
    solves at ``budget`` (through :func:`~rrtpso_ompl.planners.solve` and directly in OMPL), one
    at :data:`TINY_BUDGET`, and one whose termination condition has already fired (budget 0:
    within ``DEADLINE_SLACK``). Each is checked as soon as it has run (a planner that ignores its
    condition fails at its first solve, not after all of them)."""
    case = _case(entry, problem, budget, seed, registry)
    tiny = _case(entry, problem, TINY_BUDGET, seed, registry)

    def within(what: str, limit: float, seconds: float) -> None:
        allowed = DEADLINE_FACTOR * limit + DEADLINE_SLACK
        assert seconds <= allowed, (f"{case.name}: {what} took {seconds:.3f} s for a {limit:g} s "
                                    f"budget (allowed {allowed:.3f} s)")  # fmt: skip

    within("solve()", budget, _result(case).time)
    direct = _direct(case)
    for i, seconds in enumerate(direct.times[:2]):
        within(f"ss.solve() #{i + 1}", budget, seconds)
    within("ss.solve() with an expired termination condition", 0.0, direct.times[2])
    within("solve() with the tiny budget", TINY_BUDGET, _result(tiny).time)


def check_clear_and_solve_again(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """As OMPL's ``PlannerTest::testSolveAndClear``: solve, ``clear()``, solve again (exact both
    times), then ``clear()`` and a termination condition that has already fired: the planner
    returns at once, without a crash or an exception."""
    case = _case(entry, problem, budget, seed, registry)
    direct = _direct(case)
    first, again, expired = direct.statuses
    assert first == "Exact solution", f"{case.name}: the first solve found no exact path ({first})"
    assert again == "Exact solution", (f"{case.name}: after clear(), the planner found no exact "
                                       f"path ({again})")  # fmt: skip
    assert expired != "Crash", (
        f"{case.name}: with an expired termination condition the planner reported {expired!r}"
    )


def check_parameters(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """Every default lies in its declared range; an unknown name and every value out of range
    are refused with a ``ParameterError`` by the entry, by
    :func:`~rrtpso_ompl.planners.request.resolve` (naming where the value came from) and by the
    planner's ``set_params`` when it has one (which then leaves its parameters as they were)."""
    case = _case(entry, problem, budget, seed, registry)
    e = case.entry
    defaults = e.params.defaults()
    for spec in e.params:
        assert spec.convert(spec.default) == spec.default, (
            f"{case.name}: the default of {spec.name!r} ({spec.default!r}) is not a value of its "
            f"own declaration ({spec.range_text()})"
        )
    assert e.validate(defaults) == defaults, f"{case.name}: its defaults break one of its rules"
    bad = [({"no_such_parameter": 1}, "no_such_parameter")]
    bad += [({spec.name: value}, spec.name) for spec in e.params for value in _out_of_range(spec)]
    planner, _ctx = _planner_with_params(case)  # the context lives as long as the planner
    for values, name in bad:
        _refused(case, f"entry.validate({values})", name, lambda v=values: e.validate(v))
        _refused(case, f"resolve(params={values})", name,
                 lambda v=values: resolve(case.problem, e.name, params=v,
                                          registry=case.registry))  # fmt: skip
        if planner is not None:
            before = planner.get_params()
            _refused(case, f"set_params(**{values})", name,
                     lambda v=values: planner.set_params(**v))  # fmt: skip
            assert planner.get_params() == before, (
                f"{case.name}: a refused set_params(**{values}) changed the parameters"
            )
    try:
        resolve(case.problem, e.name, params={"no_such_parameter": 1}, registry=case.registry)
    except ParameterError as exc:
        assert exc.origin == "params['no_such_parameter']", (
            f"{case.name}: resolve's error does not name where the value came from: {exc}"
        )


def check_benchmark_run(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """The run the planner's stats report in OMPL's terms adds up: planning plus simplification
    time is the whole solve (plus the harness's simplifier, when benchmarks run it), planning is
    part of it, the final length is the returned path's and no longer than the planner's own,
    progress times strictly increase and end at the solve's end, run properties are typed as
    OMPL's log wants, and the run and the result survive JSON."""
    case = _case(entry, problem, budget, seed, registry)
    result = _solved(case)
    run, name = result.benchmark, case.name
    harness = case.entry.capabilities.simplify_in_benchmark
    extra = result.stages.get("simplification_time", 0.0) if harness else 0.0
    assert run.time > 0, f"{name}: the logged planning time is {run.time}"
    assert math.isclose(run.total_time, result.time + extra, abs_tol=1e-9), (
        f"{name}: time + simplification time = {run.total_time:.6f} s, but the solve took "
        f"{result.time + extra:.6f} s"
    )
    assert run.time <= result.time + 1e-9, (
        f"{name}: the logged planning time ({run.time:.6f} s) exceeds the solve's "
        f"({result.time:.6f} s)"
    )
    final = run.simplified_length if run.simplification_time is not None else run.solution_length
    assert final is not None and math.isclose(final, result.length, rel_tol=1e-12), (
        f"{name}: the logged final length {final} is not the returned path's {result.length}"
    )
    times = [t for t, _ in run.progress]
    assert all(b > a for a, b in itertools.pairwise(times)), (
        f"{name}: progress times do not strictly increase: {times}"
    )
    assert times and math.isclose(times[-1], result.time, abs_tol=1e-6), (
        f"{name}: the last progress row is at {times[-1] if times else None} s, the solve "
        f"ended at {result.time} s"
    )
    kinds = {"INTEGER": int, "REAL": (int, float), "BOOLEAN": bool}
    for key, (kind, value) in run.properties.items():
        assert kind in kinds, f"{name}: run property {key!r} has type {kind!r} (not OMPL's)"
        ok = isinstance(value, kinds[kind]) and (kind == "BOOLEAN" or not isinstance(value, bool))
        assert ok, f"{name}: run property {key!r} is {kind} but holds {value!r}"
    assert BenchmarkRun.from_dict(json.loads(json.dumps(run.to_dict()))) == run, (
        f"{name}: the benchmark run does not survive JSON"
    )
    json.dumps(result.to_dict())  # raises for a value JSON cannot hold (stages included)


def check_other_spaces(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """Never a wrong answer in a user's own ``og.SimpleSetup`` on a space the planner may not
    support: each of :data:`OTHER_SPACES`, bounds ``[0, 10]`` on every axis (SE(2): ``x``,
    ``y``), a ball of radius 2 at the centre across the straight line from start
    ``(1, ..., 1)`` to goal ``(9, ..., 9)`` (SE(2): yaw 0 at both), a Python validity checker
    and :data:`OTHER_SPACES_BUDGET` seconds.

    The planner may refuse: an exception from its construction or ``setup()`` (before any
    solve), or a status with no path in the problem definition. An exception from ``solve``
    fails (it would end a whole OMPL Benchmark). Every path the problem definition holds must
    start at the start and be valid at each of its states and along each motion, by the user's
    checker on states from the space's own ``interpolate`` at the space's resolution (the states
    OMPL's own motion validators check, so a planner OMPL accepts passes by property); an exact
    one must end in the goal (``goal.isSatisfied``), and an exact status needs an exact path.
    A planner whose stats name the length of the path it was seeded from (``seed_length``, as
    RRTstarPSO's do in these spaces) must return an exact path no longer than that, by the
    space's own distance.

    The objective's cost threshold is infinite, so optimizing planners stop at their first path
    (this checks answers, not their quality). ``problem`` and ``budget`` are not used (the
    planner's parameters are those it gets for the simple problem, at this budget).
    """
    case = _case(entry, problem, budget, seed, registry)
    failures = [f for kind in OTHER_SPACES if (f := _other_space_failure(case, kind))]
    assert not failures, "\n".join(failures)


#: Every check, in the order :func:`check_planner` runs them.
CHECKS: tuple[Callable[..., None], ...] = (
    check_solves,
    check_valid_path,
    check_cost_never_rises,
    check_deadline,
    check_clear_and_solve_again,
    check_parameters,
    check_benchmark_run,
    check_other_spaces,
)


def check_planner(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """Run every check of :data:`CHECKS` on a planner.

    Parameters
    ----------
    entry : PlannerEntry or str
        The planner's registry entry (registered or not), or a registered name.
    problem : Problem, optional
        What to solve; :func:`simple_problem` when omitted (one round obstacle across the
        straight line). A planner meant for other problems passes one it should solve.
    budget : float
        Seconds per solve.
    seed : int
        OMPL's seed (applied before the solve) and the planner's.
    registry : PlannerRegistry, optional
        Where to look a name up; the default registry when omitted.

    Raises
    ------
    AssertionError
        Listing every check that failed, each with its message.
    """
    failures = []
    for check in CHECKS:
        try:
            check(entry, problem=problem, budget=budget, seed=seed, registry=registry)
        except AssertionError as exc:
            failures.append(f"{check.__name__}: {exc}")
    if failures:
        raise AssertionError("\n".join(failures))


def parametrize_with_checks(
    planners: Iterable[PlannerEntry | str],
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> Any:
    """A ``pytest.mark.parametrize`` of every planner x every check, as scikit-learn's.

    The test takes ``entry`` and ``check`` and calls ``check(entry)``; the options given here
    are bound to each check. Case ids read ``RRTstarPSO-check_solves``.

    Examples
    --------
    >>> @parametrize_with_checks(["RRTstarPSO", "RRTConnect"], budget=0.2)  # doctest: +SKIP
    ... def test_planner(entry, check):
    ...     check(entry)
    """
    import pytest

    cases, ids = [], []
    for item in planners:
        entry = _entry(item, registry)
        for check in CHECKS:
            bound = functools.partial(check, problem=problem, budget=budget, seed=seed,
                                      registry=registry)  # fmt: skip
            cases.append((entry, bound))
            ids.append(f"{entry.name}-{check.__name__}")
    return pytest.mark.parametrize(("entry", "check"), cases, ids=ids)


# ----------------------------------------------------------------------------------------------
# The runs the checks share
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class _Case:
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
class _Direct:
    """The planner run in OMPL directly: each ``ss.solve``'s status text, the path it left
    (``(n, 2)``, empty for none) and the seconds it took (the two timed solves, then the one
    with an expired condition)."""

    statuses: tuple[str, ...]
    paths: tuple[np.ndarray, ...]
    times: tuple[float, ...]


#: Runs already made in this process: key -> (entry, problem, value); the entry and problem are
#: kept so that their ids, part of the key, cannot be reused by other objects.
_RUNS: dict[tuple[Any, ...], tuple[Any, Any, Any]] = {}


def _memo(kind: str, case: _Case, make: Callable[[], Any]) -> Any:
    key = (kind, *case.key)
    if key not in _RUNS:
        _RUNS[key] = (case.entry, case.problem, make())
    return _RUNS[key][2]


def _entry(item: PlannerEntry | str, registry: PlannerRegistry | None) -> PlannerEntry:
    if isinstance(item, PlannerEntry):
        return item
    return (registry or default_registry()).get(item)


def _case(
    item: PlannerEntry | str,
    problem: Problem | None,
    budget: float,
    seed: int,
    registry: PlannerRegistry | None,
) -> _Case:
    entry = _entry(item, registry)
    registry = registry or default_registry()
    if entry.name not in registry or registry.get(entry.name) is not entry:
        registry = _own_registry(entry)
    return _Case(entry, problem or simple_problem(), budget, seed, registry)


@functools.cache
def _own_registry(entry: PlannerEntry) -> PlannerRegistry:
    """A registry of one planner that is not registered (a plugin under test)."""
    registry = PlannerRegistry()
    registry.register(entry)
    return registry


def _result(case: _Case) -> SolveResult:
    """The solve through :func:`~rrtpso_ompl.planners.solve`, with progress, simplified after
    the budget when benchmarks would simplify it (as ``rrtpso bench`` runs it)."""

    def run() -> SolveResult:
        return solve(case.problem, case.name, time_limit=case.budget, seed=case.seed,
                     simplify=case.entry.capabilities.simplify_in_benchmark, progress=True,
                     registry=case.registry)  # fmt: skip

    return _memo("solve", case, run)


def _solved(case: _Case) -> SolveResult:
    result = _result(case)
    said_exact = result.ompl_status == "Exact solution"
    rejected = ", but the path failed the exact check" if said_exact else ""
    assert result.solved, (
        f"{case.name} found no exact path in {case.budget:g} s on {case.problem.name!r} (status "
        f"{result.status!r}; OMPL said {result.ompl_status!r}{rejected})"
    )
    return result


def _direct(case: _Case) -> _Direct:
    """OMPL's ``PlannerTest`` sequence in a setup of this package: solve; clear, solve; clear,
    solve with an expired condition."""

    def run() -> _Direct:
        from ompl import base as ob

        from .ompl_setup import make_context, path_to_array, seed_ompl

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
        return _Direct(tuple(statuses), tuple(paths), tuple(times))

    return _memo("direct", case, run)


@dataclass(frozen=True)
class _Scene:
    """A space of :func:`check_other_spaces` with its ball and a user's Python checker.

    ``dim`` coordinates are bounded by ``[0, 10]`` and measured from the ball's centre (SE(2)
    and Reeds-Shepp, turning radius 1: ``x`` and ``y``; the yaw is free)."""

    kind: str
    space: Any
    dim: int
    se2: bool

    @classmethod
    def make(cls, kind: str) -> _Scene:
        from ompl import base as ob

        if kind.startswith("R^"):
            n = int(kind[2:])
            return cls(kind, ob.RealVectorStateSpace(n), n, False)
        space = ob.SE2StateSpace() if kind == "SE(2)" else ob.ReedsSheppStateSpace(1.0)
        return cls(kind, space, 2, True)

    def bound(self) -> None:
        from ompl import base as ob

        bounds = ob.RealVectorBounds(self.dim)
        bounds.setLow(0.0)
        bounds.setHigh(10.0)
        self.space.setBounds(bounds)

    def coords(self, state: Any) -> list[float]:
        """The state's coordinates (copied: OMPL's states are borrowed)."""
        if self.se2:
            return [state.getX(), state.getY(), state.getYaw()]
        return [state[i] for i in range(self.dim)]

    def state(self, value: float) -> Any:
        """A state with every bounded coordinate ``value`` (and yaw 0)."""
        s = self.space.allocState()
        if self.se2:
            s.setXY(value, value)
            s.setYaw(0.0)
        else:
            for i in range(self.dim):
                s[i] = value
        return s

    def valid(self, state: Any) -> bool:
        """The user's checker: inside the bounds and outside the ball of radius 2 at 5."""
        xs = (state.getX(), state.getY()) if self.se2 else [state[i] for i in range(self.dim)]
        inside = all(0.0 <= x <= 10.0 for x in xs)
        return inside and sum((x - 5.0) ** 2 for x in xs) > 4.0


def _other_space_failure(case: _Case, kind: str) -> str | None:
    """The planner in a user's own setup of ``kind``: what it got wrong, or None."""
    from ompl import base as ob
    from ompl import geometric as og

    from .ompl_setup import seed_ompl

    name, where = case.name, f"{case.name} in a user's {kind} SimpleSetup"
    request = resolve(case.problem, name, time_limit=OTHER_SPACES_BUDGET, seed=case.seed,
                      registry=case.registry)  # fmt: skip
    seed_ompl(request.seed)
    scene = _Scene.make(kind)
    scene.bound()
    ss = og.SimpleSetup(scene.space)
    ss.setStateValidityChecker(scene.valid)
    start, goal = scene.state(1.0), scene.state(9.0)
    ss.setStartAndGoalStates(start, goal)
    si = ss.getSpaceInformation()
    objective = ob.PathLengthOptimizationObjective(si)
    objective.setCostThreshold(ob.Cost(math.inf))  # any path will do: stop at the first
    ss.setOptimizationObjective(objective)
    try:
        ss.setPlanner(planner := request.entry.make(si, request.values))
        ss.setup()
    except Exception:  # refused before any solve: no answer, so no wrong one
        return None
    try:
        status = ss.solve(ob.timedPlannerTerminationCondition(OTHER_SPACES_BUDGET))
    except Exception as exc:
        return (f"{where}: solve() raised {exc!r} (refuse at setup(), or return a failed "
                f"status: an exception out of solve() ends a whole OMPL Benchmark)")  # fmt: skip
    pdef = ss.getProblemDefinition()
    said_exact = status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    if said_exact and not pdef.hasExactSolution():
        return f"{where}: reported {str(status)!r}, but holds no exact path"
    if not pdef.hasSolution():
        return None
    exact = not pdef.hasApproximateSolution()
    path = pdef.getSolutionPath()
    wrong = _other_path_wrong(scene, si, pdef, path, start, exact)
    seed_length = getattr(getattr(planner, "last_stats", None), "seed_length", None)
    longer = seed_length is not None and path.length() > seed_length * (1 + _RTOL) + 1e-12
    if wrong is None and exact and longer:  # by the space's own distance
        wrong = f"its length {path.length():.6g} exceeds its stats' seed_length {seed_length:.6g}"
    if wrong is None:
        return None
    what = "exact" if exact else "approximate"
    return f"{where}: reported {str(status)!r} with a wrong {what} path: {wrong}"


def _other_path_wrong(
    scene: _Scene, si: Any, pdef: Any, path: Any, start: Any, exact: bool
) -> str | None:
    """What is wrong with a path of :func:`check_other_spaces`, or None."""
    space = scene.space
    states = path.getStates()
    if not states:
        return "it has no states"
    tol = 1e-9 * max(si.getMaximumExtent(), 1.0)
    if space.distance(states[0], start) > tol:
        return (f"it starts at {_fmt(scene.coords(states[0]))}, not at the start "
                f"{_fmt(scene.coords(start))}")  # fmt: skip
    if exact and not pdef.getGoal().isSatisfied(states[-1]):
        return f"it ends at {_fmt(scene.coords(states[-1]))}, which is not in the goal"
    for i, s in enumerate(states):
        if not scene.valid(s):
            return f"its state {i}, {_fmt(scene.coords(s))}, is invalid by the user's checker"
    probe = space.allocState()
    for i, (a, b) in enumerate(itertools.pairwise(states)):
        n = space.validSegmentCount(a, b)
        for j in range(1, n):
            space.interpolate(a, b, j / n, probe)
            if not scene.valid(probe):
                return (f"its motion {i} from {_fmt(scene.coords(a))} to "
                        f"{_fmt(scene.coords(b))} passes through {_fmt(scene.coords(probe))}, "
                        f"invalid by the user's checker")  # fmt: skip
    return None


def _fmt(xs: Iterable[float]) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in xs) + ")"


def _check_path(case: _Case, xy: np.ndarray, which: str) -> None:
    from .model.world import World

    problem, name = case.problem, case.name
    world = World.from_problem(problem)
    assert len(xy) >= 2, f"{name}: {which}: the path has {len(xy)} waypoint(s)"
    assert world.path_valid(xy), (f"{name}: {which}: the path collides or leaves the bounds "
                                  f"(exact check with the robot's radius)")  # fmt: skip
    assert np.allclose(xy[0], problem.start, rtol=0, atol=world.tol), (
        f"{name}: {which}: the path starts at {xy[0].tolist()}, not at the start {problem.start}"
    )
    reach = max(problem.goal_tolerance, world.tol)
    assert math.dist(xy[-1], problem.goal) <= reach * (1 + _RTOL), (
        f"{name}: {which}: the path ends at {xy[-1].tolist()}, not within {reach:g} of the goal "
        f"{problem.goal}"
    )
    straight = math.dist(problem.start, problem.goal) - problem.goal_tolerance
    assert path_length(xy) >= straight * (1 - _RTOL), (
        f"{name}: {which}: the path ({path_length(xy):.6g}) is shorter than the straight line"
    )


def _out_of_range(spec: Any) -> list[Any]:
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


def _planner_with_params(case: _Case) -> tuple[Any, Any]:
    """The planner made in a setup of the problem when it has ``set_params`` (else None), and
    the setup."""
    from .ompl_setup import make_context

    ctx = make_context(case.problem)
    planner = case.entry.make(ctx.si)
    return (planner if callable(getattr(planner, "set_params", None)) else None), ctx


def _refused(case: _Case, what: str, name: str, call: Callable[[], Any]) -> None:
    try:
        call()
    except ParameterError as exc:
        assert name in str(exc), f"{case.name}: {what} was refused without naming {name!r}: {exc}"
        return
    raise AssertionError(f"{case.name}: {what} was accepted; it must raise ParameterError")
