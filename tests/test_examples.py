"""Every script in examples/ runs as its docstring says, from a fresh process, and prints what it
promises (issue 36, item 7)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from helpers import REPO

EXAMPLES = REPO / "examples"

pytestmark = pytest.mark.slow


def _run(*args: str) -> str:
    run = subprocess.run([sys.executable, *args], capture_output=True, text=True, timeout=300,
                         cwd=REPO)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    return run.stdout


def test_every_example_is_tested_here():
    tested = {"own_setup.py", "post_pass.py", "batch.py", "bag_for_rviz.py"}
    assert {p.name for p in EXAMPLES.glob("*.py")} == tested


def test_own_setup_plans_in_the_plane_and_for_a_car():
    out = _run(str(EXAMPLES / "own_setup.py"))
    assert out.count("Exact solution") == 2
    assert "m of curves" in out


def test_the_post_pass_never_lengthens_bit_star_s_path():
    out = _run(str(EXAMPLES / "post_pass.py"))
    lengths = [float(line.split(":")[1].split()[0]) for line in out.splitlines()[:3]]
    assert lengths[0] >= lengths[1] >= lengths[2]


def test_a_batch_from_python_writes_its_rows(tmp_path):
    out = tmp_path / "rows.jsonl"
    _run(str(EXAMPLES / "batch.py"), str(out))
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(rows) == 6 and {r["planner"] for r in rows} == {"RRTstarPSO", "BITstar+simplify"}


def test_a_bag_for_rviz_holds_the_plan_and_the_map(tmp_path):
    from rosbags.highlevel import AnyReader  # an independent reader, as RViz2's bag player

    bag = tmp_path / "plan.mcap"
    _run(str(EXAMPLES / "bag_for_rviz.py"), str(bag))
    with AnyReader([bag]) as reader:
        topics = {c.topic for c in reader.connections}
        plans = [reader.deserialize(raw, c.msgtype) for c, _t, raw in reader.messages()
                 if c.topic == "/plan"]  # fmt: skip
    assert {"/plan", "/map", "/initialpose", "/goal_pose"} <= topics
    assert len(plans) == 1 and len(plans[0].poses) > 10
