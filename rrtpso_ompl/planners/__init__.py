"""Planners and the swarm: RRTstarPSO, the PSO baseline, OMPL's planners by name, one door to solve.

- :mod:`.params`: each planner parameter declared once (:class:`ParamSpec`, :class:`ParamTable`);
- :mod:`.registry`: planners by name (:class:`PlannerEntry` with its :class:`Capabilities`),
  from the first-party plugins and the entry-point group ``rrtpso_ompl.planners``;
- :mod:`.swarm`: the particle swarm of eqs. 4-5; :mod:`.path_optimizer`: the swarm over a path's
  waypoints, exactly collision-checked, never longer;
- :mod:`.post`: :class:`PSOPathOptimizer`, the swarm as an OMPL path optimiser for any planner
  (shaped like ``og.PathSimplifier``), and the post-passes of planner specs ``"BITstar+pso"``;
- :mod:`.rrtstar_pso` (:class:`RRTstarPSO`), :mod:`.pso_baseline` (:class:`PSOPlanner`),
  :mod:`.ompl_planners` (OMPL's own, declared);
- :mod:`.solve`: :func:`solve`, the one door every caller plans through, returning a
  :class:`SolveResult`.

The planner classes import OMPL; everything else here is plain numpy.
"""

from .base import PlannerStats, PythonPlanner
from .params import ParamSpec, ParamTable, Rule
from .path_optimizer import PathOptimizationResult, PathOptimizerOptions, optimize_path
from .post import POST_PARAMS, POST_STEPS, PostStep, PSOPathOptimizer, split_spec
from .pso_baseline import PSOPlanner
from .registry import Capabilities, PlannerEntry, PlannerRegistry, default_registry
from .result import BenchmarkRun, SolveResult
from .rrtstar_pso import RRTstarPSO
from .solve import DEFAULT_PLANNER, DEFAULT_TIME_LIMIT, PlannerRequest, resolve_request, solve
from .swarm import PSOOptions, PSOResult, minimize

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
    "resolve_request",
    "solve",
    "split_spec",
]
