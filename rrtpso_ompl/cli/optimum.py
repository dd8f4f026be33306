"""``rrtpso optimum``: the exact shortest path, the reference of every length ratio; with
``--cost``, the reference of the problem's objective (length plus the inflation cost)."""

from __future__ import annotations

import argparse
import math
from typing import Any

from ..errors import UsageError
from .common import EXIT_OK, EXIT_UNSOLVED, Output, check_outputs, note, with_unit
from .query import add_query_flags, load_query
from .ros_flags import add_ros_flags, ros_frame, ros_outputs, ros_poses, write_path_out

__all__ = ["HELP", "add_parser", "run"]

#: The line of ``rrtpso --help``.
HELP = "compute the exact shortest path (the reference for path-length ratios)"


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    o = sub.add_parser(
        "optimum",
        parents=parents,
        help=HELP,
        description="Compute the exact shortest path for the problem's disc robot among its "
        "circles, polygons and map cells: a tangent graph with arcs around the inflated "
        "obstacles, searched with A* and geodesic lower bounds (docs/benchmarking.md). With "
        "--cost and a robot with inflation, the reference of the objective J (length plus the "
        "inflation cost, docs/clearance.md) instead: a 16-connected grid search on the costmap. "
        "Moving obstacles are ignored. Exit status 0 when a path exists, 1 when none does (or "
        "the grid has none).",
    )
    add_query_flags(o)
    o.add_argument("--json", metavar="OUT", help='write {"length": ..., "path": [...], ...} in '
                   "the problem's units (its units key)")  # fmt: skip
    o.add_argument("--plot", metavar="OUT.png", help="draw the world and the path")
    o.add_argument(
        "--cost",
        action="store_true",
        help="the reference of the problem's objective J: with robot.inflation_radius, the "
        "grid search of docs/clearance.md (its J, length, resolution, nodes and edges); "
        "without inflation J is the length and the exact shortest path is the reference",
    )
    o.add_argument(
        "--resolution",
        type=float,
        metavar="H",
        help="node spacing of the --cost grid, problem units (default: the map's resolution, "
        "else about 500,000 nodes over the bounds; at most 2,000,000 nodes)",
    )
    add_ros_flags(
        o,
        "the path (the exact shortest path's polyline, as --json's path; with "
        "--cost, the grid reference's)",
    )
    o.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.resolution is not None:
        if not args.cost:
            raise UsageError("--resolution: only with --cost")
        if not (math.isfinite(args.resolution) and args.resolution > 0):
            raise UsageError(f"--resolution: must be a positive number, got {args.resolution:g}")
    problem = load_query(args)
    outputs = [Output("--json", args.json), Output("--plot", args.plot, "image"),
               *ros_outputs(args)]  # fmt: skip
    check_outputs(outputs, inputs=problem.inputs)
    frame = ros_frame(args, problem)  # the units and the pose spacing, known before the search
    if args.cost and problem.objective.active:
        return _cost_reference(args, problem, frame)
    return _shortest(args, problem, frame)


def _shortest(args: argparse.Namespace, problem: Any, frame: Any) -> int:
    """The exact shortest path (with ``--cost`` and no inflation: its ``J`` is its length)."""
    from ..groundtruth import shortest_path
    from ..model import World

    world = World.from_problem(problem)
    result = shortest_path(problem, world)
    # Built whatever the outputs ask for: the message, --json, the poses and the bag all read it.
    data = result.to_dict(world)  # the polyline the exact check accepts
    path = data["path"] if result.found else None
    poses = ros_poses(args, frame, path)  # may refuse: first
    if args.plot:
        from ..plotting import plot_optimum, save_figure

        save_figure(plot_optimum(problem, result), args.plot)
    write_path_out(args, frame, poses)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        if args.cost:
            data = {"length": data["length"], "path": data["path"], "cost": result.length, **data}
        write_json_atomic({**data, **units_fields(problem.units)}, args.json)
    _write_bag(args, problem, frame, path)
    if result.found:
        what = "no inflation: J is the length; " if args.cost else ""
        bound = (" (the disc's shortest path, turning radius ignored: a lower bound for this "
                 "car-like robot)") if problem.car else ""  # fmt: skip
        note(f"{problem.name}: {what}optimum length={with_unit(result.length, problem.units, 6)}"
             f"{bound}")  # fmt: skip
        return EXIT_OK
    note(f"{problem.name}: no path exists")
    return EXIT_UNSOLVED


def _write_bag(args: argparse.Namespace, problem: Any, frame: Any, path: Any) -> None:
    if args.bag:
        from ..ros.bag import write_plan_bag

        write_plan_bag(problem, frame, path, args.bag, command="optimum")


def _cost_reference(args: argparse.Namespace, problem: Any, frame: Any) -> int:
    """The grid reference of the objective (:mod:`rrtpso_ompl.groundtruth.costgrid`)."""
    from ..groundtruth.costgrid import CostGridError, cost_reference

    try:
        result = cost_reference(problem, resolution=args.resolution)
    except CostGridError as exc:
        raise UsageError(f"{args.problem}: {exc}") from None
    path = result.path if result.found else None
    poses = ros_poses(args, frame, path)  # may refuse: before anything is written
    if args.plot:
        from ..plotting import plot_cost_reference, save_figure

        save_figure(plot_cost_reference(problem, result), args.plot)
    write_path_out(args, frame, poses)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        write_json_atomic({**result.to_dict(), **units_fields(problem.units)}, args.json)
    _write_bag(args, problem, frame, path)
    grid = (
        f"grid h={result.resolution:.4g}{' (coarsened)' if result.coarsened else ''}, "
        f"{result.nodes:,} nodes, {result.edges:,} edges, {result.time:.1f}s"
    )
    if result.found:
        note(f"{problem.name}: grid reference J={with_unit(result.cost, problem.units, 6)} "
             f"length={with_unit(result.length, problem.units, 6)} ({grid})")  # fmt: skip
        return EXIT_OK
    note(f"{problem.name}: no path on the grid ({grid}); a finer --resolution may find one")
    return EXIT_UNSOLVED
