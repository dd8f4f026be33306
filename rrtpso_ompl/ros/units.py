"""Length units of a problem in metres (ROS uses SI units, REP 103): the model's table
(:mod:`rrtpso_ompl.model.units`), which the ROS outputs convert with."""

from ..model.units import METRES_PER_UNIT, metres_per_unit, units_fields

__all__ = ["METRES_PER_UNIT", "metres_per_unit", "units_fields"]
