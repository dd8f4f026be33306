"""The conformance kit's checks beyond the plane: a user's own ``og.SimpleSetup`` of R^3, R^6,
SE(2) and Reeds-Shepp, and a car-like robot's problem file: never a wrong answer."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.problem import Problem, problem_from_dict
from ..planners.registry import PlannerEntry, PlannerRegistry
from ..planners.request import resolve
from ..planners.solve import solve
from .cases import (
    BUDGET,
    RTOL,
    SIMPLE_PROBLEM,
    Case,
    case_of,
    fmt,
)

#: The spaces of :func:`check_other_spaces`: a user's own ``og.SimpleSetup`` in each. Not
#: Dubins: there OMPL's own BKPIECE1, LBKPIECE1, KPIECE1, PRM and PRMstar return paths that
#: OMPL's own ``PathGeometric.check()`` rejects (measured: up to 10 of 10 runs; they check some
#: motions in the other direction, or end a motion part-way, which on a Dubins curve is another
#: curve), so the check would report OMPL's fault, not the planner's under test.
OTHER_SPACES = ("R^3", "R^6", "SE(2)", "Reeds-Shepp")


#: Seconds per solve in :func:`check_other_spaces`: OMPL's planners find a path in each of its
#: spaces in milliseconds; one that finds none in time passes all the same (the property is
#: "never a wrong answer", not speed).
OTHER_SPACES_BUDGET = 0.1


def check_other_spaces(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """Never a wrong answer in a user's own ``og.SimpleSetup`` on a space the planner may not
    support: each of :data:`OTHER_SPACES`, bounds ``[0, 10]`` on every axis (SE(2): ``x``,
    ``y``), a ball of radius 2 at the centre across the straight line from start
    ``(1, ..., 1)`` to goal ``(9, ..., 9)`` (SE(2): yaw 0 at both), a Python validity checker
    and :data:`OTHER_SPACES_BUDGET` seconds.

    The planner may refuse: an exception from its construction or ``setup()`` (before any
    solve), or a status with no path in the problem definition. An exception from ``solve``
    fails (it would end a whole OMPL Benchmark). Every path the problem definition holds must
    start at the start and be valid at each of its states and along each motion, by the user's
    checker on states from the space's own ``interpolate`` at the space's resolution (the states
    OMPL's own motion validators check, so a planner OMPL accepts passes by property); an exact
    one must end in the goal (``goal.isSatisfied``), and an exact status needs an exact path.
    A planner whose stats name the length of the path it was seeded from (``seed_length``, as
    RRTstarPSO's do in these spaces) must return an exact path no longer than that, by the
    space's own distance.

    The objective's cost threshold is infinite, so optimizing planners stop at their first path
    (this checks answers, not their quality). ``problem`` and ``budget`` are not used (the
    planner's parameters are those it gets for the simple problem, at this budget).
    """
    case = case_of(entry, problem, budget, seed, registry)
    failures = [f for kind in OTHER_SPACES if (f := other_space_failure(case, kind))]
    assert not failures, "\n".join(failures)


#: A car-like robot's problem of :func:`check_car_problem`: the simple problem with a turning
#: radius (a Reeds-Shepp car: every planner of OMPL checks its motions as the curves they are)
#: and headings that make the car turn round.
CAR_PROBLEM = {**SIMPLE_PROBLEM, "name": "conformance_car", "start_yaw": 180, "goal_yaw": 0,
               "robot": {"radius": 28.5, "turning_radius": 40.0, "reverse": True}}  # fmt: skip


def check_car_problem(
    entry: PlannerEntry | str,
    *,
    problem: Problem | None = None,
    budget: float = BUDGET,
    seed: int = 1,
    registry: PlannerRegistry | None = None,
) -> None:
    """Never a wrong answer for a car-like robot's problem file (:data:`CAR_PROBLEM`, through
    :func:`~rrtpso_ompl.planners.solve` at :data:`OTHER_SPACES_BUDGET` seconds): a planner whose
    entry says it plans in the plane only (``capabilities.car_spaces`` False) must be refused
    before planning (:class:`~rrtpso_ompl.errors.UnsupportedSpaceError`); any other may find no
    path, but a path it reports runs from the start pose to the goal pose exactly, each of its
    motions passes the problem's sound curve check again, and its chords are valid with the
    robot's radius. ``problem`` and ``budget`` are not used."""
    from ..errors import UnsupportedSpaceError
    from ..ompl_setup import make_context

    case = case_of(entry, problem, budget, seed, registry)
    car = problem_from_dict(CAR_PROBLEM, source="<conformance car>")
    if not case.entry.capabilities.car_spaces:
        try:
            solve(car, case.name, time_limit=OTHER_SPACES_BUDGET, seed=seed,
                  registry=case.registry)  # fmt: skip
        except UnsupportedSpaceError:
            return
        raise AssertionError(f"{case.name}: says it plans in the plane only, but a car's "
                             "problem was not refused before planning")  # fmt: skip
    result = solve(car, case.name, time_limit=OTHER_SPACES_BUDGET, seed=seed,
                   registry=case.registry)  # fmt: skip
    if not result.solved:
        return
    poses = np.asarray(result.stages["poses"], dtype=float)
    ctx = make_context(car)
    assert ctx.world.path_valid(result.path), f"{case.name}: a car's chords hit an obstacle"
    yaws = car.end_yaws()
    ends = [poses[0].tolist(), poses[-1].tolist()]
    want = [[*car.start, yaws[0]], [*car.goal, yaws[1]]]
    assert np.allclose(ends, want, rtol=0, atol=1e-9), (
        f"{case.name}: a car's path runs from {ends[0]} to {ends[1]}, not {want[0]} to {want[1]}"
    )
    a, b = ctx.space.allocState(), ctx.space.allocState()
    for k in range(len(poses) - 1):
        for state, row in ((a, poses[k]), (b, poses[k + 1])):
            state.setXY(float(row[0]), float(row[1]))
            state.setYaw(float(row[2]))
        assert ctx.motion_validator.checkMotion(a, b), (
            f"{case.name}: a car's motion {k} ({fmt(poses[k])} to {fmt(poses[k + 1])}) "
            "fails the curve check"
        )


@dataclass(frozen=True)
class Scene:
    """A space of :func:`check_other_spaces` with its ball and a user's Python checker.

    ``dim`` coordinates are bounded by ``[0, 10]`` and measured from the ball's centre (SE(2)
    and Reeds-Shepp, turning radius 1: ``x`` and ``y``; the yaw is free)."""

    kind: str
    space: Any
    dim: int
    se2: bool

    @classmethod
    def make(cls, kind: str) -> Scene:
        from ompl import base as ob

        if kind.startswith("R^"):
            n = int(kind[2:])
            return cls(kind, ob.RealVectorStateSpace(n), n, False)
        space = ob.SE2StateSpace() if kind == "SE(2)" else ob.ReedsSheppStateSpace(1.0)
        return cls(kind, space, 2, True)

    def bound(self) -> None:
        from ompl import base as ob

        bounds = ob.RealVectorBounds(self.dim)
        bounds.setLow(0.0)
        bounds.setHigh(10.0)
        self.space.setBounds(bounds)

    def coords(self, state: Any) -> list[float]:
        """The state's coordinates (copied: OMPL's states are borrowed)."""
        if self.se2:
            return [state.getX(), state.getY(), state.getYaw()]
        return [state[i] for i in range(self.dim)]

    def state(self, value: float) -> Any:
        """A state with every bounded coordinate ``value`` (and yaw 0)."""
        s = self.space.allocState()
        if self.se2:
            s.setXY(value, value)
            s.setYaw(0.0)
        else:
            for i in range(self.dim):
                s[i] = value
        return s

    def valid(self, state: Any) -> bool:
        """The user's checker: inside the bounds and outside the ball of radius 2 at 5."""
        xs = (state.getX(), state.getY()) if self.se2 else [state[i] for i in range(self.dim)]
        inside = all(0.0 <= x <= 10.0 for x in xs)
        return inside and sum((x - 5.0) ** 2 for x in xs) > 4.0


def other_space_failure(case: Case, kind: str) -> str | None:
    """The planner in a user's own setup of ``kind``: what it got wrong, or None."""
    from ompl import base as ob
    from ompl import geometric as og

    from ..ompl_setup import seed_ompl

    name, where = case.name, f"{case.name} in a user's {kind} SimpleSetup"
    request = resolve(case.problem, name, time_limit=OTHER_SPACES_BUDGET, seed=case.seed,
                      registry=case.registry)  # fmt: skip
    seed_ompl(request.seed)
    scene = Scene.make(kind)
    scene.bound()
    ss = og.SimpleSetup(scene.space)
    ss.setStateValidityChecker(scene.valid)
    start, goal = scene.state(1.0), scene.state(9.0)
    ss.setStartAndGoalStates(start, goal)
    si = ss.getSpaceInformation()
    objective = ob.PathLengthOptimizationObjective(si)
    objective.setCostThreshold(ob.Cost(math.inf))  # any path will do: stop at the first
    ss.setOptimizationObjective(objective)
    try:
        ss.setPlanner(planner := request.entry.make(si, request.values))
        ss.setup()
    except Exception:  # refused before any solve: no answer, so no wrong one
        return None
    try:
        status = ss.solve(ob.timedPlannerTerminationCondition(OTHER_SPACES_BUDGET))
    except Exception as exc:
        return (f"{where}: solve() raised {exc!r} (refuse at setup(), or return a failed "
                f"status: an exception out of solve() ends a whole OMPL Benchmark)")  # fmt: skip
    pdef = ss.getProblemDefinition()
    said_exact = status.getStatus() == ob.PlannerStatus.EXACT_SOLUTION
    if said_exact and not pdef.hasExactSolution():
        return f"{where}: reported {str(status)!r}, but holds no exact path"
    if not pdef.hasSolution():
        return None
    exact = not pdef.hasApproximateSolution()
    path = pdef.getSolutionPath()
    wrong = other_path_wrong(scene, si, pdef, path, start, exact)
    seed_length = getattr(getattr(planner, "last_stats", None), "seed_length", None)
    longer = seed_length is not None and path.length() > seed_length * (1 + RTOL) + 1e-12
    if wrong is None and exact and longer:  # by the space's own distance
        wrong = f"its length {path.length():.6g} exceeds its stats' seed_length {seed_length:.6g}"
    if wrong is None:
        return None
    what = "exact" if exact else "approximate"
    return f"{where}: reported {str(status)!r} with a wrong {what} path: {wrong}"


def other_path_wrong(
    scene: Scene, si: Any, pdef: Any, path: Any, start: Any, exact: bool
) -> str | None:
    """What is wrong with a path of :func:`check_other_spaces`, or None."""
    space = scene.space
    states = path.getStates()
    if not states:
        return "it has no states"
    tol = 1e-9 * max(si.getMaximumExtent(), 1.0)
    if space.distance(states[0], start) > tol:
        return (f"it starts at {fmt(scene.coords(states[0]))}, not at the start "
                f"{fmt(scene.coords(start))}")  # fmt: skip
    if exact and not pdef.getGoal().isSatisfied(states[-1]):
        return f"it ends at {fmt(scene.coords(states[-1]))}, which is not in the goal"
    for i, s in enumerate(states):
        if not scene.valid(s):
            return f"its state {i}, {fmt(scene.coords(s))}, is invalid by the user's checker"
    probe = space.allocState()
    for i, (a, b) in enumerate(itertools.pairwise(states)):
        n = space.validSegmentCount(a, b)
        for j in range(1, n):
            space.interpolate(a, b, j / n, probe)
            if not scene.valid(probe):
                return (f"its motion {i} from {fmt(scene.coords(a))} to "
                        f"{fmt(scene.coords(b))} passes through {fmt(scene.coords(probe))}, "
                        f"invalid by the user's checker")  # fmt: skip
    return None
