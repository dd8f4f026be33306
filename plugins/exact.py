"""Registers Exact: the exact shortest path (the reference optimum) as a planner."""

from rrtpso_ompl.planners.baselines.exact import ExactPlanner
from rrtpso_ompl.planners.registry import Capabilities, PlannerEntry

PLANNERS = [
    PlannerEntry(
        name="Exact",
        factory=ExactPlanner,
        params=ExactPlanner.PARAMS,
        description="The exact shortest path (tangent graph, A*); needs this package's world, "
        "not a user's own validity checker",
        aliases=("geometric::Exact",),
        capabilities=Capabilities(optimizing=False, car_spaces=False),
    )
]
