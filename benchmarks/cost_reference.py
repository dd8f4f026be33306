"""Measure the grid reference of the inflation objective (``rrtpso optimum --cost``) and draw the
clearance figures of docs/clearance.md.

Cases: every map problem of ``problems/maps/`` with Nav2's inflation of a TurtleBot-sized
configuration added (``inflation_radius: 1.0`` m, the default ``cost_scaling_factor`` and
``cost_travel_multiplier``), a 256 x 256-cell floor plan (``rrtpso generate rooms_map --cells
256 --size 25.6``: 0.1 m cells) and a world of shapes (``rrtpso generate rooms``, walls as
rectangles, ``inflation_radius`` 4 robot radii) at the default resolution. Each case runs in a
process of its own, so that its peak memory (``ru_maxrss``) is its own; the exact shortest path
is computed after the reference has been measured, for its ``J`` and its share of length within
the inflation radius.

Usage::

    python benchmarks/cost_reference.py    # docs/cost-reference.md, docs/img/clearance_*.png

About 4 minutes on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parent.parent
#: Nav2's inflation on a TurtleBot-sized robot (metres).
INFLATION = 1.0

#: Run in a fresh process: the reference, then (unmeasured) the exact shortest path.
CASE = """
import json, resource, sys, time
import numpy as np
from rrtpso_ompl.groundtruth import shortest_path
from rrtpso_ompl.groundtruth.costgrid import cost_reference
from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.model.objective import InflationCost

problem = load_problem(sys.argv[1])
world = World.from_problem(problem)
cpu0 = time.process_time()
ref = cost_reference(problem, world)
cpu = time.process_time() - cpu0
rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
cost = InflationCost.of(problem.robot)
exact = shortest_path(problem, world).valid_polyline(world)
with np.errstate(invalid="ignore"):
    near = [cost.near_share(world, exact), cost.near_share(world, ref.path)]
print(json.dumps({
    "name": problem.name, "resolution": ref.resolution, "coarsened": ref.coarsened,
    "nodes": ref.nodes, "free": ref.free_nodes, "edges": ref.edges, "time": ref.time,
    "cpu": cpu, "rss_mb": rss, "cost": ref.cost, "length": ref.length,
    "grid_cost": ref.grid_cost, "valid": bool(world.path_valid(ref.path)),
    "exact_length": float(np.hypot(*np.diff(exact, axis=0).T).sum()),
    "exact_cost": cost.path_cost(world, exact), "near_exact": near[0], "near_ref": near[1],
}))
"""


HEADER = ["problem", "h (m)", "nodes", "free nodes", "edges", "CPU (s)", "wall (s)",
          "peak memory (MB)", "J: reference / shortest", "length: reference / shortest",
          "within R_i (%)", "smoothing (%)", "valid"]  # fmt: skip


def rrtpso() -> list[str]:
    import shutil

    exe = shutil.which("rrtpso", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "rrtpso_ompl"]


def inflated(src: Path, dest: Path, inflation: float) -> Path:
    """A copy of a problem file with the robot's inflation, its map named by absolute path."""
    doc = yaml.safe_load(src.read_text())
    doc["robot"]["inflation_radius"] = inflation
    if "map" in doc:
        doc["map"] = str((src.parent / doc["map"]).resolve())
    dest.write_text(yaml.safe_dump(doc, sort_keys=False))
    return dest


def cases(tmp: Path) -> list[Path]:
    out = [inflated(p, tmp / p.name, INFLATION) for p in sorted((REPO / "problems" / "maps")
                                                                .glob("*.yaml"))]  # fmt: skip
    plan = tmp / "rooms_map_256.yaml"
    subprocess.run([*rrtpso(), "generate", "rooms_map", "--seed", "11", "--cells", "256",
                    "--size", "25.6", "--robot-radius", "0.2", "--out", str(plan), "-q"],
                   check=True)  # fmt: skip
    out.append(inflated(plan, plan, INFLATION))
    shapes = tmp / "rooms_7.yaml"
    subprocess.run([*rrtpso(), "generate", "rooms", "--seed", "7", "--out", str(shapes), "-q"],
                   check=True)  # fmt: skip
    radius = yaml.safe_load(shapes.read_text())["robot"]["radius"]
    out.append(inflated(shapes, shapes, 4.0 * radius))
    return out


def figures(problem_file: Path) -> None:
    """The costmap with the grid reference, and the clearance profiles of it and the exact
    shortest path, on one problem."""
    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.groundtruth.costgrid import cost_reference
    from rrtpso_ompl.model import World, load_problem
    from rrtpso_ompl.plotting import plot_clearance_profile, plot_cost_reference, save_figure

    problem = load_problem(problem_file)
    world = World.from_problem(problem)
    ref = cost_reference(problem, world)
    exact = shortest_path(problem, world).valid_polyline(world)
    img = REPO / "docs" / "img"
    save_figure(plot_cost_reference(problem, ref), img / "clearance_reference.png")
    paths = {"exact shortest path": exact, "grid reference": ref.path}
    save_figure(plot_clearance_profile(problem, paths, world), img / "clearance_profile.png")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(REPO / "docs" / "cost-reference.md"))
    ap.add_argument("--no-figures", action="store_true")
    args = ap.parse_args(argv)

    from rrtpso_ompl.harness.report import markdown_table

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        files = cases(Path(tmp))
        for f in files:
            proc = subprocess.run([sys.executable, "-c", CASE, str(f)], capture_output=True,
                                  text=True, check=True)  # fmt: skip
            r = json.loads(proc.stdout)
            print(r, file=sys.stderr)
            rows.append([
                r["name"], f"{r['resolution']:.3g}" + (" (coarsened)" if r["coarsened"] else ""),
                f"{r['nodes']:,}", f"{r['free']:,}", f"{r['edges']:,}", f"{r['cpu']:.1f}",
                f"{r['time']:.1f}", f"{r['rss_mb']:.0f}",
                f"{r['cost']:.2f} / {r['exact_cost']:.2f}",
                f"{r['length']:.2f} / {r['exact_length']:.2f}",
                f"{100 * r['near_ref']:.0f} / {100 * r['near_exact']:.0f}",
                f"{100 * (r['grid_cost'] / r['cost'] - 1):.2f}",
                "yes" if r["valid"] else "NO",
            ])  # fmt: skip
        if not args.no_figures:
            figures(next(f for f in files if f.name == "office_rooms.yaml"))
    lines = [
        "# The grid reference of the inflation objective, measured",
        "",
        f"Generated by `python benchmarks/cost_reference.py` on {platform.machine()}, Python "
        f"{platform.python_version()} (2 cores shared with other work: the CPU time is the "
        "steadier figure). Each case is `rrtpso_ompl.groundtruth.costgrid.cost_reference` at its "
        "default resolution (a map's cells; about 500,000 nodes over a world of shapes) in a "
        "process of its own; memory is that process's peak. The map problems of "
        f"`problems/maps/` get `inflation_radius: {INFLATION:g}` m (Nav2's default "
        "`cost_scaling_factor` 3 /m and Smac 2D's `cost_travel_multiplier` 2); the floor plan is "
        "`rrtpso generate rooms_map --seed 11 --cells 256 --size 25.6 --robot-radius 0.2` with "
        f"the same inflation; the shapes are `rrtpso generate rooms --seed 7` (robot radius 0.5 "
        "m) with an inflation radius of 4 robot radii.",
        "",
        "J, length and the share of length within the inflation radius are given for the "
        "reference / the exact shortest path (`rrtpso optimum`); smoothing is the reference's "
        "J gained by its shortcuts (grid path's J over the smoothed one's); valid is the exact "
        "check of the returned path.",
        "",
        markdown_table(HEADER, rows, align="-" + "r" * (len(HEADER) - 1)),
    ]
    Path(args.out).write_text("\n".join(lines) + "\n")
    print("\n".join(lines), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
