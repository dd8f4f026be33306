"""The problem and its world: files in, exact geometry out (no OMPL, no matplotlib).

- :mod:`.format`: the problem-file format declared once (keys, kinds, units);
- :mod:`.problem_types`: the problem as frozen dataclasses; :mod:`.problem`: problem files
  (YAML) to those, every bad input one :class:`~rrtpso_ompl.errors.ProblemError` naming the
  file and the key; :mod:`.problem_file`: the inverse; :mod:`.occupancy`: map_server maps;
- :mod:`.world`: :class:`World`, the static obstacles prepared for exact collision checks
  (:mod:`.scalar_checks` for OMPL's callbacks, :mod:`.obstacle_index` vectorised for the swarm,
  :mod:`.local_violation` for a swarm in boxes, :mod:`.spatial` the index);
- :mod:`.raster`, :mod:`.marking`, :mod:`.grid_graph`: lattices of cells, which are free, and the
  graph every grid search walks;
- :mod:`.geometry`: polyline lengths, shortcutting and the exact distance formulas, used by
  every stage; :mod:`.objective`: the inflation cost.

The names below are imported on first use (:mod:`rrtpso_ompl.lazy`): :func:`load_problem`
loads neither :mod:`.world` nor shapely (but for a polygon's checks).
"""

from ..lazy import export_lazily

__all__ = [
    "Circle",
    "MovingObstacle",
    "Obstacle",
    "PlannerConfig",
    "Polygon",
    "Problem",
    "ProblemError",
    "Robot",
    "World",
    "load_problem",
    "path_length",
    "problem_from_dict",
    "shortcut",
]

export_lazily(
    __name__,
    {
        "path_length": ".geometry",
        "shortcut": ".geometry",
        **dict.fromkeys(
            (
                "Circle",
                "MovingObstacle",
                "Obstacle",
                "PlannerConfig",
                "Polygon",
                "Problem",
                "Robot",
            ),
            ".problem_types",
        ),
        **dict.fromkeys(
            ("ProblemError", "load_problem", "problem_from_dict"),
            ".problem",
        ),
        "World": ".world",
    },
)
