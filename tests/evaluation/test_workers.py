"""Warm workers and forked runs: a crash, an exception or a hang is one failed task, never more.

The tasks are Python expressions run by ``eval`` (a builtin, so spawned workers can unpickle it):
real child processes that really abort, raise or hang.
"""

from __future__ import annotations

import time

import pytest
from helpers import PROBLEMS

from rrtpso_ompl.evaluation.batch import Task, error_row, make_tasks, run_batch
from rrtpso_ompl.evaluation.workers import ChildFailure, run_local, run_once_in_child

ABORT = "__import__('os').abort()"
KILL_WORKER = "__import__('os').kill(__import__('os').getppid(), 9)"


def test_a_child_returns_its_value():
    assert run_once_in_child(eval, "6 * 7", timeout=30) == 42


@pytest.mark.parametrize(
    ("code", "words"),
    [
        (ABORT, "killed by signal SIGABRT"),
        ("bytearray(2**62)", "raised MemoryError"),
        ("1 / 0", "raised ZeroDivisionError"),
        ("__import__('os')._exit(3)", "exit status 3"),
    ],
)
def test_a_failing_child_is_described(code, words):
    result = run_once_in_child(eval, code, timeout=30)
    assert isinstance(result, ChildFailure) and words in result.message


def test_a_hanging_child_is_stopped_at_its_timeout():
    t0 = time.perf_counter()
    result = run_once_in_child(eval, "__import__('time').sleep(60)", timeout=0.5)
    assert isinstance(result, ChildFailure) and "longer than" in result.message
    assert time.perf_counter() - t0 < 10


def test_the_pool_goes_on_after_crashes_and_a_dead_worker():
    tasks = ["1 + 1", ABORT, KILL_WORKER, "2 + 2", "3 + 3"]
    results = dict(run_local(tasks, eval, jobs=2, timeout_of=len))
    assert results["1 + 1"] == 2 and results["2 + 2"] == 4 and results["3 + 3"] == 6
    assert isinstance(results[ABORT], ChildFailure)
    assert isinstance(results[KILL_WORKER], ChildFailure)
    assert "worker process died" in results[KILL_WORKER].message


def test_same_seed_same_path_as_a_separate_solve(tmp_path):
    """A run in a forked child of a warm worker is seeded like a fresh process: its path is the
    path ``rrtpso solve`` gives in a process of its own."""
    import json
    import subprocess

    from helpers import rrtpso_exe

    problem = str(PROBLEMS / "static" / "maze.yaml")
    params = {"RRTstarPSO": {"rrt_max_iterations": "300", "iterations": "20"}}
    tasks = make_tasks([problem], ["RRTConnect", "RRTstarPSO"], runs=2, seed=5, time_limit=5.0,
                       params=params)  # fmt: skip
    rows = run_batch(tasks, tmp_path / "r.jsonl", jobs=2, optimum=False)
    for row in rows:
        extra = [
            a for k, v in params.get(row["planner"], {}).items() for a in ("--param", f"{k}={v}")
        ]
        out = tmp_path / f"{row['planner']}_{row['seed']}.json"
        subprocess.run([*rrtpso_exe(), "solve", problem, "--planner", row["planner"], "--seed",
                        str(row["seed"]), "--time", "5", *extra, "--json", str(out)],
                       check=False, capture_output=True, timeout=60)  # fmt: skip
        alone = json.loads(out.read_text())
        assert alone["path"] == row["path"], row["planner"]


def test_error_rows_name_the_task():
    task = Task(file="x.yaml", planner="RRTstar", seed=3, run=0, time_limit=1.0)
    row = error_row(task, "x.yaml: it broke")
    assert row["status"] == "error" and row["seed"] == 3 and row["error"] == "x.yaml: it broke"
