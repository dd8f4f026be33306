"""The flags of the ROS 2 hand-off, shared by ``solve``, ``optimum`` and ``simulate``."""

from __future__ import annotations

import argparse
import math
from typing import Any

from ..errors import UsageError
from .common import Output

__all__ = ["add_ros_flags", "ros_frame", "ros_outputs", "ros_poses", "write_path_out"]


def add_ros_flags(p: argparse.ArgumentParser, path: str = "the path") -> None:
    """``--path-out``, ``--bag``, ``--frame-id`` and ``--path-resolution``; ``path`` says which
    path ``--path-out`` writes (``simulate``: the initial static plan)."""
    g = p.add_argument_group("ROS 2 outputs (metres and seconds, whatever the problem's units)")
    g.add_argument(
        "--path-out",
        metavar="FILE",
        help=f"write {path} as a ROS nav_msgs/Path document in metres, poses at most "
        "--path-resolution apart, the last one facing the problem's goal_yaw if given (JSON for "
        ".json, else YAML; nothing when there is no path)",
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
    no ROS output is asked for (the problem's units then need not be known).

    Refused here (exit 2): an empty ``--frame-id``, a ``--path-resolution`` that is not positive
    and finite, an unknown ``units`` (a :class:`~rrtpso_ompl.errors.ProblemError`), and a
    resolution at which even the straight line from start to goal would need more than
    :data:`~rrtpso_ompl.ros.poses.MAX_POSES` poses (every path is at least that long).
    """
    if not (args.path_out or args.bag):
        return None
    from ..ros import RosFrame
    from ..ros.poses import MAX_POSES

    if not args.frame_id.strip():
        raise UsageError(f"{args.problem}: --frame-id: must not be empty")
    try:
        frame = RosFrame.for_problem(problem, args.path_resolution, args.frame_id)
    except ValueError as exc:
        if getattr(exc, "key", None):  # a ProblemError: the file's own key
            raise
        raise UsageError(f"{args.problem}: --path-resolution: {exc}") from None
    shortest = max(0.0, math.dist(problem.start, problem.goal) - problem.goal_tolerance)
    poses = shortest * frame.scale / frame.resolution
    if poses > MAX_POSES:
        raise UsageError(
            f"{args.problem}: --path-resolution: even the straight line from start to goal "
            f"({shortest * frame.scale:.6g} m) needs {poses:.3g} poses at {frame.resolution:g} m; "
            f"at most {MAX_POSES:,}: give a coarser --path-resolution"
        )
    if args.bag:
        _check_bag(args, problem, frame)
    return frame


def ros_poses(args: argparse.Namespace, frame: Any, path: Any) -> Any:
    """The dense poses (metres) of ``path`` (problem units) for the ROS outputs, or None when
    none is asked for (``frame`` None) or there is no path.

    Call it before writing any output: a path longer than the straight line may still need more
    than :data:`~rrtpso_ompl.ros.poses.MAX_POSES` poses, a
    :class:`~rrtpso_ompl.errors.UsageError` naming ``--path-resolution`` (exit 2), and then
    nothing may be half-written.
    """
    if frame is None or path is None or len(path) == 0:
        return None
    try:
        if args.bag:  # a bag's /plan holds fewer poses than a path document
            import numpy as np

            from ..model.geometry import path_length
            from ..ros.bag import check_pose_count

            check_pose_count(frame, path_length(np.asarray(path)[:, :2]) * frame.scale)
        return frame.poses(path)
    except ValueError as exc:
        raise UsageError(f"{args.problem}: --path-resolution: {exc}") from None


def write_path_out(args: argparse.Namespace, frame: Any, poses: Any) -> None:
    """Write ``--path-out`` when it is asked for and there are ``poses`` (:func:`ros_poses`)."""
    if not args.path_out or poses is None:
        return
    from ..ros import nav_path, write_nav_path

    write_nav_path(nav_path(poses, frame.frame_id), args.path_out)


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
