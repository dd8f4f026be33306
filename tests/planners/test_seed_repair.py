"""Repairing RRTstarPSO's seed outside the plane (issue 35): a motion OMPL's check at the space's
resolution lets through but a check 100 times finer refuses is replaced by motions that pass it.

The obstacle is built from the resolution: a small cylinder on the straight line from the start
to the goal, between two of ``checkMotion``'s samples, wider than the fine check's spacing. So
RRT* connects the two directly (its goal bias, and the motion passes its check), and only the
fine check sees the collision; iteration-bounded and seeded, the same on any machine.
"""

from __future__ import annotations

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.ompl_setup import seed_ompl
from rrtpso_ompl.ompl_setup.spaces import space_adapter
from rrtpso_ompl.planners import RRTstarPSO
from rrtpso_ompl.planners.pso.space_path import FINAL_FINER, MotionChecker
from rrtpso_ompl.planners.rrtstar_pso.repair import MAX_CHECKS, repair_path

START, GOAL = np.array([1.0, 5.0, 1.0]), np.array([9.0, 5.0, 1.0])
DENSE = 4000


class Grazed:
    """An R^3 setup whose straight motion from START to GOAL passes ``checkMotion`` but not the
    fine check: a cylinder along z of radius ``0.3 * gap`` midway between two of its samples
    (``gap``: their spacing), or, with ``wall``, a slab across the whole box there."""

    def __init__(self, wall: bool = False) -> None:
        space = ob.RealVectorStateSpace(3)
        bounds = ob.RealVectorBounds(3)
        bounds.setLow(0.0)
        bounds.setHigh(10.0)
        space.setBounds(bounds)
        self.ss = og.SimpleSetup(space)
        self.obstacle = {"x": -1.0, "r": 0.0}
        self.wall = wall
        self.ss.setStateValidityChecker(self.valid)
        self.si = self.ss.getSpaceInformation()
        self.si.setup()  # not ss.setup(): with no start and goal it crashes the wheel
        self.adapter = space_adapter(self.si)
        sa, sb = self.si.allocState(), self.si.allocState()
        self.adapter.assign(sa, START)
        self.adapter.assign(sb, GOAL)
        gap = 8.0 / space.validSegmentCount(sa, sb)
        self.obstacle = {"x": 1.0 + gap * (round(4.0 / gap) + 0.5), "r": 0.3 * gap}
        self.checks = 0

    def valid(self, s) -> bool:
        self.checks += 1
        dx = s[0] - self.obstacle["x"]
        if self.wall:
            return abs(dx) > self.obstacle["r"]
        return dx * dx + (s[1] - 5.0) ** 2 > self.obstacle["r"] ** 2

    def dense_free(self, rows: np.ndarray) -> bool:
        path = self.adapter.array_to_path(self.si, rows)
        path.interpolate(DENSE)
        return all(self.si.isValid(s) for s in path.getStates())


def test_a_grazing_motion_is_repaired_into_motions_that_pass_the_fine_check():
    scene = Grazed()
    checker = MotionChecker(scene.si, scene.adapter)
    assert checker.motion_free(START, GOAL, fine=False)  # OMPL's own check lets it through
    assert not checker.motion_free(START, GOAL, factor=FINAL_FINER)
    rows = np.array([START, GOAL])
    repaired = repair_path(rows, scene.adapter, checker, np.random.default_rng(0))
    assert repaired is not None and len(repaired) > 2
    assert np.array_equal(repaired[0], START) and np.array_equal(repaired[-1], GOAL)
    assert checker.path_free(repaired, factor=FINAL_FINER)
    assert scene.dense_free(repaired) and not scene.dense_free(rows)
    # A detour round a cylinder of radius 0.3 gap costs little.
    assert scene.adapter.length(repaired) < 1.1 * scene.adapter.length(rows)


def test_a_motion_that_cannot_be_repaired_gives_none_within_the_bound_on_checks():
    scene = Grazed(wall=True)  # a slab across the whole box: no way round
    checker = MotionChecker(scene.si, scene.adapter)
    assert checker.motion_free(START, GOAL, fine=False)
    assert repair_path(np.array([START, GOAL]), scene.adapter, checker,
                       np.random.default_rng(0)) is None  # fmt: skip
    assert checker.calls <= MAX_CHECKS + 2


def test_a_fired_stop_ends_the_repair_with_no_path():
    scene = Grazed()
    checker = MotionChecker(scene.si, scene.adapter)
    assert repair_path(np.array([START, GOAL]), scene.adapter, checker,
                       np.random.default_rng(0), stop=lambda: True) is None  # fmt: skip
    assert checker.calls == 0


def test_rrtstarpso_repairs_a_seed_that_grazes_and_answers_rightly():
    seed_ompl(3)
    scene = Grazed()
    start, goal = scene.si.allocState(), scene.si.allocState()
    scene.adapter.assign(start, START)
    scene.adapter.assign(goal, GOAL)
    scene.ss.setStartAndGoalStates(start, goal)
    planner = RRTstarPSO(scene.si, rrt_max_iterations=50, iterations=20, refine_rounds=0,
                         polish_rounds=0, budget=0.0, seed=1)  # fmt: skip
    scene.ss.setPlanner(planner)
    status = scene.ss.solve(ob.plannerNonTerminatingCondition())
    assert status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    stats = planner.last_stats
    assert "repair" in stats.stages and stats.seed_source.endswith("+repair")
    rows = scene.adapter.path_to_array(scene.ss.getProblemDefinition().getSolutionPath())
    assert np.array_equal(rows[0], START) and np.array_equal(rows[-1], GOAL)
    assert scene.dense_free(rows)
    # The swarm shortens the repaired seed; the path is no longer than it, nor than RRT*'s.
    length = scene.adapter.length(rows)
    assert 8.0 < length <= stats.seed_length + 1e-9 and length <= stats.rrt_length + 1e-9
