"""A :class:`~rrtpso_ompl.model.Problem` as OMPL objects: a ready ``og.SimpleSetup``.

* ``RealVectorStateSpace(2)`` with the problem's bounds (the robot's centre);
* a state validity checker and an *exact* motion validator over the same
  :class:`~rrtpso_ompl.model.World` (no discretisation: a segment is valid only when every point of
  it keeps the robot radius from every obstacle);
* the problem's objective (path length, plus the inflation cost when the robot has one:
  :mod:`.objective`), the start and the goal (with its tolerance);
* for a car-like robot (``robot.turning_radius``) instead OMPL's Dubins or Reeds-Shepp space,
  its curves checked soundly against the same world (:mod:`.car`).

See ``docs/design.md`` for why some OMPL calls are avoided from Python (the bindings notes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..model.problem_types import Problem
from ..model.world import World
from .car import CarModel, CarValidityChecker, CurveMotionValidator
from .convert import path_to_array
from .objective import objective_for
from .space import centre_bounds

__all__ = ["ExactMotionValidator", "PlanningContext", "WorldValidityChecker", "make_context"]


class WorldValidityChecker(ob.StateValidityChecker):
    """A state is valid when it lies in the bounds and the robot disc there is free.

    It keeps a reference to its :class:`World`, so planners that receive only the
    ``SpaceInformation`` (such as RRTstarPSO) can reach the vectorised collision model through
    ``si.getStateValidityChecker().world``.
    """

    def __init__(self, si: ob.SpaceInformation, world: World) -> None:
        super().__init__(si)
        self.world = world

    def isValid(self, state) -> bool:
        x, y = state[0], state[1]
        return self.world.in_bounds(x, y) and self.world.point_free(x, y)

    def clearance(self, state) -> float:
        """Free distance of the robot disc at ``state`` (negative when overlapping)."""
        d = self.world.point_clearance(np.array([[state[0], state[1]]]))[0]
        return float(d - self.world.robot_radius)


class ExactMotionValidator(ob.MotionValidator):
    """Checks a whole straight motion exactly (no discretisation gaps).

    OMPL's default validator samples the segment at a resolution, and a thin obstacle corner can
    slip between samples; here the distance from the segment to each obstacle is computed in closed
    form. Counters are kept in Python because the C++ ones are not updated for Python validators.
    """

    def __init__(self, si: ob.SpaceInformation, world: World) -> None:
        super().__init__(si)
        self.world = world

    def checkMotion(self, s1, s2, *last_valid) -> bool:
        return self.world.in_bounds(s2[0], s2[1]) and self.world.motion_free(
            s1[0], s1[1], s2[0], s2[1]
        )


@dataclass
class PlanningContext:
    """The OMPL objects of one problem, kept together so that none is garbage-collected early."""

    problem: Problem
    world: World
    ss: og.SimpleSetup
    si: ob.SpaceInformation
    space: ob.RealVectorStateSpace
    checker: WorldValidityChecker
    motion_validator: ExactMotionValidator
    #: Held here too: OMPL holds it in C++, and a Python subclass whose Python object is
    #: collected silently loses its overrides (its motion costs fall back to the length).
    objective: ob.OptimizationObjective | None = None
    #: A car-like robot's curves (None: the plane, a path is its waypoints' polyline).
    car: CarModel | None = None

    def polyline(self, path: og.PathGeometric) -> np.ndarray:
        """A path of the problem's space as the polyline it is checked and reported as,
        ``(n, 2)``: its waypoints in the plane; a car's curves cut into chords
        (:meth:`.car.CarModel.polyline`)."""
        if self.car is None:
            return path_to_array(path)
        return self.car.polyline(self.car.path_poses(path))[:, :2]

    def polyline_valid(self, xy: np.ndarray) -> bool:
        """Whether a polyline from :meth:`polyline` is a valid path: exact in the plane; for a
        car, its chords with the sagitta's margin (so the curves they cut are free too)."""
        if self.car is None:
            return bool(self.world.path_valid(xy))
        return self.motion_validator.polyline_valid(xy)


def make_context(problem: Problem, world: World | None = None) -> PlanningContext:
    """Build a ready-to-solve ``og.SimpleSetup`` for ``problem``.

    Parameters
    ----------
    problem : Problem
        The validated problem.
    world : World, optional
        Its static world; built from the problem when omitted.
    """
    world = world or World.from_problem(problem)
    if problem.car:
        return _car_context(problem, world)
    space = ob.RealVectorStateSpace(2)
    space.setBounds(centre_bounds(problem.bounds))

    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    checker = WorldValidityChecker(si, world)
    ss.setStateValidityChecker(checker)
    validator = ExactMotionValidator(si, world)
    si.setMotionValidator(validator)

    start = space.allocState()
    start[0], start[1] = problem.start
    goal = space.allocState()
    goal[0], goal[1] = problem.goal
    # OMPL's GoalState accepts d < threshold, so a zero threshold would never be met: for
    # goal_tolerance 0 the goal takes the world's round-off allowance (1e-9 of the workspace's
    # scale, relative as every exact check; a path ending at the sampled goal state has d = 0).
    threshold = max(problem.goal_tolerance, world.tol)
    ss.setStartAndGoalStates(start, goal, threshold)
    objective = objective_for(si, problem.objective, world)
    ss.setOptimizationObjective(objective)
    return PlanningContext(problem, world, ss, si, space, checker, validator, objective)


def _car_context(problem: Problem, world: World) -> PlanningContext:
    """A car-like robot's setup: Dubins or Reeds-Shepp poses, the exact world's point check,
    each curve checked soundly (:mod:`.car`), the start and goal poses, the path length."""
    car = CarModel.of(problem)
    ss = og.SimpleSetup(car.space)
    si = ss.getSpaceInformation()
    checker = CarValidityChecker(si, world)
    ss.setStateValidityChecker(checker)
    validator = CurveMotionValidator(si, world, car)
    si.setMotionValidator(validator)
    start, goal = car.space.allocState(), car.space.allocState()
    ends = zip((start, goal), (problem.start, problem.goal), problem.end_yaws(), strict=True)
    for state, (x, y), yaw in ends:
        state.setXY(float(x), float(y))
        state.setYaw(float(yaw))
    # The goal's threshold is in the space's distance (a curve's length): the tolerance, or
    # the world's round-off allowance for an exact goal (as in the plane).
    ss.setStartAndGoalStates(start, goal, max(problem.goal_tolerance, world.tol))
    objective = ob.PathLengthOptimizationObjective(si)
    ss.setOptimizationObjective(objective)
    return PlanningContext(problem, world, ss, si, car.space, checker, validator, objective, car)
