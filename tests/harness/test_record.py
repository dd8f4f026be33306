"""The run record: the results file's keys and order, old rows, one identity for a run."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from helpers import PROBLEMS

from rrtpso_ompl.harness.batch import Task, _base_row, error_row, make_tasks, run_batch
from rrtpso_ompl.harness.record import RunKey, RunRecord, settings_key
from rrtpso_ompl.harness.results_file import ResultsFile, read_rows
from rrtpso_ompl.outputs import json_line
from rrtpso_ompl.planners.result import BenchmarkRun, SolveResult

#: The keys of a solved row, in the order the results file has written them since issue 22
#: (``settings`` since issue 32).
SOLVED_KEYS = ["file", "planner", "seed", "run", "budget", "settings", "source", "inputs_sha256",
               "problem", "status", "solved", "length", "time", "path", "ompl_status", "time_limit",
               "valid", "clearance", "cost", "params", "stages", "benchmark", "wall", "error",
               "optimum", "ratio"]  # fmt: skip
#: The keys of an error row, in order.
ERROR_KEYS = ["file", "planner", "seed", "run", "budget", "settings", "source", "inputs_sha256",
              "problem", "status", "solved", "length", "time", "path", "error", "optimum",
              "ratio"]  # fmt: skip
#: A row as ``rrtpso batch`` wrote it before rows had budget, source, inputs_sha256, the optimum
#: and the benchmark record (the first results-file format).
OLD_ROW = {"file": "problems/static/single_circle.yaml", "planner": "RRTConnect", "seed": 2,
           "run": 1, "problem": "single_circle", "status": "exact", "solved": True,
           "length": 660.5, "time": 0.1, "path": [[20.0, 20.0], [680.0, 320.0]],
           "time_limit": 0.1, "params": {}, "stages": {"unsimplified_length": 700.0},
           "wall": 0.4, "error": None}  # fmt: skip


def _task(tmp_path, **kw) -> Task:
    return Task(file=str(tmp_path / "p.yaml"), planner="RRTstarPSO", seed=3, run=2,
                time_limit=0.5, digest="abc", **kw)  # fmt: skip


def _result() -> SolveResult:
    return SolveResult(
        problem="p", planner="RRTstarPSO", status="exact", ompl_status="Exact solution",
        length=12.5, time=0.49, seed=3, path=np.array([[0.0, 0.0], [12.5, 0.0]]),
        time_limit=0.5, params={"iterations": 50}, stages={"pso_time": 0.1}, clearance=0.25,
        benchmark=BenchmarkRun(time=0.39, solution_length=13.0,
                                           simplification_time=0.1, simplified_length=12.5,
                                           properties={"iterations": ("INTEGER", 80)},
                                           progress=[(0.1, 14.0), (0.39, 13.0)]),
    )  # fmt: skip


def _legacy_row(task: Task, result: SolveResult, wall: float, optimum: float) -> dict:
    """A solved row as the batch built it before the record existed (``run_task`` of issue 22,
    with the ``settings`` of issue 32)."""
    base = {
        "file": task.file,
        "planner": task.planner,
        "seed": task.seed,
        "run": task.run,
        "budget": task.time_limit,
        "settings": dict(task.settings),
        "source": task.key.source,
        "inputs_sha256": task.digest,
    }
    row = {**base, **result.to_dict(), **base}  # fmt: skip
    row["wall"] = wall
    row["error"] = None
    row["optimum"] = optimum
    row["ratio"] = row["length"] / optimum
    return row


def test_a_solved_row_is_written_as_before(tmp_path):
    """Byte for byte the line the batch wrote before rows were typed."""
    task, result = _task(tmp_path), _result()
    record = RunRecord.from_solve(_base_row(task), result.to_dict(), wall=0.7).with_optimum(12.0)
    assert list(record.to_json()) == SOLVED_KEYS
    assert json_line(record.to_json()) == json_line(_legacy_row(task, result, 0.7, 12.0))
    assert record.ratio == pytest.approx(12.5 / 12.0)
    assert record.benchmark_run.properties == {"iterations": ("INTEGER", 80)}
    # And back: the line read is the record written.
    assert RunRecord.from_json(json.loads(json_line(record.to_json()))) == record


def test_an_error_row_has_no_solve_keys_and_optional_keys_stay_out(tmp_path):
    task = _task(tmp_path)
    row = error_row(task, "p.yaml: it broke")
    assert list(row.with_optimum(None).to_json()) == ERROR_KEYS
    assert row.to_json()["path"] == [] and row.is_error
    # No optimum looked up (run_batch(optimum=False)): no optimum or ratio keys.
    assert "optimum" not in row.to_json() and "ratio" not in row.to_json()
    # Paths left out (--no-path): no path key, as before.
    solved = _result().to_dict()
    solved.pop("path")
    record = RunRecord.from_solve(_base_row(task), solved, wall=0.1)
    assert record.path is None and "path" not in record.to_json()


@pytest.mark.slow
def test_an_old_row_is_read_and_its_settings_are_unknown(tmp_path, monkeypatch):
    """A row of the first format lacks the keys added since: it is read, resolved from its
    ``file`` (relative to the working directory); without ``settings`` it is the run of no task
    (what it ran with is not known), and resuming says so."""
    monkeypatch.chdir(PROBLEMS.parent)
    record = RunRecord.from_json(OLD_ROW)
    assert record.source is None and record.budget is None and record.benchmark is None
    assert record.settings is None
    assert record.key == RunKey(str(PROBLEMS / "static" / "single_circle.yaml"), "RRTConnect", 2,
                                None, None)  # fmt: skip
    assert record.effective_budget == 0.1  # the file's, as the solve ran it
    assert record.benchmark_run == BenchmarkRun(time=0.1)
    # Written again, it has today's keys (the missing ones null) and nothing is lost.
    again = record.to_json()
    assert [k for k in SOLVED_KEYS if k in again] == list(again)
    assert all(again[k] == v for k, v in OLD_ROW.items())
    # The task of the same problem (however spelled), planner, seed and budget is another run:
    # same configuration, unknown settings; resuming names the row and runs the task.
    tasks = make_tasks([str(PROBLEMS / "static" / "single_circle.yaml")], ["RRTConnect"], runs=2,
                       seed=1)  # fmt: skip
    assert tasks[1].key.configuration == record.key.configuration
    assert tasks[1].key != record.key and tasks[1].key.settings is not None
    out = tmp_path / "old.jsonl"
    out.write_text(json.dumps(OLD_ROW) + "\n")
    assert read_rows(out) == [record]  # read as it was
    seen, notes = [], []
    rows = run_batch(tasks[1:], out, resume=True, on_start=lambda n, k: seen.append((n, k)),
                     notice=notes.append)  # fmt: skip
    assert seen == [(1, 0)] and [r.key for r in rows] == [tasks[1].key]
    (note,) = notes
    assert f"{out}: 1 row of other settings (none recorded: an earlier version wrote them" in note
    assert note.endswith("these runs are new")
    assert read_rows(out)[0] == record and len(read_rows(out)) == 2  # it stays in the file


def test_unknown_keys_are_kept_and_a_row_needs_its_identity():
    row = {**OLD_ROW, "note": "from another tool"}
    record = RunRecord.from_json(row)
    assert record.extra == {"note": "from another tool"}
    assert record.to_json()["note"] == "from another tool"
    with pytest.raises(ValueError, match="no seed"):
        RunRecord.from_json({k: v for k, v in OLD_ROW.items() if k != "seed"})


def test_task_and_row_have_one_identity(tmp_path, monkeypatch):
    """``Task.key`` and ``RunRecord.key`` are one definition: a task's error row, and a row of
    the same file spelled another way, have the task's key."""
    problem = tmp_path / "p.yaml"
    problem.write_text("x")
    (tmp_path / "link.yaml").symlink_to(problem)
    monkeypatch.chdir(tmp_path)
    (task,) = make_tasks(["p.yaml"], ["RRT"], seed=4, time_limit=0.5)
    settings = settings_key(task.settings)
    assert error_row(task, "x").key == task.key == RunKey(str(problem), "RRT", 4, 0.5, settings)
    linked = RunRecord(file="link.yaml", planner="RRT", seed=4, run=0, budget=0.5, status="none",
                       settings=dict(task.settings))  # fmt: skip
    assert linked.key == task.key
    assert RunRecord(file="p.yaml", planner="RRT", seed=4, run=0, budget=1.0,
                     settings=dict(task.settings)).key != task.key  # fmt: skip
    # Settings are part of it: other parameters, or none recorded, are another run.
    assert dataclasses.replace(linked, settings=None).key != task.key
    (other,) = make_tasks(["p.yaml"], ["RRT"], seed=4, time_limit=0.5, params={"RRT": {"range": 2}})
    assert other.key != task.key and other.key.configuration == task.key.configuration


def test_the_results_file_writes_records(tmp_path):
    out = tmp_path / "r.jsonl"
    record = RunRecord.from_json(OLD_ROW)
    with ResultsFile(out) as results:
        results.append(record)
    line = out.read_bytes()
    assert line.startswith(b'{"file": ') and line.endswith(b"\n")
    assert read_rows(out) == [record]


def test_a_row_with_a_malformed_benchmark_is_not_a_row(tmp_path):
    """Read back, it is skipped; resumed, the file is refused and left as it is."""
    from rrtpso_ompl.errors import UsageError

    assert RunRecord.from_json({**OLD_ROW, "benchmark": {}}).benchmark is None  # none given
    with pytest.raises(ValueError, match="malformed benchmark"):
        RunRecord.from_json({**OLD_ROW, "benchmark": {"progress": 3}})
    out = tmp_path / "r.jsonl"
    text = json.dumps(OLD_ROW) + "\n" + json.dumps({**OLD_ROW, "benchmark": [1]}) + "\n"
    out.write_text(text)
    assert read_rows(out) == [RunRecord.from_json(OLD_ROW)]
    with (
        pytest.raises(UsageError, match="line 2 is not one of its rows"),
        ResultsFile(out, resume=True),
    ):
        pass
    assert out.read_text() == text
