"""The problem's objective as an OMPL ``OptimizationObjective``, for every planner.

Length alone is OMPL's ``PathLengthOptimizationObjective`` (C++, fast). With inflation (see
:mod:`rrtpso_ompl.model.objective`) the cost of a motion is ``length + w * integral of c``, a
state-cost integral; OMPL's ``StateCostIntegralObjective`` cannot be subclassed from Python (its
``stateCost`` override is never called: the bindings notes), so :class:`InflationObjective`
subclasses ``OptimizationObjective`` and gives ``motionCost`` directly, with the admissible
heuristics informed planners need (``motionCostHeuristic`` and the cost-to-go: the straight-line
distance, a lower bound since the integrand is at least 1).
"""

from __future__ import annotations

from ompl import base as ob

from ..model.objective import InflationCost

__all__ = ["InflationObjective", "objective_for"]


class InflationObjective(ob.PathLengthOptimizationObjective):
    """``J = length + w * integral of the inflation cost`` of motions, in problem units.

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        A 2-D real vector space.
    cost : InflationCost
        The declared cost.
    world : World
        Distances to the nearest obstacle.
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        cost: InflationCost,
        world,
    ) -> None:
        super().__init__(si)
        self.si_ = si  # keeps the space information alive as long as the objective
        self.inflation = cost
        self.world = world

    def motionCost(self, s1, s2) -> ob.Cost:
        a = (s1[0], s1[1])
        b = (s2[0], s2[1])
        return ob.Cost(self.inflation.path_cost(self.world, [a, b]))


def objective_for(si: ob.SpaceInformation, cost: InflationCost, world) -> ob.OptimizationObjective:
    """OMPL's path-length objective without inflation, else :class:`InflationObjective`."""
    if not cost.active:
        return ob.PathLengthOptimizationObjective(si)
    return InflationObjective(si, cost, world)
