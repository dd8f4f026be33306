"""Plugins that raise anything cannot stop the tool (issue 32, item 8).

A planner or strategy plugin whose import calls ``sys.exit(3)`` or raises ``SystemExit`` or a
``KeyboardInterrupt`` of its own is skipped with a warning naming it, and every command goes on;
a real Ctrl-C (or SIGTERM) that arrives while a plugin loads or plans still stops the command
(exit 130, 143). A plugin planner whose ``solve`` raises makes ``rrtpso solve`` (and
``simulate``) write the JSON with status ``error`` and say it in one line, as ``batch`` makes an
error row of it.

Each plugin is a real module with a real entry point (a ``.dist-info`` folder beside it on
``PYTHONPATH``, what pip installs), run by the real command in a child process; what the plugin
does is chosen by environment variables, and a "real" signal is one the plugin's code sends to
its own process, so every case happens by construction, on any machine.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest
from helpers import PROBLEMS, rrtpso_exe

pytestmark = pytest.mark.slow

PLUGIN = '''
"""A plugin that misbehaves as its environment asks: at import (CRASH_AT), or in a planner's
solve (CRASH_SOLVE)."""
import os
import signal
import sys
import time

from ompl import base as ob, geometric as og


def misbehave(what):
    if what == "exit":
        sys.exit(3)
    if what == "systemexit":
        raise SystemExit("bye")
    if what == "keyboard":
        raise KeyboardInterrupt
    if what == "error":
        raise ValueError("boom\\nsecond line")
    if what in ("sigint", "sigterm", "sigint-swallowed"):
        # A real signal, from outside as far as Python can tell.
        sig = signal.SIGTERM if what == "sigterm" else signal.SIGINT
        try:
            os.kill(os.getpid(), sig)
            time.sleep(30)  # the handler runs before this ends
        except KeyboardInterrupt:
            if what != "sigint-swallowed":
                raise
    if what == "print":
        print("plugin noise on sys.stdout")
        os.write(1, b"plugin noise on descriptor 1\\n")


misbehave(os.environ.get("CRASH_AT", ""))


class Crash(ob.Planner):
    """The straight line from start to goal, after misbehaving as CRASH_SOLVE asks."""

    def __init__(self, si):
        super().__init__(si, "Crash")

    def solve(self, ptc):
        misbehave(os.environ.get("CRASH_SOLVE", "error"))
        pis = self.getPlannerInputStates()
        pis.restart()
        s, g = pis.nextStart(), pis.nextGoal(ptc)
        si = self.getSpaceInformation()
        self.getProblemDefinition().addSolutionPath(og.PathGeometric(si, s, g), False, 0.0,
                                                    self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


from rrtpso_ompl.dynamic.strategies import NoReplanning
from rrtpso_ompl.planners.registry import PlannerEntry


class Crashy(NoReplanning):
    """Raises in its simulation (a plugin)."""

    name = "crashy"

    def simulate(self, *args, **kwargs):
        misbehave(os.environ.get("CRASH_SOLVE", "error"))


planners = [PlannerEntry("Crash", factory=Crash, description="misbehaves")]
strategies = [Crashy]
'''


def _site(tmp_path: Path, group: str) -> Path:
    """The plugin module and its distribution's metadata, as pip leaves them, with one entry
    point in ``group`` (the planners' or the strategies')."""
    site = tmp_path / "site"
    info = site / "crashplug-0.1.dist-info"
    info.mkdir(parents=True)
    (site / "crashplug.py").write_text(PLUGIN)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: crashplug\nVersion: 0.1\n")
    target = "planners" if group == "rrtpso_ompl.planners" else "strategies"
    (info / "entry_points.txt").write_text(f"[{group}]\ncrash = crashplug:{target}\n")
    return site


def run(tmp_path: Path, group: str, *args: str, **env: str) -> subprocess.CompletedProcess:
    """``rrtpso *args`` in ``tmp_path`` with the plugin installed in ``group``."""
    site = _site(tmp_path, group) if not (tmp_path / "site").exists() else tmp_path / "site"
    full = {**os.environ, "PYTHONPATH": str(site), **env}
    proc = subprocess.run([*rrtpso_exe(), *args], cwd=tmp_path, env=full, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    (tmp_path / "p.yaml").write_text((PROBLEMS / "static" / "single_circle.yaml").read_text())
    (tmp_path / "d.yaml").write_text((PROBLEMS / "dynamic" / "head_on.yaml").read_text())
    return tmp_path


GROUPS = ["rrtpso_ompl.planners", "rrtpso_ompl.strategies"]
KINDS = {"planners": "planner", "strategies": "strategy"}
#: Per group: a command that loads its plugins (a command loads only what it runs, issue 33:
#: solve looks a planner up, simulate builds --strategy from the strategies), one that lists
#: them with a word the listing shows, and one quiet (-q) command that loads them.
COMMAND = {
    "rrtpso_ompl.planners": ["solve", "p.yaml", "--planner", "RRTConnect"],
    "rrtpso_ompl.strategies": ["simulate", "d.yaml"],
}
LISTING = {
    "rrtpso_ompl.planners": (["planners"], "RRTstarPSO"),
    "rrtpso_ompl.strategies": (["simulate", "--help"], "contour"),
}
QUIET = {
    "rrtpso_ompl.planners": ["planners", "-q"],
    "rrtpso_ompl.strategies": ["simulate", "d.yaml", "--time", "0.05", "--seed", "1", "-q"],
}


@pytest.mark.parametrize("group", GROUPS, ids=["planner", "strategy"])
@pytest.mark.parametrize(
    ("crash", "reason"),
    [
        ("exit", "SystemExit: sys.exit(3) was called"),
        ("systemexit", "SystemExit: sys.exit('bye') was called"),
        ("keyboard", "KeyboardInterrupt"),
        ("error", "ValueError: boom second line"),
    ],
)  # fmt: skip
def test_a_plugin_that_raises_anything_at_import_is_skipped(folder, group, crash, reason):
    """Every command still works: the plugin is named in one warning, and nothing else."""
    proc = run(folder, group, *COMMAND[group], "--time", "0.05", "--seed", "1", "--json",
               "r.json", CRASH_AT=crash)  # fmt: skip
    result = json.loads((folder / "r.json").read_text())
    if group == "rrtpso_ompl.planners":
        assert proc.returncode == 0 and result["solved"] is True, proc.stderr
    else:  # a simulation ran (whether it reaches the goal is not this test's business)
        assert proc.returncode in (0, 1) and result["status"] != "error", proc.stderr
    kind = KINDS[group.split(".")[1]]
    warning = f"skipping {kind} plugin entry point 'crash = crashplug:{group.split('.')[1]}': "
    assert f"WARNING: rrtpso_ompl.{'planners' if kind == 'planner' else 'dynamic'}" in proc.stderr
    assert warning + reason in proc.stderr, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 2  # the warning and the command's line
    args, word = LISTING[group]
    listed = run(folder, group, *args, CRASH_AT=crash)
    assert listed.returncode == 0 and word in listed.stdout and warning in listed.stderr
    # -q shows only errors: the warning too waits for the flags (the strategies are loaded
    # while simulate's parser is built).
    quiet = run(folder, group, *QUIET[group], CRASH_AT=crash)
    assert quiet.returncode in (0, 1) and quiet.stderr == ""


@pytest.mark.parametrize("group", GROUPS, ids=["planner", "strategy"])
@pytest.mark.parametrize(
    ("crash", "status", "words"),
    [
        ("sigint", 130, "rrtpso: interrupted"),
        ("sigint-swallowed", 130, "rrtpso: interrupted"),
        ("sigterm", 143, "rrtpso: terminated by SIGTERM"),
    ],
)  # fmt: skip
def test_a_real_signal_while_a_plugin_loads_still_stops_the_command(
    folder, group, crash, status, words
):
    """Only a KeyboardInterrupt the plugin raised itself is the plugin's failure: a signal the
    process received ends the command as anywhere else, even when the plugin swallowed it."""
    proc = run(folder, group, *COMMAND[group], "--time", "0.05", "--json", "r.json",
               CRASH_AT=crash)  # fmt: skip
    assert proc.returncode == status, proc.stderr
    assert proc.stderr.strip().splitlines() == [words]
    assert not (folder / "r.json").exists()


@pytest.mark.parametrize(
    ("crash", "reason"),
    [
        ("error", "ValueError: boom second line"),
        ("exit", "SystemExit: sys.exit(3) was called"),
        ("keyboard", "KeyboardInterrupt"),
    ],
)  # fmt: skip
def test_a_plugin_planner_that_raises_is_an_error_result(folder, crash, reason):
    """As batch makes it an error row: the JSON with status "error" and the message, exit
    status 1, one line on stderr, no other output written."""
    proc = run(folder, "rrtpso_ompl.planners", "solve", "p.yaml", "--planner", "Crash", "--time",
               "0.5", "--json", "r.json", "--plot", "r.png", CRASH_SOLVE=crash)  # fmt: skip
    message = f"p.yaml: the run raised {reason}"
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.strip().splitlines() == [f"rrtpso: error: {message}"]
    data = json.loads((folder / "r.json").read_text())
    assert data["status"] == "error" and data["error"] == message
    assert data["solved"] is False and data["path"] == [] and data["length"] is None
    assert data["planner"] == "Crash" and data["problem"] == "single_circle"
    assert not (folder / "r.png").exists()
    # The same run in a batch: one error row, its message on one line.
    batch = run(folder, "rrtpso_ompl.planners", "batch", "p.yaml", "--planner", "Crash",
                "--time", "0.5", "--out", "r.jsonl", CRASH_SOLVE=crash)  # fmt: skip
    assert batch.returncode == 1, batch.stderr
    row = json.loads((folder / "r.jsonl").read_text())
    assert row["status"] == "error" and row["error"] == message


def test_a_plugin_that_crashes_a_simulation_is_an_error_result(folder):
    """A strategy plugin and a planner plugin: the simulation's JSON says "error"."""
    for group, flags in (("rrtpso_ompl.strategies", ["--strategy", "crashy"]),
                         ("rrtpso_ompl.planners", ["--planner", "Crash"])):  # fmt: skip
        sub = folder / group
        sub.mkdir()
        (sub / "d.yaml").write_text((folder / "d.yaml").read_text())
        proc = run(sub, group, "simulate", "d.yaml", *flags, "--time", "0.3", "--json", "s.json")
        message = "d.yaml: the simulation raised ValueError: boom second line"
        assert proc.returncode == 1, proc.stderr
        assert proc.stderr.strip().splitlines()[-1] == f"rrtpso: error: {message}"
        data = json.loads((sub / "s.json").read_text())
        assert data["status"] == "error" and data["error"] == message
        assert data["reached_goal"] is False


@pytest.mark.parametrize("crash", ["sigint", "sigint-swallowed", "sigterm"])
def test_a_real_signal_while_a_plugin_plans_still_stops_the_command(folder, crash):
    proc = run(folder, "rrtpso_ompl.planners", "solve", "p.yaml", "--planner", "Crash",
               "--time", "0.5", "--json", "r.json", CRASH_SOLVE=crash)  # fmt: skip
    assert proc.returncode == (143 if crash == "sigterm" else 130), proc.stderr
    assert not (folder / "r.json").exists()


def test_what_a_plugin_prints_never_reaches_a_result_on_standard_output(folder):
    """Its print() and its writes to descriptor 1 go to stderr, in solve and in a batch's
    workers: standard output holds the JSON (item 3's family)."""
    text = (folder / "p.yaml").read_text().split("obstacles:")[0]
    (folder / "e.yaml").write_text(text + "obstacles: []\n")  # the straight line is free
    proc = run(folder, "rrtpso_ompl.planners", "solve", "e.yaml", "--planner", "Crash",
               "--time", "0.5", "--json", "-", CRASH_SOLVE="print")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["status"] == "exact"
    assert "plugin noise on sys.stdout" in proc.stderr
    assert "plugin noise on descriptor 1" in proc.stderr
    batch = run(folder, "rrtpso_ompl.planners", "batch", "e.yaml", "--planner", "Crash",
                "--runs", "2", "--time", "0.5", "--out", "-", CRASH_SOLVE="print")  # fmt: skip
    assert batch.returncode == 0, batch.stderr
    rows = [json.loads(line) for line in batch.stdout.splitlines()]
    assert [r["status"] for r in rows] == ["exact", "exact"]
    assert batch.stderr.count("plugin noise on descriptor 1") == 2
