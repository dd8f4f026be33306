"""From a problem to OMPL objects: the only place that builds them for a problem.

- :func:`make_context`: ``RealVectorStateSpace(2)`` with the problem's bounds, a validity checker
  and an *exact* motion validator over the :class:`~rrtpso_ompl.model.World`, the problem's
  objective, start and goal (:mod:`.context`);
- :func:`objective_for`, :class:`InflationObjective`: length plus the inflation cost as an OMPL
  objective every planner optimises (:mod:`.objective`);
- :func:`path_to_array`, :func:`array_to_path`, :func:`assign_path`: paths as numpy arrays
  and back (:mod:`.convert`);
- :func:`plane_space_problem`, :func:`require_plane_space`: the one state space this package's
  planners plan in, ``ob.RealVectorStateSpace(2)``, and why another is refused (:mod:`.space`);
- :func:`seed_ompl`, :func:`set_ompl_log_level`: OMPL's process-wide seed, applied before each
  seeded solve builds its OMPL objects, and its log level (:mod:`.process`).
"""

from .context import (
    ExactMotionValidator,
    PlanningContext,
    WorldValidityChecker,
    make_context,
)
from .convert import array_to_path, assign_path, path_to_array
from .objective import InflationObjective, objective_for
from .process import seed_ompl, set_ompl_log_level
from .space import PLANE_SPACE, describe_space, plane_space_problem, require_plane_space

__all__ = [
    "PLANE_SPACE",
    "ExactMotionValidator",
    "InflationObjective",
    "PlanningContext",
    "WorldValidityChecker",
    "array_to_path",
    "assign_path",
    "describe_space",
    "make_context",
    "objective_for",
    "path_to_array",
    "plane_space_problem",
    "require_plane_space",
    "seed_ompl",
    "set_ompl_log_level",
]
