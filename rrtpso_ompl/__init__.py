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

The names below are importable from here; ``solve`` and ``RRTstarPSO`` load OMPL on first use,
so ``import rrtpso_ompl`` alone stays light.
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version
from typing import Any

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

try:
    __version__ = version("rrtpso-ompl")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

#: Names that need OMPL, imported on first access (PEP 562).
_LAZY = {
    "solve": "rrtpso_ompl.planners",
    "SolveResult": "rrtpso_ompl.planners",
    "RRTstarPSO": "rrtpso_ompl.planners",
    "default_registry": "rrtpso_ompl.planners",
}

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


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'rrtpso_ompl' has no attribute {name!r}")
