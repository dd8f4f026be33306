"""A third-party planner through the command line: a tiny package with an entry point in
the group the planner registry reads (``rrtpso_ompl.planners``), installed offline into a target
folder, listed by ``rrtpso planners`` and solving with ``rrtpso solve --planner``."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from helpers import CLI_CODE, SINGLE_CIRCLE, install_plugin

from rrtpso_ompl.model.problem import load_problem
from rrtpso_ompl.model.world import World

pytestmark = pytest.mark.slow


PLUGIN_SRC = '''
"""A tiny third-party planner: the straight line from start to goal, if it is free."""
from ompl import base as ob, geometric as og
from rrtpso_ompl.planners.registry import ParamSpec, PlannerEntry


class Straight(ob.Planner):
    def __init__(self, si):
        super().__init__(si, "TinyStraight")
        self.scale = 1.0

    def set_param(self, name, value):
        setattr(self, name, value)

    def solve(self, ptc):
        pis = self.getPlannerInputStates()
        pis.restart()
        s, g = pis.nextStart(), pis.nextGoal(ptc)
        si = self.getSpaceInformation()
        if not si.checkMotion(s, g):
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        self.getProblemDefinition().addSolutionPath(og.PathGeometric(si, s, g), False, 0.0,
                                                    self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


PLANNERS = [PlannerEntry("TinyStraight", factory=Straight,
                         params=(ParamSpec("scale", float, 1.0, "unused", low=0.0),),
                         description="straight line or nothing")]
'''


@pytest.mark.slow
def test_entry_point_plugin_is_selectable_by_name(tmp_path):
    """A real package, really installed (into a target folder), found through the entry-point
    group and selected by name from the command line."""
    env = install_plugin(tmp_path, "tinyplug", PLUGIN_SRC, "rrtpso_ompl.planners",
                         {"tiny": "tinyplug:PLANNERS"})  # fmt: skip
    import yaml

    empty = dict(SINGLE_CIRCLE, obstacles=[])
    problem = tmp_path / "empty.yaml"
    problem.write_text(yaml.safe_dump(empty))
    code = CLI_CODE
    listed = subprocess.run(
        [sys.executable, "-c", code, "planners", "TinyStraight"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert listed.returncode == 0, listed.stderr
    assert "TinyStraight" in listed.stdout and "entry point" in listed.stdout
    every = subprocess.run([sys.executable, "-c", code, "planners", "--json"],
                           capture_output=True, text=True, env=env)  # fmt: skip
    assert every.returncode == 0, every.stderr
    assert "TinyStraight" in {row["name"] for row in json.loads(every.stdout)}
    solved = subprocess.run(
        [
            sys.executable,
            "-c",
            code,
            "solve",
            str(problem),
            "--planner",
            "TinyStraight",
            "--param",
            "scale=2",
            "--json",
            str(tmp_path / "r.json"),
        ],
        capture_output=True,
        text=True,
        env=env,
    )
    assert solved.returncode == 0, solved.stderr
    data = json.loads((tmp_path / "r.json").read_text())
    assert data["planner"] == "TinyStraight" and len(data["path"]) == 2
    # A valid path: from the start to the goal, free along every segment with the robot's radius.
    path = np.array(data["path"], dtype=float)
    assert np.allclose(path[0], empty["start"]) and np.allclose(path[-1], empty["goal"])
    assert World.from_problem(load_problem(problem)).path_valid(path)
