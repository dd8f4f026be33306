"""Ground truth: what a planner is measured against, by geometry alone (no OMPL, no processes).

- :mod:`.optimum`: :func:`shortest_path`, the exact shortest path for the disc robot (the
  reference of every length ratio);
- :mod:`.costgrid`: :func:`cost_reference`, the reference of the inflation objective (length plus
  the costmap's inflation cost): a 16-connected grid search, as NavFn and Smac 2D plan;
- :mod:`.certify`: :func:`grid_path`, a collision-checked grid path that certifies a problem
  solvable (and bounds the optimum from above);
- :mod:`.generate`: seeded random problems with such a certificate, by a kind's name; the
  kinds' registry is :mod:`.kinds`, the kinds are :mod:`.field_kinds` (circles, polygons),
  :mod:`.maze_kind`, :mod:`.map_kinds` (occupancy-grid maps, on :mod:`.map_problem` and
  :mod:`.map_files`) and :mod:`.shape_kinds`.

The names below are imported on first use (:mod:`rrtpso_ompl.lazy`): ``rrtpso optimum`` loads
the optimum's modules, not the generators'.
"""

from ..lazy import export_lazily

__all__ = [
    "CostGridResult",
    "GeneratedMap",
    "OptimumResult",
    "cost_reference",
    "generate",
    "generate_map",
    "generate_to_file",
    "grid_path",
    "is_solvable",
    "shortest_path",
]

export_lazily(
    __name__,
    {
        "grid_path": ".certify",
        "is_solvable": ".certify",
        "CostGridResult": ".costgrid",
        "cost_reference": ".costgrid",
        "generate": ".generate",
        "generate_to_file": ".generate",
        "generate_map": ".generate",
        "GeneratedMap": ".map_files",
        "OptimumResult": ".optimum",
        "shortest_path": ".optimum",
    },
)
