"""Planners and the swarm: RRTstarPSO, the PSO baseline, OMPL's planners by name, one door to solve.

- :mod:`.params`: each planner parameter declared once (:class:`ParamSpec`, :class:`ParamTable`);
- :mod:`.registry`: planners by name (:class:`PlannerEntry` with its :class:`Capabilities`),
  from the first-party plugins and the entry-point group ``rrtpso_ompl.planners``;
- :mod:`.request`: :func:`resolve`, the one place that turns a problem, a planner spec and the
  caller's choices into a :class:`PlannerRequest` (and says where each value came from);
- :mod:`.swarm`: the particle swarm of eqs. 4-5; :mod:`.path_optimizer`: the swarm over a path's
  waypoints, exactly collision-checked, never longer;
- :mod:`.post`: :class:`PSOPathOptimizer`, the swarm as an OMPL path optimiser for any planner
  (shaped like ``og.PathSimplifier``), and the post-passes of planner specs ``"BITstar+pso"``;
- :mod:`.rrtstar_pso` (:class:`RRTstarPSO`), :mod:`.pso_baseline` (:class:`PSOPlanner`),
  :mod:`.ompl_planners` (OMPL's own, declared);
- :mod:`.solve`: :func:`solve`, the one door every caller plans through, returning a
  :class:`SolveResult`.

The planner classes and the post-passes import OMPL, on first access (PEP 562), and
:func:`solve` when it runs; everything else here is plain numpy, so importing
``rrtpso_ompl.planners.swarm`` (or this package) loads no OMPL.
"""

from importlib import import_module
from typing import Any

from .params import ParamSpec, ParamTable, Rule
from .path_optimizer import PathOptimizationResult, PathOptimizerOptions, optimize_path
from .registry import Capabilities, PlannerEntry, PlannerRegistry, default_registry
from .request import (
    DEFAULT_PLANNER,
    DEFAULT_TIME_LIMIT,
    POST_PARAMS,
    POST_STEPS,
    PlannerRequest,
    resolve,
    split_spec,
)
from .result import BenchmarkRun, SolveResult
from .solve import solve
from .swarm import PSOOptions, PSOResult, minimize

#: Names whose modules import OMPL, imported on first access.
_LAZY = {
    "PlannerStats": ".base",
    "PythonPlanner": ".base",
    "PostStep": ".post",
    "PSOPathOptimizer": ".post",
    "PSOPlanner": ".pso_baseline",
    "RRTstarPSO": ".rrtstar_pso",
}

__all__ = [
    "DEFAULT_PLANNER",
    "DEFAULT_TIME_LIMIT",
    "POST_PARAMS",
    "POST_STEPS",
    "BenchmarkRun",
    "Capabilities",
    "PSOOptions",
    "PSOPathOptimizer",
    "PSOPlanner",
    "PSOResult",
    "ParamSpec",
    "ParamTable",
    "PathOptimizationResult",
    "PathOptimizerOptions",
    "PlannerEntry",
    "PlannerRegistry",
    "PlannerRequest",
    "PlannerStats",
    "PostStep",
    "PythonPlanner",
    "RRTstarPSO",
    "Rule",
    "SolveResult",
    "default_registry",
    "minimize",
    "optimize_path",
    "resolve",
    "solve",
    "split_spec",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
