"""RRTstarPSO on its own: the known optimum, its stages, a foreign SimpleSetup, parameters by
name (get_params / set_params), the automatic range reported and not written back, crashes
reported (the conformance every planner passes is in test_conformance.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers import SINGLE_CIRCLE_OPTIMUM
from ompl import base as ob

from rrtpso_ompl.errors import ParameterError
from rrtpso_ompl.ompl_setup import make_context
from rrtpso_ompl.planners import PSOPathOptimizer, solve
from rrtpso_ompl.planners.registry import default_registry
from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSO

REGISTRY = default_registry()


def _make(problem, name: str, budget: float):
    ctx = make_context(problem)
    planner = REGISTRY.get(name).make(ctx.si, {"budget": budget})
    ctx.ss.setPlanner(planner)
    ctx.ss.setup()
    return ctx, planner


#: Work-bounded RRTstarPSO (RRT* iterations, one swarm round of bounded iterations): the same
#: path on any machine; the time limits given with it are caps, far from reached.
BOUNDED = {"rrt_max_iterations": 100, "iterations": 20, "refine_rounds": 0, "polish_rounds": 0}


def test_rrtstarpso_reaches_known_optimum(single_circle):
    result = solve(single_circle, "RRTstarPSO", time_limit=60.0, seed=5, params=BOUNDED)
    assert result.solved and result.valid
    assert SINGLE_CIRCLE_OPTIMUM - 1e-6 <= result.length <= SINGLE_CIRCLE_OPTIMUM * 1.005
    stages = result.stages
    # The PSO stage never makes RRT*'s path longer, and its best cost never rises.
    assert stages["pso_length"] <= stages["rrt_length"] + 1e-9
    hist = np.asarray(stages["pso_history"])
    assert len(hist) == stages["pso_iterations"] + stages["pso_rounds"]
    assert np.all(np.diff(hist) <= 1e-9)


def test_rrtstarpso_records_stages(single_circle):
    # No convergence stop: the corridor stage's path is already taut round the circle, and the
    # swarm would stop early.
    result = solve(single_circle, "RRTstarPSO", time_limit=60.0, seed=2,
                   params={**BOUNDED, "tolerance": 0.0})  # fmt: skip
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
    assert s["rrt_iterations"] == BOUNDED["rrt_max_iterations"]
    assert s["pso_iterations"] == BOUNDED["iterations"] and s["pso_rounds"] == 1
    # The stages run one after the other inside the solve.
    assert 0 < s["rrt_time"] + s["pso_time"] <= result.time
    assert result.params["budget"] == 60.0


def test_the_rrtstar_stage_stops_when_its_share_of_the_budget_ends(single_circle):
    """RRT* stops at its share of the budget (the swarm gets the rest) by its own condition: with
    the budget already spent it grows nothing although the outer condition never fires, and with
    a fresh budget it returns by itself (the outer condition still never fires)."""
    import time

    from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSOStats

    _ctx, planner = _make(single_circle, "RRTstarPSO", 0.2)
    never = ob.PlannerTerminationCondition(lambda: False)
    spent = RRTstarPSOStats()
    planner._run_rrtstar(never, time.perf_counter() - 0.2, spent)
    assert spent.rrt_iterations == 0
    fresh = RRTstarPSOStats()
    planner._run_rrtstar(never, time.perf_counter(), fresh)
    # Returning at all is the property (it would loop for ever otherwise), having grown the
    # tree or, with no path by ``connect_after`` of its share, handed over to BIT*.
    assert fresh.rrt_iterations > 0 or fresh.first_solution == "BITstar"


def test_rrtstarpso_works_in_a_foreign_simple_setup():
    """Selectable like any stock planner: a SimpleSetup not built by this package (plain
    validity function, OMPL's default motion validator) still gets a valid, shorter path."""
    from ompl import geometric as og

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
    params = planner.get_params()
    assert params["swarm_size"] == 12 and params["goal_bias"] == 0.2 and params["prune"] is False
    assert set(params) == set(RRTstarPSO.PARAMS.names())  # every parameter, defaults included
    with pytest.raises(ValueError, match="goal_bias"):
        entry.make(ctx.si, {"goal_bias": 1.5})
    with pytest.raises(ParameterError, match="known"):
        entry.make(ctx.si, {"no_such_param": 1})
    stock = REGISTRY.get("RRTstar").make(ctx.si, {"range": 42.0, "rewire_factor": 1.5})
    assert stock.getRange() == 42.0 and stock.getRewireFactor() == 1.5


def test_set_params_takes_keywords_validates_them_together_and_returns_the_planner(single_circle):
    """scikit-learn's form: ``set_params(**params)`` returns the planner; rules apply to the new
    values jointly; a refused call changes nothing."""
    ctx = make_context(single_circle)
    planner = RRTstarPSO(ctx.si)
    assert planner.set_params(c1=3.0, c2=0.5) is planner  # c1 + c2 < 4 only together
    assert (planner.get_params()["c1"], planner.get_params()["c2"]) == (3.0, 0.5)
    before = planner.get_params()
    with pytest.raises(ParameterError, match="c1 \\+ c2 < 4"):
        planner.set_params(c2=1.5, swarm_size=20)
    with pytest.raises(ParameterError, match="swarm_siz"):
        planner.set_params(swarm_siz=20)
    assert planner.get_params() == before


def test_the_automatic_range_is_reported_not_written_back(single_circle):
    """``range`` 0 lets RRTstarPSO choose; the choice goes to the stats (``range_used``), the
    user's parameter stays 0 (before, setup() overwrote it)."""
    ctx, planner = _make(single_circle, "RRTstarPSO", 0.1)
    assert planner.get_params()["range"] == 0.0  # after setup()
    ctx.ss.solve(0.1)
    assert planner.get_params()["range"] == 0.0
    assert planner.last_stats.range_used == pytest.approx(0.2 * math.hypot(500, 500))
    result = solve(single_circle, "RRTstarPSO", time_limit=0.1, seed=1)
    assert result.params["range"] == 0.0 and result.stages["range_used"] > 0
    chosen = solve(single_circle, "RRTstarPSO", time_limit=0.1, seed=1, params={"range": 50})
    assert chosen.params["range"] == 50.0 and chosen.stages["range_used"] == 50.0


def test_the_path_optimizer_has_get_params_and_set_params(single_circle):
    ctx = make_context(single_circle)
    optimizer = PSOPathOptimizer(ctx.si, swarm_size=12)
    assert optimizer.get_params()["swarm_size"] == 12
    assert optimizer.set_params(iterations="7") is optimizer
    assert optimizer.options.iterations == 7
    with pytest.raises(ParameterError, match="c1 \\+ c2 < 4"):
        optimizer.set_params(c1=3.0)
    with pytest.raises(ParameterError, match="swarm_sizes"):
        optimizer.set_params(swarm_sizes=3)
    assert optimizer.get_params()["c1"] == PSOPathOptimizer(ctx.si).get_params()["c1"]
    with pytest.raises(TypeError):
        PSOPathOptimizer(ctx.si, None)  # the options are keyword-only


def test_crash_is_reported_not_raised(single_circle, monkeypatch):
    from rrtpso_ompl.planners import post

    def boom(*args, **kwargs):
        raise RuntimeError("injected failure")

    monkeypatch.setattr(post, "optimize_path", boom)
    ctx, _ = _make(single_circle, "RRTstarPSO", 0.1)
    status = ctx.ss.solve(ob.timedPlannerTerminationCondition(0.1))
    assert status.getStatus() == ob.PlannerStatus.CRASH
