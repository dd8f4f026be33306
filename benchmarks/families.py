"""Tune on some problems, report on others: RRTstarPSO against BIT* with OMPL's simplifier, with
and without the swarm post-pass, on seeded generated families (shapes and occupancy-grid maps)
and on the library, path length over the exact optimum.

The protocol (docs/benchmarking.md, "Tuning and reporting"):

- **tuning set**: the families below with seeds 1-3, and the tuning part of ``problems/``
  (:data:`TUNING_FILES`); defaults were chosen on these only;
- **report set**: the same families with fresh seeds (101-103 unless ``--seeds``), never used in
  tuning, and the rest of ``problems/`` (static and maps).

Every planner runs through the same :func:`rrtpso_ompl.planners.solve` as ``rrtpso solve``, each
run in a child process of its own (``fork`` before any OMPL object exists, so that OMPL is seeded
once per run as ``rrtpso solve`` seeds it), one at a time (timing is measured). The exact
optimum of each problem is computed once, then every budget of ``--time`` runs on it.

Usage::

    python benchmarks/families.py --set report --time 0.25 1 4 --out docs/families.md
    python benchmarks/families.py --set tuning --time 1 --out -    # print only
    python benchmarks/families.py --set tuning --param corridor_fraction=0.4  # a variant
    python benchmarks/families.py --set report --time 0.25 1 4 --planners RRTstarPSO \
        --families circles --merge docs/families.jsonl --rows docs/families.jsonl \
        --out docs/families.md                                    # re-run some rows only
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

#: Generated shape families: ``rrtpso generate`` kind and options.
SHAPE_FAMILIES = {
    "circles": ("circles", {}),
    "circles_point": ("circles", {"n": 70, "radius_range": (1.0, 6.0), "robot_radius": 0.0}),
    "polygons": ("polygons", {}),
    "maze": ("maze", {}),
    # Corridors 1.3 % of the width (8.33 - 7), a point robot, one solution.
    "maze_narrow": ("maze", {"cells": 12, "robot_radius": 0.0, "wall": 7.0}),
    "slabs": ("slabs", {}),
    "combs": ("combs", {}),
    "spiral": ("spiral", {}),
    "rooms": ("rooms", {}),
}
#: Generated occupancy-grid map families (ROS map_server YAML + PGM), two queries per map. Mazes,
#: random fields, caves and cities with a point robot on the grid, as MovingAI's grid benchmarks
#: pose them; rooms, warehouses and wide mazes with the generator's robot (a quarter cell).
MAP_FAMILIES = {
    "rooms_map": ("rooms_map", {"cells": 128}),
    "maze_map_c1": ("maze_map", {"cells": 128, "corridor": 1, "wall_cells": 1, "robot_radius": 0}),
    "maze_map_c2": ("maze_map", {"cells": 128, "corridor": 2, "loops": 0.1, "robot_radius": 0}),
    "maze_map_c4_256": ("maze_map", {"cells": 256, "corridor": 4, "wall_cells": 2}),
    "city_map_256": ("city_map", {"cells": 256, "robot_radius": 0}),
    "warehouse_map": ("warehouse_map", {"cells": 128}),
    "caves_map": ("caves_map", {"cells": 128, "robot_radius": 0}),
    "random_map_256": ("random_map", {"cells": 256, "density": 0.3, "robot_radius": 0}),
}
QUERIES = (0, 1)
TUNING_SEEDS = (1, 2, 3)
REPORT_SEEDS = (101, 102, 103)
#: The part of problems/ the defaults were tuned on; the rest is for reporting.
TUNING_FILES = (
    "static/paper_static.yaml",
    "static/single_circle.yaml",
    "static/narrow_passage.yaml",
    "static/cluttered_circles.yaml",
    "static/polygon_map.yaml",
    "static/dense_circles.yaml",
    "static/maze.yaml",
    "static/bug_trap.yaml",
)
PLANNERS = ("RRTstarPSO", "BITstar+simplify", "BITstar+simplify+pso")


def problem_files(which: str, seeds, folder: Path, only=None) -> list[tuple[str, Path]]:
    """``(family, problem file)`` of the set: generated into ``folder``, then the library's part."""
    from rrtpso_ompl.groundtruth.generate import GENERATORS, generate_to_file

    out = []
    for family, (kind, options) in {**SHAPE_FAMILIES, **MAP_FAMILIES}.items():
        if (only and family not in only) or kind not in GENERATORS:
            continue
        queries = QUERIES if family in MAP_FAMILIES else (None,)
        for seed in seeds:
            for q in queries:
                extra = {} if q is None else {"query": q}
                path = folder / f"{family}_{seed}{'' if q is None else f'_q{q}'}.yaml"
                generate_to_file(kind, seed, path, **options, **extra)
                out.append((family, path))
    library = sorted(REPO.glob("problems/static/*.yaml")) + sorted(
        REPO.glob("problems/maps/*.yaml")
    )
    for path in library if not only or "library" in only else []:
        rel = str(path.relative_to(REPO / "problems"))
        if (rel in TUNING_FILES) == (which == "tuning"):
            out.append(("library", path))
    return out


def in_child(work, failed: dict) -> dict:
    """``work()`` (a row) in a forked child, so that OMPL is seeded once in it as in ``rrtpso
    solve``; an exception is ``failed`` with its ``error``, a dead child says so."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(r)
        try:
            row = work()
        except Exception as exc:  # a failed run is a row, not the end of the benchmark
            row = {**failed, "error": f"{type(exc).__name__}: {exc}"}
        os.write(w, json.dumps(row).encode())
        os._exit(0)
    os.close(w)
    with os.fdopen(r) as f:
        text = f.read()
    os.waitpid(pid, 0)
    return json.loads(text) if text else {"solved": False, "error": "the child died"}


def run_one(path: Path, planner: str, budget: float, seed: int, params: dict) -> dict:
    """One ``solve`` in a child process of its own; its row."""

    def work() -> dict:
        from rrtpso_ompl.model import World, load_problem
        from rrtpso_ompl.ompl_setup import set_ompl_log_level
        from rrtpso_ompl.planners import solve

        set_ompl_log_level(0)
        problem = load_problem(path)
        world = World.from_problem(problem)
        res = solve(problem, planner, time_limit=budget, seed=seed,
                    params=params if planner == "RRTstarPSO" else None, world=world)  # fmt: skip
        valid = bool(res.solved and world.path_valid(__import__("numpy").array(res.path)))
        return {"solved": bool(res.solved), "valid": valid, "length": res.length,
                "time": res.time}  # fmt: skip

    return in_child(work, {"solved": False, "valid": False, "length": None, "time": None})


def percentile(values: list[float], q: float) -> float:
    """The ``q`` quantile by the nearest rank (no interpolation between runs)."""
    vals = sorted(values)
    return vals[min(len(vals) - 1, round(q * (len(vals) - 1)))]


def summary(rows: list[dict], budget: float, planners) -> tuple[list[list], list[str]]:
    """Per family: median (p90) of length over the optimum and unsolved runs, per planner; and
    the families where RRTstarPSO is behind a stock spec in median or p90."""
    families = list(dict.fromkeys(r["family"] for r in rows))
    table, behind = [], []
    for fam in families:
        cells, stats = [], {}
        for planner in planners:
            mine = [
                r
                for r in rows
                if (r["family"], r["planner"], r["budget"]) == (fam, planner, budget)
            ]
            vals = [r["ratio"] for r in mine if r.get("ratio") is not None]
            miss = len(mine) - len(vals)
            if not vals:
                cells.append(f"unsolved x{miss}")
                stats[planner] = (float("inf"), float("inf"), miss)
                continue
            med, p90 = statistics.median(vals), percentile(vals, 0.9)
            stats[planner] = (med, p90, miss)
            cells.append(f"{med:.4f} ({p90:.4f})" + (f", {miss} unsolved" if miss else ""))
        ours = stats.get("RRTstarPSO")
        worse = [
            p
            for p, s in stats.items()
            if p != "RRTstarPSO"
            and ours
            and (ours[2] > s[2] or ours[0] > s[0] + 1e-4 or ours[1] > s[1] + 1e-4)
        ]
        if worse:
            behind.append(f"{fam} ({', '.join(worse)})")
        overrun = max(
            (
                r["time"] / budget
                for r in rows
                if r["family"] == fam
                and r["budget"] == budget
                and r["planner"] == "RRTstarPSO"
                and r.get("time")
            ),
            default=0.0,
        )
        table.append([fam, *cells, f"{overrun:.3f}"])
    return table, behind


def report(rows: list[dict], args, seeds, planners) -> list[str]:
    from rrtpso_ompl.harness.report import markdown_table

    command = "python benchmarks/families.py " + " ".join(args.argv)
    lines = [
        f"# RRTstarPSO on the {args.set} set",
        "",
        f"Generated by `{command}` on {platform.machine()}, Python "
        f"{platform.python_version()}: family seeds {', '.join(map(str, seeds))} (maps: "
        f"queries {', '.join(map(str, QUERIES))} of each), planner seeds "
        f"{', '.join(map(str, args.runs))}, one run at a time, each in a process of its own. "
        "Median (and 90th percentile) of path length over the exact optimum; every path was "
        "checked valid with the exact checker. The library rows are the "
        f"{args.set} part of problems/ (see docs/benchmarking.md). *Deadline*: RRTstarPSO's "
        "largest planning time over the budget."
        + (f" Runs of {', '.join(args.families or ['every family'])} by "
           f"{args.planners.replace(',', ', ')} from this command; the others kept from "
           f"`{args.merge}`'s earlier run." if args.merge else ""),
    ]
    for budget in args.time:
        table, behind = summary(rows, budget, planners)
        lines += [
            "",
            f"## {budget:g} s",
            "",
            markdown_table(["family", *planners, "deadline"], table),
            "",
            "RRTstarPSO behind in median, 90th percentile or solved runs: "
            + ("; ".join(behind) if behind else "nowhere")
            + ".",
        ]
    return lines + footer(rows)


def merged(earlier: Path, rows: list[dict]) -> tuple[list[dict], list[str]]:
    """The runs of ``earlier`` (JSON lines) with those ``rows`` repeat replaced, in their order,
    and ``rows``' others after them; the planners of both, in :data:`PLANNERS`' order."""

    def key(r: dict) -> tuple:
        return r["file"], r["planner"], r["budget"], r.get("seed", 1)

    new = {key(r): r for r in rows}
    old = [json.loads(line) for line in earlier.read_text().splitlines() if line.strip()]
    out = [new.pop(key(r), r) for r in old]
    out += [r for r in rows if key(r) in new]
    named = {r["planner"] for r in out}
    return out, [p for p in PLANNERS if p in named] + sorted(named - set(PLANNERS))


def footer(rows: list[dict]) -> list[str]:
    """A report's last lines: invalid paths and failed runs (the first 20 named)."""
    invalid = [r for r in rows if r.get("solved") and not r.get("valid")]
    errors = [r for r in rows if r.get("error")]
    return ["", f"Invalid paths: {len(invalid)}.", f"Failed runs: {len(errors)}."] + [
        f"- {r['file']} {r['planner']} {r['budget']:g} s: {r['error']}" for r in errors[:20]
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", choices=("tuning", "report"), default="report")
    ap.add_argument("--time", type=float, nargs="+", default=[1.0], help="budgets, s")
    ap.add_argument("--runs", type=int, nargs="+", default=[1], help="planner seeds")
    ap.add_argument("--seeds", type=int, nargs="+", help="family seeds")
    ap.add_argument("--param", action="append", default=[], help="RRTstarPSO NAME=VALUE")
    ap.add_argument("--planners", default=",".join(PLANNERS))
    ap.add_argument("--families", nargs="+", help="only these families (or library)")
    ap.add_argument("--out", default="-", help="markdown file to write (default: print)")
    ap.add_argument("--rows", help="JSON lines of every run, to write")
    ap.add_argument("--merge", help="JSON lines of an earlier run: its runs this one does not "
                    "repeat are kept, in rows and report (re-run a planner or family after a "
                    "change)")
    args = ap.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else argv

    # Loaded once here, used only in the children: importing OMPL starts no random stream, so
    # each forked run still seeds its own (docs: "forking after OMPL was used").
    import rrtpso_ompl.planners  # noqa: F401
    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.harness.report import write_markdown
    from rrtpso_ompl.model import World, load_problem

    params = dict(p.split("=", 1) for p in args.param)
    planners = args.planners.split(",")
    seeds = args.seeds or (TUNING_SEEDS if args.set == "tuning" else REPORT_SEEDS)
    rows: list[dict] = []
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for family, path in problem_files(args.set, seeds, Path(tmp), args.families):
            problem = load_problem(path)
            best = shortest_path(problem, World.from_problem(problem)).length
            for budget in args.time:
                for planner in planners:
                    for run in args.runs:
                        row = run_one(path, planner, budget, run, params)
                        length = row.get("length")
                        row.update(
                            family=family,
                            file=path.name,
                            planner=planner,
                            budget=budget,
                            seed=run,
                            optimum=best,
                            ratio=length / best if row["valid"] and best else None,
                        )
                        rows.append(row)
            print(f"{path.name} done ({time.perf_counter() - t_start:.0f} s)", file=sys.stderr)
    if args.merge:
        rows, planners = merged(Path(args.merge), rows)
    if args.rows:
        Path(args.rows).write_text("".join(json.dumps(r) + "\n" for r in rows))
    write_markdown(report(rows, args, seeds, planners), args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
