"""rrtpso-ompl: the hybrid RRT*PSO path planner as a first-class OMPL planner.

One subpackage per stage, each with a short ``__init__`` that is its public face:

- :mod:`rrtpso_ompl.model`: problem files and the world's exact geometry;
- :mod:`rrtpso_ompl.ompl_setup`: the problem as OMPL objects (space, checkers, seeding);
- :mod:`rrtpso_ompl.planners`: RRTstarPSO, the swarm, the PSO baseline, OMPL's planners by name,
  and :func:`~rrtpso_ompl.planners.solve`, the one door to planning;
- :mod:`rrtpso_ompl.kinematics`: reference path, velocities and wheel speeds;
- :mod:`rrtpso_ompl.dynamic`: moving obstacles, prediction and replanning;
- :mod:`rrtpso_ompl.groundtruth`: the exact optimum, certificates of solvability, generated
  problems (geometry only);
- :mod:`rrtpso_ompl.harness`: batches, benchmarks in OMPL's format, worker processes, results
  files;
- :mod:`rrtpso_ompl.cli`: the ``rrtpso`` command; :mod:`rrtpso_ompl.plotting`: every figure.

The names below are importable from here, each imported on first use (PEP 562,
:mod:`rrtpso_ompl.lazy`): ``import rrtpso_ompl`` alone loads neither numpy nor OMPL, and
``solve`` and ``RRTstarPSO`` load OMPL when first used.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._version import __version__
from .lazy import export_lazily

if TYPE_CHECKING:  # what the lazy names are, for type checkers and editors
    from .errors import (
        ArgumentError,
        ParameterError,
        PlannerError,
        ProblemError,
        RrtpsoError,
        UnknownPlannerError,
        UnsupportedSpaceError,
    )
    from .model import Problem, World, load_problem, problem_from_dict
    from .planners import RRTstarPSO, SolveResult, default_registry, solve

__all__ = [
    "ArgumentError",
    "ParameterError",
    "PlannerError",
    "Problem",
    "ProblemError",
    "RRTstarPSO",
    "RrtpsoError",
    "SolveResult",
    "UnknownPlannerError",
    "UnsupportedSpaceError",
    "World",
    "__version__",
    "default_registry",
    "load_problem",
    "problem_from_dict",
    "solve",
]

export_lazily(
    __name__,
    {
        **dict.fromkeys(
            (
                "ArgumentError",
                "ParameterError",
                "PlannerError",
                "ProblemError",
                "RrtpsoError",
                "UnknownPlannerError",
                "UnsupportedSpaceError",
            ),
            ".errors",
        ),
        **dict.fromkeys(("Problem", "World", "load_problem", "problem_from_dict"), ".model"),
        # the planners stage: solve and RRTstarPSO load OMPL when first used
        **dict.fromkeys(("RRTstarPSO", "SolveResult", "default_registry", "solve"), ".planners"),
    },
)
