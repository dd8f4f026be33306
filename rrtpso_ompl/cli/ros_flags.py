"""The flags of the ROS 2 hand-off, shared by ``solve``, ``optimum`` and ``simulate``."""

from __future__ import annotations

import argparse
from typing import Any

from ..errors import UsageError
from .common import Output

__all__ = ["add_ros_flags", "ros_frame", "ros_outputs"]


def add_ros_flags(p: argparse.ArgumentParser) -> None:
    """``--path-out``, ``--bag``, ``--frame-id`` and ``--path-resolution``."""
    g = p.add_argument_group("ROS 2 outputs (metres and seconds, whatever the problem's units)")
    g.add_argument(
        "--path-out",
        metavar="FILE",
        help="write the path as a ROS nav_msgs/Path document (JSON for .json, else YAML)",
    )
    g.add_argument(
        "--bag",
        metavar="OUT",
        help="write a ROS 2 bag: MCAP when OUT ends in .mcap, else a rosbag2 sqlite3 directory "
        "(topics in docs/ros.md)",
    )
    g.add_argument(
        "--frame-id",
        default="map",
        metavar="FRAME",
        help="header.frame_id of the plan and the map (default: map)",
    )
    g.add_argument(
        "--path-resolution",
        type=float,
        metavar="METRES",
        help="largest spacing of the plan's poses (default: the map's resolution, else 0.05)",
    )


def ros_outputs(args: argparse.Namespace) -> list[Output]:
    """The ROS outputs asked for, for :func:`~.common.check_outputs`."""
    return [Output("--path-out", args.path_out), Output("--bag", args.bag, "bag")]


def ros_frame(args: argparse.Namespace, problem: Any) -> Any:
    """The :class:`~rrtpso_ompl.ros.RosFrame` of the outputs, checked before planning; None when
    no ROS output is asked for (the problem's units then need not be known)."""
    if not (args.path_out or args.bag):
        return None
    from ..ros import RosFrame

    if not args.frame_id.strip():
        raise UsageError(f"{args.problem}: --frame-id: must not be empty")
    try:
        frame = RosFrame.for_problem(problem, args.path_resolution, args.frame_id)
    except ValueError as exc:
        if getattr(exc, "key", None):  # a ProblemError: the file's own key
            raise
        raise UsageError(f"{args.problem}: --path-resolution: {exc}") from None
    if args.bag:
        _check_bag(args, problem, frame)
    return frame


def _check_bag(args: argparse.Namespace, problem: Any, frame: Any) -> None:
    """What a bag can hold, known before planning: the obstacles' markers, and the poses of
    even the straight line to the goal."""
    import math

    from ..ros.bag import check_pose_count
    from ..ros.markers import check_marker_count

    try:
        check_marker_count(problem)
        shortest = max(0.0, math.dist(problem.start, problem.goal) - problem.goal_tolerance)
        check_pose_count(frame, shortest * frame.scale, "even the straight line to the goal")
    except ValueError as exc:
        raise UsageError(f"{args.problem}: --bag: {exc}") from None
