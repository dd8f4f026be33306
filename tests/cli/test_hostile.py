"""Hostile input and output through the real command line, as a careless user would try it.

Every case runs ``rrtpso`` in a child process with an address-space limit, in a temporary folder
(never with system paths as targets), and checks: no traceback, the documented exit status,
inputs and foreign files unchanged, results files valid line by line.
"""

from __future__ import annotations

import json
import math
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import PROBLEMS, HeldBatch, rrtpso_exe

pytestmark = pytest.mark.slow

#: Address space of every child (bytes): a run that tries to expand a bomb hits it.
MEMORY_LIMIT = 2 << 30
CIRCLE = (PROBLEMS / "static" / "single_circle.yaml").read_text()
DYNAMIC = (PROBLEMS / "dynamic" / "head_on.yaml").read_text()


def _limit() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def run(*args, cwd: Path, timeout: float = 120, before=None,
        **kwargs) -> subprocess.CompletedProcess:  # fmt: skip
    """``rrtpso *args`` in a child; ``before`` runs in the child before the command starts."""

    def setup() -> None:
        _limit()
        if before is not None:
            before()

    kwargs.setdefault("capture_output", True)
    proc = subprocess.run([*rrtpso_exe(), *map(str, args)], cwd=cwd, text=True, timeout=timeout,
                          preexec_fn=setup, **kwargs)  # fmt: skip
    assert "Traceback" not in (proc.stderr or ""), proc.stderr
    return proc


def rows_of(path: Path) -> list[dict]:
    """Every line of a results file is one JSON row (no torn or foreign lines)."""
    text = path.read_text()
    assert text == "" or text.endswith("\n")
    rows = [json.loads(line) for line in text.splitlines()]
    assert all({"file", "planner", "seed", "run", "status"} <= set(r) for r in rows)
    return rows


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    (tmp_path / "p.yaml").write_text(CIRCLE)
    (tmp_path / "d.yaml").write_text(DYNAMIC)
    return tmp_path


# ----------------------------------------------------------------------------------------------
# Data loss and overwriting
# ----------------------------------------------------------------------------------------------
def test_a_second_batch_on_the_same_file_is_refused_and_the_first_keeps_its_rows(folder):
    # The first batch holds after its first row (the test hook) until the second has been refused:
    # "while the first still writes" by construction. RRTConnect stops at its first path.
    args = ["batch", "p.yaml", "--planner", "RRTConnect", "--runs", "4", "--time", "5",
            "--out", "r.jsonl"]  # fmt: skip
    held = HeldBatch(folder)
    first = subprocess.Popen([*rrtpso_exe(), *args], cwd=folder, stderr=subprocess.PIPE,
                             text=True, preexec_fn=_limit, env=held.env)  # fmt: skip
    held.wait_for_rows(first, folder / "r.jsonl")
    second = run(*args, "--overwrite", cwd=folder)
    assert second.returncode == 2 and "another rrtpso batch or bench is writing" in second.stderr
    held.release()
    _, err = first.communicate(timeout=120)
    assert first.returncode == 0 and "Traceback" not in err, err
    assert len(rows_of(folder / "r.jsonl")) == 4


def test_outputs_that_are_inputs_or_each_other_are_refused(folder):
    before = (folder / "p.yaml").read_text()
    for args, words in [
        (["solve", "p.yaml", "--json", "p.yaml"], "is an input"),
        (["batch", "p.yaml", "--out", "p.yaml"], "is an input"),
        (["solve", "p.yaml", "--json", "x", "--trajectory", "x"], "both name the same file"),
        (["solve", "p.yaml", "--json", "-", "--trajectory", "-"], "standard output"),
        (["solve", "p.yaml", "--json", ""], "give a file name"),
        (["solve", "p.yaml", "--planner", ""], "give a planner name"),
        (["solve", "p.yaml", "--plot", "-"], "only for text outputs"),
        (["optimum", "p.yaml", "--json", "p.yaml"], "is an input"),
    ]:
        proc = run(*args, cwd=folder)
        assert proc.returncode == 2 and words in proc.stderr, (args, proc.stderr)
    assert (folder / "p.yaml").read_text() == before
    assert not (folder / "x").exists()


def test_only_our_results_files_are_resumed_or_replaced(folder):
    (folder / "notes.txt").write_text("my notes\n")
    (folder / "keep.jsonl").write_text('{"keep": 1}\n')
    for target in ("notes.txt", "keep.jsonl"):
        for flag in ("--resume", "--overwrite", None):
            extra = [flag] if flag else []
            proc = run("batch", "p.yaml", "--time", "0.1", "--out", target, *extra, cwd=folder)
            assert proc.returncode == 2, proc.stderr
    assert (folder / "notes.txt").read_text() == "my notes\n"
    assert (folder / "keep.jsonl").read_text() == '{"keep": 1}\n'
    # An earlier run's results: refused without a flag, continued or replaced with one.
    assert run("batch", "p.yaml", "--time", "0.1", "--out", "r.jsonl", cwd=folder).returncode == 0
    proc = run("batch", "p.yaml", "--time", "0.1", "--out", "r.jsonl", cwd=folder)
    assert proc.returncode == 2 and "--resume" in proc.stderr and "--overwrite" in proc.stderr
    assert len(rows_of(folder / "r.jsonl")) == 1
    proc = run("batch", "p.yaml", "--time", "0.1", "--runs", "2", "--out", "r.jsonl", "--resume",
               cwd=folder)  # fmt: skip
    assert proc.returncode == 0 and len(rows_of(folder / "r.jsonl")) == 2
    assert run("batch", "p.yaml", "--time", "0.1", "--out", "r.jsonl", "--overwrite",
               cwd=folder).returncode == 0  # fmt: skip
    assert len(rows_of(folder / "r.jsonl")) == 1


def test_links_fifos_modes_and_stdout_are_written_as_what_they_are(folder):
    (folder / "target.json").write_text("old")
    (folder / "link.json").symlink_to("target.json")
    (folder / "private.json").write_text("old")
    (folder / "private.json").chmod(0o600)
    for out in ("link.json", "private.json"):
        assert run("solve", "p.yaml", "--time", "0.1", "--json", out, cwd=folder).returncode == 0
    assert (folder / "link.json").is_symlink()
    assert json.loads((folder / "target.json").read_text())["solved"]
    assert (folder / "private.json").stat().st_mode & 0o777 == 0o600
    os.mkfifo(folder / "fifo")
    reader = subprocess.Popen(["cat", str(folder / "fifo")], stdout=subprocess.PIPE, text=True)
    assert run("solve", "p.yaml", "--time", "0.1", "--json", "fifo", cwd=folder).returncode == 0
    assert json.loads(reader.communicate(timeout=30)[0])["solved"]
    assert (folder / "fifo").is_fifo()
    proc = run("solve", "p.yaml", "--time", "0.1", "--json", "-", cwd=folder)
    assert proc.returncode == 0 and json.loads(proc.stdout)["planner"] == "RRTstarPSO"


# ----------------------------------------------------------------------------------------------
# Crashes, tracebacks, hangs
# ----------------------------------------------------------------------------------------------
SEEDS = [
    (["solve", "p.yaml", "--seed", "-1"], "--seed"),
    (["solve", "p.yaml", "--seed", str(2**64)], "--seed"),
    (["solve", "p.yaml", "--param", f"seed={2**32}"], "seed"),
    (["simulate", "d.yaml", "--seed=-1"], "--seed"),
    (["batch", "p.yaml", "--seed", str(2**32 - 1), "--runs", "2", "--out", "o.jsonl"], "last run"),
    (["generate", "circles", "--seed", "-3", "--out", "g.yaml"], "--seed"),
]


@pytest.mark.parametrize(("args", "words"), SEEDS, ids=lambda a: " ".join(a)[:40])
def test_one_seed_range_everywhere(folder, args, words):
    proc = run(*args, cwd=folder)
    assert proc.returncode == 2 and words in proc.stderr
    assert "2**32 - 1" in proc.stderr or "4294967295" in proc.stderr


def _problem(folder: Path, name: str, text: str) -> str:
    (folder / name).write_text(text)
    return name


BAD_VALUES = [
    ("planner:\n  params: {swarm_size: .inf}\n", "planner.params.swarm_size"),
    ("planner:\n  seed: 18446744073709551615\n", "planner.seed"),
    ("planner:\n  time_limit: 1.0e+308\n", "planner.time_limit"),
]


@pytest.mark.parametrize(("extra", "key"), BAD_VALUES, ids=["swarm", "seed", "time"])
def test_values_that_cannot_be_honoured_in_a_file(folder, extra, key):
    name = _problem(folder, "bad.yaml", CIRCLE.split("planner:")[0] + extra)
    proc = run("solve", name, "--json", "out.json", cwd=folder)
    assert proc.returncode == 2 and f"bad.yaml: {key}" in proc.stderr
    assert not (folder / "out.json").exists()


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("bounds: [[0, 0], [1.0e-15, 1.0e-15]]\nstart: [0, 0]\ngoal: [1.0e-15, 1.0e-15]\n"
         "robot: {radius: 0}\n", "too small"),
        ("bounds: [[0, 0], [30, 40]]\nstart: [1, 1]\ngoal: [20, 20]\nrobot: {radius: 1}\n"
         "obstacles:\n  - {type: rectangle, min: [5, 5], max: [30, 1.0e+160]}\n", "within +-1e+09"),
        ("bounds: [[0, 0], [1.0e+12, 1.0e+12]]\nstart: [1, 1]\ngoal: [20, 20]\n"
         "robot: {radius: 1}\n", "within +-1e+09"),
    ],
    ids=["tiny-bounds", "huge-rectangle", "huge-bounds"],
)  # fmt: skip
def test_geometry_that_cannot_be_checked_exactly(folder, text, words):
    name = _problem(folder, "g.yaml", text)
    for command in ("solve", "optimum"):
        proc = run(command, name, cwd=folder)
        assert proc.returncode == 2 and words in proc.stderr, proc.stderr


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--time", "1e10"], "at most 1e+06 s"),
        (["--time", "nan"], "finite"),
        (["--param", "budget=1e300"], "budget"),
        (["--trajectory", "afile/t.csv"], "is a file, not a directory"),
    ],
)
def test_flags_that_cannot_be_honoured(folder, args, words):
    (folder / "afile").write_text("a file")
    proc = run("solve", "p.yaml", *args, cwd=folder)
    assert proc.returncode == 2 and words in proc.stderr, proc.stderr


def test_missing_output_folders_are_created(folder):
    proc = run("solve", "p.yaml", "--time", "0.2", "--trajectory", "new/dir/t.csv", "--json",
               "new/r.json", cwd=folder)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert (folder / "new/dir/t.csv").read_text().startswith("t,x,y,theta")


def test_a_closed_pipe_is_not_a_traceback(folder):
    for _ in range(3):  # whether head leaves before or after the last write: the same answer
        proc = subprocess.run(f"{' '.join(rrtpso_exe())} planners | head -1; "
                              "exit ${PIPESTATUS[0]}", shell=True, executable="/bin/bash",
                              capture_output=True, text=True, timeout=60)  # fmt: skip
        assert proc.stdout.strip() and proc.stderr == "" and proc.returncode == 0, proc.stderr


def _with_closed_stdout(*args: str, cwd: Path) -> tuple[int, str]:
    """Run ``rrtpso args`` with a standard output whose reader has already gone away: every
    write to it fails with EPIPE, deterministically."""
    proc = subprocess.Popen([*rrtpso_exe(), *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=_limit)  # fmt: skip
    proc.stdout.close()
    err = proc.stderr.read()
    return proc.wait(timeout=120), err


@pytest.mark.parametrize(
    ("args", "status"),
    [
        (["planners"], 0),
        (["planners", "--json"], 0),
        # a single result on stdout: the command finishes and keeps its own status
        (["solve", "p.yaml", "--planner", "RRTConnect", "--time", "0.5", "--json", "-"], 0),
        (["solve", "walled.yaml", "--planner", "RRTstar", "--time", "0.05", "--json", "-"], 1),
        # a batch streaming rows: nobody reads the rest, so it stops
        (["batch", "p.yaml", "--planner", "RRTConnect", "--runs", "50", "--time", "0.5",
          "--out", "-"], 0),
    ],
    ids=["planners", "planners-json", "solve-solved", "solve-unsolved", "batch"],
)  # fmt: skip
def test_a_closed_pipe_is_quiet(folder, args, status):
    # A wall across the whole workspace: unsolved on any machine, however fast.
    (folder / "walled.yaml").write_text(
        "bounds: [[0, 0], [100, 100]]\nstart: [50, 10]\ngoal: [50, 90]\nrobot: {radius: 2}\n"
        "obstacles:\n  - {type: rectangle, min: [0, 45], max: [100, 55]}\n"
    )
    code, err = _with_closed_stdout(*args, "-q", cwd=folder)
    assert code == status and err == "", err


def test_quiet_silences_a_broken_plugins_warning(folder):
    """A third-party plugin that fails to load is a warning, and -q shows only errors."""
    info = folder / "site" / "broken_plugin-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        "[rrtpso_ompl.planners]\nbroken = no_such_module_of_rrtpso:PLANNERS\n"
    )
    env = {**os.environ, "PYTHONPATH": str(folder / "site")}
    loud = run("planners", cwd=folder, env=env)
    assert loud.returncode == 0 and "skipping planner plugin" in loud.stderr  # it is found
    quiet = run("planners", "-q", cwd=folder, env=env)
    assert quiet.returncode == 0 and quiet.stderr == "" and "RRTstarPSO" in quiet.stdout
    quiet = run("solve", "p.yaml", "--time", "0.1", "-q", cwd=folder, env=env)
    assert quiet.returncode == 0 and quiet.stderr == ""


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["solve", "p.yaml", "--param", "swarm_siz=3"], "(did you mean 'swarm_size'?)"),
        (["solve", "p.yaml", "--planner", "RRTstar", "--param", "rang=3"],
         "(did you mean 'range'?)"),
        (["batch", "p.yaml", "--planner", "RRTstar,RRTConnect", "--param", "rang=3", "--out",
          "r.jsonl"], "(did you mean 'range'?)"),
        (["bench", "p.yaml", "--planner", "RRTstar+pso", "--param", "post_fractio=0.3", "--out",
          "b"], "(did you mean 'post_fraction'?)"),
        (["solve", "p.yaml", "--param", "swarm_size=3", "--param", "swarm_size=4"],
         "--param swarm_size: given twice (swarm_size=3 and swarm_size=4)"),
        (["batch", "p.yaml", "--param", "iterations=3", "--param", "iterations = 4", "--out",
          "r.jsonl"], "--param iterations: given twice"),
    ],
    ids=["solve", "solve-rrtstar", "batch", "bench-post-pass", "twice-solve", "twice-batch"],
)  # fmt: skip
def test_a_misspelt_or_repeated_param_is_refused_with_a_hint(folder, args, words):
    proc = run(*args, cwd=folder)
    assert proc.returncode == 2 and words in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") == 1  # one message
    assert not (folder / "r.jsonl").exists() and not (folder / "b").exists()


def test_ctrl_c_in_a_batch_leaves_a_valid_file_and_no_tracebacks(folder):
    # Held after its first row (the test hook): Ctrl-C comes while the batch runs, on any machine.
    args = ["batch", "p.yaml", "--planner", "RRTConnect", "--runs", "6", "--time", "5",
            "--jobs", "2", "--out", "r.jsonl"]  # fmt: skip
    held = HeldBatch(folder)
    proc = subprocess.Popen([*rrtpso_exe(), *args], cwd=folder, stderr=subprocess.PIPE,
                            text=True, preexec_fn=_limit, env=held.env)  # fmt: skip
    held.wait_for_rows(proc, folder / "r.jsonl")
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err, err
    assert len(rows_of(folder / "r.jsonl")) == 1
    # and it continues: the same runs, the one done kept
    proc = run(*args, "--resume", cwd=folder)
    assert proc.returncode == 0, proc.stderr
    rows = rows_of(folder / "r.jsonl")
    assert sorted(r["seed"] for r in rows) == [1, 2, 3, 4, 5, 6] and all(r["solved"] for r in rows)


def test_inputs_too_large_for_the_machine_end_cleanly(folder):
    circles = "\n".join(f"  - {{type: circle, center: [{10 + (i % 60) * 16}, "
                        f"{10 + (i // 60) * 16}], radius: 2}}" for i in range(2100))  # fmt: skip
    head = "bounds: [[0, 0], [1000, 1000]]\nstart: [1, 1]\ngoal: [999, 999]\n"
    name = _problem(folder, "many.yaml", f"{head}robot: {{radius: 0.5}}\nobstacles:\n{circles}\n")
    # The optimum grows its graph as it searches: thousands of obstacles are routine now.
    proc = run("optimum", name, "--json", "o.json", cwd=folder)
    assert proc.returncode == 0 and json.loads((folder / "o.json").read_text())["length"] > 1400
    proc = run("generate", "circles", "--seed", "1", "--n", "100000000", "--out", "g.yaml",
               cwd=folder)  # fmt: skip
    assert proc.returncode == 2 and "'n' must be in [1, 100000], got 100000000" in proc.stderr


@pytest.mark.parametrize(
    ("edit", "status", "words"),
    [
        (("speed: 15, heading_deg: 180", "speed: 0, heading_deg: 180"), 1, "goal blocked"),
        (("start: [470, 250], speed: 15", "start: [30, 250], speed: 0"), 1, "start blocked"),
        (("sample_time: 0.15", "sample_time: 1.0e-9"), 2, "control steps"),
        (("  speed: 20", "  speed: 1.0e-9"), 2, "control steps"),
    ],
    ids=["still-on-goal", "still-on-start", "tiny-sample-time", "tiny-speed"],
)
def test_simulations_that_cannot_end_stop_with_a_status(folder, edit, status, words):
    name = _problem(folder, "s.yaml", DYNAMIC.replace(*edit))
    proc = run("simulate", name, "--json", "s.json", cwd=folder, timeout=60)
    assert proc.returncode == status and words in proc.stderr, proc.stderr


# ----------------------------------------------------------------------------------------------
# Memory
# ----------------------------------------------------------------------------------------------
def test_an_alias_bomb_is_refused_within_the_memory_limit(folder):
    lines = ["bounds: [[0, 0], [100, 100]]", "start: [1, 1]", "goal: [99, 99]",
             "robot: {radius: 1}", "x0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]"]  # fmt: skip
    lines += [f"x{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 10)]
    lines.append("planner: {params: {swarm_size: *a9}}")
    name = _problem(folder, "bomb.yaml", "\n".join(lines) + "\n")
    proc = run("solve", name, cwd=folder)
    assert proc.returncode == 2 and "aliases expand" in proc.stderr
    assert len(proc.stderr) < 500
    name = _problem(folder, "loop.yaml", CIRCLE + "x: &a [1, *a]\n")
    proc = run("solve", name, cwd=folder)
    assert proc.returncode == 2 and "recursive alias" in proc.stderr


def test_a_long_value_is_echoed_short(folder):
    name = _problem(folder, "long.yaml", CIRCLE.split("planner:")[0] +
                    f"planner:\n  params: {{swarm_size: {'9' * 5000}}}\n")  # fmt: skip
    proc = run("solve", name, cwd=folder)
    assert proc.returncode == 2 and len(proc.stderr) < 400


#: A megabyte of one letter, and a long command-line argument (Linux allows 128 KiB).
MEGABYTE, ARGUMENT = "u" * 2**20, "u" * 100_000
#: A problem without robot, obstacles, units or planner: each case adds what it tests.
_BASE = "bounds: [[0, 0], [500, 500]]\nstart: [20, 20]\ngoal: [450, 450]\n"
_ROBOT = "robot: {radius: 1}\n"


@pytest.mark.parametrize(
    ("args", "text", "where"),
    [
        (["solve", "x.yaml", "--path-out", "p.yaml"], f"{_ROBOT}units: {MEGABYTE}\n",
         "x.yaml: units: "),
        (["solve", "x.yaml"], f"{_ROBOT}? {MEGABYTE}\n: 1\n", "x.yaml: uuuu"),  # a long key
        (["solve", "x.yaml"], f"robot:\n  radius: 1\n  ? {MEGABYTE}\n  : 2\n",
         "x.yaml: robot.uuu"),
        (["solve", "x.yaml"], f"{_ROBOT}planner: {{type: {MEGABYTE}}}\n",
         "x.yaml: planner.type: "),
        (["solve", "x.yaml"], f"{_ROBOT}planner:\n  params:\n    ? {MEGABYTE}\n    : 3\n",
         "x.yaml: planner.params.uuu"),
        (["solve", "x.yaml"], f"{_ROBOT}planner: {{params: {{swarm_size: '{'1' * 2**20}e3'}}}}\n",
         "x.yaml: planner.params.swarm_size: "),
        (["optimum", "x.yaml"], f"{_ROBOT}obstacles: [{{type: {MEGABYTE}}}]\n",
         "x.yaml: obstacles[0]"),
        (["optimum", "x.yaml"], f"{_ROBOT}map: {MEGABYTE}\n", "x.yaml: map: "),
        (["solve", "p.yaml", "--planner", ARGUMENT], "", "--planner: unknown planner 'uuu"),
        (["solve", "p.yaml", "--param", f"{ARGUMENT}=1"], "", "no parameter 'uuu"),
        (["solve", "p.yaml", "--param", f"swarm_size={ARGUMENT}"], "", "swarm_size"),
        (["solve", "p.yaml", "--param", ARGUMENT], "", "expected NAME=VALUE"),
        (["solve", "p.yaml", "--post", ARGUMENT], "", "unknown post-pass 'uuu"),
        (["simulate", "d.yaml", "--strategy", ARGUMENT], "", "--strategy: invalid choice"),
        (["batch", "p.yaml", "--runs", "9" * 4000, "--out", "r.jsonl"], "", "--runs: must be"),
        (["batch", "p.yaml", "--runs", "9" * 5000, "--out", "r.jsonl"], "", "argument --runs"),
        (["batch", "p.yaml", "--planner", ARGUMENT, "--out", "r.jsonl"], "", "unknown planner"),
    ],
    ids=["units", "key", "robot-key", "planner-type", "param-key", "param-number", "obstacle-type",
         "map", "--planner", "--param-name", "--param-value", "--param-form", "--post",
         "--strategy", "--runs", "--runs-digits", "batch-planner"],
)  # fmt: skip
def test_every_echoed_value_is_shown_short(folder, args, text, where):
    """A value of a megabyte (or a whole command-line argument) is echoed by its beginning, its
    end and its length, in one short message that still names the file and the key (issue 32,
    item 10: a 1 MB `units:` value was echoed whole)."""
    if text:
        (folder / "x.yaml").write_text(_BASE + text)
    proc = run(*args, cwd=folder)
    assert proc.returncode == 2, proc.stderr[:500]
    message = proc.stderr.strip().splitlines()[-1]  # after argparse's usage lines
    assert where in message and len(message) < 1200, proc.stderr[-1200:]
    assert len(proc.stderr) < 2500 and "characters)" in message  # and how long the value was
    assert len(proc.stderr.strip().splitlines()) == 1 or proc.stderr.startswith("usage:")


def test_a_batch_input_whose_name_is_too_long_is_an_error_row(folder):
    """Not a traceback (pathlib's is_dir lets ENAMETOOLONG through): an error row, its message
    naming the input by its ends and its length."""
    proc = run("batch", ARGUMENT, "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out",
               "r.jsonl", cwd=folder)  # fmt: skip
    assert proc.returncode == 1, proc.stderr[-500:]
    bad, good = rows_of(folder / "r.jsonl")
    assert bad["file"] == ARGUMENT and bad["status"] == "error" and good["status"] == "exact"
    assert bad["error"].endswith("(100,000 characters): cannot read it: File name too long")
    assert len(bad["error"]) < 1200 and len(proc.stderr) < 2500


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("/dev/zero", "/dev/zero: is a character device, not a regular file"),
        ("fifo.yaml", "fifo.yaml: is a fifo (named pipe), not a regular file"),
        ("sub", "sub: is a directory, not a regular file"),
        ("absent.yaml", "absent.yaml: no such file"),
        ("big.yaml", "big.yaml: the file is larger than 64 MiB"),
        ("m.yaml", "m.yaml: image: /dev/zero is a character device"),
    ],
    ids=["dev-zero", "fifo", "dir", "absent", "huge", "image-device"],
)
def test_a_map_that_cannot_be_read_names_the_problem_file_and_its_key(folder, name, words):
    """`map: /dev/zero` said only "/dev/zero: is a character device" (issue 32, item 10): the
    problem file and its key come first, then what the map's own reader says."""
    os.mkfifo(folder / "fifo.yaml")
    (folder / "sub").mkdir()
    with open(folder / "big.yaml", "wb") as fh:  # sparse: no 64 MiB written
        fh.truncate(64 * 2**20 + 1)
    (folder / "m.yaml").write_text(MAP_YAML.format(image="/dev/zero"))
    for key, text in (("map", f"map: {name}\n"), ("map.file", f"map: {{file: {name}}}\n")):
        (folder / "mp.yaml").write_text(MAP_PROBLEM.replace("map: m.yaml\n", text))
        for command in ("solve", "optimum"):
            proc = run(command, "mp.yaml", cwd=folder, timeout=60)
            assert proc.returncode == 2, proc.stderr
            assert f"rrtpso: error: mp.yaml: {key}: " in proc.stderr and words in proc.stderr
            assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr


# ----------------------------------------------------------------------------------------------
# Command-line conventions
# ----------------------------------------------------------------------------------------------
def test_conventions(folder):
    proc = run("solve", "p.yaml", "--planner", "rrtstar", cwd=folder)
    assert proc.returncode == 2 and "did you mean 'RRTstar'" in proc.stderr
    proc = subprocess.run([sys.executable, "-m", "rrtpso_ompl", "--version"],
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert proc.returncode == 0 and proc.stdout.startswith("rrtpso ")
    proc = run("solve", "p.yaml", "--time", "0.1", "-q", cwd=folder)
    assert proc.returncode == 0 and proc.stderr == ""
    proc = run("bench", "p.yaml", "--planner", "RRTConnect", "--runs", "1", "--time", "0.1",
               "--out", "b", "-q", cwd=folder)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert (folder / "b" / "benchmark.db").exists()


def test_generate_never_replaces_a_file_unasked(folder):
    before = (folder / "p.yaml").read_text()
    proc = run("generate", "circles", "--seed", "1", "--out", "p.yaml", cwd=folder)
    assert proc.returncode == 2 and "--overwrite" in proc.stderr
    assert (folder / "p.yaml").read_text() == before
    proc = run("generate", "circles", "--seed", "1", "--out", "p.yaml", "--overwrite", cwd=folder)
    assert proc.returncode == 0 and (folder / "p.yaml").read_text() != before


# ----------------------------------------------------------------------------------------------
# Never touch what is the user's (issue 22)
# ----------------------------------------------------------------------------------------------
def snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every entry under ``folder``: a file's bytes, a link's target, or what else it is."""
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        key = str(p.relative_to(folder))
        if p.is_symlink():
            out[key] = "-> " + os.readlink(p)
        elif p.is_fifo():
            out[key] = "fifo"
        elif p.is_dir():
            out[key] = "dir"
        else:
            out[key] = p.read_bytes()
    return out


@pytest.fixture
def maps(folder: Path) -> Path:
    """``folder`` with the map problems (maps/) and a moving-obstacle problem on a map
    (dynamic/office_people.yaml, whose map is ../maps/grids/office.yaml)."""
    import shutil

    shutil.copytree(PROBLEMS / "maps", folder / "maps")
    (folder / "dynamic").mkdir()
    shutil.copy(PROBLEMS / "dynamic" / "office_people.yaml", folder / "dynamic")
    (folder / "image-link.pgm").symlink_to("maps/grids/office.pgm")
    os.link(folder / "maps/grids/office.pgm", folder / "hard-link.pgm")
    return folder


MAP_AS_OUTPUT = [
    ("solve", "maps/office_corridor.yaml", "--json", "maps/grids/office.pgm"),
    ("solve", "maps/office_corridor.yaml", "--json", "maps/grids/office.yaml"),
    ("solve", "maps/office_corridor.yaml", "--path-out", "maps/grids/office.yaml"),
    ("solve", "maps/office_corridor.yaml", "--trajectory", "image-link.pgm"),
    ("solve", "maps/office_corridor.yaml", "--json", "hard-link.pgm"),
    ("solve", "maps/lab_clutter.yaml", "--plot", "maps/grids/lab.png"),
    ("optimum", "maps/office_corridor.yaml", "--json", "maps/grids/office.yaml"),
    ("optimum", "maps/lab_clutter.yaml", "--plot", "maps/grids/lab.png"),
    ("optimum", "maps/office_corridor.yaml", "--path-out", "maps/grids/office.yaml"),
    ("simulate", "dynamic/office_people.yaml", "--path-out", "hard-link.pgm"),
    ("simulate", "dynamic/office_people.yaml", "--json", "maps/grids/office.yaml"),
    ("simulate", "dynamic/office_people.yaml", "--plot", "image-link.pgm.png"),
]


@pytest.mark.parametrize("args", MAP_AS_OUTPUT, ids=lambda a: f"{a[0]} {a[2]} {a[3]}")
def test_map_files_are_inputs_and_never_outputs(maps, args):
    if args[-1] == "image-link.pgm.png":  # a link named like an image, to the map's image
        (maps / "image-link.pgm.png").symlink_to("maps/grids/office.pgm")
    before = snapshot(maps)
    extra = ["--time", "0.1"] if args[0] != "optimum" else []
    proc = run(*args, *extra, cwd=maps)
    assert proc.returncode == 2 and f"{args[2]}: '{args[3]}' is an input" in proc.stderr, (
        proc.stderr
    )
    assert snapshot(maps) == before


def test_batch_and_bench_refuse_map_files_as_outputs(maps):
    before = snapshot(maps)
    proc = run("batch", "maps/office_corridor.yaml", "--out", "image-link.pgm", cwd=maps)
    assert proc.returncode == 2 and "is an input" in proc.stderr, proc.stderr
    # The bench writes report.md and others into --out: a map image of one of those names.
    (maps / "b").mkdir()
    (maps / "b/runs.jsonl").write_text("")
    (maps / "b/ratio.png").symlink_to("../maps/grids/lab.png")
    before = snapshot(maps)
    proc = run("bench", "maps/lab_clutter.yaml", "--planner", "RRTConnect", "--runs", "1",
               "--time", "0.1", "--out", "b", cwd=maps)  # fmt: skip
    assert proc.returncode == 2 and "'b/ratio.png' is an input" in proc.stderr, proc.stderr
    assert snapshot(maps) == before


#: Files that are not results files of this program (item 2 of issue 22).
ROW = b'{"file": "p.yaml", "planner": "RRTConnect", "seed": 1, "run": 0, "status": "exact"}\n'
FOREIGN = {
    "notes": b"my notes",
    "keep": b'{"keep": 1}',
    "binary": bytes(b for b in range(256) if b != 10),
    "blank-lines": b"\n\n",
    "rows-then-foreign": ROW + b'{"foreign": 2',
    "row-then-text": ROW + b"total: 1 run",
    "notes-with-newline": b"my notes\n",
}


@pytest.mark.parametrize("flag", ["--resume", "--overwrite", None])
@pytest.mark.parametrize("name", list(FOREIGN))
def test_files_that_are_not_results_files_are_never_continued_or_replaced(folder, name, flag):
    (folder / "r.jsonl").write_bytes(FOREIGN[name])
    before = snapshot(folder)
    proc = run("batch", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out",
               "r.jsonl", *([flag] if flag else []), cwd=folder)  # fmt: skip
    assert proc.returncode == 2 and "not a results file" in proc.stderr, proc.stderr
    assert snapshot(folder) == before


def test_a_bench_never_takes_over_a_runs_file_it_did_not_write(folder):
    (folder / "b").mkdir()
    for content in (b"my notes", b'{"keep": 1}\n', ROW + b"garbage"):
        (folder / "b/runs.jsonl").write_bytes(content)
        before = snapshot(folder)
        for flag in ("--resume", "--overwrite"):
            proc = run("bench", "p.yaml", "--planner", "RRTConnect", "--runs", "1", "--time",
                       "0.05", "--out", "b", flag, cwd=folder)  # fmt: skip
            assert proc.returncode == 2 and "not a results file" in proc.stderr, proc.stderr
            assert snapshot(folder) == before


def test_a_results_file_of_ours_cut_short_is_continued(folder):
    # A batch killed in its first write: the start of one row, no newline.
    (folder / "r.jsonl").write_bytes(ROW[:30])
    proc = run("batch", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out", "r.jsonl",
               cwd=folder)  # fmt: skip
    assert proc.returncode == 2 and "0 rows (and a row cut short)" in proc.stderr, proc.stderr
    proc = run("batch", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out", "r.jsonl",
               "--resume", cwd=folder)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert len(rows_of(folder / "r.jsonl")) == 1


def test_resume_knows_a_file_however_it_is_spelled(folder):
    (folder / "probs").mkdir()
    (folder / "probs/p.yaml").write_text(CIRCLE)
    (folder / "link.yaml").symlink_to("probs/p.yaml")
    common = ["--planner", "RRTConnect", "--runs", "2", "--time", "0.05", "--out", "r.jsonl"]
    assert run("batch", "probs/p.yaml", *common, cwd=folder).returncode == 0
    spellings = (folder / "probs/p.yaml", "./probs/p.yaml", "link.yaml", "probs/../probs/p.yaml")
    for spelling in spellings:
        proc = run("batch", spelling, *common, "--resume", cwd=folder)
        assert proc.returncode == 0 and "2 rows already done" in proc.stderr, proc.stderr
        assert len(rows_of(folder / "r.jsonl")) == 2
    # One file named twice is one set of runs.
    proc = run("batch", "probs/p.yaml", str(folder / "probs/p.yaml"), "link.yaml", *common[:-1],
               "twice.jsonl", cwd=folder)  # fmt: skip
    assert proc.returncode == 0 and len(rows_of(folder / "twice.jsonl")) == 2


def test_resume_runs_again_what_an_edited_problem_file_would_change(folder):
    common = ["--planner", "RRTConnect", "--runs", "2", "--time", "0.05", "--out", "r.jsonl"]
    assert run("batch", "p.yaml", *common, cwd=folder).returncode == 0
    first = rows_of(folder / "r.jsonl")
    assert len({r["inputs_sha256"] for r in first}) == 1
    (folder / "p.yaml").write_text(CIRCLE.replace("radius: 80", "radius: 60"))
    proc = run("batch", "p.yaml", *common, "--resume", cwd=folder)
    assert proc.returncode == 0 and "already done" not in proc.stderr, proc.stderr
    rows = rows_of(folder / "r.jsonl")
    assert len(rows) == 4 and rows[2]["inputs_sha256"] != first[0]["inputs_sha256"]
    from rrtpso_ompl.harness import read_rows

    assert [r.inputs_sha256 for r in read_rows(folder / "r.jsonl")] == [
        rows[2]["inputs_sha256"]
    ] * 2


# -- writes that fail -------------------------------------------------------------------------
def _close_stdout() -> None:
    os.close(1)


def _close_stderr() -> None:
    os.close(2)


def _file_size_limit(size: int = 64):
    """Files of the child may not grow past ``size`` bytes: a write beyond fails (EFBIG), as on a
    full disk (which only a real file system can be, not /dev/full)."""

    def limit() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))

    return limit


TO_STDOUT = [
    ["solve", "p.yaml", "--time", "0.05", "--json", "-"],
    ["optimum", "p.yaml", "--json", "-"],
    ["generate", "circles", "--seed", "1", "--n", "3", "--out", "-"],
    ["batch", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out", "-"],
    ["planners"],
]


@pytest.mark.parametrize("args", TO_STDOUT, ids=lambda a: a[0])
def test_a_full_or_closed_standard_output_is_one_message(folder, args):
    before = snapshot(folder)
    with open("/dev/full", "w") as full:
        proc = run(*args, cwd=folder, stdout=full, stderr=subprocess.PIPE, capture_output=False)
    assert proc.returncode == 2, proc.stderr
    assert "standard output: cannot write: No space left on device" in proc.stderr
    assert proc.stderr.count("\n") == 1  # one message, not Python's at exit too
    proc = run(*args, cwd=folder, before=_close_stdout)
    assert proc.returncode == 2 and "standard output" in proc.stderr and "closed" in proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert snapshot(folder) == before


@pytest.mark.parametrize("args", TO_STDOUT[:4], ids=lambda a: a[0])
def test_a_reader_that_went_away_is_quiet(folder, args):
    """A reader that stops reading chose to (`| head -1`): no message, no traceback, and the
    command's own status (solve: 0 solved or 1 unsolved; the others 0)."""
    before = snapshot(folder)
    proc = subprocess.Popen([*rrtpso_exe(), *args, "-q"], cwd=folder, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=_limit)  # fmt: skip
    proc.stdout.close()  # before the command has imported anything, let alone written
    err = proc.stderr.read()
    code = proc.wait(timeout=120)
    assert err == "" and code in ((0, 1) if args[0] == "solve" else (0,)), (code, err)
    assert snapshot(folder) == before  # nothing left behind


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["solve", "p.yaml", "-v", "--time", "0.3", "--json", "-"], "Info:    RRTstar: Started"),
        (["solve", "p.yaml", "-vv", "--time", "0.3", "--json", "-"], "Debug:   RRTstar: "),
        (["solve", "p.yaml", "-v", "--planner", "PRMstar", "--time", "0.2", "--json", "-"],
         "Info:    PRMstar: "),
        (["simulate", "d.yaml", "-v", "--time", "0.3", "--json", "-"], "Info:    RRTstar: "),
        (["batch", "p.yaml", "-v", "--planner", "RRTstar,RRTConnect", "--runs", "2", "--time",
          "0.1", "--out", "-"], "batch: 4 rows"),
    ],
    ids=["solve-v", "solve-vv", "prmstar", "simulate", "batch"],
)  # fmt: skip
def test_with_ompl_talking_standard_output_holds_only_the_results(folder, args, words):
    """OMPL writes its Info and Debug lines to C++'s std::cout, descriptor 1: `-v --json -`
    gave a document jq could not parse (issue 32, item 3). Every log line goes to stderr."""
    proc = run(*args, cwd=folder)
    assert proc.returncode in (0, 1), proc.stderr
    if args[0] == "batch":
        rows = [json.loads(line) for line in proc.stdout.splitlines()]
        assert len(rows) == 4 and all(r["status"] == "exact" for r in rows)
    else:
        assert isinstance(json.loads(proc.stdout), dict)
    assert "Info:" not in proc.stdout and "Debug:" not in proc.stdout
    assert words in proc.stderr, proc.stderr[-2000:]


def test_with_ompl_talking_a_reader_that_went_away_is_still_quiet(folder):
    """The duplicate of standard output that results are written to is the one silenced: no
    Broken pipe, no traceback, the command's own status; OMPL's lines still on stderr."""
    proc = subprocess.Popen([*rrtpso_exe(), "solve", "p.yaml", "-v", "--time", "0.2", "--json",
                             "-"], cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, preexec_fn=_limit)  # fmt: skip
    proc.stdout.close()
    err = proc.stderr.read()
    assert proc.wait(timeout=120) in (0, 1), err
    assert "Info:    RRTstar" in err and "Broken pipe" not in err and "Traceback" not in err


def test_closed_standard_streams_change_nothing_else(folder):
    # stdout closed: the results file must not take its place (OMPL writes to descriptor 1).
    proc = run("batch", "-v", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out",
               "r.jsonl", cwd=folder, before=_close_stdout)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert len(rows_of(folder / "r.jsonl")) == 1
    proc = run("solve", "p.yaml", "--time", "0.05", "--json", "s.json", cwd=folder,
               before=_close_stdout)  # fmt: skip
    assert proc.returncode == 0 and json.loads((folder / "s.json").read_text())["solved"]
    # stderr closed: the summary line must not fall through into the JSON on stdout.
    proc = run("solve", "p.yaml", "--time", "0.05", "--json", "-", cwd=folder,
               before=_close_stderr)  # fmt: skip
    assert proc.returncode == 0 and json.loads(proc.stdout)["solved"]


@pytest.mark.parametrize(
    "args",
    [
        ["solve", "p.yaml", "--time", "0.05", "--json", "/dev/full"],
        ["solve", "p.yaml", "--time", "0.05", "--trajectory", "/dev/full"],
        ["optimum", "p.yaml", "--json", "/dev/full"],
        ["batch", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out", "/dev/full"],
    ],
    ids=lambda a: f"{a[0]} {a[-2]}",
)
def test_a_full_device_is_one_message(folder, args):
    proc = run(*args, cwd=folder)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip() == "rrtpso: error: /dev/full: cannot write: No space left on device"


SHORT_DYNAMIC = DYNAMIC.replace("goal: [470, 250]", "goal: [90, 250]")
#: Commands whose one output cannot be written; the second item: whether an old file is there.
WRITES = [
    (["solve", "p.yaml", "--json", "out.json"], True),
    (["solve", "p.yaml", "--plot", "out.png"], True),
    (["solve", "p.yaml", "--trajectory", "out.csv"], True),
    (["solve", "p.yaml", "--path-out", "out.yaml"], True),
    (["simulate", "s.yaml", "--gif", "out.gif"], True),
    (["optimum", "p.yaml", "--json", "out.json"], True),
    (["optimum", "p.yaml", "--path-out", "out.yaml"], True),
    (["simulate", "s.yaml", "--path-out", "out.yaml"], True),
    (["generate", "circles", "--seed", "1", "--overwrite", "--out", "out.yaml"], True),
    (["solve", "p.yaml", "--json", "new/folder/out.json"], False),
    (["batch", "p.yaml", "--planner", "RRTConnect", "--out", "new.jsonl"], False),
    (["batch", "p.yaml", "--planner", "RRTConnect", "--out", "new/r.jsonl"], False),
    (["bench", "p.yaml", "--planner", "RRTConnect", "--runs", "1", "--out", "nb"], False),
]


@pytest.mark.parametrize(("args", "old"), WRITES, ids=[f"{a[0]} {a[-1]}" for a, _ in WRITES])
def test_a_write_that_fails_leaves_the_old_file_and_nothing_else(folder, args, old):
    (folder / "s.yaml").write_text(SHORT_DYNAMIC)
    if old:  # an existing file: it must survive whole
        (folder / args[-1]).write_text("old\n")
    if args[0] in ("solve", "simulate", "batch", "bench"):
        args = [*args, "--time", "0.05"]
    before = snapshot(folder)
    proc = run(*args, cwd=folder, before=_file_size_limit())
    assert proc.returncode == 2, proc.stderr
    assert "cannot write: File too large" in proc.stderr and proc.stderr.count("\n") == 1
    assert snapshot(folder) == before  # no temporary file, no empty file or folder


def test_a_resumed_or_replaced_results_file_survives_a_failed_write(folder):
    common = ["batch", "p.yaml", "--planner", "RRTConnect", "--time", "0.05", "--out", "r.jsonl"]
    assert run(*common, "--no-path", cwd=folder).returncode == 0
    before = snapshot(folder)
    # Room for the rows there are, not for a row with a path: the first new row fails.
    room = _file_size_limit(len(before["r.jsonl"]) + 16)
    for flag in ("--resume", "--overwrite"):
        proc = run(*common, "--runs", "3", flag, cwd=folder, before=room)
        assert proc.returncode == 2 and "r.jsonl: cannot write: File too large" in proc.stderr
        assert snapshot(folder) == before, flag


def test_a_bench_whose_database_cannot_be_written_keeps_its_runs(folder):
    args = ["bench", "p.yaml", "--planner", "RRTConnect", "--runs", "1", "--time", "0.05",
            "--out", "b"]  # fmt: skip
    # Room for the runs and the log (about 1 kB each), not for the database (about 37 kB).
    proc = run(*args, cwd=folder, before=_file_size_limit(20_000))
    assert proc.returncode == 2, proc.stderr
    assert "b/benchmark.db: cannot write: " in proc.stderr and proc.stderr.count("\n") == 1
    assert sorted(p.name for p in (folder / "b").iterdir()) == [
        "runs.jsonl",
        "single_circle_0.05s.log",
    ]  # no temporary database
    proc = run(*args, "--resume", cwd=folder)
    assert proc.returncode == 0 and "1 runs already done" in proc.stderr, proc.stderr
    assert (folder / "b" / "benchmark.db").exists()


def test_a_full_disk_is_one_message(folder):
    """A real full file system: a 64 KiB tmpfs (in a user namespace, where one may be mounted)."""
    import shlex
    import shutil

    unshare = shutil.which("unshare")
    small = folder / "small"
    small.mkdir()
    exe = shlex.join(rrtpso_exe())
    script = (
        f"mount -t tmpfs -o size=64k tmpfs {shlex.quote(str(small))} || exit 77; "
        f"cd {shlex.quote(str(folder))}; echo old > small/r.json; "
        "head -c 100000 /dev/zero > small/fill; "
        f"{exe} solve p.yaml --time 0.05 --json small/r.json; echo status=$?; "
        f"{exe} batch p.yaml --planner RRTConnect --time 0.05 --out small/b.jsonl; echo status=$?;"
        f" {exe} bench p.yaml --planner RRTConnect --time 0.05 --runs 1 --out small/b; "
        "echo status=$?; cat small/r.json; ls -A small"
    )
    if unshare is None:
        pytest.skip("no unshare")
    proc = subprocess.run([unshare, "--user", "--map-root-user", "--mount", "sh", "-c", script],
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    if proc.returncode == 77 or "unshare:" in proc.stderr:
        pytest.skip(f"cannot mount a tmpfs here: {proc.stderr.strip()[:200]}")
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.stdout.split() == ["status=2", "status=2", "status=2", "old", "fill", "r.json"]
    assert "small/r.json: cannot write: No space left on device" in proc.stderr
    assert "small/b.jsonl: cannot write: No space left on device" in proc.stderr


# -- names too long for the file system ------------------------------------------------------
@pytest.mark.parametrize("size", [246, 250, 255])
def test_the_longest_names_are_written(folder, size):
    name = "a" * (size - 5) + ".json"
    proc = run("solve", "p.yaml", "--time", "0.05", "--json", name, cwd=folder)
    assert proc.returncode == 0, proc.stderr
    assert json.loads((folder / name).read_text())["solved"]
    assert sorted(p.name for p in folder.iterdir()) == sorted([name, "p.yaml", "d.yaml"])


@pytest.mark.parametrize(
    ("flag", "out"),
    [
        ("--json", "a" * 256 + ".json"),
        ("--plot", "b" * 300 + ".png"),
        ("--trajectory", "new/" + "c" * 256 + "/t.csv"),
        ("--out", "d" * 256 + ".jsonl"),
    ],
    ids=["json", "plot", "folder", "batch"],
)
def test_names_too_long_are_refused_before_planning(folder, flag, out):
    command = "batch" if flag == "--out" else "solve"
    before = snapshot(folder)
    proc = run(command, "p.yaml", "--time", "0.05", flag, out, cwd=folder)
    # "--json: ..." is the check before planning (a failed write after it names the file).
    assert proc.returncode == 2 and f"{flag}: cannot write" in proc.stderr, proc.stderr
    assert "bytes long, and the file system allows at most 255" in proc.stderr
    assert snapshot(folder) == before


def test_a_bench_of_a_problem_with_a_long_name_writes_its_log(folder):
    _problem(folder, "long.yaml", CIRCLE.replace("name: single_circle", "name: " + "n" * 300))
    proc = run("bench", "long.yaml", "--planner", "RRTConnect", "--runs", "1", "--time", "0.05",
               "--out", "b", cwd=folder)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    (log,) = (folder / "b").glob("*.log")
    assert log.name.startswith("nnnn") and len(log.name) <= 255


# -- inputs that are not regular files -------------------------------------------------------
MAP_YAML = "image: {image}\nresolution: 1.0\norigin: [0, 0, 0]\n"
MAP_PROBLEM = "map: m.yaml\nstart: [1, 1]\ngoal: [2, 2]\nrobot: {radius: 0.1}\n"


@pytest.mark.parametrize(
    ("image", "words"),
    [
        ("loop.png", "loop.png is a symbolic link loop"),
        ('"a\\0b.png"', "the file name holds a NUL byte"),
        ("sub", "sub is a directory, not a regular file"),
        ("fifo.pgm", "fifo.pgm is a fifo (named pipe), not a regular file"),
        ("/dev/zero", "/dev/zero is a character device, not a regular file"),
        ("absent.png", "no such image file"),
    ],
    ids=["loop", "nul", "dir", "fifo", "dev-zero", "absent"],
)
def test_map_images_that_are_not_files_are_named_for_what_they_are(folder, image, words):
    (folder / "loop.png").symlink_to("loop.png")
    (folder / "sub").mkdir()
    os.mkfifo(folder / "fifo.pgm")
    (folder / "m.yaml").write_text(MAP_YAML.format(image=image))
    (folder / "mp.yaml").write_text(MAP_PROBLEM)
    for command in ("solve", "optimum"):
        proc = run(command, "mp.yaml", cwd=folder, timeout=60)
        assert proc.returncode == 2 and "m.yaml: image: " in proc.stderr, proc.stderr
        assert words in proc.stderr, proc.stderr


def test_inputs_that_are_fifos_are_refused_at_once(folder):
    os.mkfifo(folder / "fifo.yaml")
    for command in ("solve", "optimum", "simulate"):
        proc = run(command, "fifo.yaml", cwd=folder, timeout=60)
        assert proc.returncode == 2, proc.stderr
        assert "fifo.yaml: is a fifo (named pipe), not a regular file" in proc.stderr
    # A map YAML that is a fifo, and a batch with a fifo among its files.
    os.mkfifo(folder / "m.yaml")
    (folder / "mp.yaml").write_text(MAP_PROBLEM)
    proc = run("solve", "mp.yaml", cwd=folder, timeout=60)
    assert proc.returncode == 2 and "m.yaml: is a fifo" in proc.stderr, proc.stderr
    proc = run("batch", "fifo.yaml", "p.yaml", "--planner", "RRTConnect", "--time", "0.05",
               "--out", "r.jsonl", cwd=folder, timeout=120)  # fmt: skip
    assert proc.returncode == 1
    rows = rows_of(folder / "r.jsonl")
    assert [bool(r["error"]) for r in rows] == [True, False]
    assert "is a fifo" in rows[0]["error"]


def test_an_output_inside_a_loop_of_links_is_refused(folder):
    (folder / "loop").symlink_to("loop")
    proc = run("solve", "p.yaml", "--time", "0.05", "--json", "loop/x.json", cwd=folder)
    assert proc.returncode == 2, proc.stderr
    assert "--json: cannot write 'loop/x.json': Too many levels of symbolic links" in proc.stderr
    proc = run("batch", "p.yaml", "--time", "0.05", "--out", "loop/r.jsonl", cwd=folder)
    assert proc.returncode == 2 and "Too many levels of symbolic links" in proc.stderr


# Signals: whatever stops the parent, its workers go with it (issue 22)
# ----------------------------------------------------------------------------------------------
def processes_in(folder: Path) -> list[int]:
    """Live processes (not zombies) whose working folder is ``folder``: the command and every
    process it started, however they were re-parented (no psutil: /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if os.readlink(entry / "cwd") != str(folder):
                continue
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue  # gone meanwhile, or not ours to read
        if state != "Z":
            found.append(int(entry.name))
    return found


def wait_for(predicate, seconds: float) -> bool:
    deadline = time.time() + seconds
    while time.time() < deadline:
        if predicate():
            return True
        time.sleep(0.1)
    return predicate()


needs_proc = pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="needs /proc")


@needs_proc
@pytest.mark.parametrize(
    ("command", "sig"),
    [("batch", signal.SIGTERM), ("batch", signal.SIGHUP), ("batch", signal.SIGKILL),
     ("bench", signal.SIGTERM)],
    ids=["batch-TERM", "batch-HUP", "batch-KILL", "bench-TERM"],
)  # fmt: skip
def test_a_killed_batch_leaves_no_worker_and_a_valid_file(tmp_path, command, sig):
    (tmp_path / "p.yaml").write_text(CIRCLE)
    out = ["--out", "r.jsonl"] if command == "batch" else ["--out", "b"]
    # RRT* uses its whole budget: 30 s runs that must not outlive the parent.
    proc = subprocess.Popen([*rrtpso_exe(), command, "p.yaml", "--planner", "RRTstar", "--runs",
                             "4", "--time", "30", "--jobs", "2", *out],
                            cwd=tmp_path, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_limit)  # fmt: skip
    # The parent, the tracker, two workers and the children they fork for the runs.
    assert wait_for(lambda: len(processes_in(tmp_path)) >= 6, 90), processes_in(tmp_path)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert wait_for(lambda: not processes_in(tmp_path), 15), processes_in(tmp_path)
    assert "Traceback" not in err, err
    results = tmp_path / ("r.jsonl" if command == "batch" else "b/runs.jsonl")
    if results.exists():
        rows_of(results)  # valid line by line, whatever killed it
    if sig != signal.SIGKILL:  # these end like Ctrl-C: documented status, no temporary files
        # ... and no empty results file: before any run ended there is nothing to keep
        assert not results.exists() or results.stat().st_size > 0
        assert proc.returncode == 128 + sig, err
        assert f"terminated by {signal.Signals(sig).name}" in err
        assert not [p for p in tmp_path.rglob(".*") if p.is_file()]


@needs_proc
def test_sigterm_while_writing_a_trajectory_removes_its_temporary_file(tmp_path):
    # About 700,000 wheel-command rows: seconds of writing, and a temporary file meanwhile.
    (tmp_path / "p.yaml").write_text(CIRCLE.replace("sample_time: 0.15", "sample_time: 5.0e-5"))
    proc = subprocess.Popen([*rrtpso_exe(), "solve", "p.yaml", "--planner", "RRTConnect",
                             "--time", "0.5", "--trajectory", "t.csv"],
                            cwd=tmp_path, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_limit)  # fmt: skip
    assert wait_for(lambda: list(tmp_path.glob(".t.*.csv")) or proc.poll() is not None, 120)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.yaml"]


# ----------------------------------------------------------------------------------------------
# Bounds: every size the input chooses has a limit, named when it is passed (issue 22)
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["batch", "p.yaml", "--runs", "4294967295", "--out", "r.jsonl"], "--runs: must be"),
        (["batch", "p.yaml", "--runs", "100000000", "--out", "r.jsonl"], "got 100000000"),
        (["batch", "p.yaml", "p.yaml", "d.yaml", "--runs", "60000", "--planner", "RRTstar,PRM",
          "--out", "r.jsonl"], "runs 60,000 x 2 planners x 2 files = 240,000"),
        (["bench", "p.yaml", "--runs", "30000", "--planner", "RRTstar,PRM", "--time", "1,2",
          "--out", "b"], "x 2 budgets = 120,000"),
        (["batch", "p.yaml", "--jobs", "100000", "--out", "r.jsonl"], "--jobs: must be at most"),
    ],
    ids=["runs-2**32", "runs-1e8", "batch-tasks", "bench-tasks", "jobs"],
)  # fmt: skip
def test_run_counts_have_a_bound_named_by_the_flag(folder, args, words):
    proc = run(*args, cwd=folder, timeout=60)
    assert proc.returncode == 2 and words in proc.stderr, proc.stderr
    assert not (folder / "r.jsonl").exists() and not (folder / "b").exists()


def test_a_trajectory_of_too_many_samples_is_refused_before_planning(folder):
    name = _problem(folder, "s.yaml", CIRCLE.replace("sample_time: 0.15", "sample_time: 1.0e-6"))
    # A 100 s budget would outlast the timeout: the refusal comes before any planning.
    proc = run("solve", name, "--time", "100", "--trajectory", "t.csv", cwd=folder, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert "s.yaml" in proc.stderr and "robot.sample_time" in proc.stderr
    assert "at most 1,000,000" in proc.stderr
    assert not (folder / "t.csv").exists()


def _gear(n: int) -> str:
    """A problem with one star-shaped polygon of ``n`` vertices (0.01 units apart at 10,000)."""
    pts = ", ".join(
        f"[{50 + (20 + 3 * (k % 2)) * math.cos(2 * math.pi * k / n):.6f}, "
        f"{50 + (20 + 3 * (k % 2)) * math.sin(2 * math.pi * k / n):.6f}]"
        for k in range(n)
    )
    return ("bounds: [[0, 0], [100, 100]]\nstart: [5, 5]\ngoal: [95, 95]\nrobot: {radius: 1}\n"
            f"obstacles:\n  - type: polygon\n    points: [{pts}]\n")  # fmt: skip


@pytest.mark.parametrize(("n", "planner"), [(10_000, "RRTstarPSO"), (100_000, "RRTstar")])
def test_a_polygon_of_many_vertices_is_planned_around_within_the_memory_limit(folder, n, planner):
    # Before the polygons' edges were indexed one by one, 10,000 vertices took 1.8 GB and left
    # RRTstarPSO no time to find this easy path; 100,000 ran out of memory.
    name = _problem(folder, "gear.yaml", _gear(n))
    proc = run("solve", name, "--planner", planner, "--time", "0.3", "--json", "o.json",
               cwd=folder, timeout=240)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    result = json.loads((folder / "o.json").read_text())
    assert result["solved"] and result["valid"]


# ----------------------------------------------------------------------------------------------
# Silent wrong answers (issue 22)
# ----------------------------------------------------------------------------------------------
def _map(folder: Path, resolution: str, pixels: str = "255 255 255 255") -> str:
    rows = "\n".join([pixels] * 4)
    (folder / "m.pgm").write_text(f"P2\n4 4\n255\n{rows}\n")
    (folder / "m.yaml").write_text(f"image: m.pgm\nresolution: {resolution}\norigin: [0, 0, 0]\n")
    return "m.yaml"


@pytest.mark.parametrize(
    ("resolution", "pixels", "words"),
    [
        ("1.0e-9", "255 255 255 255", "map: its extent (image size x resolution) is too small"),
        ("1.0e+12", "255 255 255 255", "resolution: must be at most 1e+09"),
        ("1.0e+9", "255 255 255 255", "beyond +-1e+09"),
        ("1e-3", "255 255 255 255", "YAML reads 1e-3 as text"),
        ("1.0", "-1 255 255 255", "is -1: pixel values run from 0 to maxval 255"),
        ("1.0", "255 256 255 255", "exceeds maxval 255"),
    ],
    ids=["tiny-cells", "huge-cells", "beyond-coordinates", "yaml-1e-3", "negative-pixel",
         "pixel-over-maxval"],
)  # fmt: skip
def test_maps_that_cannot_be_checked_exactly_are_refused(folder, resolution, pixels, words):
    _map(folder, resolution, pixels)
    res = float(resolution) if "." in resolution else 1.0
    lo, hi = f"{0.5 * res:.6e}", f"{3.5 * res:.6e}"  # with a point: YAML 1.1 reads a number
    name = _problem(folder, "p9.yaml", f"map: m.yaml\nstart: [{lo}, {lo}]\ngoal: [{hi}, {hi}]\n"
                    "robot: {radius: 0}\n")  # fmt: skip
    proc = run("solve", name, "--json", "o.json", cwd=folder)
    assert proc.returncode == 2 and words in proc.stderr, proc.stderr
    assert not (folder / "o.json").exists()


def test_a_quoted_number_in_planner_params_is_refused_as_everywhere(folder):
    name = _problem(folder, "q.yaml", CIRCLE.split("planner:")[0] +
                    "planner:\n  params: {swarm_size: '30'}\n")  # fmt: skip
    for args in (["solve", name], ["batch", name, "--out", "r.jsonl"]):
        proc = run(*args, cwd=folder)
        assert proc.returncode in (1, 2), proc.stderr
        assert "q.yaml: planner.params.swarm_size" in proc.stderr, proc.stderr
        assert "a number in quotes is text" in proc.stderr


TINY = """bounds: [[0, 0], [1.0e-6, 1.0e-6]]
start: [4.0e-8, 4.0e-8]
goal: [9.0e-7, 9.0e-7]
robot: {radius: 5.7e-8}
obstacles:
  - {type: circle, center: [5.0e-7, 5.0e-7], radius: 1.6e-7}
  - {type: polygon, points: [[2.0e-7, 6.0e-7], [3.0e-7, 6.0e-7], [2.5e-7, 8.0e-7]]}
  - {type: rectangle, min: [6.0e-7, 1.0e-7], max: [8.0e-7, 3.0e-7]}
"""


@pytest.mark.parametrize("planner", ["RRTstarPSO", "RRTConnect"])
def test_a_workspace_a_micrometre_wide_is_checked_as_exactly_as_any(folder, planner):
    # The round-off allowance is 1e-9 of the workspace (1e-15 here), not 1e-9 absolute: that
    # would let a path 1.7 % of the robot's radius into an obstacle's safety zone.
    name = _problem(folder, "tiny.yaml", TINY)
    proc = run("solve", name, "--planner", planner, "--time", "0.2", "--json", "o.json",
               cwd=folder)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    result = json.loads((folder / "o.json").read_text())
    assert result["solved"] and result["valid"]
    assert result["clearance"] >= -1e-15
    assert math.dist(result["path"][-1], [9.0e-7, 9.0e-7]) <= 1e-15
