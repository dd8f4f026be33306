"""The ROS 2 hand-off: plans in metres and seconds, dense poses, ROS 2 bags.

Everything a ROS tool reads leaves through this stage: the problem's lengths converted to metres
(REP 103) by :mod:`.units`, the path resampled into poses at about the costmap resolution by
:mod:`.poses`. The algorithms upstream keep the problem's own units. ROS 2 bags (:mod:`.bag`)
hold messages built by :mod:`.messages`, :mod:`.grid` (the map) and :mod:`.markers` (the
obstacles).
"""

from .bag import write_plan_bag, write_simulation_bag
from .nav_path import nav_path, write_nav_path
from .plan import DEFAULT_PATH_RESOLUTION, RosFrame
from .poses import Poses, dense_poses
from .units import metres_per_unit, units_fields

__all__ = [
    "DEFAULT_PATH_RESOLUTION",
    "Poses",
    "RosFrame",
    "dense_poses",
    "metres_per_unit",
    "nav_path",
    "units_fields",
    "write_nav_path",
    "write_plan_bag",
    "write_simulation_bag",
]
