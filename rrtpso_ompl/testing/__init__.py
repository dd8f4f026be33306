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
:func:`check_car_problem`
                          never a wrong answer for a car's problem file: refused before
                          planning by a planner of the plane only, else no path or one from the
                          start pose to the goal pose whose curves pass the sound check
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
from collections.abc import Callable, Iterable
from typing import Any

from ..model.problem import Problem
from ..planners.registry import PlannerEntry, PlannerRegistry
from .cases import (
    BUDGET,
    DEADLINE_FACTOR,
    DEADLINE_SLACK,
    SIMPLE_PROBLEM,
    TINY_BUDGET,
    entry_of,
    simple_problem,
)
from .plane import (
    check_benchmark_run,
    check_clear_and_solve_again,
    check_cost_never_rises,
    check_deadline,
    check_parameters,
    check_solves,
    check_valid_path,
)
from .spaces import (
    CAR_PROBLEM,
    OTHER_SPACES,
    OTHER_SPACES_BUDGET,
    check_car_problem,
    check_other_spaces,
)

__all__ = [
    "BUDGET",
    "CAR_PROBLEM",
    "CHECKS",
    "DEADLINE_FACTOR",
    "DEADLINE_SLACK",
    "OTHER_SPACES",
    "OTHER_SPACES_BUDGET",
    "SIMPLE_PROBLEM",
    "TINY_BUDGET",
    "check_benchmark_run",
    "check_car_problem",
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
    check_car_problem,
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
        entry = entry_of(item, registry)
        for check in CHECKS:
            bound = functools.partial(check, problem=problem, budget=budget, seed=seed,
                                      registry=registry)  # fmt: skip
            cases.append((entry, bound))
            ids.append(f"{entry.name}-{check.__name__}")
    return pytest.mark.parametrize(("entry", "check"), cases, ids=ids)
