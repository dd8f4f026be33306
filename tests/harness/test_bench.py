"""``rrtpso bench``: OMPL logs, the Planner Arena database, the report, the property mapping."""

from __future__ import annotations

import itertools

import pytest
from helpers import PROBLEMS

from rrtpso_ompl.harness.bench import run_bench, run_properties, summarise
from rrtpso_ompl.harness.record import RunRecord
from rrtpso_ompl.model.problem import load_problem
from rrtpso_ompl.planners.result import BenchmarkRun


def test_property_mapping_takes_each_planner_s_own_figures():
    """The row's ``benchmark`` record (made by the planner's stats) decides the mapping; nothing
    is guessed from the keys of ``stages``."""
    swarm = BenchmarkRun(
        time=0.85,
        solution_length=700.0,
        simplification_time=0.15,
        simplified_length=650.0,
        properties={"pso rounds": ("INTEGER", 3)},
    )
    ids = {"file": "f", "planner": "A", "run": 0}
    pso_row = {**ids, "solved": True, "status": "exact", "ompl_status": "Exact solution",
               "valid": True, "length": 650.0, "time": 1.0, "optimum": 647.5, "seed": 3,
               "clearance": 0.1, "stages": {"pso_length": 650.0, "pso_time": 0.15},
               "benchmark": swarm.to_dict()}  # fmt: skip
    p = run_properties(RunRecord.from_json(pso_row))
    assert p["time"] == pytest.approx(0.85) and p["simplification time"] == 0.15
    assert p["solution length"] == 700.0 and p["simplified solution length"] == 650.0
    assert p["length over optimum"] == pytest.approx(650 / 647.5) and p["total time"] == 1.0
    assert p["pso rounds"] == 3
    # A planner whose stats have pso_* keys but no simplification stage (the PSO baseline).
    baseline = {**pso_row, "benchmark": BenchmarkRun(time=1.0, solution_length=650.0).to_dict()}
    p = run_properties(RunRecord.from_json(baseline))
    assert p["time"] == 1.0 and p["simplification time"] is None
    assert p["solution length"] == 650.0 and p["simplified solution length"] is None
    stock = {**ids, "solved": True, "status": "exact", "ompl_status": "Exact solution",
             "valid": True, "length": 660.0, "time": 1.0, "optimum": 647.5, "seed": 3,
             "benchmark": BenchmarkRun(time=1.0, solution_length=720.0, simplification_time=0.01,
                                       simplified_length=660.0).to_dict()}  # fmt: skip
    p = run_properties(RunRecord.from_json(stock))
    assert p["time"] == 1.0 and p["total time"] == pytest.approx(1.01)
    assert p["solution length"] == 720.0 and p["simplified solution length"] == 660.0
    failed = {**ids, "solved": False, "status": "none", "ompl_status": "Timeout", "valid": False,
              "length": None, "time": 1.0, "optimum": 647.5, "seed": 4, "stages": {}}  # fmt: skip
    p = run_properties(RunRecord.from_json(failed))
    assert not p["solved"] and p["solution length"] is None and p["length over optimum"] is None
    summary = summarise(
        [RunRecord.from_json({**pso_row, "problem": "p", "budget": 1.0}),
         RunRecord.from_json({**failed, "problem": "p", "budget": 1.0})], ["A"]
    )  # fmt: skip
    (s,) = summary
    assert s.runs == 2 and s.solved == 1 and s.success == 0.5
    assert s.median_ratio == pytest.approx(650 / 647.5)
    assert s.median_raw_ratio == pytest.approx(700 / 647.5)


@pytest.mark.slow  # the optional Dask executor: a cluster of processes
def test_dask_local_cluster_runs_a_bench(tmp_path):
    distributed = pytest.importorskip("distributed")
    problem = str(PROBLEMS / "static" / "single_circle.yaml")
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    )
    with cluster, distributed.Client(cluster) as client:
        result = run_bench([problem], ["RRTConnect"], tmp_path, runs=2, times=[0.1],
                           executor="dask", scheduler=client)  # fmt: skip
    assert len(result.rows) == 2 and all(r.solved for r in result.rows)
    assert result.database is not None and result.database.exists()
    assert [s.planner for s in result.summary] == ["RRTConnect"]


@pytest.mark.parametrize("planner", ["RRTstar", "BITstar", "PRMstar", "RRTConnect", "RRTstarPSO"])
def test_solve_records_progress_for_every_kind_of_planner(planner):
    from rrtpso_ompl.planners.solve import solve

    problem = load_problem(PROBLEMS / "static" / "polygon_map.yaml")
    simplify = planner != "RRTstarPSO"
    result = solve(problem, planner, time_limit=0.3, seed=2, simplify=simplify, progress=True)
    assert result.solved  # and PRM*, whose condition runs in a second thread, did not hang
    rows = result.benchmark.progress
    times = [t for t, _ in rows]
    costs = [c for _, c in rows]
    assert rows and all(b > a for a, b in itertools.pairwise(times))
    assert all(b <= a + 1e-9 for a, b in itertools.pairwise(costs))
    assert times[-1] == pytest.approx(result.time, abs=1e-6)
    if planner in ("RRTstar", "BITstar"):
        assert len(rows) >= 4  # sampled every 0.05 s once a solution exists
    if simplify:
        # The last row is the planner's own path, before OMPL's simplifier shortened it.
        assert costs[-1] == pytest.approx(result.stages["unsimplified_length"])
        assert result.length <= result.stages["unsimplified_length"] + 1e-9
    else:
        assert costs[-1] == pytest.approx(result.length)


def test_overview_counts_the_cells_the_first_planner_loses():
    from rrtpso_ompl.harness.bench import SummaryRow, overview_markdown

    def row(problem, planner, ratio, solved=10):
        return SummaryRow(problem, 1.0, planner, 10, solved, solved / 10, 100.0, None, ratio,
                          None, None, ratio, ratio, 1.0)  # fmt: skip

    text = overview_markdown([
        row("a", "Ours", 1.001), row("a", "Theirs", 1.002),  # we win
        row("b", "Ours", 1.003), row("b", "Theirs", 1.002),  # they win by 0.1 %
        row("c", "Ours", None, solved=0), row("c", "Theirs", 1.5),  # we solve nothing
    ])  # fmt: skip
    assert "Ours has the shortest median path alone in 1 of 3 problem x budget cells." in text
    assert "- 1 s, b: Theirs, shorter by 0.100 % of the optimum" in text
    assert "- 1 s, c: Theirs; Ours solved no run" in text
    assert "| Ours | +0.20 %, 67%, 1.00 s |" in text  # median of 1.001 and 1.003; 20 of 30 runs


def test_overview_counts_a_tie_as_no_win_and_lists_no_loss_when_there_is_none():
    from rrtpso_ompl.harness.bench import SummaryRow, overview_markdown

    def row(problem, planner, ratio):
        return SummaryRow(problem, 1.0, planner, 10, 10, 1.0, 100.0, None, ratio, None, None,
                          ratio, ratio, 1.0)  # fmt: skip

    text = overview_markdown([
        row("a", "Ours", 1.001), row("a", "Theirs", 1.002),  # we win
        row("b", "Ours", 1.000), row("b", "Theirs", 1.000),  # both found the optimum: a tie
    ])  # fmt: skip
    assert "Ours has the shortest median path alone in 1 of 2 problem x budget cells and ties " \
           "for it in 1." in text  # fmt: skip
    assert "Ours is behind in none." in text
    assert "- none" not in text and "In the others" not in text
