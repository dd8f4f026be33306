"""Registers RRTstarPSO: OMPL's RRT* followed by the particle swarm over its waypoints."""

from rrtpso_ompl.planners.registry import Capabilities, PlannerEntry
from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSO

PLANNERS = [
    PlannerEntry(
        name="RRTstarPSO",
        factory=RRTstarPSO,
        params=RRTstarPSO.PARAMS,
        description="RRT* for a share of the budget, then PSO over its waypoints (the paper)",
        aliases=("geometric::RRTstarPSO", "RRT*PSO"),
        capabilities=Capabilities(optimizing=True),
    )
]
