"""RRTstarPSO and the swarm in a user's own ``og.SimpleSetup`` outside the plane: R^3, R^6,
SE(2), Dubins and Reeds-Shepp with a Python validity checker (issue 35).

Every run is bounded by iterations (RRT*'s ``rrt_max_iterations``, the swarm's ``iterations``,
no budget, a termination condition that never fires) and seeded (OMPL's sequence and the
planner's ``seed``), so the same work is done on any machine.
"""

from __future__ import annotations

import json
import logging
import time

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.errors import UnsupportedSpaceError
from rrtpso_ompl.ompl_setup import seed_ompl
from rrtpso_ompl.ompl_setup.spaces import space_adapter
from rrtpso_ompl.planners import PSOPathOptimizer, RRTstarPSO
from rrtpso_ompl.planners.post import run_post
from rrtpso_ompl.planners.pso.path_optimizer import PathOptimizerOptions
from rrtpso_ompl.planners.pso.space_path import optimize_space_path
from rrtpso_ompl.planners.registry import PlannerEntry
from rrtpso_ompl.testing import OTHER_SPACES, check_other_spaces

#: Circular obstacles (centre x, centre y, radius) in the 0..10 box; in R^n they are cylinders
#: along the other axes.
OBSTACLES = ((5.0, 5.0, 2.0), (2.5, 7.0, 1.0), (7.5, 3.0, 1.0))
#: Work bounds: iterations, not seconds.
PARAMS = dict(rrt_max_iterations=600, iterations=40, refine_rounds=1, polish_rounds=0,
              budget=0.0, seed=5)  # fmt: skip
#: States a path is cut into for the dense check (far finer than checkMotion's resolution).
DENSE = 4000

KINDS = ("R^3", "R^6", "SE(2)", "Dubins", "Reeds-Shepp")


class Scene:
    """A user's setup of one kind: bounds 0..10, the obstacles, start (1, ..) and goal (9, ..)
    (SE(2)-like: headings 0 and pi/2)."""

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.se2 = not kind.startswith("R^")
        self.n = 2 if self.se2 else int(kind[2:])
        space = {"SE(2)": ob.SE2StateSpace, "Dubins": lambda: ob.DubinsStateSpace(0.8),
                 "Reeds-Shepp": lambda: ob.ReedsSheppStateSpace(0.8)}.get(
            kind, lambda: ob.RealVectorStateSpace(self.n))()  # fmt: skip
        bounds = ob.RealVectorBounds(self.n)
        bounds.setLow(0.0)
        bounds.setHigh(10.0)
        space.setBounds(bounds)
        self.space = space
        self.ss = og.SimpleSetup(space)
        self.ss.setStateValidityChecker(self.valid)
        self.start, self.goal = self.state(1.0, 0.0), self.state(9.0, 1.5707963267948966)
        self.ss.setStartAndGoalStates(self.start, self.goal)
        self.si = self.ss.getSpaceInformation()

    def coords(self, s) -> list[float]:
        if self.se2:
            return [s.getX(), s.getY(), s.getYaw()]
        return [s[i] for i in range(self.n)]

    def state(self, value: float, yaw: float):
        s = self.space.allocState()
        if self.se2:
            s.setXY(value, value)
            s.setYaw(yaw)
        else:
            for i in range(self.n):
                s[i] = value
        return s

    def valid(self, s) -> bool:
        xs = self.coords(s)[: self.n]
        if not all(0.0 <= x <= 10.0 for x in xs):
            return False
        return all((xs[0] - cx) ** 2 + (xs[1] - cy) ** 2 > r * r for cx, cy, r in OBSTACLES)

    def dense_invalid(self, path: og.PathGeometric) -> list[list[float]]:
        """States of the path, cut by the space itself into DENSE, that the checker refuses."""
        dense = og.PathGeometric(path)
        dense.interpolate(DENSE)
        assert dense.getStateCount() >= DENSE
        return [self.coords(s) for s in dense.getStates() if not self.si.isValid(s)]


def _solve(kind: str, **params):
    seed_ompl(11)
    scene = Scene(kind)
    planner = RRTstarPSO(scene.si, **(PARAMS | params))
    scene.ss.setPlanner(planner)
    status = scene.ss.solve(ob.plannerNonTerminatingCondition())
    return scene, planner, status


@pytest.mark.parametrize("kind", KINDS)
def test_rrtstarpso_solves_validly_and_no_longer_than_its_seed(kind):
    scene, planner, status = _solve(kind)
    assert status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    pdef = scene.ss.getProblemDefinition()
    assert pdef.hasExactSolution() and scene.ss.getSolutionPlannerName() == "RRTstarPSO"
    path = pdef.getSolutionPath()
    states = path.getStates()
    assert scene.coords(states[0]) == scene.coords(scene.start)  # exactly
    assert scene.coords(states[-1]) == scene.coords(scene.goal)
    assert path.check()
    assert scene.dense_invalid(path) == []
    stats = planner.last_stats
    assert stats.stages == ["RRTstar", "simplify", "pso"] and stats.space == kind.replace(
        "R^3", "R^n").replace("R^6", "R^n")  # fmt: skip
    # No longer than the path it was seeded from, nor RRT*'s, by the space's own distance.
    length = path.length()
    assert length <= stats.seed_length + 1e-9 and stats.seed_length <= stats.rrt_length + 1e-9
    assert abs(length - stats.pso_length) <= 1e-9 * max(length, 1.0)
    assert json.loads(json.dumps(stats.to_dict()))["stages"] == stats.stages


@pytest.mark.parametrize("kind", ["R^3", pytest.param("Dubins", marks=pytest.mark.slow)])
def test_the_same_seeds_give_the_same_path(kind):
    paths = []
    for _ in range(2):
        scene, _planner, _status = _solve(kind)
        paths.append([scene.coords(s) for s in scene.ss.getSolutionPath().getStates()])
    assert paths[0] == paths[1]


def test_the_swarm_shortens_a_detour_in_se2_and_keeps_it_valid():
    """The optimiser alone on a valid but long SE(2) path: shorter, valid, ends kept."""
    scene = Scene("SE(2)")
    scene.si.setup()
    adapter = space_adapter(scene.si)
    rows = np.array([[1.0, 1.0, 0.0], [1.0, 9.0, 1.0], [4.0, 9.5, 0.0], [9.0, 9.0, 1.5707963]])
    path = adapter.array_to_path(scene.si, rows)
    assert path.check()
    before = path.length()
    optimizer = PSOPathOptimizer(scene.si, rng=np.random.default_rng(0), iterations=40)
    assert optimizer.optimize(path)  # no time limit: bounded by iterations
    assert path.length() < before and path.check() and scene.dense_invalid(path) == []
    out = adapter.path_to_array(path)
    assert out[0].tolist() == rows[0].tolist() and out[-1].tolist() == rows[-1].tolist()
    assert optimizer.last_result.motion_checks > 0


def test_an_invalid_input_comes_back_unchanged_when_nothing_valid_is_shorter():
    """A straight line through the central obstacle: no valid path is shorter, so the swarm
    returns its input (never a 'shorter' invalid one)."""
    scene = Scene("R^3")
    scene.si.setup()
    adapter = space_adapter(scene.si)
    rows = np.array([[1.0, 1.0, 1.0], [5.0, 5.0, 5.0], [9.0, 9.0, 9.0]])
    options = PathOptimizerOptions(iterations=20)
    result = optimize_space_path(rows, adapter, scene.si, options, np.random.default_rng(1))
    assert not result.improved and np.array_equal(result.path, rows)


def test_a_fired_condition_stops_the_swarm_before_it_starts():
    scene = Scene("Dubins")
    scene.si.setup()
    adapter = space_adapter(scene.si)
    rows = np.array([[1.0, 1.0, 0.0], [1.0, 9.0, 1.0], [9.0, 9.0, 1.5707963]])
    result = optimize_space_path(rows, adapter, scene.si, PathOptimizerOptions(),
                                 np.random.default_rng(1), terminate=lambda: True)  # fmt: skip
    assert not result.improved and result.n_iterations == 0 and result.motion_checks == 0


def _se3_setup():
    space = ob.SE3StateSpace()
    bounds = ob.RealVectorBounds(3)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: True)
    start, goal = space.allocState(), space.allocState()
    start.setXYZ(1.0, 1.0, 1.0)
    start.rotation().setIdentity()
    goal.setXYZ(9.0, 9.0, 9.0)
    goal.rotation().setIdentity()
    ss.setStartAndGoalStates(start, goal)
    return ss


def test_an_unsupported_space_is_refused_with_its_name(caplog):
    ss = _se3_setup()
    planner = RRTstarPSO(ss.getSpaceInformation())
    assert planner.unsupported.startswith("RRTstarPSO refuses to plan: the state space ")
    assert "(ob.SE3StateSpace, 6 dimensions)" in planner.unsupported
    ss.setPlanner(planner)
    with caplog.at_level(logging.ERROR):
        status = ss.solve(0.5)
    assert status.getStatus() == ob.PlannerStatus.ABORT and not ss.haveSolutionPath()
    assert planner.unsupported in [r.getMessage() for r in caplog.records]
    with pytest.raises(UnsupportedSpaceError, match=r"^PSOPathOptimizer: .*SE3StateSpace"):
        PSOPathOptimizer(ss.getSpaceInformation())


def test_the_pso_post_pass_after_ompl_s_rrtstar_in_r6():
    """``run_post(..., ["simplify", "pso"])``, as ``+pso`` runs it, on og.RRTstar's path in R^6:
    valid, exact ends, no longer than before each step."""
    seed_ompl(3)
    scene = Scene("R^6")
    rrt = og.RRTstar(scene.si)
    scene.ss.setPlanner(rrt)
    iterations = []

    def enough() -> bool:
        iterations.append(1)
        return len(iterations) > 800  # bounded by iterations, not seconds

    assert scene.ss.solve(ob.PlannerTerminationCondition(enough))
    path = scene.ss.getProblemDefinition().getSolutionPath()
    steps = run_post(scene.si, path, ["simplify", "pso"], time.perf_counter() + 60.0,
                     values={"iterations": 30, "polish_rounds": 0},
                     rng=np.random.default_rng(2))  # fmt: skip
    assert [s.step for s in steps] == ["simplify", "pso"]
    assert all(s.length_after <= s.length_before + 1e-9 for s in steps)
    assert path.check() and scene.dense_invalid(path) == []
    states = path.getStates()
    assert scene.coords(states[0]) == scene.coords(scene.start)
    assert scene.coords(states[-1]) == scene.coords(scene.goal)


class _Inflating(RRTstarPSO):
    """Reports a seed shorter than the path it returns (a swarm that made its path longer).
    Bounded by iterations, not by the kit's 0.1 s, so that it answers on any machine."""

    def solve(self, ptc):
        self.set_params(budget=0.0, rrt_max_iterations=300, iterations=20)
        status = super().solve(ob.plannerNonTerminatingCondition())
        if self.last_stats is not None and self.last_stats.seed_length is not None:
            self.last_stats.seed_length *= 0.5
        return status


def test_the_kit_checks_the_planners_in_these_spaces_and_catches_a_longer_path():
    """The conformance kit's other-space check: RRTstarPSO's answers pass it (it plans there
    now, it used to refuse), and a path longer than the seed its stats name fails it."""
    check_other_spaces("RRTstarPSO")
    with pytest.raises(AssertionError) as exc:
        check_other_spaces(PlannerEntry("Inflating", factory=_Inflating))
    lines = str(exc.value).splitlines()
    assert len(lines) == len(OTHER_SPACES)
    assert all("exceeds its stats' seed_length" in line for line in lines)
    assert lines[0].startswith("Inflating in a user's R^3 SimpleSetup: reported 'Exact solution'")


def test_a_returned_path_is_checked_ten_times_finer_than_the_swarm_s_candidates():
    """A slab across a straight R^3 motion, between two samples of the check at 10 times the
    resolution and six samples wide at 100 times: the candidates' check lets it through, the
    check of a returned path does not, so the swarm returns its input rather than that motion."""
    from rrtpso_ompl.planners.pso.space_path import FINAL_FINER, FINER, MotionChecker

    space = ob.RealVectorStateSpace(3)
    bounds = ob.RealVectorBounds(3)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    slab = {"centre": 0.0, "half": 0.0}  # placed once the resolution is known
    ss.setStateValidityChecker(lambda s: abs(s[0] - slab["centre"]) > slab["half"])
    si = ss.getSpaceInformation()
    si.setup()  # not ss.setup(): with no start and goal it crashes the wheel
    adapter = space_adapter(si)
    a, b = np.array([1.0, 1.0, 1.0]), np.array([9.0, 1.0, 1.0])
    sa, sb = si.allocState(), si.allocState()
    adapter.assign(sa, a)
    adapter.assign(sb, b)
    gap = 8.0 / (FINER * space.validSegmentCount(sa, sb))  # between the 10x samples
    slab["centre"] = 1.0 + gap * (round(4.0 / gap) + 0.5)  # midway between two, near x = 5
    slab["half"] = 0.3 * gap
    checker = MotionChecker(si, adapter)
    assert checker.motion_free(a, b, factor=FINER)  # the slab lies between its samples
    assert not checker.motion_free(a, b, factor=FINAL_FINER)
    # A path round the slab cannot be (it spans the space): whatever the swarm made of a path
    # through it, it returns the input.
    path = np.array([a, [5.0, 2.0, 1.0], b])
    result = optimize_space_path(path, adapter, si, PathOptimizerOptions(),
                                 np.random.default_rng(1))  # fmt: skip
    assert not result.improved
    assert np.array_equal(result.path, path)
