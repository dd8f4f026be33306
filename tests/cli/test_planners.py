"""``rrtpso planners``: every registered planner with its parameters, as text and JSON."""

from __future__ import annotations

import json

import pytest
from helpers import run

pytestmark = pytest.mark.slow


def test_planners_lists_everything_with_params():
    proc = run("planners", "--json")
    assert proc.returncode == 0
    rows = {r["name"]: r for r in json.loads(proc.stdout)}
    for name in ("RRTstarPSO", "PSO", "RRTstar", "BITstar", "RRTConnect", "InformedRRTstar"):
        assert name in rows
    assert "geometric::RRTstar" in rows["RRTstar"]["aliases"]
    params = {p["name"]: p for p in rows["RRTstarPSO"]["params"]}
    for name in (
        "range",
        "goal_bias",
        "rewire_factor",
        "rrt_time_fraction",
        "swarm_size",
        "iterations",
        "w",
        "c1",
        "c2",
    ):
        assert name in params
    text = run("planners", "RRTstarPSO")
    assert text.returncode == 0 and "swarm_size" in text.stdout
    assert run("planners", "Nope").returncode == 2
