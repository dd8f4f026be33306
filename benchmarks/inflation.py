"""Clearance-aware planning measured: RRTstarPSO and BIT* with OMPL's simplifier under the
inflation objective (issue 27), against the exact shortest path and the fine-grid reference.

For every problem, the same world is planned with a costmap-like inflation cost
(:mod:`rrtpso_ompl.model.objective`; the radius and factor of each family below) and measured:

- *near share*: the share of the path's length closer than ``inflation_radius`` to an obstacle,
  against the exact shortest path's (``rrtpso optimum``): the issue asks it to fall by half;
- *length growth*: the path's length over the shortest path's (at most +10 % asked);
- *cost*: ``J`` over the fine-grid reference's (:mod:`rrtpso_ompl.groundtruth.costgrid`, when
  it is there) and RRTstarPSO's ``J`` over BIT* + simplifier's on the same problem and seed.

The protocol of docs/benchmarking.md: a **tuning set** (generated seeds 1-3 and the tuning part of
``problems/static`` with a disc robot) and a **report set** (fresh seeds 101-103 and
``problems/maps``), each run in a child process of its own, one at a time.

Usage::

    python benchmarks/inflation.py --set report --time 0.25 1 4 --out docs/inflation.md
    python benchmarks/inflation.py --set tuning --time 1 --out -
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import tempfile
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

from families import TUNING_FILES, in_child, percentile  # noqa: E402

#: Generated families: ``rrtpso generate`` kind, its options, and the inflation (radius, factor)
#: in the family's units. Rooms with doors 1.6-3.9 m (maps) and 6.25-10 units (shapes): many
#: doors are narrower than twice the inflation radius, and must still be passed.
FAMILIES = {
    "rooms_map": ("rooms_map", {"cells": 128}, (1.0, 2.0)),
    "warehouse_map": ("warehouse_map", {"cells": 128}, (1.0, 2.0)),
    "rooms": ("rooms", {}, (4.0, 0.5)),
}
#: problems/maps: Nav2's defaults (inflation_radius 0.55 m, cost_scaling_factor 3.0).
NAV2_INFLATION = (0.55, 3.0)
TUNING_SEEDS = (1, 2, 3)
REPORT_SEEDS = (101, 102, 103)
PLANNERS = ("RRTstarPSO", "BITstar+simplify")


#: ``cost_travel_multiplier`` of every problem (None: the default); ``--weight`` sets it.
WEIGHT: list[float | None] = [None]


def inflated(src: Path, dst: Path, radius: float, factor: float) -> Path:
    """A copy of problem ``src`` with the robot's inflation, its map resolved beside it."""
    doc = yaml.safe_load(src.read_text())
    doc["robot"]["inflation_radius"] = radius
    doc["robot"]["cost_scaling_factor"] = factor
    if WEIGHT[0] is not None:
        doc["robot"]["cost_travel_multiplier"] = WEIGHT[0]
    if "map" in doc:
        doc["map"] = str((src.parent / doc["map"]).resolve())
    dst.write_text(yaml.safe_dump(doc, sort_keys=False))
    return dst


def problem_files(which: str, seeds, folder: Path) -> list[tuple[str, Path]]:
    """``(family, problem file)`` of the set, written into ``folder``."""
    from rrtpso_ompl.groundtruth.generate import generate_to_file

    out = []
    for family, (kind, options, (radius, factor)) in FAMILIES.items():
        for seed in seeds:
            raw = folder / f"{family}_{seed}_raw.yaml"
            generate_to_file(kind, seed, raw, **options)
            out.append((family, inflated(raw, folder / f"{family}_{seed}.yaml", radius, factor)))
    if which == "report":
        for src in sorted(REPO.glob("problems/maps/*.yaml")):
            out.append(("library maps", inflated(src, folder / src.name, *NAV2_INFLATION)))
    else:
        for rel in TUNING_FILES:
            src = REPO / "problems" / rel
            r = yaml.safe_load(src.read_text())["robot"]["radius"]
            if r > 0:  # three radii of inflation, the cost falling by e^-1.5 across it
                dst = folder / Path(rel).name
                out.append(("library static", inflated(src, dst, 4.0 * r, 1.5 / (3.0 * r))))
    return out


def measure(path: Path, reference: bool = True) -> dict:
    """The shortest path's and the grid reference's figures of one problem."""
    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.model import World, load_problem
    from rrtpso_ompl.model.objective import InflationCost

    problem = load_problem(path)
    world = World.from_problem(problem)
    cost = InflationCost.of(problem.robot)
    opt = shortest_path(problem)
    row: dict = {"optimum": None}
    if opt.found:
        p = opt.valid_polyline(world)
        row.update(optimum=opt.length, optimum_cost=cost.path_cost(world, p),
                   optimum_near=cost.near_share(world, p))  # fmt: skip
    if not reference:
        return row
    from rrtpso_ompl.groundtruth.costgrid import cost_reference

    # On a map, cells a quarter of the inflated band when the map's are coarser (the generated
    # maps' 0.78 m cells would make a poor reference), else the map's own.
    h = None
    if problem.map is not None:
        h = min(problem.map.resolution, 0.25 * (cost.inflation_radius - cost.radius))
    ref = cost_reference(problem, resolution=h)
    if ref.found:
        row.update(reference=ref.cost, reference_resolution=ref.resolution,
                   reference_length=ref.length, reference_time=ref.time)  # fmt: skip
    return row


def run_one(path: Path, planner: str, budget: float, seed: int) -> dict:
    """One ``solve`` in a child process of its own; its row."""

    def work() -> dict:
        import numpy as np

        from rrtpso_ompl.model import World, load_problem
        from rrtpso_ompl.model.objective import InflationCost
        from rrtpso_ompl.ompl_setup import set_ompl_log_level
        from rrtpso_ompl.planners import solve

        set_ompl_log_level(0)
        problem = load_problem(path)
        world = World.from_problem(problem)
        res = solve(problem, planner, time_limit=budget, seed=seed, world=world)
        p = np.asarray(res.path, dtype=float).reshape(-1, 2)
        row = {"solved": bool(res.solved), "valid": bool(res.solved and world.path_valid(p)),
               "length": res.length, "cost": res.cost, "time": res.time}  # fmt: skip
        if res.solved:
            row["near"] = InflationCost.of(problem.robot).near_share(world, p)
        return row

    return in_child(work, {"solved": False})


def _cell(values: list[float], fmt: str = "{:.3f}") -> str:
    if not values:
        return "-"
    return f"{fmt.format(statistics.median(values))} ({fmt.format(percentile(values, 0.9))})"


def summary(rows: list[dict], budget: float) -> list[list[str]]:
    """Per family and planner: solved, near share over the shortest path's, length over the
    shortest, cost over the reference, share of runs whose near share at least halved."""
    table = []
    for fam in dict.fromkeys(r["family"] for r in rows):
        for planner in PLANNERS:
            key = (fam, planner, budget)
            mine = [r for r in rows if (r["family"], r["planner"], r["budget"]) == key]
            ok = [r for r in mine if r.get("solved") and r.get("optimum")]
            near = [r["near"] / r["optimum_near"] for r in ok if r.get("optimum_near")]
            halved = sum(1 for r in ok if r["near"] <= 0.5 * r.get("optimum_near", 0.0))
            longer = [r["length"] / r["optimum"] for r in ok]
            vs_ref = [r["cost"] / r["reference"] for r in ok if r.get("reference")]
            table.append([fam, planner, f"{len(ok)}/{len(mine)}", _cell(near),
                          f"{halved}/{len(ok)}", _cell(longer),
                          _cell(vs_ref, "{:.4f}")])  # fmt: skip
    return table


def head_to_head(rows: list[dict], budget: float) -> list[list[str]]:
    """RRTstarPSO's cost over BIT* + simplifier's, on the same problem and seed, per family."""
    table = []
    for fam in dict.fromkeys(r["family"] for r in rows):
        pairs, only_ours, only_theirs = [], 0, 0
        by_key = {}
        for r in rows:
            if r["family"] == fam and r["budget"] == budget:
                by_key.setdefault((r["file"], r["seed"]), {})[r["planner"]] = r
        for runs in by_key.values():
            a, b = runs.get(PLANNERS[0], {}), runs.get(PLANNERS[1], {})
            if a.get("solved") and b.get("solved"):
                pairs.append(a["cost"] / b["cost"])
            only_ours += bool(a.get("solved") and not b.get("solved"))
            only_theirs += bool(b.get("solved") and not a.get("solved"))
        wins = sum(1 for x in pairs if x <= 1.0 + 1e-9)
        table.append([fam, _cell(pairs, "{:.4f}"), f"{wins}/{len(pairs)}", str(only_ours),
                      str(only_theirs)])  # fmt: skip
    return table


def report(rows: list[dict], args, seeds) -> list[str]:
    from rrtpso_ompl.harness.report import markdown_table

    command = "python benchmarks/inflation.py " + " ".join(args.argv)
    res = sorted({r["reference_resolution"] for r in rows if r.get("reference_resolution")})
    lines = [
        f"# Clearance-aware planning on the {args.set} set",
        "",
        f"Generated by `{command}` on {platform.machine()}, Python {platform.python_version()}: "
        f"family seeds {', '.join(map(str, seeds))}, planner seeds "
        f"{', '.join(map(str, args.runs))}, one run at a time, each in a process of its own. "
        "Inflation per family in benchmarks/inflation.py. Cells are median (90th percentile). "
        "*near*: the path's share of length closer than the inflation radius to an obstacle, "
        "over the exact shortest path's; *halved*: runs where that share at least halved; "
        "*length*: over the shortest path's; *cost / ref*: the objective J over the fine-grid "
        "reference's"
        + (f" (resolutions {', '.join(f'{x:g}' for x in res)})" if res else " (not computed)")
        + ".",
    ]
    invalid = [r for r in rows if r.get("solved") and not r.get("valid")]
    for budget in args.time:
        lines += ["", f"## {budget:g} s", "",
                  markdown_table(["family", "planner", "solved", "near", "halved", "length",
                                  "cost / ref"], summary(rows, budget)),
                  "", "RRTstarPSO's J over BIT* + simplifier's (same problem and seed):", "",
                  markdown_table(["family", "J ratio", "RRTstarPSO no worse",
                                  "only RRTstarPSO solved", "only BIT* solved"],
                                 head_to_head(rows, budget))]  # fmt: skip
        deadline = max((r["time"] / budget for r in rows
                        if r["budget"] == budget and r.get("time")), default=0.0)  # fmt: skip
        lines += ["", f"Largest planning time over the budget: {deadline:.3f}."]
    lines += ["", f"Invalid paths: {len(invalid)}."]
    errors = [r for r in rows if r.get("error")]
    lines += [f"Failed runs: {len(errors)}."] + [
        f"- {r['file']} {r['planner']} {r['budget']:g} s: {r['error']}" for r in errors[:20]
    ]
    return lines


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", choices=("tuning", "report"), default="report")
    ap.add_argument("--time", type=float, nargs="+", default=[0.25, 1.0, 4.0])
    ap.add_argument("--runs", type=int, nargs="+", default=[1, 2], help="planner seeds")
    ap.add_argument("--seeds", type=int, nargs="+", help="family seeds (default: the set's)")
    ap.add_argument("--out", default="-", help="Markdown report (- prints it)")
    ap.add_argument("--rows", help="also write every run as JSON lines")
    ap.add_argument("--weight", type=float, help="cost_travel_multiplier (default: the default)")
    ap.add_argument("--no-reference", action="store_true", help="skip the grid reference")
    args = ap.parse_args(argv)
    WEIGHT[0] = args.weight
    args.argv = argv
    seeds = args.seeds or (TUNING_SEEDS if args.set == "tuning" else REPORT_SEEDS)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        files = problem_files(args.set, seeds, Path(tmp))
        for i, (family, path) in enumerate(files):
            base = {"family": family, "file": path.name,
                    **measure(path, reference=not args.no_reference)}  # fmt: skip
            print(f"[{i + 1}/{len(files)}] {path.name}", file=sys.stderr, flush=True)
            for budget in args.time:
                for seed in args.runs:
                    for planner in PLANNERS:
                        row = run_one(path, planner, budget, seed)
                        rows.append({**base, "planner": planner, "budget": budget,
                                     "seed": seed, **row})  # fmt: skip
    text = "\n".join(report(rows, args, seeds)) + "\n"
    if args.rows:
        Path(args.rows).write_text("".join(json.dumps(r) + "\n" for r in rows))
    if args.out == "-":
        print(text)
    else:
        Path(args.out).write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
