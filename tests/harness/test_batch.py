"""``rrtpso batch``: isolation of bad files, the JSON-lines schema, resuming, interruption, Dask."""

from __future__ import annotations

import pytest
from helpers import PROBLEMS

from rrtpso_ompl.harness.batch import expand_inputs, make_tasks, read_rows, run_batch


def test_inputs_mix_files_globs_and_directories(folder, tmp_path):
    items = [str(folder / "a_circle.yaml"), str(folder / "*.yaml"), str(folder), "nope.yaml",
             str(tmp_path / "*.none")]  # fmt: skip
    got = expand_inputs(items)
    paths = [p for p, _ in got]
    assert paths[:3] == [str(folder / f) for f in ("a_circle.yaml", "b_passage.yaml", "c_bad.yaml")]
    assert len(paths) == len(set(paths)) == 5  # no repeats
    errors = dict(got)
    assert "no such file" in errors["nope.yaml"]
    assert "no file matches" in errors[str(tmp_path / "*.none")]


def test_dask_local_cluster_runs_the_same_batch(folder, tmp_path):
    distributed = pytest.importorskip("distributed")
    tasks = make_tasks([str(folder / "a_circle.yaml"), str(folder / "c_bad.yaml")], ["RRTConnect"],
                       runs=2, time_limit=0.1)  # fmt: skip
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    )
    with cluster, distributed.Client(cluster) as client:
        rows = run_batch(tasks, tmp_path / "d.jsonl", executor="dask", scheduler=client)
    assert len(rows) == 4
    assert sum(r.is_error for r in rows) == 2
    assert all(r.solved for r in rows if not r.is_error)
    assert len(read_rows(tmp_path / "d.jsonl")) == 4


def _cluster_batch(tasks, out):
    """A batch on a real process-based Dask cluster (its workers are daemonic processes)."""
    import distributed

    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)  # fmt: skip
    with cluster, distributed.Client(cluster) as client:
        return run_batch(tasks, out, executor="dask", scheduler=client, optimum=False)


def test_dask_process_workers_fork_warm_runs_with_the_same_paths(tmp_path):
    """Dask's worker processes are daemonic and run threads: each run is forked from a warm fork
    server instead, and its path is the one the local warm workers give for the same seed."""
    pytest.importorskip("distributed")
    problem = str(PROBLEMS / "static" / "single_circle.yaml")
    tasks = make_tasks([problem], ["RRTConnect", "RRT"], runs=2, seed=3, time_limit=1.0)
    on_dask = {(r.planner, r.seed): r for r in _cluster_batch(tasks, tmp_path / "d.jsonl")}
    local = {(r.planner, r.seed): r
             for r in run_batch(tasks, tmp_path / "l.jsonl", jobs=2, optimum=False)}  # fmt: skip
    assert len(on_dask) == 4 and not any(r.is_error for r in on_dask.values())
    for key, row in local.items():
        assert on_dask[key].path == row.path, key


def test_only_a_solved_row_gets_a_ratio():
    """An approximate path stops short of the goal, so it can be shorter than the optimum: it
    gets the optimum but no ratio (seen on the maze at 0.2 s: ratio 0.39 before the fix)."""
    from rrtpso_ompl.harness.batch import _Optima
    from rrtpso_ompl.harness.record import RunRecord

    maze = str(PROBLEMS / "static" / "maze.yaml")
    optima = _Optima()
    row = RunRecord(file=maze, planner="RRT", seed=1, run=0, status="approximate", length=79.2)
    approximate = optima.annotate(row)
    solved = optima.annotate(RunRecord(file=maze, planner="RRT", seed=1, run=0, status="exact",
                                       solved=True, length=210.0))  # fmt: skip
    assert approximate.optimum == pytest.approx(204.30, abs=0.01)
    assert approximate.ratio is None
    assert solved.ratio == pytest.approx(210.0 / solved.optimum)


def test_the_old_evaluation_package_still_imports_and_warns():
    """rrtpso_ompl.evaluation was split into harness and groundtruth; old imports keep working."""
    import importlib
    import sys
    import warnings

    sys.modules.pop("rrtpso_ompl.evaluation", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("rrtpso_ompl.evaluation")
        from rrtpso_ompl.evaluation.optimum import shortest_path
    from rrtpso_ompl.groundtruth import shortest_path as new
    from rrtpso_ompl.harness import run_batch

    assert shortest_path is new and old.run_batch is run_batch
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)
