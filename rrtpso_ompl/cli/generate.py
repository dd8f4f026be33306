"""``rrtpso generate``: a seeded random problem file, certified solvable."""

from __future__ import annotations

import argparse
import os
from typing import Any

from ..errors import GenerationError, UsageError
from ..outputs import is_stream
from .common import EXIT_OK, Output, check_outputs, check_seed_flag, note

__all__ = ["add_parser", "run"]

#: The options passed on to the generator, as named on the command line.
_OPTIONS = (
    "size",
    "n",
    "cells",
    "robot_radius",
    "radius_range",
    "vertices",
    "gap",
    "wall",
    "algorithm",
    "name",
)


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    g = sub.add_parser(
        "generate",
        parents=parents,
        help="write a seeded random problem (circles, polygons or a maze)",
        description="Write a seeded random problem file whose start and goal are free and "
        "connected (certified by a collision-checked grid path). The same seed and options give "
        "the same file, byte for byte.",
    )
    g.add_argument("kind", choices=("circles", "polygons", "maze"))
    g.add_argument("--seed", type=int, required=True, help="seed (>= 0)")
    g.add_argument("--out", required=True, metavar="FILE.yaml", help="where to write the problem")
    g.add_argument("--size", type=float, help="side of the square workspace (default 100)")
    g.add_argument("--n", type=int, help="number of obstacles (circles 30, polygons 20)")
    g.add_argument("--cells", type=int, help="maze cells per side (default 8)")
    g.add_argument("--robot-radius", type=float, help="robot radius (0: a point robot)")
    g.add_argument(
        "--radius-range",
        type=float,
        nargs=2,
        metavar=("LO", "HI"),
        help="obstacle radii (circles) or circumradii (polygons)",
    )
    g.add_argument(
        "--vertices",
        type=int,
        nargs=2,
        metavar=("LO", "HI"),
        help="polygon vertex counts (default 3 8)",
    )
    g.add_argument("--gap", type=float, help="least free distance between obstacles")
    g.add_argument("--wall", type=float, help="maze wall thickness")
    g.add_argument("--algorithm", choices=("dfs", "kruskal"), help="maze algorithm")
    g.add_argument("--name", help="problem name (default: from kind and seed)")
    g.add_argument("--overwrite", action="store_true",
                   help="replace --out when it exists (it is refused otherwise)")  # fmt: skip
    g.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..groundtruth import generate_to_file

    check_seed_flag(args.seed)
    options = {k: getattr(args, k) for k in _OPTIONS if getattr(args, k) is not None}
    check_outputs([Output("--out", args.out)])
    if os.path.lexists(args.out) and not args.overwrite and not is_stream(args.out):
        raise UsageError(f"--out: '{args.out}' exists; pass --overwrite to replace it")
    try:
        path = generate_to_file(args.kind, args.seed, args.out, **options)
    except (GenerationError, ValueError) as exc:
        raise UsageError(f"generate {args.kind}: {exc}") from None
    note(f"wrote {path}")
    return EXIT_OK
