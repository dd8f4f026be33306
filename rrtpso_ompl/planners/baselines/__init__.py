"""The planners RRTstarPSO is compared with.

- :mod:`.ompl_planners`: OMPL's geometric planners, declared (parameters, capabilities, figures);
- :mod:`.pso_baseline`: :class:`PSOPlanner`, the paper's PSO-only baseline;
- :mod:`.exact`: the exact optimum (:mod:`rrtpso_ompl.groundtruth.optimum`) as a planner.
"""
