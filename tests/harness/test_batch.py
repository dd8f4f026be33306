"""``rrtpso batch``: isolation of bad files, the JSON-lines schema, resuming, interruption, Dask."""

from __future__ import annotations

import json
import shutil
import signal
import subprocess
import time

import pytest
from helpers import PROBLEMS, rrtpso_exe

from rrtpso_ompl.groundtruth.optimum import shortest_path
from rrtpso_ompl.harness.batch import expand_inputs, make_tasks, read_rows, run_batch
from rrtpso_ompl.model.problem import load_problem

ROW_KEYS = {"file", "problem", "planner", "seed", "run", "status", "solved", "length", "time",
            "path", "error", "budget", "optimum", "ratio"}  # fmt: skip


def batch(*args: str, timeout: float = 240) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*rrtpso_exe(), "batch", *args], capture_output=True, text=True, timeout=timeout
    )


@pytest.fixture
def folder(tmp_path):
    """Two good problems and a bad one."""
    d = tmp_path / "problems"
    d.mkdir()
    shutil.copy(PROBLEMS / "static" / "single_circle.yaml", d / "a_circle.yaml")
    shutil.copy(PROBLEMS / "static" / "narrow_passage.yaml", d / "b_passage.yaml")
    (d / "c_bad.yaml").write_text("bounds: [[0, 0], [10, 10]]\nstart: [1, 1]\ngoal: [9, 9]\n")
    return d


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


def test_a_bad_file_is_its_row_and_the_batch_goes_on(folder, tmp_path):
    out = tmp_path / "out.jsonl"
    proc = batch(str(folder), "--planner", "RRTstarPSO,RRTConnect", "--time", "0.2", "--jobs",
                 "2", "--out", str(out))  # fmt: skip
    assert proc.returncode == 1, proc.stderr  # one row failed
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(rows) == 6  # 3 files x 2 planners
    for row in rows:
        assert set(row) >= ROW_KEYS
    bad = [r for r in rows if r["file"].endswith("c_bad.yaml")]
    assert len(bad) == 2 and all(r["status"] == "error" and not r["solved"] for r in bad)
    assert all("robot" in r["error"] and "c_bad.yaml" in r["error"] for r in bad)
    good = [r for r in rows if not r["file"].endswith("c_bad.yaml")]
    assert all(r["solved"] and r["error"] is None and r["length"] > 0 for r in good)
    # Every row carries the exact optimum of its problem and its ratio to it.
    for r in good:
        optimum = shortest_path(load_problem(r["file"])).length
        assert r["optimum"] == pytest.approx(optimum, rel=1e-12)
        assert r["ratio"] == pytest.approx(r["length"] / optimum) and r["ratio"] >= 1 - 1e-9
    assert all(r["optimum"] is None and r["ratio"] is None for r in bad)
    assert "c_bad.yaml" in proc.stderr and "Traceback" not in proc.stderr


def test_unknown_planner_is_a_usage_error(folder, tmp_path):
    out = tmp_path / "out.jsonl"
    proc = batch(str(folder), "--planner", "RRTsta", "--out", str(out))
    assert proc.returncode == 2 and "RRTsta" in proc.stderr and not out.exists()


def test_resume_skips_done_rows_and_retries_a_torn_line(folder, tmp_path):
    out = tmp_path / "out.jsonl"
    good = str(folder / "a_circle.yaml")
    tasks = make_tasks([good], ["RRTConnect"], runs=3, seed=5, time_limit=0.1)
    rows = run_batch(tasks[:2], out)
    assert [r.seed for r in rows] == [5, 6]
    # Simulate an interrupted write at the end of the file.
    with out.open("a") as fh:
        fh.write('{"file": "' + good + '", "planner": "RRTC')
    seen = []
    rows = run_batch(tasks, out, resume=True, on_start=lambda n, skipped: seen.append((n, skipped)))
    assert seen == [(1, 2)]
    assert sorted(r.seed for r in rows) == [5, 6, 7]
    assert sorted(r.seed for r in read_rows(out)) == [5, 6, 7]
    assert all(json.loads(line) for line in out.read_text().splitlines())


def test_same_seed_same_row_in_a_fresh_process(tmp_path):
    # Iteration-bounded so that the result does not depend on the machine's speed.
    params = {"PSO": {"iterations": 30, "restarts": False}}
    problem = str(PROBLEMS / "static" / "single_circle.yaml")
    tasks = make_tasks([problem], ["PSO"], seed=3, time_limit=5.0, params=params)
    a = run_batch(tasks, tmp_path / "a.jsonl")[0]
    b = run_batch(tasks, tmp_path / "b.jsonl", jobs=2)[0]
    assert a.solved == b.solved and a.path == b.path


def test_ctrl_c_leaves_a_valid_partial_file(folder, tmp_path):
    out = tmp_path / "out.jsonl"
    proc = subprocess.Popen(
        [*rrtpso_exe(), "batch", str(folder / "a_circle.yaml"), "--planner", "RRTstar",
         "--runs", "8", "--time", "0.2", "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (not out.exists() or not out.read_text().strip()):
        time.sleep(0.2)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    lines = out.read_text().splitlines()
    assert 1 <= len(lines) < 8
    assert all(json.loads(line)["solved"] for line in lines)
    # And the batch continues where it stopped (the same tasks: the time limit is part of a task).
    again = batch(str(folder / "a_circle.yaml"), "--planner", "RRTstar", "--runs", "8", "--time",
                  "0.2", "--out", str(out), "--resume", "--jobs", "2")  # fmt: skip
    assert again.returncode in (0, 1), again.stderr
    assert f"{len(lines)} rows already done" in again.stderr
    rows = read_rows(out)
    assert sorted(r.seed for r in rows) == list(range(1, 9))


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


def test_an_unsolvable_file_is_an_unsolved_row_and_exit_1(tmp_path):
    """A wall across the whole workspace: a valid file with no path. Its row says so honestly
    (not solved, no error, no optimum) and the batch exits 1."""
    wall = tmp_path / "wall.yaml"
    wall.write_text(
        "bounds: [[0, 0], [100, 100]]\nstart: [50, 10]\ngoal: [50, 90]\nrobot: {radius: 2}\n"
        "obstacles:\n  - {type: rectangle, min: [0, 45], max: [100, 55]}\n"
    )
    out = tmp_path / "out.jsonl"
    proc = batch(str(wall), str(PROBLEMS / "static" / "single_circle.yaml"),
                 "--planner", "RRTConnect", "--time", "0.1", "--out", str(out))  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    rows = {r.problem: r for r in read_rows(out)}
    assert rows["single_circle"].solved
    walled = next(r for name, r in rows.items() if name != "single_circle")
    assert not walled.solved and walled.error is None
    assert walled.optimum is None and walled.ratio is None
    assert walled.to_json()["optimum"] is None  # written as null: looked up, not connected


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
