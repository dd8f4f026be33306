"""``rrtpso optimum``: the exact shortest path, the reference of every length ratio."""

from __future__ import annotations

import argparse
from typing import Any

from .common import EXIT_OK, EXIT_UNSOLVED, Output, check_outputs, note
from .ros_flags import add_ros_flags, ros_frame, ros_outputs, ros_poses, write_path_out

__all__ = ["add_parser", "run"]


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    o = sub.add_parser(
        "optimum",
        parents=parents,
        help="compute the exact shortest path (the reference for path-length ratios)",
        description="Compute the exact shortest path for the problem's disc robot among its "
        "circles, polygons and map cells: a tangent graph with arcs around the inflated "
        "obstacles, searched with A* and geodesic lower bounds (docs/benchmarking.md). Moving "
        "obstacles are ignored. Exit status 0 when a path exists, 1 when none does.",
    )
    o.add_argument("problem", help="problem file (YAML)")
    o.add_argument("--json", metavar="OUT", help='write {"length": ..., "path": [...], ...} in '
                   "the problem's units (its units key)")  # fmt: skip
    o.add_argument("--plot", metavar="OUT.png", help="draw the world and the shortest path")
    add_ros_flags(o, "the shortest path (its polyline, as --json's path)")
    o.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..groundtruth import shortest_path
    from ..model import load_problem

    problem = load_problem(args.problem)
    outputs = [Output("--json", args.json), Output("--plot", args.plot, "image"),
               *ros_outputs(args)]  # fmt: skip
    check_outputs(outputs, inputs=problem.inputs)
    frame = ros_frame(args, problem)  # the units and the pose spacing, known before the search
    result = shortest_path(problem)
    data = None
    if args.json or frame is not None:
        from ..model import World

        data = result.to_dict(World.from_problem(problem))  # the polyline the exact check accepts
    poses = ros_poses(args, frame, data["path"] if result.found else None)  # may refuse: first
    if args.plot:
        from ..plotting import plot_optimum, save_figure

        save_figure(plot_optimum(problem, result), args.plot)
    write_path_out(args, frame, poses)
    if args.json:
        from ..outputs import write_json_atomic
        from ..ros import units_fields

        write_json_atomic({**data, **units_fields(problem.units)}, args.json)
    if args.bag:
        from ..ros.bag import write_plan_bag

        path = data["path"] if result.found else None
        write_plan_bag(problem, frame, path, args.bag, command="optimum")
    if result.found:
        note(f"{problem.name}: optimum length={result.length:.6f}")
        return EXIT_OK
    note(f"{problem.name}: no path exists")
    return EXIT_UNSOLVED
