"""Never a lost row (issue 32, items 4-6), as a user meets it: real batches and benches, real
files and locks, real ``rrtpso`` processes.

- No output of ``solve``, ``optimum``, ``simulate`` or ``generate`` replaces a results file,
  being written (locked, the way a running batch holds it) or finished, nor a bench folder's
  files: exit 2, the file named and what it is, nothing written. Also at the last moment: a
  batch that takes the file after the command's checks (built with a fifo: the command waits on
  it, between its checks and its last output) keeps its rows.
- ``--resume`` with other settings runs the runs again and says so; batch and bench alike.
- A budget or planner named twice runs once (rows, database and report agree); a folder's fifo,
  socket, link to nothing or directory named like a problem is an error row, never skipped.
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import shutil
import socket
import sqlite3
import subprocess
import threading

import pytest
from helpers import PROBLEMS, rrtpso_exe, run

from rrtpso_ompl.harness.record import RunRecord
from rrtpso_ompl.harness.results_file import ResultsFile

pytestmark = pytest.mark.slow

PROBLEM = str(PROBLEMS / "static" / "single_circle.yaml")
DYNAMIC = str(PROBLEMS / "dynamic" / "head_on.yaml")
#: A quick solve: the outputs are refused before planning, or the plan does not matter.
QUICK = ("--planner", "RRTConnect", "--time", "0.1")


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A finished batch's results file and a finished bench's folder (made once: each run is a
    process of its own)."""
    d = tmp_path_factory.mktemp("made")
    batch = run("batch", PROBLEM, *QUICK, "--runs", "2", "--out", str(d / "res.jsonl"))
    assert batch.returncode == 0, batch.stderr
    bench = run("bench", PROBLEM, "--planner", "RRTConnect", "--time", "0.1", "--runs", "1",
                "--out", str(d / "bench"))  # fmt: skip
    assert bench.returncode == 0, bench.stderr
    return d


def _copy_results(made, to):
    shutil.copy(made / "res.jsonl", to)
    return to


def _row(seed: int) -> RunRecord:
    return RunRecord(file=PROBLEM, planner="RRTConnect", seed=seed, run=seed - 1, status="error",
                     error="held by the test")  # fmt: skip


# -- item 4: a results file is never a target -----------------------------------------------------
@pytest.mark.parametrize(
    ("flag", "name"),
    [("--json", "res.jsonl"), ("--plot", "res.png"), ("--plot-clearance", "res.svg"),
     ("--trajectory", "res.csv"), ("--plot-velocities", "res.pdf"), ("--path-out", "res.json")],
)  # fmt: skip
def test_solve_never_replaces_a_running_batch_s_file(made, tmp_path, flag, name):
    """The file is held the way a running batch holds it (a ResultsFile open in this process):
    ``solve`` refuses it before planning, and the batch's rows keep landing in the file."""
    out = _copy_results(made, tmp_path / name)
    with ResultsFile(out, resume=True) as batch:
        inode = out.stat().st_ino
        proc = run("solve", PROBLEM, *QUICK, flag, str(out))
        assert proc.returncode == 2, proc.stderr
        assert f"{flag}: '{out}' is a results file locked by another process" in proc.stderr
        assert "2 rows so far" in proc.stderr and "Traceback" not in proc.stderr
        batch.append(_row(3))  # the batch goes on
    assert out.stat().st_ino == inode
    assert [json.loads(line)["seed"] for line in out.read_text().splitlines()] == [1, 2, 3]
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # nothing else written


def test_a_batch_that_has_not_written_a_row_yet_is_seen_too(tmp_path):
    out = tmp_path / "res.jsonl"
    with ResultsFile(out) as batch:  # the batch has started: its file is empty, and locked
        proc = run("solve", PROBLEM, *QUICK, "--json", str(out))
        assert proc.returncode == 2 and "a file locked by another process" in proc.stderr
        batch.append(_row(1))
    assert len(out.read_text().splitlines()) == 1


@pytest.mark.parametrize(
    ("args", "target", "what"),
    [
        (["solve", PROBLEM, *QUICK, "--json"], "res.jsonl", "a results file of rrtpso batch"),
        (["optimum", PROBLEM, "--json"], "res.jsonl", "a results file of rrtpso batch"),
        (["simulate", DYNAMIC, "--time", "0.1", "--json"], "res.jsonl", "a results file"),
        (["simulate", DYNAMIC, "--time", "0.1", "--gif"], "res.gif", "a results file"),
        (["generate", "slabs", "--seed", "1", "--overwrite", "--out"], "res.yaml",
         "a results file"),
        (["generate", "rooms_map", "--seed", "1", "--overwrite", "--out"], "g_map.pgm",
         "a results file"),
        (["solve", PROBLEM, *QUICK, "--json"], "bench/runs.jsonl",
         "the results file of the rrtpso bench in"),
        (["solve", PROBLEM, *QUICK, "--plot"], "bench/ratio.png", "the ratio.png of the rrtpso"),
        (["solve", PROBLEM, *QUICK, "--trajectory"], "bench/single_circle_0.1s.log",
         "an OMPL benchmark log written by rrtpso bench"),
        (["generate", "slabs", "--seed", "1", "--overwrite", "--out"], "bench/benchmark.db",
         "the benchmark.db of the rrtpso bench in"),
    ],
    ids=["solve", "optimum", "simulate-json", "simulate-gif", "generate", "generate-map-side",
         "bench-runs", "bench-plot", "bench-log", "bench-db"],
)  # fmt: skip
def test_no_command_replaces_a_finished_batch_or_bench(made, tmp_path, args, target, what):
    shutil.copytree(made / "bench", tmp_path / "bench")
    path = tmp_path / target
    if not path.exists():
        _copy_results(made, path)
    # A map kind writes the map's image beside the problem: g.yaml, g_map.yaml, g_map.pgm.
    out = str(tmp_path / "g.yaml" if target == "g_map.pgm" else path)
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    proc = run(*args, out)
    assert proc.returncode == 2, proc.stderr
    assert f"'{path}' is {what}" in proc.stderr and "Traceback" not in proc.stderr
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before


def test_a_batch_taking_the_file_after_the_checks_keeps_its_rows(tmp_path):
    """The race, built: ``solve`` checks its outputs (``res.jsonl`` is not there yet), plans,
    then waits on its ``--plot`` fifo; a batch creates ``res.jsonl`` and writes a row; only then
    is the fifo read. The last look before the rename sees the batch's lock: exit 2, and the
    batch's rows are all in its file."""
    fifo, out = tmp_path / "plot.png", tmp_path / "res.jsonl"
    os.mkfifo(fifo)
    proc = subprocess.Popen([*rrtpso_exe(), "solve", PROBLEM, *QUICK, "--plot", str(fifo),
                             "--json", str(out)], stderr=subprocess.PIPE, text=True)  # fmt: skip
    # Should solve end without opening the fifo, open it here: the test fails instead of waiting.
    threading.Thread(target=_open_when_done, args=(proc, fifo), daemon=True).start()
    try:
        with open(fifo, "rb") as plot:  # returns once solve opens it: its checks are past
            assert not out.exists()
            with ResultsFile(out) as batch:
                batch.append(_row(1))
                assert plot.read()[:4] == b"\x89PNG"  # solve goes on to its --json
                _, err = proc.communicate(timeout=120)
                batch.append(_row(2))
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 2, err
    assert f"{out}: cannot write: it is a results file locked by another process" in err
    assert [json.loads(line)["seed"] for line in out.read_text().splitlines()] == [1, 2]


def _open_when_done(proc: subprocess.Popen, fifo) -> None:
    """Once ``proc`` has ended, open ``fifo`` for writing (and close it), so that a reader still
    waiting for it returns (with nothing read)."""
    proc.wait()
    with contextlib.suppress(OSError):
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))


def test_batch_and_bench_leave_each_other_s_files_alone(made, tmp_path):
    bench = tmp_path / "bench"
    shutil.copytree(made / "bench", bench)
    before = (bench / "runs.jsonl").read_bytes()
    for extra in ([], ["--resume"], ["--overwrite"]):
        proc = run("batch", PROBLEM, *QUICK, "--out", str(bench / "runs.jsonl"), *extra)
        assert proc.returncode == 2 and "is the results file of the rrtpso bench in" in proc.stderr
        assert "rrtpso bench --resume" in proc.stderr
    assert (bench / "runs.jsonl").read_bytes() == before
    # A bench folder whose report.md is a batch's results file: the bench would replace it.
    folder = tmp_path / "b2"
    folder.mkdir()
    _copy_results(made, folder / "report.md")
    proc = run("bench", PROBLEM, "--planner", "RRTConnect", "--time", "0.1", "--runs", "1",
               "--out", str(folder))  # fmt: skip
    assert proc.returncode == 2 and "its report.md is a results file" in proc.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["report.md"]


def test_generate_overwrites_only_what_it_could_have_written(tmp_path):
    db = tmp_path / "results.db"
    db.write_bytes(b"SQLite format 3\0" + bytes(100))
    proc = run("generate", "slabs", "--seed", "1", "--overwrite", "--out", str(db))
    assert proc.returncode == 2, proc.stderr
    assert f"'{db}' is an SQLite database, not a problem or map file" in proc.stderr
    assert db.read_bytes().startswith(b"SQLite format 3\0")
    problem = tmp_path / "p.yaml"
    problem.write_text("# an older problem\n")
    proc = run("generate", "slabs", "--seed", "1", "--overwrite", "--out", str(problem))
    assert proc.returncode == 0, proc.stderr
    assert problem.read_text().startswith("# Generated by: rrtpso generate slabs --seed 1")


# -- item 5: a resumed batch or bench honours its settings ---------------------------------------
def test_batch_resume_with_other_parameters_runs_them_and_says_so(tmp_path):
    out = tmp_path / "res.jsonl"
    assert run("batch", PROBLEM, *QUICK, "--out", str(out)).returncode == 0
    proc = run("batch", PROBLEM, *QUICK, "--out", str(out), "--resume", "--param", "range=5")
    assert proc.returncode == 0, proc.stderr
    assert "already done" not in proc.stderr
    assert ("1 row of other settings (default parameters; these runs: range=5.0) stays in the "
            "file") in proc.stderr  # fmt: skip
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert [r["settings"]["params"] for r in rows] == [{}, {"range": 5.0}]
    assert rows[1]["params"]["range"] == 5.0  # the planner ran with it
    # The same setting spelled otherwise is done.
    proc = run("batch", PROBLEM, *QUICK, "--out", str(out), "--resume", "--param", "range=5.0")
    assert "resuming: 1 rows already done" in proc.stderr
    assert len(out.read_text().splitlines()) == 2
    # A row without settings (an earlier version's) is not taken for any settings.
    old = tmp_path / "old.jsonl"
    old.write_text(json.dumps({k: v for k, v in rows[0].items() if k != "settings"}) + "\n")
    proc = run("batch", PROBLEM, *QUICK, "--out", str(old), "--resume")
    assert "1 row of other settings (none recorded: an earlier version wrote them" in proc.stderr
    assert len(old.read_text().splitlines()) == 2


def _db_runs(db) -> int:
    with sqlite3.connect(db) as con:
        return con.execute("SELECT COUNT(*) FROM runs").fetchone()[0]


def _report_runs(folder) -> list[int]:
    with (folder / "report.csv").open(newline="") as fh:
        return [int(r["runs"]) for r in csv.DictReader(fh)]


def test_bench_resume_with_other_parameters_reports_only_them(tmp_path):
    out = tmp_path / "b"
    args = ("bench", PROBLEM, "--planner", "RRTConnect", "--time", "0.1", "--runs", "1", "--out",
            str(out))  # fmt: skip
    assert run(*args).returncode == 0
    proc = run(*args, "--resume", "--param", "range=5")
    assert proc.returncode == 0, proc.stderr
    assert "1 row of other settings (default parameters; these runs: range=5.0)" in proc.stderr
    assert len((out / "runs.jsonl").read_text().splitlines()) == 2  # both kept in the file
    assert _db_runs(out / "benchmark.db") == 1 and _report_runs(out) == [1]  # one configuration
    with sqlite3.connect(out / "benchmark.db") as con:
        (settings,) = con.execute("SELECT settings FROM plannerConfigs").fetchone()
    assert settings.startswith("range = 5.0")  # the database describes the runs it holds


# -- item 6: nothing duplicated, nothing dropped -------------------------------------------------
def test_a_budget_or_planner_named_twice_runs_once(tmp_path):
    out = tmp_path / "b"
    proc = run("bench", PROBLEM, "--planner", "RRTConnect,RRTConnect", "--time", "0.1,0.1",
               "--runs", "1", "--out", str(out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "--time: the budget 0.1 s is given 2 times; it is run once" in proc.stderr
    assert "--planner: RRTConnect is given 2 times; it is run once" in proc.stderr
    assert len((out / "runs.jsonl").read_text().splitlines()) == 1
    assert _db_runs(out / "benchmark.db") == 1 and _report_runs(out) == [1]


def test_a_folder_batch_makes_an_error_row_of_every_odd_entry(folder, tmp_path):
    os.mkfifo(folder / "fifo.yaml")  # never opened: the batch would wait for a writer
    (folder / "dangling.yaml").symlink_to("nowhere.yaml")
    (folder / "dir.yaml").mkdir()
    sock = socket.socket(socket.AF_UNIX)
    sock.bind(str(folder / "sock.yaml"))
    out = tmp_path / "r.jsonl"
    try:
        proc = run("batch", str(folder), *QUICK, "--out", str(out), timeout=240)
    finally:
        sock.close()
    assert proc.returncode == 1, proc.stderr
    errors = {json.loads(line)["file"]: json.loads(line)["error"]
              for line in out.read_text().splitlines()}  # fmt: skip
    assert errors[str(folder / "fifo.yaml")].endswith("is a fifo (named pipe), not a problem file")
    assert errors[str(folder / "sock.yaml")].endswith("is a socket, not a problem file")
    assert errors[str(folder / "dir.yaml")].endswith("is a directory, not a problem file")
    assert errors[str(folder / "dangling.yaml")].endswith(
        "is a symbolic link to 'nowhere.yaml', which does not exist"
    )
    assert errors[str(folder / "a_circle.yaml")] is None and len(errors) == 7  # 3 + 4 odd ones
    for name in ("fifo.yaml", "sock.yaml", "dir.yaml", "dangling.yaml"):
        assert str(folder / name) in proc.stderr


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads every file")
def test_an_unreadable_file_in_a_folder_is_an_error_row(folder, tmp_path):
    (folder / "a_circle.yaml").chmod(0)
    out = tmp_path / "r.jsonl"
    proc = run("batch", str(folder), *QUICK, "--out", str(out), timeout=240)
    assert proc.returncode == 1
    rows = {json.loads(line)["file"]: json.loads(line) for line in out.read_text().splitlines()}
    assert "Permission denied" in rows[str(folder / "a_circle.yaml")]["error"]
