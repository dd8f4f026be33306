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
from rrtpso_ompl.params import ParamSpec, ParamTable
from rrtpso_ompl.planners import default_registry
from rrtpso_ompl.planners.base import PlannerStats, PythonPlanner
from rrtpso_ompl.planners.registry import PlannerEntry
from rrtpso_ompl.testing import (
    CHECKS,
    SIMPLE_PROBLEM,
    check_clear_and_solve_again,
    check_cost_never_rises,
    check_deadline,
    check_other_spaces,
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
    """Ignores its termination condition: 1.3 s, whatever the budget (more than the kit's
    tolerance, ``1.5 x 0.05 s + 1 s``)."""

    def solve(self, ptc):
        time.sleep(1.3)
        return super().solve(ptc)


class Late(Line):
    """Keeps its timed deadlines, but with a condition that has fired before it starts it does a
    first long iteration (1.3 s) before it looks."""

    def solve(self, ptc):
        if ptc():
            time.sleep(1.3)
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
LATE = _entry("Late", Late)
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
    with pytest.raises(AssertionError, match=r"solve\(\) took 1\.3\d* s for a 0\.05 s budget"):
        check_deadline(SLEEPY, problem=OPEN, budget=FAST)


def test_a_planner_that_ignores_an_expired_condition_is_caught():
    with pytest.raises(AssertionError, match=r"expired termination condition took 1\.3\d* s for "
                                             r"a 0 s budget \(allowed 1\.000 s\)"):  # fmt: skip
        check_deadline(LATE, problem=OPEN, budget=FAST)


def test_a_planner_that_cannot_solve_after_clear_is_caught():
    with pytest.raises(AssertionError, match=r"after clear\(\), the planner found no exact path"):
        check_clear_and_solve_again(ONCE, problem=OPEN, budget=FAST)


def test_a_rising_best_cost_is_caught():
    with pytest.raises(AssertionError, match=r"the best cost rose from 600 .* to 700"):
        check_cost_never_rises(RISING, problem=OPEN, budget=FAST)


def test_a_planner_that_takes_a_value_out_of_range_is_caught():
    with pytest.raises(AssertionError, match=r"Sloppy: set_params\(\*\*\{.*\}\) was accepted"):
        check_parameters(SLOPPY, problem=OPEN, budget=FAST)


class Hasty(Line):
    """OMPL's RRTConnect, but the straight line when the condition has already fired."""

    def __init__(self, si, name="Hasty"):
        super().__init__(si, name)
        self.inner = og.RRTConnect(si)

    def setup(self):
        super().setup()
        self.inner.setProblemDefinition(self.getProblemDefinition())
        self.inner.setup()

    def clear(self):
        super().clear()
        self.inner.clear()

    def solve(self, ptc):
        return super().solve(ptc) if ptc() else self.inner.solve(ptc)


class TwoCoordinates(Line):
    """Issue 32's RRTstarPSO: reads two coordinates of each state and makes a path of new
    states with those two set (the others at 8.739), in any real vector space."""

    def solve(self, ptc):
        pis = self.getPlannerInputStates()
        pis.restart()
        start, goal = pis.nextStart(), pis.nextGoal(ptc)
        si = self.getSpaceInformation()
        if not isinstance(start, ob.RealVectorStateType):
            return ob.PlannerStatus(ob.PlannerStatus.CRASH)
        path = og.PathGeometric(si)
        for x, y in ((start[0], start[1]), (goal[0], goal[1])):
            state = si.allocState()
            for i in range(si.getStateDimension()):
                state[i] = 8.739
            state[0], state[1] = x, y
            path.append(state)
        self.getProblemDefinition().addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


class Boaster(Line):
    """Says "Exact solution" and leaves no path."""

    def solve(self, ptc):
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


class Raiser(Line):
    """Raises out of solve in any space but the plane."""

    def solve(self, ptc):
        if self.getSpaceInformation().getStateDimension() != 2:
            raise TypeError("'SE2StateType' object is not subscriptable")
        return super().solve(ptc)


class SetupRefuser(Line):
    """Refuses every space but R^2 with an exception from setup(), before any solve."""

    def setup(self):
        if not isinstance(self.getSpaceInformation().getStateSpace(), ob.RealVectorStateSpace):
            raise ValueError("SetupRefuser plans in R^n only")
        if self.getSpaceInformation().getStateDimension() != 2:
            raise ValueError("SetupRefuser plans in R^2 only")
        super().setup()


def test_a_wrong_path_after_an_expired_condition_is_caught():
    hasty = _entry("Hasty", Hasty)
    check_solves(hasty, budget=BUDGET)  # a real path while it has time
    with pytest.raises(AssertionError, match="solve with an expired termination condition: the "
                                             "path collides"):  # fmt: skip
        check_valid_path(hasty, budget=BUDGET)


def test_a_path_that_does_not_join_start_and_goal_in_another_space_is_caught():
    with pytest.raises(AssertionError) as exc:
        check_other_spaces(_entry("TwoCoordinates", TwoCoordinates))
    lines = str(exc.value).splitlines()
    assert lines[0] == ("TwoCoordinates in a user's R^3 SimpleSetup: reported 'Exact solution' "
                        "with a wrong exact path: it starts at (1, 1, 8.739), not at the start "
                        "(1, 1, 1)")  # fmt: skip
    assert lines[1].startswith("TwoCoordinates in a user's R^6 SimpleSetup: reported 'Exact ")
    assert len(lines) == 2  # a crash status in SE(2) and Reeds-Shepp is a refusal


def test_a_straight_line_through_the_ball_is_caught_in_every_other_space():
    with pytest.raises(AssertionError) as exc:
        check_other_spaces(LINE)
    lines = str(exc.value).splitlines()
    assert len(lines) == 4
    assert lines[0].startswith("Line in a user's R^3 SimpleSetup: reported 'Exact solution' with "
                               "a wrong exact path: its motion 0 from (1, 1, 1) to (9, 9, 9) "
                               "passes through (")  # fmt: skip
    assert lines[0].endswith("invalid by the user's checker")
    assert lines[2].startswith("Line in a user's SE(2) SimpleSetup: ")


def test_an_exact_status_without_a_path_is_caught():
    with pytest.raises(
        AssertionError,
        match=r"Boaster in a user's R\^3 SimpleSetup: reported "
        r"'Exact solution', but holds no exact path",
    ):
        check_other_spaces(_entry("Boaster", Boaster))


def test_an_exception_out_of_solve_is_caught_and_one_out_of_setup_is_a_refusal():
    with pytest.raises(
        AssertionError,
        match=r"Raiser in a user's R\^3 SimpleSetup: solve\(\) "
        r"raised TypeError\(",
    ):
        check_other_spaces(_entry("Raiser", Raiser))
    check_other_spaces(_entry("SetupRefuser", SetupRefuser))  # passes: no answer, no wrong one


def test_the_kit_lists_each_check_once_and_ids_read_as_planner_and_check():
    assert len({c.__name__ for c in CHECKS}) == len(CHECKS) == 9
    mark = parametrize_with_checks(["RRTConnect"], budget=FAST)
    ids = mark.kwargs["ids"]
    assert ids[0] == "RRTConnect-check_solves" and len(ids) == len(CHECKS)
