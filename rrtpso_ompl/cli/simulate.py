"""``rrtpso simulate``: drive among moving obstacles with collision prediction and replanning."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from typing import Any

from ..errors import RrtpsoError, UsageError
from ..foreign import contained
from .common import (
    EXIT_OK,
    EXIT_UNSOLVED,
    Output,
    add_planner_flags,
    check_outputs,
    check_positive_seconds,
    check_seed_flag,
    choose_planner,
    note,
    progress_bar,
    report_errors,
    with_unit,
)
from .query import add_query_flags
from .ros_flags import add_ros_flags, ros_frame, ros_outputs, ros_poses, write_path_out

__all__ = ["HELP", "OPTION_FLAGS", "add_parser", "run"]

#: The line of ``rrtpso --help``.
HELP = "drive among moving obstacles with collision prediction and replanning"

#: The ``DynamicOptions`` the command sets, and their flags (``--time`` and ``--planner`` come
#: from the planner flags; the others keep their declared defaults).
OPTION_FLAGS = {
    "planner": "--planner",
    "strategy": "--strategy",
    "replan_time": "--replan-time",
    "reshorten": "--no-reshorten",
    "initial_time": "--time",
    "heading_changes": "--heading-changes",
    "params": "--param",
}


def _help(name: str, default: str | None = None) -> str:
    """A flag's help: the option's declared documentation and default."""
    from ..dynamic.options import DynamicOptions

    spec = DynamicOptions.PARAMS[name]
    unit = f" {spec.unit}" if spec.unit and spec.unit != "length" else ""
    shown = default if default is not None else f"{spec.default}{unit}"
    return f"{spec.doc} (default: {shown})".replace("%", "%%")


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    # The dynamic stage, and the strategies with their plugins (the choices of --strategy):
    # only for this command (the parser of another command does not build this one).
    from ..dynamic.options import DynamicOptions
    from ..dynamic.registry import STRATEGY_ENTRY_POINT_GROUP, default_strategies

    m = sub.add_parser(
        "simulate",
        parents=parents,
        help=HELP,
        description="Drive the robot from start to goal among the problem's moving obstacles: it "
        "senses them within robot.sensor_range, predicts collisions and replans contour detours "
        "(docs/dynamic.md). Exit status 0 when the goal is reached without a collision, else 1.",
    )
    add_query_flags(m)
    m.add_argument(
        "--json", metavar="OUT", help="write the simulation as JSON, in the problem's units"
    )
    m.add_argument("--gif", metavar="OUT.gif", help="write an animation")
    m.add_argument("--plot", metavar="OUT.png", help="draw the driven path (paper Fig. 24)")
    add_planner_flags(
        m,
        planner="planner of the static path and the detours (default: the file's planner.type, "
        "else RRTstarPSO)",
        time="budget of the initial static path (default: the file's planner.time_limit, else 1.0)",
        param="planner parameter, repeatable",
    )
    m.add_argument("--replan-time", type=float, metavar="SECONDS", help=_help("replan_time"))
    m.add_argument("--no-reshorten", dest="reshorten", action="store_false",
                   help=_help("reshorten", "on"))  # fmt: skip
    strategies = default_strategies()
    m.add_argument(
        "--strategy",
        choices=strategies.names(),
        default=DynamicOptions.PARAMS["strategy"].default,
        help="; ".join(f"{n}: {strategies.description(n).rstrip('.')}" for n in strategies.names())
        + f" (default: %(default)s; plugins register through the entry-point group "
        f"{STRATEGY_ENTRY_POINT_GROUP}, docs/dynamic.md)",
    )
    m.add_argument("--heading-changes", type=float, metavar="RATE",
                   default=DynamicOptions.PARAMS["heading_changes"].default,
                   help=_help("heading_changes"))  # fmt: skip
    add_ros_flags(m, "the initial static plan (not the path driven)")
    m.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..ompl_setup import set_ompl_log_level

    set_ompl_log_level(args.verbose)
    choice = choose_planner(args)
    problem = choice.problem
    _check_flags(args, problem)
    outputs = [
        Output("--json", args.json),
        Output("--plot", args.plot, "image"),
        Output("--gif", args.gif, "gif"),
        *ros_outputs(args),
    ]
    check_outputs(outputs, inputs=problem.inputs)
    frame = ros_frame(args, problem)  # the units and the pose spacing, known before planning

    from ..dynamic import DynamicOptions, simulate

    timing = {} if args.replan_time is None else {"replan_time": args.replan_time}
    options = DynamicOptions(
        planner=choice.entry.name,
        strategy=args.strategy,
        **timing,
        reshorten=args.reshorten,
        initial_time=args.time,
        heading_changes=args.heading_changes,
        params=choice.params,
    )
    seed = args.seed if args.seed is not None else problem.planner.seed
    # The planner's and the strategy's code (a plugin's) may raise anything: the simulation is
    # then an error, not a traceback; bad input and a real Ctrl-C go on to main. What they
    # print is no result: standard error (`--json -` keeps standard output for the JSON).
    with (
        progress_bar("simulating", unit="s") as bar,
        contained(passthrough=(RrtpsoError, MemoryError)) as box,
        contextlib.redirect_stdout(sys.stderr),
    ):

        def progress(t: float, t_end: float) -> None:
            bar.total = round(t_end, 1)
            bar.n = round(t, 1)
            bar.refresh()

        sim = simulate(problem, options, seed=seed, progress=progress)
    if box.error is not None:
        return _failed(args, problem, options, seed, box)
    _write_outputs(args, problem, sim, frame)
    verdict = "reached the goal" if sim.reached_goal else f"did not reach the goal ({sim.status})"
    note(
        f"{problem.name}: {verdict}, {sim.collisions} collisions, {len(sim.replans)} replans, "
        f"driving time {sim.total_time:.1f} s (simulated), "
        f"driven {with_unit(sim.path_length, problem.units, 1)}",
    )
    return EXIT_OK if sim.success else EXIT_UNSOLVED


def _check_flags(args: argparse.Namespace, problem: Any) -> None:
    """The robot keys a simulation needs and the flags' values (UsageError naming them)."""
    src = args.problem
    if problem.car:  # the replanning manager drives a differential-drive robot's polylines
        raise UsageError(f"{src}: robot.turning_radius: simulate drives a differential-drive "
                         "robot; a car-like robot's curves are planned by solve (--trajectory "
                         "for its wheel commands)")  # fmt: skip
    for key in ("speed", "sample_time", "sensor_range"):
        if getattr(problem.robot, key) is None:
            raise UsageError(f"{src}: robot.{key}: required for simulate")
    check_positive_seconds(args.time, "--time", src)
    check_positive_seconds(args.replan_time, "--replan-time", src)
    check_seed_flag(args.seed)
    if not (args.heading_changes >= 0 and math.isfinite(args.heading_changes)):
        raise UsageError(f"{src}: --heading-changes: must be >= 0, got {args.heading_changes}")


def _failed(args: argparse.Namespace, problem: Any, options: Any, seed: Any, box: Any) -> int:
    """A simulation that raised (:func:`~rrtpso_ompl.foreign.contained`): one message, and the
    JSON with status ``error`` and the message, nothing else written; exit status 1. With
    ``-v`` the traceback is logged too."""
    import logging

    message = f"{args.problem}: the simulation raised {box.message}"
    logging.getLogger(__name__).info("the simulation's traceback:", exc_info=box.error)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        data = {"problem": problem.name, "status": "error", "strategy": options.strategy,
                "planner": options.planner, "seed": seed, "reached_goal": False,
                "replans": [], "trajectory": [], "static_path": [],
                "error": message}  # fmt: skip
        write_json_atomic({**data, **units_fields(problem.units)}, args.json)
    report_errors([f"error: {message}"])
    return EXIT_UNSOLVED


def _write_outputs(args: argparse.Namespace, problem: Any, sim: Any, frame: Any) -> None:
    poses = ros_poses(args, frame, sim.static_path)  # may refuse: before anything is written
    if args.plot:
        from ..plotting import plot_simulation, save_figure

        save_figure(plot_simulation(problem, sim), args.plot)
    if args.gif and sim.motion is not None:
        from ..plotting import animate_simulation

        with progress_bar("drawing the GIF", unit="frame") as bar:

            def progress(done: int, total: int) -> None:
                bar.total, bar.n = total, done
                bar.refresh()

            animate_simulation(problem, sim, args.gif, progress=progress)
    write_path_out(args, frame, poses)  # nothing when no static plan was found
    if args.bag:
        from ..ros.bag import write_simulation_bag

        write_simulation_bag(problem, frame, sim, args.bag)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        write_json_atomic({**sim.to_dict(), **units_fields(problem.units)}, args.json)
