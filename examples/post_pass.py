"""The swarm after any planner: OMPL's BIT*, its simplifier, then RRTstarPSO's swarm as a path
optimiser (``PSOPathOptimizer``, used like ``og.PathSimplifier``).

Run: ``python examples/post_pass.py`` (about 1 s). The same from the command line:
``rrtpso solve problems/static/paper_static.yaml --planner BITstar+simplify+pso``.
"""

from __future__ import annotations

from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from rrtpso_ompl.planners import PSOPathOptimizer

ou.RNG.setSeed(1)  # once, before any OMPL object
ou.setLogLevel(ou.LOG_WARN)

DISCS = ((5.0, 5.0, 2.0), (2.5, 7.0, 1.0), (7.5, 3.0, 1.0))


def main() -> None:
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(
        lambda s: all((s[0] - x) ** 2 + (s[1] - y) ** 2 > r * r for x, y, r in DISCS))
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 1.0, 1.0, 9.0, 9.0
    ss.setStartAndGoalStates(start, goal)
    ss.setPlanner(og.BITstar(ss.getSpaceInformation()))
    if not ss.solve(0.3) or not ss.haveExactSolutionPath():
        raise SystemExit("BIT* found no path")
    path = ss.getSolutionPath()
    print(f"BIT*:               {path.length():.4f} m")
    og.PathSimplifier(ss.getSpaceInformation()).simplifyMax(path)
    print(f"+ OMPL's simplifier: {path.length():.4f} m")
    optimizer = PSOPathOptimizer(ss.getSpaceInformation())
    improved = optimizer.optimize(path, 0.3)  # seconds; never longer, never invalid
    print(f"+ the swarm:         {path.length():.4f} m (improved: {improved})")
    assert path.check()


if __name__ == "__main__":
    main()
