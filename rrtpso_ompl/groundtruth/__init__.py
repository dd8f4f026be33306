"""Ground truth: what a planner is measured against, by geometry alone (no OMPL, no processes).

- :mod:`.optimum`: :func:`shortest_path`, the exact shortest path for the disc robot (the
  reference of every length ratio);
- :mod:`.certify`: :func:`grid_path`, a collision-checked grid path that certifies a problem
  solvable (and bounds the optimum from above);
- :mod:`.generate`: seeded random problems with such a certificate.
"""

from .certify import grid_path, is_solvable
from .generate import generate, generate_to_file
from .map_kinds import GeneratedMap, generate_map
from .optimum import OptimumResult, shortest_path

__all__ = [
    "GeneratedMap",
    "OptimumResult",
    "generate",
    "generate_map",
    "generate_to_file",
    "grid_path",
    "is_solvable",
    "shortest_path",
]
