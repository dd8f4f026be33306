"""Registers PSO: the paper's particle-swarm-only baseline (random initial waypoints)."""

from rrtpso_ompl.planners.baselines.pso_baseline import PSOPlanner
from rrtpso_ompl.planners.registry import Capabilities, PlannerEntry

PLANNERS = [
    PlannerEntry(
        name="PSO",
        factory=PSOPlanner,
        params=PSOPlanner.PARAMS,
        description="Particle swarm over random waypoints (the paper's PSO baseline, Table 3)",
        aliases=("geometric::PSO",),
        capabilities=Capabilities(optimizing=True, car_spaces=False),
    )
]
