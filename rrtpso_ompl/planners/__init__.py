"""Planners and the swarm: RRTstarPSO, the PSO baseline, OMPL's planners by name, one door to solve.

The framework (this folder's modules) knows no algorithm; the algorithms live in subpackages:

- :mod:`.registry`: planners by name (:class:`PlannerEntry` with its :class:`Capabilities`),
  from the first-party plugins and the entry-point group ``rrtpso_ompl.planners``;
- :mod:`.request`: :func:`resolve`, the one place that turns a problem, a planner spec and the
  caller's choices into a :class:`PlannerRequest` (and says where each value came from);
- :mod:`.base`: :class:`PythonPlanner`, what a planner written in Python is to OMPL;
- :mod:`.post`: :class:`PSOPathOptimizer`, the swarm as an OMPL path optimiser for any planner
  (shaped like ``og.PathSimplifier``), and the post-passes of planner specs ``"BITstar+pso"``;
- :mod:`.solve`: :func:`solve`, the one door every caller plans through, returning a
  :class:`SolveResult` (:mod:`.result`);
- :mod:`.pso`: the particle swarm of eqs. 4-5 (:mod:`.pso.swarm`) and the swarm over a path's
  waypoints, exactly collision-checked, never longer (:mod:`.pso.path_optimizer`);
- :mod:`.rrtstar_pso`: :class:`RRTstarPSO` and its stages (RRT*, corridor, cost route);
- :mod:`.baselines`: what RRTstarPSO is compared with: OMPL's planners declared, the paper's
  PSO planner (:class:`PSOPlanner`), the exact optimum as a planner.

Parameter declarations (:class:`ParamSpec`, :class:`ParamTable`, :class:`Rule`) live one floor
down, in :mod:`rrtpso_ompl.params`, and are re-exported here.

Every name here is imported on first access (PEP 562, :mod:`rrtpso_ompl.lazy`), so importing
this package, or ``rrtpso_ompl.params`` (the declarations the generators and the dynamic
stage use), loads no planner. The planner classes and the post-passes import OMPL, and
:func:`solve` when it runs; everything else here is plain numpy, so importing
``rrtpso_ompl.planners.pso.swarm`` loads no OMPL.
"""

from ..lazy import export_lazily

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


export_lazily(
    __name__,
    {
        **dict.fromkeys(("ParamSpec", "ParamTable", "Rule"), "..params"),
        **dict.fromkeys(
            ("PathOptimizationResult", "PathOptimizerOptions", "optimize_path"),
            ".pso.path_optimizer",
        ),
        **dict.fromkeys(
            ("Capabilities", "PlannerEntry", "PlannerRegistry", "default_registry"), ".registry"
        ),
        **dict.fromkeys(
            (
                "DEFAULT_PLANNER",
                "DEFAULT_TIME_LIMIT",
                "POST_PARAMS",
                "POST_STEPS",
                "PlannerRequest",
                "resolve",
                "split_spec",
            ),
            ".request",
        ),
        **dict.fromkeys(("BenchmarkRun", "SolveResult"), ".result"),
        "solve": ".solve",
        **dict.fromkeys(("PSOOptions", "PSOResult", "minimize"), ".pso.swarm"),
        # these import OMPL
        **dict.fromkeys(("PlannerStats", "PythonPlanner"), ".base"),
        **dict.fromkeys(("PostStep", "PSOPathOptimizer"), ".post"),
        "PSOPlanner": ".baselines.pso_baseline",
        "RRTstarPSO": ".rrtstar_pso.planner",
    },
)
