"""Registers every geometric planner of the OMPL wheel under its plain and its MoveIt name."""

from rrtpso_ompl.planners.baselines.ompl_planners import PLANNERS, UNAVAILABLE

__all__ = ["PLANNERS", "UNAVAILABLE"]
