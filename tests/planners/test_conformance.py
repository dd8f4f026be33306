"""The conformance kit (rrtpso_ompl.testing) over every registered planner and docs/planners.md's
plugin example; and the kit itself: each of its checks fails for a planner that breaks its
property (so none passes by checking nothing)."""

from __future__ import annotations

import re
import sys
import time
import types

import pytest
from helpers import REPO
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.model import problem_from_dict
from rrtpso_ompl.planners import default_registry
from rrtpso_ompl.planners.base import PlannerStats, PythonPlanner
from rrtpso_ompl.planners.params import ParamSpec, ParamTable
from rrtpso_ompl.planners.registry import PlannerEntry
from rrtpso_ompl.testing import (
    CHECKS,
    SIMPLE_PROBLEM,
    check_clear_and_solve_again,
    check_cost_never_rises,
    check_deadline,
    check_parameters,
    check_planner,
    check_solves,
    check_valid_path,
    parametrize_with_checks,
)

#: Seconds per solve in this suite (every planner solves the simple problem in milliseconds).
BUDGET = 0.2
#: The simple problem without its obstacle: a straight line solves it.
OPEN = problem_from_dict({**SIMPLE_PROBLEM, "name": "open", "obstacles": []}, "<open>")


@parametrize_with_checks(default_registry().names(), budget=BUDGET)
def test_every_registered_planner_conforms(entry, check):
    check(entry)


# ----------------------------------------------------------------------------------------------
# docs/planners.md's plugin example, as a plugin author runs the kit
# ----------------------------------------------------------------------------------------------
def _python_blocks() -> list[str]:
    text = (REPO / "docs" / "planners.md").read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def _documented_plugin() -> types.ModuleType:
    """The ``my_package/planners.py`` block of docs/planners.md, as a module."""
    (source,) = [b for b in _python_blocks() if b.startswith("# my_package/planners.py")]
    module = types.ModuleType("my_package.planners")
    exec(compile(source, "docs/planners.md", "exec"), module.__dict__)
    return module


def test_the_documented_plugin_passes_the_kit_as_the_docs_run_it(monkeypatch):
    """The docs' test module for the plugin, run as written: every check at once, then the
    parametrised cases one by one."""
    plugin = _documented_plugin()
    package = types.ModuleType("my_package")
    package.planners = plugin
    monkeypatch.setitem(sys.modules, "my_package", package)
    monkeypatch.setitem(sys.modules, "my_package.planners", plugin)
    (source,) = [b for b in _python_blocks() if "rrtpso_ompl.testing import" in b]
    tests: dict = {}
    exec(compile(source, "docs/planners.md", "exec"), tests)
    tests["test_all_checks_at_once"]()  # raises AssertionError listing any failure
    (mark,) = tests["test_straight"].pytestmark
    assert mark.kwargs["ids"] == [f"Straight-{check.__name__}" for check in CHECKS]
    for entry, check in mark.args[1]:
        tests["test_straight"](entry, check)


def test_the_documented_plugin_fails_where_a_straight_line_is_blocked():
    (entry,) = _documented_plugin().PLANNERS
    with pytest.raises(AssertionError) as exc:
        check_planner(entry, budget=BUDGET)
    assert "check_solves: Straight found no exact path" in str(exc.value)
    assert "check_parameters" not in str(exc.value)  # its parameter is declared soundly


# ----------------------------------------------------------------------------------------------
# Each check fails for a planner that breaks its property
# ----------------------------------------------------------------------------------------------
class Line(ob.Planner):
    """The straight line from start to goal, whatever lies between."""

    def __init__(self, si, name="Line"):
        super().__init__(si, name)

    def solve(self, ptc):
        pis = self.getPlannerInputStates()
        pis.restart()
        start, goal = pis.nextStart(), pis.nextGoal(ptc)
        if start is None or goal is None:
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        si = self.getSpaceInformation()
        path = og.PathGeometric(si, start, goal)
        self.getProblemDefinition().addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


class Sleepy(Line):
    """Ignores its termination condition: 0.3 s, whatever the budget."""

    def solve(self, ptc):
        time.sleep(0.3)
        return super().solve(ptc)


class OnceOnly(Line):
    """Solves until ``clear()`` has been called twice (the kit clears before its first solve)."""

    clears = 0

    def clear(self):
        super().clear()
        self.clears += 1

    def solve(self, ptc):
        if self.clears >= 2:
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        return super().solve(ptc)


class RisingStats(PlannerStats):
    def progress(self):
        return [(1e-6, 600.0), (2e-6, 700.0)]


class Sloppy(PythonPlanner):
    """Stores whatever ``set_params`` is given."""

    PARAMS = ParamTable(ParamSpec("n", int, 1, "How many.", low=0, high=10))

    def __init__(self, si):
        super().__init__(si, "Sloppy")

    def set_params(self, **params):
        self._values.update(params)
        return self

    def _solve(self, ptc):
        return Line.solve(self, ptc)


def _entry(name, factory, **kw):
    return PlannerEntry(name, factory=factory, **kw)


LINE = _entry("Line", Line)
SLEEPY = _entry("Sleepy", Sleepy)
ONCE = _entry("OnceOnly", OnceOnly)
RISING = _entry("Rising", Line, stats=lambda planner: RisingStats())
SLOPPY = _entry("Sloppy", Sloppy, params=Sloppy.PARAMS)
FAST = 0.05


def test_a_path_through_the_obstacle_is_caught():
    with pytest.raises(AssertionError, match="but the path failed the exact check"):
        check_solves(LINE, budget=FAST)
    with pytest.raises(AssertionError, match="the path collides or leaves the bounds"):
        check_valid_path(LINE, budget=FAST)


def test_a_planner_that_ignores_its_deadline_is_caught():
    with pytest.raises(AssertionError, match=r"took 0\.3\d* s for a 0\.05 s budget \(allowed"):
        check_deadline(SLEEPY, problem=OPEN, budget=FAST)


def test_a_planner_that_cannot_solve_after_clear_is_caught():
    with pytest.raises(AssertionError, match=r"after clear\(\), the planner found no exact path"):
        check_clear_and_solve_again(ONCE, problem=OPEN, budget=FAST)


def test_a_rising_best_cost_is_caught():
    with pytest.raises(AssertionError, match=r"the best cost rose from 600 .* to 700"):
        check_cost_never_rises(RISING, problem=OPEN, budget=FAST)


def test_a_planner_that_takes_a_value_out_of_range_is_caught():
    with pytest.raises(AssertionError, match=r"Sloppy: set_params\(\*\*\{.*\}\) was accepted"):
        check_parameters(SLOPPY, problem=OPEN, budget=FAST)


def test_the_kit_lists_each_check_once_and_ids_read_as_planner_and_check():
    assert len({c.__name__ for c in CHECKS}) == len(CHECKS) == 7
    mark = parametrize_with_checks(["RRTConnect"], budget=FAST)
    ids = mark.kwargs["ids"]
    assert ids[0] == "RRTConnect-check_solves" and len(ids) == len(CHECKS)
