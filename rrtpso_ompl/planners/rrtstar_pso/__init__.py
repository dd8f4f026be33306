"""RRTstarPSO, the paper's hybrid planner, and its stages.

- :mod:`.planner`: :class:`RRTstarPSO` (OMPL's RRT* grown in slices, then the swarm);
- :mod:`.corridor`: the corridor stage (lattice routes through every corridor, the funnel, a disc
  robot's path wrapped round wall corners);
- :mod:`.costroute`: the cost route of the inflation objective.
"""

from ...lazy import export_lazily

__all__ = ["RRTstarPSO"]

export_lazily(__name__, {"RRTstarPSO": ".planner"})
