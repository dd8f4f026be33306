"""Strategies behind a registry: the first-party ones, plugins through the entry-point group
``rrtpso_ompl.strategies`` (a real package, really installed, run through ``rrtpso simulate``),
the one wiring of each strategy, imports that run one way in dynamic/, and the option tables
of docs/dynamic.md derived from the declarations."""

from __future__ import annotations

import ast
import json
import logging
import subprocess
import sys

import numpy as np
import pytest
from helpers import CLI_CODE, PROBLEMS, REPO, corridor, install_plugin

from rrtpso_ompl.dynamic import (
    DynamicOptions,
    StrategyRegistry,
    UnknownStrategyError,
    default_strategies,
    simulate,
)
from rrtpso_ompl.dynamic.manager import FALLBACK_KINDS
from rrtpso_ompl.dynamic.strategies import DWA, Contour, DWAOptions, NoReplanning, WholePath
from rrtpso_ompl.errors import ParameterError
from rrtpso_ompl.model.problem import load_problem

DYNAMIC = REPO / "rrtpso_ompl" / "dynamic"


# ----------------------------------------------------------------------------------------------
# The registry
# ----------------------------------------------------------------------------------------------
def test_first_party_strategies_are_registered_in_order():
    reg = default_strategies()
    assert reg.names()[:4] == ["contour", "global", "none", "dwa"]
    assert [reg.get(n) for n in reg.names()[:4]] == [Contour, WholePath, NoReplanning, DWA]
    for name in reg.names()[:4]:
        assert reg.description(name) and "\n" not in reg.description(name)


def test_a_taken_name_and_a_non_strategy_are_refused():
    reg = StrategyRegistry()
    reg.load_first_party()

    class Shadow(NoReplanning):
        name = "contour"

    with pytest.raises(ValueError, match="'contour' is already registered"):
        reg.register(Shadow, "a plugin")
    with pytest.raises(TypeError, match="strategy class"):
        reg.register(object, "a plugin")

    class BadOptions(NoReplanning):
        name = "bad_options"
        options = dict

    with pytest.raises(TypeError, match="declared option set"):
        reg.register(BadOptions, "a plugin")
    assert "bad_options" not in reg


def test_unknown_strategy_names_the_known_ones():
    with pytest.raises(UnknownStrategyError, match=r"no strategy 'contur' \(did you mean"):
        default_strategies().get("contur")


def test_strategy_options_are_validated_by_their_declarations():
    reg = default_strategies()
    assert reg.make("dwa", {"guide_time": 0.5}).params == DWAOptions(guide_time=0.5)
    with pytest.raises(ParameterError, match="guide_time"):
        reg.make("dwa", {"guide_time": -1.0})
    with pytest.raises(ParameterError, match="no parameter 'sim_tme'"):
        reg.make("dwa", {"sim_tme": 1.0})
    with pytest.raises(UnknownStrategyError, match="takes no options"):
        reg.make("contour", {"stretch": 2.0})


def test_a_broken_plugin_is_skipped_with_a_warning(monkeypatch, caplog):
    import rrtpso_ompl.dynamic.registry as registry

    class EP:
        name, value = "broken", "nowhere:STRATEGY"

        def load(self):
            raise ImportError("no module named nowhere")

    class Good(NoReplanning):
        name = "good_plugin"

    class GoodEP:
        name, value = "good", "somewhere:Good"

        def load(self):
            return [Good]

    monkeypatch.setattr(registry, "entry_points", lambda group: [EP(), GoodEP()])
    reg = StrategyRegistry()
    reg.load_first_party()
    with caplog.at_level(logging.WARNING):
        reg.load_entry_points()
    assert "skipping strategy plugin entry point 'broken = nowhere:STRATEGY'" in caplog.text
    assert reg.get("good_plugin") is Good and "somewhere:Good" in reg.sources["good_plugin"]


# ----------------------------------------------------------------------------------------------
# One wiring per strategy
# ----------------------------------------------------------------------------------------------
def test_simulate_runs_the_named_strategy_with_its_policy():
    problem = corridor([{"radius": 28.5, "start": [250, 440], "speed": 20, "heading_deg": -90}])
    path = np.array([problem.start, problem.goal])
    blind = simulate(problem, DynamicOptions(strategy="none"), seed=1, initial_path=path)
    assert blind.strategy == "none" and not blind.replans
    whole = simulate(problem, DynamicOptions(strategy="global", planner="RRTstar"), seed=1,
                     initial_path=path)  # fmt: skip
    assert whole.strategy == "global" and whole.replans
    assert all(r.kind in ("global", *FALLBACK_KINDS) for r in whole.replans)
    assert all(r.side is None for r in whole.replans)


def test_the_dwa_strategy_is_the_guide_path_then_the_controller():
    """``simulate(strategy="dwa")`` is the wiring the benchmark and the command share: the guide
    path planned with the run's seed, then the DWA along it."""
    from rrtpso_ompl.dynamic.dwa import guide_path, simulate_dwa

    problem = load_problem(PROBLEMS / "dynamic" / "crossing_from_below.yaml")
    path = np.array([problem.start, problem.goal])
    opts = DynamicOptions(strategy="dwa", max_time=8.0)
    via_registry = default_strategies().make("dwa", {"guide_time": 0.2})
    ours = via_registry.simulate(problem, opts, seed=3, initial_path=path)
    guide = guide_path(problem, path, "RRTstarPSO", 0.2, {"seed": 3})
    theirs = simulate_dwa(problem, guide, options=opts, seed=3)
    assert ours.strategy == "dwa" and ours.planner == "DWA"
    assert np.array_equal(ours.static_path, guide)
    assert ours.to_dict() == theirs.to_dict()


# ----------------------------------------------------------------------------------------------
# Imports run one way
# ----------------------------------------------------------------------------------------------
def _dynamic_imports() -> dict[str, set[str]]:
    """Module of rrtpso_ompl.dynamic -> the modules of rrtpso_ompl.dynamic it imports (at the
    top or inside functions)."""
    graph: dict[str, set[str]] = {}
    for path in DYNAMIC.rglob("*.py"):
        rel = path.relative_to(DYNAMIC).with_suffix("")
        parts = [p for p in rel.parts if p != "__init__"]
        module = ".".join(["rrtpso_ompl", "dynamic", *parts])
        package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
        deps = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join([*base, *([node.module] if node.module else [])])
                names = [target] if node.module else [f"{target}.{a.name}" for a in node.names]
                deps.update(n for n in names if n.startswith("rrtpso_ompl.dynamic"))
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                "rrtpso_ompl.dynamic"
            ):
                deps.add(node.module)
        graph[module] = deps - {module}
    return graph


def test_dynamic_modules_import_each_other_one_way():
    graph = _dynamic_imports()
    assert {"rrtpso_ompl.dynamic.options", "rrtpso_ompl.dynamic.registry"} <= set(graph)
    # A package's own __init__ may gather its modules; nothing below may import it back.
    state: dict[str, int] = {}

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for dep in graph.get(node, ()):
            if state.get(dep) == 1:
                cycle = [*trail[trail.index(dep) :], dep] if dep in trail else [node, dep]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if dep not in state:
                visit(dep, [*trail, dep])
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])


def test_the_cycle_check_finds_a_cycle(tmp_path, monkeypatch):
    """The check above is not vacuous: the manager importing the simulation back is found."""
    graph = _dynamic_imports()
    assert "rrtpso_ompl.dynamic.options" in graph["rrtpso_ompl.dynamic.manager"]
    graph["rrtpso_ompl.dynamic.options"].add("rrtpso_ompl.dynamic.manager")
    monkeypatch.setattr(sys.modules[__name__], "_dynamic_imports", lambda: graph)
    with pytest.raises(pytest.fail.Exception, match="import cycle"):
        test_dynamic_modules_import_each_other_one_way()


@pytest.mark.parametrize("module", ["options", "result", "world_view", "manager", "registry"])
def test_each_module_imports_alone(module):
    out = subprocess.run([sys.executable, "-c", f"import rrtpso_ompl.dynamic.{module}"],
                         capture_output=True, text=True)  # fmt: skip
    assert out.returncode == 0, out.stderr


def test_listing_strategies_loads_neither_ompl_nor_scipy():
    code = ("import sys; from rrtpso_ompl.dynamic import default_strategies; default_strategies(); "
            "print(sorted(m for m in ('ompl', 'scipy') if m in sys.modules))")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


# ----------------------------------------------------------------------------------------------
# Docs and flags from the declarations
# ----------------------------------------------------------------------------------------------
def test_documented_option_tables_match_the_declarations():
    """docs/dynamic.md's tables are generated; regenerate them when this fails
    (python benchmarks/param_tables.py --update docs/dynamic.md)."""
    sys.path.insert(0, str(REPO / "benchmarks"))
    try:
        from param_tables import options_table
    finally:
        sys.path.remove(str(REPO / "benchmarks"))
    text = (REPO / "docs" / "dynamic.md").read_text()
    for name in ("DynamicOptions", "DWAOptions"):
        block = f"<!-- options:{name} -->\n{options_table(name)}\n<!-- /options:{name} -->"
        assert block in text, f"the table of {name} in docs/dynamic.md is not the declared one"
    assert "`rrtpso_ompl.strategies`" in text


def test_simulate_flags_are_declared_options():
    from rrtpso_ompl.cli.simulate import OPTION_FLAGS

    assert set(OPTION_FLAGS) <= set(DynamicOptions.PARAMS.names())
    out = subprocess.run([sys.executable, "-m", "rrtpso_ompl", "simulate", "--help"],
                         capture_output=True, text=True, check=True)  # fmt: skip
    help_text = " ".join(out.stdout.split())
    assert "{contour,global,none,dwa}" in help_text
    assert " ".join(DynamicOptions.PARAMS["replan_time"].doc.split()) in help_text


# ----------------------------------------------------------------------------------------------
# A third-party strategy, installed, through the command line
# ----------------------------------------------------------------------------------------------
PLUGIN_SRC = '''
"""A strategy plugin: contour detours on the left only, never a wait."""
from rrtpso_ompl.dynamic.manager import ReplanPolicy
from rrtpso_ompl.dynamic.replanning import ReplanningStrategy


class LeftOnly(ReplanningStrategy):
    """Detour on the left of the obstacle only (a plugin)."""

    name = "left_only"
    policy = ReplanPolicy(kind="left_only", sides=("up",), wait=False)
'''


@pytest.mark.slow
def test_entry_point_strategy_runs_through_the_command_line(tmp_path):
    env = install_plugin(tmp_path, "leftonly", PLUGIN_SRC, "rrtpso_ompl.strategies",
                         {"left": "leftonly:LeftOnly", "broken": "leftonly:Missing"})  # fmt: skip
    code = CLI_CODE
    listed = subprocess.run([sys.executable, "-c", code, "simulate", "--help"],
                            capture_output=True, text=True, env=env)  # fmt: skip
    assert listed.returncode == 0, listed.stderr
    assert "{contour,global,none,dwa,left_only}" in listed.stdout
    # The broken entry point is reported and skipped; the tool still works.
    assert "skipping strategy plugin entry point 'broken = leftonly:Missing'" in listed.stderr
    out = tmp_path / "run.json"
    problem = PROBLEMS / "dynamic" / "crossing_from_below.yaml"
    run = subprocess.run([sys.executable, "-c", code, "simulate", str(problem), "--strategy",
                          "left_only", "--time", "0.3", "--seed", "1", "--json", str(out)],
                         capture_output=True, text=True, env=env)  # fmt: skip
    assert run.returncode in (0, 1), run.stderr
    data = json.loads(out.read_text())
    assert data["strategy"] == "left_only" and data["planner"] == "RRTstarPSO"
    assert data["replans"], "the crossing obstacle must make the plugin react"
    planned = [r for r in data["replans"] if r["kind"] == "left_only"]
    assert all(r["kind"] in ("left_only", *FALLBACK_KINDS) for r in data["replans"])
    assert all(c["side"] == "up" for r in planned for c in r["candidates"])
    assert (run.returncode == 0) == (data["reached_goal"] and data["collisions"] == 0)
