"""Tune on some problems, report on others: RRTstarPSO against BIT* and Informed RRT* (each with
OMPL's simplifier) on seeded generated families and on the library, median path length over the
exact optimum.

The protocol (docs/benchmarking.md, "Tuning and reporting"):

- **tuning set**: the families below with seeds 1-3, and the tuning part of ``problems/``
  (:data:`TUNING_FILES`); defaults were chosen on these only;
- **report set**: the same families with fresh seeds (101-103 unless ``--seeds``), never used in
  tuning, and the rest of ``problems/`` (static and maps).

Usage::

    python benchmarks/families.py --set report --time 1 --out docs/families-1s.md
    python benchmarks/families.py --set tuning --time 1 --out -    # print only
    python benchmarks/families.py --set report --param stall_fraction=0  # a variant
"""

from __future__ import annotations

import argparse
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

#: Generated families: ``rrtpso generate`` kind and options (issue 13 adds the point-robot
#: circle field and the narrow unique-solution maze).
FAMILIES = {
    "circles": ("circles", {}),
    "circles_point": ("circles", {"n": 70, "radius_range": (1.0, 6.0), "robot_radius": 0.0}),
    "polygons": ("polygons", {}),
    "maze": ("maze", {}),
    # Corridors 1.3 % of the width (8.33 - 7), a point robot, one solution.
    "maze_narrow": ("maze", {"cells": 12, "robot_radius": 0.0, "wall": 7.0}),
}
TUNING_SEEDS = (1, 2, 3)
REPORT_SEEDS = (101, 102, 103)
#: The part of problems/ the defaults were tuned on; the rest is for reporting.
TUNING_FILES = (
    "static/paper_static.yaml", "static/single_circle.yaml", "static/narrow_passage.yaml",
    "static/cluttered_circles.yaml", "static/polygon_map.yaml", "static/dense_circles.yaml",
    "static/maze.yaml", "static/bug_trap.yaml",
)  # fmt: skip
PLANNERS = (("RRTstarPSO", False), ("BITstar", True), ("InformedRRTstar", True))


def problem_files(which: str, seeds, folder: Path, only=None) -> list[tuple[str, Path]]:
    from rrtpso_ompl.groundtruth.generate import generate_to_file

    out = []
    for family, (kind, options) in FAMILIES.items():
        if only and family not in only:
            continue
        for seed in seeds:
            path = folder / f"{family}_{seed}.yaml"
            generate_to_file(kind, seed, path, **options)
            out.append((family, path))
    library = sorted(REPO.glob("problems/static/*.yaml")) + sorted(
        REPO.glob("problems/maps/*.yaml")
    )
    for path in library if not only or "library" in only else []:
        rel = str(path.relative_to(REPO / "problems"))
        if (rel in TUNING_FILES) == (which == "tuning"):
            out.append(("library", path))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", choices=("tuning", "report"), default="report")
    ap.add_argument("--time", type=float, default=1.0)
    ap.add_argument("--runs", type=int, nargs="+", default=[1, 2, 3], help="planner seeds")
    ap.add_argument("--seeds", type=int, nargs="+", help="family seeds")
    ap.add_argument("--param", action="append", default=[], help="RRTstarPSO NAME=VALUE")
    ap.add_argument("--planners", default=",".join(p for p, _ in PLANNERS))
    ap.add_argument("--families", nargs="+", help="only these families (or library)")
    ap.add_argument("--out", default="-", help="markdown file to write (default: print)")
    args = ap.parse_args(argv)

    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.harness.report import markdown_table, write_markdown
    from rrtpso_ompl.model import World, load_problem
    from rrtpso_ompl.ompl_setup import set_ompl_log_level
    from rrtpso_ompl.planners import solve

    set_ompl_log_level(0)
    params = dict(p.split("=", 1) for p in args.param)
    planners = [(p, s) for p, s in PLANNERS if p in args.planners.split(",")]
    seeds = args.seeds or (TUNING_SEEDS if args.set == "tuning" else REPORT_SEEDS)
    ratios: dict[tuple[str, str], list[float]] = {}
    unsolved: dict[tuple[str, str], int] = {}
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for family, path in problem_files(args.set, seeds, Path(tmp), args.families):
            problem = load_problem(path)
            world = World.from_problem(problem)
            best = shortest_path(problem, world).length
            for planner, simplify in planners:
                for run in args.runs:
                    extra = params if planner == "RRTstarPSO" else None
                    r = solve(problem, planner, time_limit=args.time, seed=run, params=extra,
                              simplify=simplify, world=world)  # fmt: skip
                    key = (family, planner)
                    if r.solved and best:
                        ratios.setdefault(key, []).append(r.length / best)
                    else:
                        unsolved[key] = unsolved.get(key, 0) + 1
            print(f"{path.name} done ({time.perf_counter() - t_start:.0f} s)", file=sys.stderr)
    families = list(dict.fromkeys([f for f, _ in ratios] + [f for f, _ in unsolved]))
    lines = [
        f"# RRTstarPSO on the {args.set} set",
        "",
        f"Generated by `python benchmarks/families.py --set {args.set} --time {args.time:g}"
        + "".join(f" --param {p}" for p in args.param)
        + f"` on {platform.machine()}, Python {platform.python_version()}: family seeds "
        f"{', '.join(map(str, seeds))}, planner seeds {', '.join(map(str, args.runs))}, "
        f"{args.time:g} s each. Median (and 90th percentile) of path length over the exact "
        "optimum; BIT* and Informed RRT* followed by OMPL's simplifier. The library rows are "
        f"the {args.set} part of problems/ (see docs/benchmarking.md).",
        "",
    ]
    table = []
    for fam in families:
        cells = []
        for planner, _ in planners:
            vals = sorted(ratios.get((fam, planner), []))
            miss = unsolved.get((fam, planner), 0)
            if not vals:
                cells.append(f"unsolved x{miss}")
                continue
            p90 = vals[min(len(vals) - 1, round(0.9 * (len(vals) - 1)))]
            cell = f"{statistics.median(vals):.4f} ({p90:.4f})"
            cells.append(cell + (f", {miss} unsolved" if miss else ""))
        table.append([fam, *cells])
    lines.append(markdown_table(["family", *(p for p, _ in planners)], table))
    write_markdown(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
