"""The conformance kit's checks on the plane's simple problem: solved, valid, never dearer,
within the deadline, solved again after ``clear()``, its parameters, its benchmark run."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np

from ..errors import ParameterError
from ..model.geometry import path_length
from ..model.problem import Problem
from ..planners.registry import PlannerEntry, PlannerRegistry
from ..planners.request import resolve
from ..planners.result import BenchmarkRun
from .cases import (
    BUDGET,
    DEADLINE_FACTOR,
    DEADLINE_SLACK,
    RTOL,
    TINY_BUDGET,
    case_of,
    check_path,
    direct_run,
    out_of_range,
    planner_with_params,
    refused,
    run_result,
    solved_result,
)


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
    case = case_of(entry, problem, budget, seed, registry)
    solved_result(case)


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
    case = case_of(entry, problem, budget, seed, registry)
    direct = direct_run(case)
    for i, (status, xy) in enumerate(zip(direct.statuses[:2], direct.paths[:2], strict=True)):
        which = ("first solve", "solve after clear()")[i]
        assert status == "Exact solution", f"{case.name}: {which}: no exact path ({status})"
        check_path(case, xy, which)
    if direct.statuses[2] == "Exact solution":  # no time at all is no excuse for a wrong path
        check_path(case, direct.paths[2], "solve with an expired termination condition")


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
    case = case_of(entry, problem, budget, seed, registry)
    result = solved_result(case)
    rows = result.benchmark.progress
    assert rows, f"{case.name}: a solved run has no progress rows (the final path is one)"
    for (t0, c0), (t1, c1) in itertools.pairwise(rows):
        assert c1 <= c0 * (1 + RTOL), (f"{case.name}: the best cost rose from {c0:.6g} at "
                                        f"{t0:.3f} s to {c1:.6g} at {t1:.3f} s")  # fmt: skip
    own = result.benchmark.solution_length
    assert own is not None, f"{case.name}: the benchmark run has no solution length"
    assert result.length <= own * (1 + RTOL), (
        f"{case.name}: the returned path ({result.length:.6g}) is longer than the planner's own "
        f"({own:.6g})"
    )
    seed_path = result.stages.get("seed_path")
    if seed_path:  # a planner that optimises a seed path (RRTstarPSO) names it
        start = path_length(np.asarray(seed_path, dtype=float))
        assert result.length <= start * (1 + RTOL), (
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
    case = case_of(entry, problem, budget, seed, registry)
    tiny = case_of(entry, problem, TINY_BUDGET, seed, registry)

    def within(what: str, limit: float, seconds: float) -> None:
        allowed = DEADLINE_FACTOR * limit + DEADLINE_SLACK
        assert seconds <= allowed, (f"{case.name}: {what} took {seconds:.3f} s for a {limit:g} s "
                                    f"budget (allowed {allowed:.3f} s)")  # fmt: skip

    within("solve()", budget, run_result(case).time)
    direct = direct_run(case)
    for i, seconds in enumerate(direct.times[:2]):
        within(f"ss.solve() #{i + 1}", budget, seconds)
    within("ss.solve() with an expired termination condition", 0.0, direct.times[2])
    within("solve() with the tiny budget", TINY_BUDGET, run_result(tiny).time)


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
    case = case_of(entry, problem, budget, seed, registry)
    direct = direct_run(case)
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
    case = case_of(entry, problem, budget, seed, registry)
    e = case.entry
    defaults = e.params.defaults()
    for spec in e.params:
        assert spec.convert(spec.default) == spec.default, (
            f"{case.name}: the default of {spec.name!r} ({spec.default!r}) is not a value of its "
            f"own declaration ({spec.range_text()})"
        )
    assert e.validate(defaults) == defaults, f"{case.name}: its defaults break one of its rules"
    bad = [({"no_such_parameter": 1}, "no_such_parameter")]
    bad += [({spec.name: value}, spec.name) for spec in e.params for value in out_of_range(spec)]
    planner, _ctx = planner_with_params(case)  # the context lives as long as the planner
    for values, name in bad:
        refused(case, f"entry.validate({values})", name, lambda v=values: e.validate(v))
        refused(case, f"resolve(params={values})", name,
                 lambda v=values: resolve(case.problem, e.name, params=v,
                                          registry=case.registry))  # fmt: skip
        if planner is not None:
            before = planner.get_params()
            refused(case, f"set_params(**{values})", name,
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
    case = case_of(entry, problem, budget, seed, registry)
    result = solved_result(case)
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
