"""The planner registry: names, aliases, parameter tables, entry-point plugins."""

from __future__ import annotations

import pytest

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


def test_documented_parameter_tables_match_the_registry():
    """docs/planners.md is generated from the registry; regenerate it when this fails
    (python benchmarks/param_tables.py)."""
    from helpers import REPO

    text = (REPO / "docs" / "planners.md").read_text()
    for name in ("RRTstarPSO", "PSO"):
        table = default_registry().get(name).params.markdown()
        block = f"<!-- params:{name} -->\n{table}\n<!-- /params:{name} -->"
        assert block in text, f"the table of {name} in docs/planners.md is not the declared one"
