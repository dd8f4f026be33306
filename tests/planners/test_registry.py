"""The planner registry: names, aliases, parameter tables, entry-point plugins."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from helpers import SINGLE_CIRCLE

from rrtpso_ompl.planners.registry import (
    ParamSpec,
    PlannerEntry,
    PlannerRegistry,
    UnknownPlannerError,
    default_registry,
)

OMPL_GEOMETRIC = [
    "BFMT",
    "BITstar",
    "BKPIECE1",
    "FMT",
    "InformedRRTstar",
    "KPIECE1",
    "LBKPIECE1",
    "PRM",
    "PRMstar",
    "RRT",
    "RRTConnect",
    "RRTstar",
    "SORRTstar",
]


def test_every_ompl_geometric_planner_under_both_names():
    reg = default_registry()
    for name in OMPL_GEOMETRIC:
        assert reg.get(name) is reg.get(f"geometric::{name}")
    assert reg.get("geometric::KPIECE").name == "KPIECE1"  # MoveIt's name
    assert {"RRTstarPSO", "PSO"} <= set(reg.names())


def test_unknown_name_lists_known_ones():
    with pytest.raises(UnknownPlannerError) as info:
        default_registry().get("RRTstra")
    message = str(info.value)
    assert "RRTstra" in message and "RRTstar" in message and "RRTstarPSO" in message


def test_excluded_planner_says_why():
    """AORRTC is bound by the wheel but crashes; selecting it explains that instead."""
    with pytest.raises(UnknownPlannerError, match=r"unavailable.*segmentation fault"):
        default_registry().get("AORRTC")


def test_duplicate_names_are_refused():
    reg = PlannerRegistry()
    reg.register(PlannerEntry("A", factory=object, aliases=("geometric::A",)))
    with pytest.raises(ValueError, match="already registered"):
        reg.register(PlannerEntry("geometric::A", factory=object))
    with pytest.raises(ValueError, match="must be in"):
        reg.register(
            PlannerEntry(
                "B", factory=object, params=(ParamSpec("x", float, 5.0, "", low=0, high=1),)
            )
        )


def test_ompl_table_defaults_match_ompl():
    """Every default in our table is what the OMPL planner itself reports (no drift)."""
    from ompl import base as ob
    from ompl import geometric as og

    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: True)
    si = ss.getSpaceInformation()
    keep = []  # some planners' destructors misbehave when freed mid-loop; keep them alive
    for entry in default_registry().entries():
        if not entry.source.endswith("ompl_geometric"):
            continue
        planner = entry.factory(si)
        keep.append(planner)
        for spec in entry.params:
            assert hasattr(planner, spec.setter), (entry.name, spec.setter)
            if spec.getter:
                assert getattr(planner, spec.getter)() == spec.default, (entry.name, spec.name)


def test_param_conversion():
    spec = ParamSpec("n", int, 3, "", low=1, high=10)
    assert spec.convert("4") == 4 and spec.convert(5.0) == 5
    for bad in ("x", 0, 11, 2.5, True):
        with pytest.raises(ValueError):
            spec.convert(bad)
    flag = ParamSpec("f", bool, False, "")
    assert flag.convert("yes") is True and flag.convert("0") is False
    with pytest.raises(ValueError):
        flag.convert("maybe")


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
    pkg = tmp_path / "tinyplug"
    (pkg / "tinyplug").mkdir(parents=True)
    (pkg / "tinyplug" / "__init__.py").write_text(PLUGIN_SRC)
    (pkg / "pyproject.toml").write_text(
        textwrap.dedent("""
        [build-system]
        requires = ["setuptools"]
        build-backend = "setuptools.build_meta"
        [project]
        name = "tinyplug"
        version = "0.1"
        [project.entry-points."rrtpso_ompl.planners"]
        tiny = "tinyplug:PLANNERS"
    """)
    )
    target = tmp_path / "site"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "--target",
            str(target),
            str(pkg),
        ],
        check=True,
        capture_output=True,
    )
    import yaml

    empty = dict(SINGLE_CIRCLE, obstacles=[])
    problem = tmp_path / "empty.yaml"
    problem.write_text(yaml.safe_dump(empty))
    env = {"PYTHONPATH": str(target), "PATH": str(Path(sys.executable).parent)}
    code = "import sys; from rrtpso_ompl.cli.main import main; sys.exit(main(sys.argv[1:]))"
    listed = subprocess.run(
        [sys.executable, "-c", code, "planners", "TinyStraight"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert listed.returncode == 0, listed.stderr
    assert "TinyStraight" in listed.stdout and "entry point" in listed.stdout
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
    import json

    data = json.loads((tmp_path / "r.json").read_text())
    assert data["planner"] == "TinyStraight" and len(data["path"]) == 2


def test_documented_parameter_tables_match_the_registry():
    """docs/planners.md is generated from the registry; regenerate it when this fails
    (python benchmarks/param_tables.py)."""
    from helpers import REPO

    text = (REPO / "docs" / "planners.md").read_text()
    for name in ("RRTstarPSO", "PSO"):
        table = default_registry().get(name).params.markdown()
        block = f"<!-- params:{name} -->\n{table}\n<!-- /params:{name} -->"
        assert block in text, f"the table of {name} in docs/planners.md is not the declared one"
