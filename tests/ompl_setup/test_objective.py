"""The inflation objective as OMPL sees it: the same values, admissible heuristics."""

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.model.objective import InflationCost
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.ompl_setup import InflationObjective, array_to_path, make_context

DOC = {"bounds": [[0, 0], [10, 10]], "start": [1, 1], "goal": [9, 9],
       "robot": {"radius": 0.2, "inflation_radius": 1.0, "cost_scaling_factor": 2.0},
       "obstacles": [{"type": "rectangle", "min": [0, 4], "max": [4.5, 5]},
                     {"type": "circle", "center": [7, 2], "radius": 0.8}]}  # fmt: skip


@pytest.fixture(scope="module")
def ctx():
    return make_context(problem_from_dict(DOC))


def _state(ctx, xy):
    s = ctx.space.allocState()
    s[0], s[1] = xy
    return s


def test_the_context_carries_the_problems_objective(ctx):
    obj = ctx.ss.getProblemDefinition().getOptimizationObjective()
    assert isinstance(obj, InflationObjective)
    plain = make_context(problem_from_dict({**DOC, "robot": {"radius": 0.2}}))
    got = plain.ss.getProblemDefinition().getOptimizationObjective()
    assert not isinstance(got, InflationObjective)


def test_ompl_path_costs_equal_the_declared_objective(ctx):
    obj = ctx.ss.getProblemDefinition().getOptimizationObjective()
    path = np.array([[1, 1], [5, 3.6], [6, 3.0], [9, 9]])
    expected = InflationCost.of(ctx.problem.robot).path_cost(ctx.world, path)
    # OMPL's planners see motions on the interpolated field (within 0.05 %), reports are exact.
    assert array_to_path(ctx.si, path).cost(obj).value() == pytest.approx(expected, rel=1e-3)
    assert obj.exact_cost(array_to_path(ctx.si, path)) == pytest.approx(expected, rel=1e-15)


def test_the_heuristics_are_lower_bounds(ctx):
    obj = ctx.ss.getProblemDefinition().getOptimizationObjective()
    goal = ctx.ss.getProblemDefinition().getGoal()
    rng = np.random.default_rng(7)
    pts = rng.uniform(0, 10, size=(200, 2))
    for a, b in zip(pts[::2], pts[1::2], strict=True):
        sa, sb = _state(ctx, a), _state(ctx, b)
        true = obj.motionCost(sa, sb).value()
        assert obj.motionCostHeuristic(sa, sb).value() <= true + 1e-12
        # The cost-to-go: at most the cost of the straight motion to the goal (any path to the
        # goal costs at least its length, at least the straight line's length).
        to_goal = obj.motionCost(sa, _state(ctx, ctx.problem.goal)).value()
        assert obj.costToGo(sa, goal).value() <= to_goal + 1e-9
    # OMPL's default cost-to-go (the wheel lets Python set no other): zero, uninformed.
    assert obj.costToGo(_state(ctx, (1, 1)), goal).value() == 0.0


def test_rrtstar_optimises_the_objective_and_it_survives_garbage_collection(ctx):
    import gc

    ctx.ss.clear()
    ctx.ss.setPlanner(og.RRTstar(ctx.si))
    gc.collect()  # OMPL holds the objective in C++; its Python overrides must stay alive
    assert ctx.ss.solve(ob.timedPlannerTerminationCondition(0.3))
    obj = ctx.ss.getProblemDefinition().getOptimizationObjective()
    path = ctx.ss.getSolutionPath()
    assert path.cost(obj).value() == pytest.approx(obj.exact_cost(path), rel=1e-3)
    along_wall = obj.motionCost(_state(ctx, (0.5, 3.6)), _state(ctx, (4.0, 3.6)))
    assert along_wall.value() > 3.5 * 1.5  # 0.4 from the wall: c = exp(-2 * 0.2)
