"""``rrtpso solve``: one problem file, one planner; the path as JSON, plots and wheel commands."""

from __future__ import annotations

import argparse
from typing import Any

from ..errors import UsageError
from .common import (
    EXIT_OK,
    EXIT_UNSOLVED,
    Output,
    add_planner_flags,
    check_outputs,
    choose_planner,
    note,
    report_errors,
    with_unit,
)
from .query import add_query_flags
from .ros_flags import add_ros_flags, ros_frame, ros_outputs, ros_poses, write_path_out

__all__ = ["HELP", "add_parser", "run"]

#: The line of ``rrtpso --help``.
HELP = "solve one problem file"


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "solve",
        parents=parents,
        help=HELP,
        description="Solve one problem file and report the path.",
    )
    add_query_flags(p)
    add_planner_flags(
        p,
        planner="planner name (default: the file's planner.type, else RRTstarPSO); "
        "see 'rrtpso planners'",
        time="time limit (default: the file's planner.time_limit, else 1.0)",
        param="planner parameter, repeatable (e.g. --param swarm_size=50)",
    )
    p.add_argument(
        "--json",
        metavar="OUT",
        help="write the result as JSON, in the problem's units (its units key)",
    )
    p.add_argument(
        "--plot",
        metavar="OUT.png",
        help="draw the world, the paths and the PSO best-cost curve "
        "(and the costmap's inflation cost under them when the robot has inflation)",
    )
    p.add_argument(
        "--plot-clearance",
        metavar="OUT.png",
        help="draw the path's clearance (distance to the nearest obstacle) against arc length, "
        "with the robot radius and the inflation radius",
    )
    add_ros_flags(p)
    p.add_argument(
        "--post",
        metavar="STEPS",
        help="post-passes after the planner, in order, within the same --time: a comma list of "
        "simplify (OMPL's simplifier) and pso (the swarm); they get post_fraction of the time "
        "(--param post_fraction=0.2); the planner name may carry them too (BITstar+simplify+pso)",
    )
    p.add_argument(
        "--simplify",
        action="store_true",
        help="alias of --post simplify (before any other --post step)",
    )
    _add_drive_flags(p)
    p.set_defaults(func=run)


def _add_drive_flags(p: argparse.ArgumentParser) -> None:
    """The flags of driving the path (:func:`_drive`): the wheel commands and their profile."""
    p.add_argument(
        "--trajectory",
        metavar="OUT.csv",
        help="write the wheel commands every robot.sample_time, in the problem's units (lengths) "
        "and seconds, radians: the columns t, x, y, theta, v, omega, v_right, v_left, "
        "omega_right, omega_left (the header has no spaces); with goal_yaw it ends with the "
        "turn in place to that heading (a car-like robot: no turn in place, v < 0 backing)",
    )
    p.add_argument(
        "--plot-velocities",
        metavar="OUT.png",
        help="draw v and omega (paper Fig. 17) and the wheel speeds (Fig. 18)",
    )
    p.add_argument(
        "--profile",
        choices=("auto", "constant", "limits"),
        default="auto",
        help="velocity profile: the paper's constant robot.speed, or within the robot's "
        "limits from rest to rest (auto: limits when any limit is given)",
    )
    p.add_argument(
        "--slow-near-obstacles",
        action="store_true",
        help="cap the speed where clearance is small: full speed from robot.inflation_radius "
        "on, down to 30%% of it at robot.radius (docs/clearance.md); needs "
        "robot.inflation_radius",
    )


def run(args: argparse.Namespace) -> int:
    from ..ompl_setup import set_ompl_log_level

    set_ompl_log_level(args.verbose)
    request = choose_planner(args)  # --planner, --post, --param, --time and --seed, checked
    problem = request.problem
    outputs = [
        Output("--json", args.json),
        Output("--plot", args.plot, "image"),
        Output("--plot-clearance", args.plot_clearance, "image"),
        Output("--trajectory", args.trajectory),
        Output("--plot-velocities", args.plot_velocities, "image"),
        *ros_outputs(args),
    ]
    check_outputs(outputs, inputs=problem.inputs)
    frame = ros_frame(args, problem)  # the units and the pose spacing, known before planning
    wants_motion = bool(args.trajectory or args.plot_velocities)
    if wants_motion:
        _check_drive_keys(args, problem)
    elif args.slow_near_obstacles:
        raise UsageError("--slow-near-obstacles: only with --trajectory or --plot-velocities")

    import contextlib
    import sys
    import time

    from ..errors import RrtpsoError
    from ..foreign import contained
    from ..planners import solve

    t0 = time.perf_counter()
    # A planner's code (a plugin's) may raise anything: the run is then an error, as in a batch
    # row, not a traceback; bad input and a real Ctrl-C go on to main. What it prints is no
    # result: standard error (`--json -` keeps standard output for the JSON).
    with (
        contained(passthrough=(RrtpsoError, MemoryError)) as box,
        contextlib.redirect_stdout(sys.stderr),
    ):
        result = solve(request)
    if box.error is not None:
        return _failed(args, request, box, time.perf_counter() - t0)
    motion = None
    if wants_motion and result.solved:
        motion = _drive(problem, result, args.profile, args.slow_near_obstacles)
    _write_outputs(args, problem, result, motion, frame)
    length = with_unit(result.length, problem.units) if result.length is not None else "-"
    note(
        f"{problem.name}: {result.planner} {result.status} length={length} "
        f"planning time={result.time:.3f} s",
    )
    return EXIT_OK if result.solved else EXIT_UNSOLVED


def _failed(args: argparse.Namespace, request: Any, box: Any, elapsed: float) -> int:
    """A run that raised (:func:`~rrtpso_ompl.foreign.contained`): one message, and the JSON
    with status ``error`` and the message (as a batch's error row), nothing else written;
    exit status 1. With ``-v`` the traceback is logged too."""
    import logging

    message = f"{args.problem}: the run raised {box.message}"
    logging.getLogger(__name__).info("the run's traceback:", exc_info=box.error)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        problem = request.problem
        data = {"problem": problem.name, "planner": request.label, "status": "error",
                "solved": False, "length": None, "time": elapsed, "seed": request.seed,
                "path": [], "time_limit": request.time_limit, "error": message}  # fmt: skip
        write_json_atomic({**data, **units_fields(problem.units)}, args.json)
    report_errors([f"error: {message}"])
    return EXIT_UNSOLVED


def _check_drive_keys(args: argparse.Namespace, problem: Any) -> None:
    """Wheel commands need the drive's parameters, and a bounded number of samples: refuse
    before planning when one is missing, or when even the straight line from start to goal at
    the top speed would take too many samples."""
    import math

    from ..errors import ProblemError
    from ..kinematics import REQUIRED_ROBOT_KEYS, TrajectoryError, check_samples

    robot = problem.robot
    flag = "--trajectory" if args.trajectory else "--plot-velocities"
    for key in REQUIRED_ROBOT_KEYS:
        if getattr(robot, key) is None:
            raise UsageError(f"{args.problem}: robot.{key}: required for {flag}")
    if args.slow_near_obstacles and not (robot.inflation_radius or 0.0) > robot.radius:
        raise UsageError(f"{args.problem}: robot.inflation_radius: required, above robot.radius, "
                         "for --slow-near-obstacles (the speed falls inside it)")  # fmt: skip
    shortest = max(0.0, math.dist(problem.start, problem.goal) - problem.goal_tolerance)
    top = max(robot.speed, robot.max_speed or 0.0)  # no profile drives faster
    try:
        check_samples(shortest / top, robot.sample_time, "even the straight line to the goal")
    except TrajectoryError as exc:
        raise ProblemError(problem.source, "", f"{exc} (for {flag})") from None


def _drive(problem: Any, result: Any, profile: str, slow: bool = False) -> Any:
    import math

    from ..errors import ProblemError
    from ..kinematics import TrajectoryError, drive
    from ..model import World

    if problem.car:
        return _drive_car(problem, result, profile)
    yaw = None if problem.goal_yaw is None else math.radians(problem.goal_yaw)
    try:
        return drive(
            result.path,
            World.from_problem(problem),
            problem.robot,
            profile,
            yaw,
            slow_near_obstacles=slow,
        )
    except TrajectoryError as exc:  # the path found is longer than the straight line
        raise ProblemError(problem.source, "", str(exc)) from None


def _drive_car(problem: Any, result: Any, profile: str) -> Any:
    """A car's trajectory: its curves' dense poses driven as they are (no turn in place)."""
    import numpy as np

    from ..errors import ProblemError
    from ..kinematics import TrajectoryError, drive_car
    from ..ompl_setup.car import CarModel

    car = CarModel.of(problem)
    poses = car.polyline(np.asarray(result.stages["poses"], dtype=float))
    try:
        return drive_car(poses, problem.robot, profile, result.stages["car"]["space"])
    except TrajectoryError as exc:
        raise ProblemError(problem.source, "", str(exc)) from None


def _ros_path(result: Any) -> Any:
    """The path the ROS outputs take: its points, with a car's headings as a third column."""
    import numpy as np

    yaw = (result.stages or {}).get("path_yaw")
    if yaw is None or len(yaw) != len(result.path):
        return result.path
    return np.column_stack([result.path, yaw])


def _write_outputs(
    args: argparse.Namespace, problem: Any, result: Any, motion: Any, frame: Any
) -> None:
    plan = _ros_path(result) if result.solved else None
    poses = ros_poses(args, frame, plan)  # may refuse: first
    if args.plot:
        from ..plotting import plot_solution, save_figure

        save_figure(plot_solution(problem, result, motion.curve if motion else None), args.plot)
    if args.plot_clearance:
        from ..plotting import plot_clearance_profile, save_figure

        paths = {result.planner: result.path} if result.solved else {}
        save_figure(plot_clearance_profile(problem, paths), args.plot_clearance)
    if motion and args.plot_velocities:
        from ..plotting import plot_velocities, save_figure

        save_figure(plot_velocities(motion.trajectory, problem.units), args.plot_velocities)
    if motion and args.trajectory:
        motion.trajectory.write_csv(args.trajectory)
    write_path_out(args, frame, poses)
    if args.bag:
        from ..ros.bag import write_plan_bag

        write_plan_bag(problem, frame, plan, args.bag)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        data = result.to_dict()
        if motion:
            data["kinematics"] = motion.summary()
        write_json_atomic({**data, **units_fields(problem.units)}, args.json)
