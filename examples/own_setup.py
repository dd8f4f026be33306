"""RRTstarPSO in your own OMPL SimpleSetup, with your own validity checker.

Two setups, each as an OMPL user writes one: the plane (``RealVectorStateSpace(2)``) and a
car-like robot (``DubinsStateSpace``). Nothing of rrtpso-ompl is needed but the planner.

Run: ``python examples/own_setup.py`` (about 2 s).

Three things differ from OMPL's classic demos:

- OMPL 2.0's Python states come from ``space.allocState()`` (``ob.State(space)`` is not bound);
- seed OMPL once per process, before any OMPL object (``ompl.util.RNG.setSeed``), for
  reproducible runs;
- RRTstarPSO splits its time between its stages by its ``budget`` parameter: give it the same
  seconds as ``ss.solve``, or it plans as if it had no budget (bounded by iterations only).
"""

from __future__ import annotations

import math

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from rrtpso_ompl import RRTstarPSO

ou.RNG.setSeed(1)  # once, before any OMPL object
ou.setLogLevel(ou.LOG_WARN)

#: Discs (x, y, radius) of the world, in metres.
DISCS = ((5.0, 5.0, 2.0), (2.5, 7.0, 1.0), (7.5, 3.0, 1.0))
BUDGET = 0.5  # seconds


def free(x: float, y: float) -> bool:
    """Your own validity checker: outside every disc."""
    return all((x - cx) ** 2 + (y - cy) ** 2 > r * r for cx, cy, r in DISCS)


def plan(space, start, goal, point) -> og.PathGeometric:
    """A SimpleSetup over ``space`` with the checker ``free(*point(state))``, solved by
    RRTstarPSO within BUDGET seconds."""
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(lambda s: free(*point(s)))  # a Python function will do
    ss.setStartAndGoalStates(start, goal)
    planner = RRTstarPSO(ss.getSpaceInformation(), budget=BUDGET, seed=1)
    ss.setPlanner(planner)
    status = ss.solve(BUDGET)
    print(f"  status {status}, the swarm's seed from {planner.last_stats.seed_source}")
    if not ss.haveExactSolutionPath():
        raise SystemExit("no path found")
    return ss.getSolutionPath()


def main() -> None:
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)

    print("The plane:")
    plane = ob.RealVectorStateSpace(2)
    plane.setBounds(bounds)
    start, goal = plane.allocState(), plane.allocState()
    start[0], start[1], goal[0], goal[1] = 1.0, 1.0, 9.0, 9.0
    path = plan(plane, start, goal, lambda s: (s[0], s[1]))
    print(f"  length {path.length():.3f} m, {path.getStateCount()} waypoints")

    print("A car (Dubins curves, turning radius 0.8 m):")
    car = ob.DubinsStateSpace(0.8)
    car.setBounds(bounds)
    start, goal = car.allocState(), car.allocState()
    start.setXY(1.0, 1.0)
    start.setYaw(0.0)
    goal.setXY(9.0, 9.0)
    goal.setYaw(math.pi / 2)
    path = plan(car, start, goal, lambda s: (s.getX(), s.getY()))
    print(f"  length {path.length():.3f} m of curves, {path.getStateCount()} poses")


if __name__ == "__main__":
    main()
