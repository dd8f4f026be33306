"""One contract for every registered planner (after OMPL's tests/base/PlannerTest.h)."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from helpers import SINGLE_CIRCLE_OPTIMUM
from ompl import base as ob

from rrtpso_ompl.errors import ParameterError
from rrtpso_ompl.ompl_setup import make_context, path_to_array
from rrtpso_ompl.planners.registry import default_registry
from rrtpso_ompl.planners.solve import solve

REGISTRY = default_registry()
BUDGET = 0.25


def _make(problem, name: str, budget: float):
    ctx = make_context(problem)
    entry = REGISTRY.get(name)
    params = {"budget": budget} if any(p.name == "budget" for p in entry.params) else {}
    planner = entry.make(ctx.si, params)
    ctx.ss.setPlanner(planner)
    ctx.ss.setup()
    return ctx, planner


def _check_solution(ctx, problem) -> float:
    pdef = ctx.ss.getProblemDefinition()
    assert pdef.hasExactSolution()
    xy = path_to_array(pdef.getSolutionPath())
    assert ctx.world.path_valid(xy), "returned path collides or leaves the bounds"
    assert np.allclose(xy[0], problem.start) and np.allclose(xy[-1], problem.goal)
    length = float(np.linalg.norm(np.diff(xy, axis=0), axis=1).sum())
    straight = math.dist(problem.start, problem.goal)
    assert length >= straight - 1e-9, "a path cannot be shorter than the straight line"
    return length


@pytest.mark.parametrize("name", REGISTRY.names())
def test_planner_contract(name, single_circle):
    ctx, _planner = _make(single_circle, name, BUDGET)
    # solve, clear, solve again: the planner must work after clear() (OMPL's PlannerTest).
    for _ in range(2):
        ctx.ss.clear()
        status = ctx.ss.solve(ob.timedPlannerTerminationCondition(BUDGET))
        assert status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION, str(status)
        _check_solution(ctx, single_circle)

    # A tiny budget must be honoured: whatever it returns, it returns (a generous bound, 100x
    # the budget, so that only a planner that ignores its termination condition fails).
    ctx.ss.clear()
    tiny = make_context(single_circle)
    small = REGISTRY.get(name).make(
        tiny.si, {"budget": 0.01} if "budget" in {p.name for p in REGISTRY.get(name).params} else {}
    )
    tiny.ss.setPlanner(small)
    t0 = time.perf_counter()
    status = tiny.ss.solve(ob.timedPlannerTerminationCondition(0.01))
    assert time.perf_counter() - t0 < 1.0
    if status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION:
        _check_solution(tiny, single_circle)


@pytest.mark.parametrize("name", REGISTRY.names())
def test_always_terminating_condition(name, single_circle):
    ctx, _ = _make(single_circle, name, 0.0)
    status = ctx.ss.solve(ob.plannerAlwaysTerminatingCondition())
    assert status.getStatus() != ob.PlannerStatus.CRASH


def test_rrtstarpso_reaches_known_optimum(single_circle):
    result = solve(single_circle, "RRTstarPSO", time_limit=1.0, seed=5)
    assert result.solved and result.valid
    assert SINGLE_CIRCLE_OPTIMUM - 1e-6 <= result.length <= SINGLE_CIRCLE_OPTIMUM * 1.005
    stages = result.stages
    # The PSO stage never makes RRT*'s path longer, and its best cost never rises.
    assert stages["pso_length"] <= stages["rrt_length"] + 1e-9
    hist = np.asarray(stages["pso_history"])
    assert len(hist) == stages["pso_iterations"] + stages["pso_rounds"]
    assert result.time <= 1.0 + 0.2  # budget split by the planner itself (loose bound)


def test_rrtstarpso_records_stages(single_circle):
    result = solve(single_circle, "RRTstarPSO", time_limit=0.3, seed=2)
    s = result.stages
    for key in (
        "rrt_length",
        "rrt_time",
        "rrt_iterations",
        "pso_length",
        "pso_time",
        "pso_iterations",
        "pso_history",
        "rrt_path",
    ):
        assert key in s
    assert s["rrt_iterations"] > 0 and s["pso_iterations"] > 0
    assert s["rrt_time"] < 0.3  # RRT* stopped at its share, leaving time for the swarm
    assert result.params["budget"] == 0.3


def test_rrtstarpso_works_in_a_foreign_simple_setup():
    """Selectable like any stock planner: a SimpleSetup not built by this package (plain
    validity function, OMPL's default motion validator) still gets a valid, shorter path."""
    from ompl import geometric as og

    from rrtpso_ompl.planners.rrtstar_pso import RRTstarPSO

    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: math.hypot(s[0] - 0.5, s[1] - 0.5) > 0.2)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.05, 0.05, 0.95, 0.95
    ss.setStartAndGoalStates(start, goal, 1e-9)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(ss.getSpaceInformation()))
    planner = RRTstarPSO(ss.getSpaceInformation(), budget=0.3, iterations=20)
    ss.setPlanner(planner)
    status = ss.solve(0.3)
    assert status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    path = ss.getSolutionPath()
    assert path.check()
    assert ss.getSolutionPlannerName() == "RRTstarPSO"
    assert planner.last_stats.pso_length <= planner.last_stats.rrt_length + 1e-12


def test_params_by_name_and_validation(single_circle):
    ctx = make_context(single_circle)
    entry = REGISTRY.get("RRTstarPSO")
    planner = entry.make(ctx.si, {"swarm_size": "12", "goal_bias": 0.2, "prune": "false"})
    assert planner.get_param("swarm_size") == 12
    assert planner.get_param("goal_bias") == 0.2
    assert planner.get_param("prune") is False
    with pytest.raises(ValueError, match="goal_bias"):
        entry.make(ctx.si, {"goal_bias": 1.5})
    with pytest.raises(ParameterError, match="known"):
        entry.make(ctx.si, {"no_such_param": 1})
    stock = REGISTRY.get("RRTstar").make(ctx.si, {"range": 42.0, "rewire_factor": 1.5})
    assert stock.getRange() == 42.0 and stock.getRewireFactor() == 1.5


def test_crash_is_reported_not_raised(single_circle, monkeypatch):
    from rrtpso_ompl.planners import post

    def boom(*args, **kwargs):
        raise RuntimeError("injected failure")

    monkeypatch.setattr(post, "optimize_path", boom)
    ctx, _ = _make(single_circle, "RRTstarPSO", 0.1)
    status = ctx.ss.solve(ob.timedPlannerTerminationCondition(0.1))
    assert status.getStatus() == ob.PlannerStatus.CRASH


def test_unsolvable_problem_reports_no_solution():
    from rrtpso_ompl.model.problem import problem_from_dict

    # The goal sits in a closed box: start and goal are free but no path exists.
    walls = [
        {"type": "rectangle", "min": [300, 300], "max": [460, 310]},
        {"type": "rectangle", "min": [300, 450], "max": [460, 460]},
        {"type": "rectangle", "min": [300, 300], "max": [310, 460]},
        {"type": "rectangle", "min": [450, 300], "max": [460, 460]},
    ]
    problem = problem_from_dict(
        {
            "bounds": [[0, 0], [500, 500]],
            "start": [50, 50],
            "goal": [380, 380],
            "robot": {"radius": 10},
            "obstacles": walls,
        }
    )
    for name in ("RRTstarPSO", "PSO", "RRTstar"):
        result = solve(problem, name, time_limit=0.2, seed=1)
        assert not result.solved
        assert result.status in ("none", "approximate")
        if result.status == "approximate":
            assert result.valid  # an approximate path is still collision-free
