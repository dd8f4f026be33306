"""What every Python planner of this package shares (planners/base.py): outside the plane it
refuses, never a wrong answer (issue 32).

Each case is a user's own ``og.SimpleSetup`` as the issue describes it: bounds 0-10, a ball (or
a disc, for SE(2) and its kin) of radius 2 at the centre, start (1, 1, ...) and goal (9, 9, ...),
a Python validity checker. Before, RRTstarPSO said "Exact solution" on ``RealVectorStateSpace(3)``
with the two-state path ``[1, 1, 8.739] -> [9, 9, 8.739]`` (neither the start nor the goal), the
PSO baseline did the same with an unset third coordinate, and in SE(2), Dubins and Reeds-Shepp
both crashed with ``TypeError: 'SE2StateType' object is not subscriptable``.
"""

from __future__ import annotations

import logging

import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.errors import PlannerError, UnsupportedSpaceError
from rrtpso_ompl.planners import PSOPlanner, RRTstarPSO, default_registry
from rrtpso_ompl.planners.baselines.exact import ExactPlanner

PLANNERS = [RRTstarPSO, PSOPlanner, ExactPlanner]
#: The logger that reports a refusal (the base class's).
LOGGER = "rrtpso_ompl.planners.base"


def _bounds(n: int) -> ob.RealVectorBounds:
    bounds = ob.RealVectorBounds(n)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    return bounds


def real_vector(n: int):
    space = ob.RealVectorStateSpace(n)
    space.setBounds(_bounds(n))

    def valid(s) -> bool:
        return sum((s[i] - 5.0) ** 2 for i in range(n)) > 4.0

    def put(s, v: float) -> None:
        for i in range(n):
            s[i] = v

    return space, valid, put


def plane_like(space):
    space.setBounds(_bounds(2))

    def valid(s) -> bool:
        return (s.getX() - 5.0) ** 2 + (s.getY() - 5.0) ** 2 > 4.0

    def put(s, v: float) -> None:
        s.setXY(v, v)
        s.setYaw(0.0)

    return space, valid, put


SPACES = {
    "R^3": lambda: real_vector(3),
    "R^6": lambda: real_vector(6),
    "SE(2)": lambda: plane_like(ob.SE2StateSpace()),
    "Dubins": lambda: plane_like(ob.DubinsStateSpace(1.0)),
    "Reeds-Shepp": lambda: plane_like(ob.ReedsSheppStateSpace(1.0)),
}
#: What the refusal names: the space's class as a user writes it.
KINDS = {
    "R^3": "ob.RealVectorStateSpace(3)",
    "R^6": "ob.RealVectorStateSpace(6)",
    "SE(2)": "ob.SE2StateSpace",
    "Dubins": "ob.DubinsStateSpace",
    "Reeds-Shepp": "ob.ReedsSheppStateSpace",
}


def users_setup(kind: str):
    """The issue's own SimpleSetup in ``kind``: (ss, space)."""
    space, valid, put = SPACES[kind]()
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(valid)
    start, goal = space.allocState(), space.allocState()
    put(start, 1.0)
    put(goal, 9.0)
    ss.setStartAndGoalStates(start, goal)
    return ss, space


def refusals(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records
            if r.name == LOGGER and r.levelno == logging.ERROR]  # fmt: skip


@pytest.mark.parametrize("kind", list(SPACES))
@pytest.mark.parametrize("cls", PLANNERS, ids=lambda c: c.__name__)
def test_a_space_other_than_the_plane_is_refused_never_answered(cls, kind, caplog):
    ss, space = users_setup(kind)
    planner = cls(ss.getSpaceInformation())
    ss.setPlanner(planner)
    with caplog.at_level(logging.ERROR):
        status = ss.solve(1.0)
    # A failed status (False), no path anywhere: not exact, not approximate, not a crash.
    assert status.getStatus() == ob.PlannerStatus.ABORT and not bool(status)
    assert not ss.haveSolutionPath() and not ss.getProblemDefinition().hasSolution()
    # One error line (setup's; solve does not repeat it), naming the planner and the space.
    (said,) = refusals(caplog)
    assert said == planner.unsupported
    assert said.startswith(f"{planner.getName()} refuses to plan: the state space ")
    assert f"{space.getName()!r} ({KINDS[kind]}" in said
    assert "ob.RealVectorStateSpace(2)" in said and "og.RRTstar" in said
    assert not any(r.exc_info for r in caplog.records)  # a refusal, not a traceback

    # Solving again (setup is not run again) refuses again, saying so again.
    caplog.clear()
    with caplog.at_level(logging.ERROR):
        again = ss.solve(1.0)
    assert again.getStatus() == ob.PlannerStatus.ABORT and not ss.haveSolutionPath()
    assert refusals(caplog) == [planner.unsupported]


@pytest.mark.parametrize("cls", PLANNERS, ids=lambda c: c.__name__)
def test_the_refusal_is_known_before_any_solve_and_absent_in_the_plane(cls):
    ss, space = users_setup("SE(2)")
    assert space.getName() in cls(ss.getSpaceInformation()).unsupported
    plane = ob.RealVectorStateSpace(2)
    plane.setBounds(_bounds(2))
    assert cls(ob.SpaceInformation(plane)).unsupported is None


def test_the_registry_s_planners_refuse_as_well():
    """Made by name, as ``default_registry().get(NAME).make(si)`` does."""
    ss, _space = users_setup("Dubins")
    for name in ("RRTstarPSO", "PSO", "Exact"):
        planner = default_registry().get(name).make(ss.getSpaceInformation())
        assert planner.unsupported is not None, name


def test_a_subclass_never_reads_a_state_of_another_space():
    """``_start_and_goal``, the helper subclasses read the start and goal with, refuses outside
    the plane rather than read a state as two coordinates."""
    ss, _space = users_setup("R^3")
    planner = PSOPlanner(ss.getSpaceInformation())
    planner.setProblemDefinition(ss.getProblemDefinition())
    with pytest.raises(UnsupportedSpaceError, match="RealVectorStateSpace\\(3\\)") as exc:
        planner._start_and_goal(ob.plannerNonTerminatingCondition())
    assert isinstance(exc.value, PlannerError) and isinstance(exc.value, ValueError)
