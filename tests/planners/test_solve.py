"""``solve``: its named steps end in one verdict (``status``), from which ``solved`` and ``valid``
follow; a path that fails the exact check is never returned; the JSON keys of ``rrtpso solve
--json`` stay as the contract has them."""

from __future__ import annotations

import json

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.planners import PlannerRegistry, SolveResult, resolve, solve
from rrtpso_ompl.planners.registry import PlannerEntry

#: Every key ``rrtpso solve --json`` wrote before the verdicts were one (the contract's first).
JSON_KEYS = ["problem", "planner", "status", "solved", "length", "time", "seed", "path",
             "ompl_status", "time_limit", "valid", "clearance", "cost", "params", "stages",
             "benchmark"]  # fmt: skip


class Line(ob.Planner):
    """The straight line, through whatever lies between."""

    def __init__(self, si):
        super().__init__(si, "Line")

    def solve(self, ptc):
        pis = self.getPlannerInputStates()
        pis.restart()
        start, goal = pis.nextStart(), pis.nextGoal(ptc)
        path = og.PathGeometric(self.getSpaceInformation(), start, goal)
        self.getProblemDefinition().addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)


def test_a_path_through_an_obstacle_is_not_returned(single_circle):
    registry = PlannerRegistry()
    registry.register(PlannerEntry("Line", factory=Line))
    result = solve(single_circle, "Line", time_limit=0.1, seed=1, registry=registry)
    assert result.ompl_status == "Exact solution"  # as OMPL said
    assert result.status == "none" and not result.solved and not result.valid
    assert len(result.path) == 0 and result.length is None and result.clearance is None


def test_the_verdicts_are_one_status_and_the_json_keeps_its_keys(single_circle):
    result = solve(single_circle, "RRTConnect", time_limit=0.2, seed=1)
    data = json.loads(json.dumps(result.to_dict()))
    assert list(data) == JSON_KEYS
    assert (data["status"], data["solved"], data["valid"]) == ("exact", True, True)
    fields = set(SolveResult.__dataclass_fields__)
    assert "solved" not in fields and "valid" not in fields  # derived, not stored
    for status, solved, valid in [("exact", True, True), ("approximate", False, True),
                                  ("none", False, False)]:  # fmt: skip
        r = SolveResult(problem="p", planner="x", status=status, ompl_status="", length=None,
                        time=0.0, seed=None, path=np.empty((0, 2)))  # fmt: skip
        assert (r.solved, r.valid) == (solved, valid)
    with pytest.raises(ValueError, match="status must be one of"):
        SolveResult(problem="p", planner="x", status="solved", ompl_status="", length=None,
                    time=0.0, seed=None, path=np.empty((0, 2)))  # fmt: skip


def test_a_budget_the_file_gives_is_kept_with_post_passes():
    """The budget rule fills ``budget`` only when nobody gave it: the file's value stays, with
    post-passes too (before, the post-passes' share replaced it)."""
    from helpers import SINGLE_CIRCLE

    problem = problem_from_dict({**SINGLE_CIRCLE, "planner": {"params": {"budget": 0.1}}})
    result = solve(problem, "RRTstarPSO+pso", time_limit=0.25, seed=1)
    assert result.params["budget"] == 0.1
    filled = resolve(problem_from_dict(SINGLE_CIRCLE), "RRTstarPSO+pso", time_limit=0.25)
    assert filled.values["budget"] == pytest.approx(0.2)  # the planner's share, 1 - 0.2


def test_unsolvable_problem_reports_no_solution():
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
