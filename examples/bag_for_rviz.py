"""A plan on an occupancy-grid map, as a ROS 2 bag that RViz2 and Foxglove open.

Run: ``python examples/bag_for_rviz.py OUT.mcap`` (about 2 s). Then ``ros2 bag play OUT.mcap``
with RViz2's fixed frame ``map`` shows ``/map``, ``/plan``, ``/initialpose`` and ``/goal_pose``
(Foxglove opens the file directly). The same from the command line:
``rrtpso solve problems/maps/office_rooms.yaml --bag OUT.mcap``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from rrtpso_ompl import load_problem, solve
from rrtpso_ompl.ros import RosFrame
from rrtpso_ompl.ros.bag import write_plan_bag

REPO = Path(__file__).resolve().parent.parent


def main(out: Path) -> None:
    problem = load_problem(REPO / "problems" / "maps" / "office_rooms.yaml")
    result = solve(problem, "RRTstarPSO", time_limit=1.0, seed=1)
    if not result.solved:
        raise SystemExit("no path found")
    frame = RosFrame.for_problem(problem)  # metres, the map's resolution between poses
    write_plan_bag(problem, frame, result.path, out)
    print(f"length {result.length:.2f} {problem.units}; wrote {out}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        raise SystemExit("usage: python examples/bag_for_rviz.py OUT.mcap")
    main(Path(sys.argv[1]))
