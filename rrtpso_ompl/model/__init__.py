"""The problem and its world: files in, exact geometry out (no OMPL, no matplotlib).

- :mod:`.problem`: problem files (YAML) to frozen dataclasses, every bad input one
  :class:`~rrtpso_ompl.errors.ProblemError` naming the file and the key;
- :mod:`.world`: :class:`World`, the static obstacles prepared for exact collision checks
  (scalar for OMPL's callbacks, vectorised for the swarm);
- :mod:`.geometry`: polyline lengths, shortcutting and point-segment distances, used by every
  stage.

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
                "ProblemError",
                "Robot",
                "load_problem",
                "problem_from_dict",
            ),
            ".problem",
        ),
        "World": ".world",
    },
)
