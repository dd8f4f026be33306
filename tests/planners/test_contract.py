"""Checks every registered planner passes, whoever wrote it (as scikit-learn's estimator checks).

A planner's figures are its own: the time and lengths its stats report for OMPL's benchmark log
must add up to what the harness measured, for every planner in the registry, so that no report
guesses a planner's kind from the keys of its statistics.
"""

from __future__ import annotations

import itertools

import pytest
from helpers import PROBLEMS

from rrtpso_ompl.model.problem import load_problem
from rrtpso_ompl.planners import BenchmarkRun, default_registry, solve

REGISTRY = default_registry()
PROBLEM = load_problem(PROBLEMS / "static" / "single_circle.yaml")
BUDGET = 0.2


@pytest.fixture(scope="module", params=REGISTRY.names())
def solved(request):
    entry = REGISTRY.get(request.param)
    simplify = entry.capabilities.simplify_in_benchmark
    result = solve(PROBLEM, entry.name, BUDGET, seed=1, simplify=simplify, progress=True)
    return entry, simplify, result


def test_a_returned_path_is_valid_and_solved_means_exact(solved):
    _, _, result = solved
    if result.solved:
        assert result.valid and result.status == "exact" and len(result.path) >= 2
        assert result.clearance is not None and result.clearance >= -1e-9
    else:
        assert result.length is None or result.status == "approximate"


def test_the_logged_time_is_the_planner_s_own(solved):
    """time + simplification time is the whole solve (plus the harness's simplifier, if any),
    never a fragment of it (the PSO baseline used to be logged with 0.0003 s)."""
    _, simplify, result = solved
    run: BenchmarkRun = result.benchmark
    assert run.time > 0
    harness = result.stages.get("simplification_time", 0.0) if simplify else 0.0
    assert run.total_time == pytest.approx(result.time + harness, abs=1e-9)
    assert run.time <= result.time + 1e-9


def test_the_logged_lengths_are_the_planner_s_own(solved):
    _, simplify, result = solved
    run = result.benchmark
    if not result.solved:
        return
    final = run.simplified_length if run.simplification_time is not None else run.solution_length
    assert final == pytest.approx(result.length, rel=1e-12)
    # Simplification never lengthens the planner's own path.
    assert run.solution_length is not None
    assert result.length <= run.solution_length + 1e-9
    if simplify:
        assert run.solution_length == pytest.approx(result.stages["unsimplified_length"])


def test_progress_rows_increase_in_time_and_end_at_the_planner_s_path(solved):
    _, _, result = solved
    rows = result.benchmark.progress
    if not result.solved:
        return
    times = [t for t, _ in rows]
    assert rows and all(b > a for a, b in itertools.pairwise(times))
    assert times[-1] == pytest.approx(result.time, abs=1e-6)


def test_every_default_is_within_its_declared_range():
    for entry in REGISTRY.entries():
        for spec in entry.params:
            assert spec.convert(spec.default) == spec.default, (entry.name, spec.name)
        assert entry.validate(entry.params.defaults()) == entry.params.defaults()
