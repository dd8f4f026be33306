"""Warm workers and forked runs: a crash, an exception or a hang is one failed task, never more.

The tasks are Python expressions run by ``eval`` (a builtin, so spawned workers can unpickle it):
real child processes that really abort, raise or hang.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from multiprocessing.connection import Connection
from pathlib import Path

import pytest
from helpers import PROBLEMS

from rrtpso_ompl.harness.batch import Task, error_row, make_tasks, run_batch
from rrtpso_ompl.harness.workers import ChildFailure, _ParentGone, run_local, run_once_in_child

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


@pytest.mark.slow  # seconds of work: the full run only
def test_same_seed_same_path_as_a_separate_solve(tmp_path):
    """A run in a forked child of a warm worker is seeded like a fresh process: its path is the
    path ``rrtpso solve`` gives in a process of its own."""
    import json
    import subprocess

    from helpers import rrtpso_exe

    problem = str(PROBLEMS / "static" / "maze.yaml")
    params = {"RRTstarPSO": {"rrt_max_iterations": "300", "iterations": "20", "refine_rounds": "0",
                            "polish_rounds": "0"}}  # fmt: skip
    # Bounded by iterations (RRT*'s, the swarm's, one round), not by the clock: a budget no run
    # comes near (a warm worker after a Dask cluster ran 4 times slower, and a swarm cut by the
    # deadline differs run to run).
    tasks = make_tasks([problem], ["RRTConnect", "RRTstarPSO"], runs=1, seed=5, time_limit=30.0,
                       params=params)  # fmt: skip
    rows = run_batch(tasks, tmp_path / "r.jsonl", jobs=2, optimum=False)
    assert len(rows) == 2
    solves = []  # each in a process of its own, at the same time
    for row in rows:
        extra = [a for k, v in params.get(row.planner, {}).items() for a in ("--param", f"{k}={v}")]
        out = tmp_path / f"{row.planner}_{row.seed}.json"
        command = [*rrtpso_exe(), "solve", problem, "--planner", row.planner, "--seed",
                   str(row.seed), "--time", "30", *extra, "--json", str(out)]  # fmt: skip
        solves.append((row, out, subprocess.Popen(command, stderr=subprocess.PIPE, text=True)))
    for row, out, proc in solves:
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 0, err
        assert json.loads(out.read_text())["path"] == row.path, row.planner


def test_error_rows_name_the_task():
    task = Task(file="x.yaml", planner="RRTstar", seed=3, run=0, time_limit=1.0)
    row = error_row(task, "x.yaml: it broke")
    assert row.status == "error" and row.seed == 3 and row.error == "x.yaml: it broke"


# ----------------------------------------------------------------------------------------------
# Nothing outlives its parent (issue 22; the command-line side is in tests/cli/test_hostile.py)
# ----------------------------------------------------------------------------------------------
def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie waiting for its parent does not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _wait_for_pid(path, seconds: float = 60) -> int:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if path.exists() and path.read_text().strip():
            return int(path.read_text())
        time.sleep(0.05)
    raise AssertionError(f"{path} never got a pid")


def _sleeper(path) -> str:
    """A task that writes its process id to ``path``, then sleeps for a minute."""
    return (f"open({str(path)!r}, 'w').write(str(__import__('os').getpid())) and "
            "__import__('time').sleep(60)")  # fmt: skip


@pytest.mark.skipif(not os.path.exists("/proc/self"), reason="needs /proc")
def test_a_run_is_killed_when_its_worker_s_parent_goes_away(tmp_path):
    """The fallback where the kernel cannot help (no PR_SET_PDEATHSIG): the worker watches its
    pipe to the parent while a child runs; when it closes, the child is killed at once."""
    # The parent's end of the pipe lives in another process (as the batch's does), so that the
    # forked child holds no copy of it: killing that process closes the pipe.
    r, w = os.pipe()
    parent = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"],
                              pass_fds=(w,))  # fmt: skip
    os.close(w)
    watched = Connection(r, writable=False)
    pid_file = tmp_path / "pid"
    closer = threading.Thread(target=lambda: (_wait_for_pid(pid_file), parent.kill()))
    closer.start()
    t0 = time.perf_counter()
    with pytest.raises(_ParentGone):
        run_once_in_child(eval, _sleeper(pid_file), timeout=120, watch=watched)
    closer.join()
    parent.wait(timeout=30)
    watched.close()
    assert time.perf_counter() - t0 < 60  # not the child's minute, nor the timeout
    assert not _alive(int(pid_file.read_text()))


SPAWNER = """
import sys
from rrtpso_ompl.harness.workers import run_spawned
print(run_spawned(eval, sys.argv[1], 120, warm=True))
"""


@pytest.mark.skipif(not os.path.exists("/proc/self"), reason="needs /proc")
def test_a_dask_style_run_dies_with_the_process_that_started_it(tmp_path):
    """run_spawned's process is a child of the fork server, not of its caller (a Dask worker):
    it watches the caller's pid and ends with it, even after a kill -9."""
    pid_file = tmp_path / "pid"
    owner = subprocess.Popen([sys.executable, "-c", SPAWNER, _sleeper(pid_file)], cwd=tmp_path)
    run_pid = _wait_for_pid(pid_file)
    assert _alive(run_pid)
    owner.kill()
    owner.wait(timeout=30)
    deadline = time.monotonic() + 15
    while _alive(run_pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive(run_pid)
