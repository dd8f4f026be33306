"""``rrtpso batch`` as a user runs it: bad files as rows, resume, Ctrl-C, exit codes."""

from __future__ import annotations

import json
import signal
import subprocess

import pytest
from helpers import PROBLEMS, HeldBatch, rrtpso_exe

from rrtpso_ompl.groundtruth.optimum import shortest_path
from rrtpso_ompl.harness.batch import make_tasks, read_rows, run_batch
from rrtpso_ompl.model.problem import load_problem

pytestmark = pytest.mark.slow

ROW_KEYS = {"file", "problem", "planner", "seed", "run", "status", "solved", "length", "time",
            "path", "error", "budget", "optimum", "ratio"}  # fmt: skip


def batch(*args: str, timeout: float = 240) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*rrtpso_exe(), "batch", *args], capture_output=True, text=True, timeout=timeout
    )


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
    # The batch holds after its first row (the test hook), so Ctrl-C comes while it still runs
    # on any machine. RRTConnect stops at its first path: 5 s is a cap, never reached.
    out = tmp_path / "out.jsonl"
    args = [str(folder / "a_circle.yaml"), "--planner", "RRTConnect", "--runs", "4", "--time",
            "5", "--out", str(out)]  # fmt: skip
    held = HeldBatch(tmp_path)
    proc = subprocess.Popen([*rrtpso_exe(), "batch", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=held.env)  # fmt: skip
    held.wait_for_rows(proc, out)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    lines = out.read_text().splitlines()
    assert len(lines) == 1 and json.loads(lines[0])["solved"]
    # And the batch continues where it stopped (the same tasks: the time limit is part of a task).
    again = batch(*args, "--resume", "--jobs", "2")
    assert again.returncode == 0, again.stderr
    assert "1 rows already done" in again.stderr or "1 row already done" in again.stderr
    rows = read_rows(out)
    assert sorted(r.seed for r in rows) == [1, 2, 3, 4] and all(r.solved for r in rows)


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
