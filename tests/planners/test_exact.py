"""The Exact planner: the optimum by name, with its honest failures and its benchmark row."""

from __future__ import annotations

import json
import shutil
import sqlite3
import subprocess

import pytest
from helpers import PROBLEMS, rrtpso_exe
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.groundtruth.optimum import shortest_path
from rrtpso_ompl.model.problem import load_problem, problem_from_dict
from rrtpso_ompl.planners import default_registry, solve
from rrtpso_ompl.planners.baselines.exact import ExactPlanner


def test_registered_by_name():
    entry = default_registry().get("Exact")
    assert entry.name == "Exact" and "budget" in entry.params.names()
    assert not entry.capabilities.optimizing  # nothing to improve: it is the optimum


@pytest.mark.parametrize("name", ["single_circle", "polygon_map", "maze"])
def test_returns_the_optimum_as_a_valid_path(name):
    problem = load_problem(PROBLEMS / "static" / f"{name}.yaml")
    optimum = shortest_path(problem).length
    result = solve(problem, "Exact", time_limit=30.0, seed=1)
    assert result.solved and result.valid and result.status == "exact"
    # Arcs become circumscribed polygons: a hair longer than the optimum, never shorter.
    assert optimum - 1e-9 <= result.length <= optimum * (1 + 2e-4)
    assert result.stages["optimum_length"] == pytest.approx(optimum, rel=1e-12)
    row = result.benchmark
    assert row.time == pytest.approx(result.time, rel=0.5)
    assert row.solution_length == pytest.approx(result.length)
    assert row.simplification_time is None and row.progress == []
    assert "iterations" not in " ".join(row.properties)
    assert row.properties["graph nodes"][1] > 0


def test_proves_infeasible():
    walls = [{"type": "rectangle", "min": m, "max": x} for m, x in
             (([60, 60], [90, 62]), ([60, 88], [90, 90]), ([60, 60], [62, 90]),
              ([88, 60], [90, 90]))]  # fmt: skip
    problem = problem_from_dict({"name": "boxed", "bounds": [[0, 0], [100, 100]],
                                 "start": [10, 10], "goal": [75, 75], "robot": {"radius": 1},
                                 "obstacles": walls})  # fmt: skip
    result = solve(problem, "Exact", time_limit=5.0)
    assert not result.solved and result.status == "none" and result.length is None
    assert result.stages["infeasible"] is True and result.stages["stopped"] is False


def test_stops_at_the_time_limit_and_says_so():
    """A budget far too small: the search is cut, reports a timeout and returns no path (a
    partial search proves nothing)."""
    problem = load_problem(PROBLEMS / "maps" / "warehouse_aisles.yaml")
    result = solve(problem, "Exact", time_limit=0.05)
    assert not result.solved and result.length is None
    assert "timeout" in result.ompl_status.lower()
    assert result.stages["stopped"] is True
    assert result.time < 5.0  # generous: the raster set-up is not interruptible


def test_refuses_a_users_own_validity_checker(caplog):
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0)
    bounds.setHigh(1)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda state: not (0.3 < state[0] < 0.7 and 0.3 < state[1] < 0.7))
    si.setup()
    ss = og.SimpleSetup(si)
    start, goal = si.allocState(), si.allocState()
    start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.9
    ss.setStartAndGoalStates(start, goal)
    planner = ExactPlanner(si)
    ss.setPlanner(planner)
    with caplog.at_level("ERROR"):
        status = ss.solve(1.0)
    assert status.getStatus() == ob.PlannerStatus.ABORT
    assert "explicit geometry" in caplog.text and "validity checker" in caplog.text


@pytest.mark.slow  # the rrtpso command end to end
def test_bench_logs_its_rows(tmp_path):
    """``rrtpso bench --planner Exact``: Planner Arena rows with time and length, and the graph's
    size as run properties."""
    shutil.copy(PROBLEMS / "static" / "single_circle.yaml", tmp_path / "single_circle.yaml")
    out = tmp_path / "out"
    proc = subprocess.run(
        [*rrtpso_exe(), "bench", str(tmp_path / "single_circle.yaml"), "--planners",
         "Exact,RRTstar", "--runs", "1", "--time", "0.5", "--out", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in (out / "runs.jsonl").read_text().splitlines()]
    exact = [r for r in rows if r["planner"] == "Exact"]
    assert len(exact) == 1 and exact[0]["solved"]
    with sqlite3.connect(out / "benchmark.db") as con:
        con.row_factory = sqlite3.Row
        runs = [dict(r) for r in con.execute(
            "SELECT runs.* FROM runs JOIN plannerConfigs ON runs.plannerid = plannerConfigs.id "
            "WHERE plannerConfigs.name LIKE '%Exact%'")]  # fmt: skip
    assert len(runs) == 1
    assert runs[0]["solution_length"] == pytest.approx(exact[0]["length"])
    assert runs[0]["time"] > 0 and runs[0]["graph_nodes"] > 0
    assert runs[0]["length_over_optimum"] == pytest.approx(1.0, abs=2e-4)


def test_documented_parameter_table_matches_the_registry():
    """docs/planners.md is generated from the registry (python benchmarks/param_tables.py)."""
    from helpers import REPO

    text = (REPO / "docs" / "planners.md").read_text()
    table = default_registry().get("Exact").params.markdown()
    assert f"<!-- params:Exact -->\n{table}\n<!-- /params:Exact -->" in text
