"""First-party planner plugins of rrtpso-ompl (installed as ``rrtpso_ompl.plugins``).

Each module exposes ``PLANNERS``: a sequence of :class:`rrtpso_ompl.planners.registry.PlannerEntry`.
Third-party packages use the same shape through the entry-point group ``rrtpso_ompl.planners``; see
``docs/planners.md`` ("Writing a planner plugin").
"""
