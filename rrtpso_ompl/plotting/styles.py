"""The colours and sizes every figure shares (matplotlib colour specifications; sizes in
inches), so that the same thing looks the same in every picture. No matplotlib here: a name's
import costs nothing.
"""

__all__ = [
    "COSTMAP",
    "COSTMAP_ALPHA",
    "DETOUR",
    "GOAL",
    "LEGEND_WIDTH",
    "MOVING",
    "OBSTACLE",
    "PATH_COLOUR",
    "RRT_COLOUR",
    "SAFETY",
    "START",
    "UNKNOWN_BLOCKED",
    "UNKNOWN_FREE",
]

OBSTACLE = "#5b6770"
SAFETY = "#e0a030"
RRT_COLOUR = "#8c8c8c"
PATH_COLOUR = "#d62728"
MOVING = "#7b3294"
DETOUR = "#1a9641"
START = "tab:green"
GOAL = "tab:blue"
#: Map cells: unknown space drawn blocked, or free (``unknown: free``).
UNKNOWN_BLOCKED, UNKNOWN_FREE = "0.62", "0.85"
#: The inflation cost (the costmap's shade, the inflated band of the clearance profile).
COSTMAP = "#1f8a8a"
#: Opacity of the costmap's shade where the cost is 1 (the robot touching an obstacle).
COSTMAP_ALPHA = 0.6
#: Room for :func:`world_legend` beside a world (inches).
LEGEND_WIDTH = 3.0
