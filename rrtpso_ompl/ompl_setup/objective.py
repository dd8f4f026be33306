"""The problem's objective as an OMPL ``OptimizationObjective``, for every planner.

Length alone is OMPL's ``PathLengthOptimizationObjective`` (C++, fast). With inflation (see
:mod:`rrtpso_ompl.model.objective`) the cost of a motion is ``length + w * integral of c``, a
state-cost integral. What the OMPL 2.0.1 wheel allows from Python shaped this class (measured,
see docs/design.md):

- ``StateCostIntegralObjective`` cannot be subclassed (its ``stateCost`` override is never
  called: the bindings notes), so :class:`InflationObjective` subclasses
  ``OptimizationObjective`` and gives ``motionCost`` directly;
- ``setCostToGoHeuristic`` cannot take a Python function (no ``std::function`` caster) and a
  ``costToGo`` override is never called; a subclass of ``PathLengthOptimizationObjective`` (whose
  C++ cost-to-go and informed sampler would apply) crashed BIT* (a segmentation fault in
  ``bestPathFromGoalToStart``, 3 of 10 seeds on paper_static). So the cost-to-go is OMPL's
  default, zero: admissible, uninformed; informed samplers sample the whole space.
- ``motionCostHeuristic`` overrides are called (BIT* orders its edges with them): the
  straight-line distance, a lower bound since the integrand is at least 1; and the motion cost
  adds to exactly that distance (``si.distance``), so it is never below its heuristic by a
  rounding step.

The planners measure motions on a :class:`~rrtpso_ompl.model.objective.ClearanceField`
(interpolated distances, within 0.05 % of the exact integral where it was measured, and about ten
times faster); every cost the project reports, and every "no post-pass raises it" decision, uses
the exact distances (:meth:`InflationObjective.exact_cost`).
"""

from __future__ import annotations

from ompl import base as ob

from ..model.objective import ClearanceField, InflationCost
from .convert import path_to_array

__all__ = ["InflationObjective", "objective_for", "path_cost"]


class InflationObjective(ob.OptimizationObjective):
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
        step = cost.step
        # Measured beyond the inflation radius, so that most motions far from obstacles are
        # known to cost their length from their end points alone.
        self.field = ClearanceField(world, step, 2.0 * cost.inflation_radius + 2.0 * step)

    def motionCost(self, s1, s2) -> ob.Cost:
        ax, ay, bx, by = s1[0], s1[1], s2[0], s2[1]
        extra = self.inflation.segment_integral(self.field, ax, ay, bx, by)
        # The length exactly as the heuristic measures it: never below it by a rounding step.
        return ob.Cost(self.si_.distance(s1, s2) + self.inflation.weight * extra)

    def motionCostHeuristic(self, s1, s2) -> ob.Cost:
        return ob.Cost(self.si_.distance(s1, s2))

    def exact_cost(self, path) -> float:
        """``J`` of a path (an ``og.PathGeometric`` or ``(n, 2)`` waypoints) with exact
        distances."""
        xy = path if hasattr(path, "shape") else path_to_array(path)
        return self.inflation.path_cost(self.world, xy)


def path_cost(objective: ob.OptimizationObjective, path) -> float:
    """The cost of an ``og.PathGeometric`` under ``objective``: exact for ours
    (:meth:`InflationObjective.exact_cost`), OMPL's own for any other."""
    if isinstance(objective, InflationObjective):
        return objective.exact_cost(path)
    return path.cost(objective).value()


def objective_for(si: ob.SpaceInformation, cost: InflationCost, world) -> ob.OptimizationObjective:
    """OMPL's path-length objective without inflation, else :class:`InflationObjective`."""
    if not cost.active:
        return ob.PathLengthOptimizationObjective(si)
    return InflationObjective(si, cost, world)
