"""``rrtpso optimum``: the exact shortest path, the reference of every length ratio."""

from __future__ import annotations

import argparse
from typing import Any

from .common import EXIT_OK, EXIT_UNSOLVED, Output, check_outputs, note

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
    o.add_argument("--json", metavar="OUT", help='write {"length": ..., "path": [...], ...}')
    o.add_argument("--plot", metavar="OUT.png", help="draw the world and the shortest path")
    o.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..groundtruth import shortest_path
    from ..model import load_problem

    problem = load_problem(args.problem)
    check_outputs([Output("--json", args.json), Output("--plot", args.plot, "image")],
                  inputs=problem.inputs)  # fmt: skip
    result = shortest_path(problem)
    if args.plot:
        from ..plotting import plot_optimum, save_figure

        save_figure(plot_optimum(problem, result), args.plot)
    if args.json:
        from ..model import World
        from ..outputs import write_json_atomic

        write_json_atomic(result.to_dict(World.from_problem(problem)), args.json)
    if result.found:
        note(f"{problem.name}: optimum length={result.length:.6f}")
        return EXIT_OK
    note(f"{problem.name}: no path exists")
    return EXIT_UNSOLVED
