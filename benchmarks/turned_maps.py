"""What a turned map (a map YAML whose origin yaw is not 0) costs. Writes docs/turned-maps.md.

Each map problem of ``problems/maps/`` is planned as shipped and turned by 0.3 rad about its
origin (start and goal turned with it; a rotation keeps every length, so the two should agree):

- the exact checks on the warehouse (696 merged boxes): the turned boxes as the world keeps them
  (axis-aligned in the map's grid coordinates, each query turned into them) against the same
  squares as polygons in the world's coordinates, and the unturned map: the cost of one motion
  check (OMPL's callback, random segments about 1 m long), one point check, and one segment of
  the vectorised check;
- the exact optimum (``rrtpso optimum``): its time and length, unturned and turned (searched in
  grid coordinates, where the map keeps its lattice), and turned with ``unknown: free`` (the robot
  may leave the map, so the turned cells are searched as polygons);
- RRTstarPSO at 1 s, seeds 1 to 3: the median length, unturned and turned (a turned map has no
  lattice of the world's axes, so its corridor stage runs on generic cells).

One process, in-process solves; the trends are the point, not the last digit.

Usage::

    python benchmarks/turned_maps.py            # about 3 minutes; writes docs/turned-maps.md
    python benchmarks/turned_maps.py --quick    # two problems, one seed, no file written
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from rrtpso_ompl.groundtruth import shortest_path  # noqa: E402
from rrtpso_ompl.model import World, load_problem  # noqa: E402
from rrtpso_ompl.planners import solve  # noqa: E402

YAW = 0.3
NAMES = ("office_corridor", "office_rooms", "lab_clutter", "lab_diagonal", "warehouse_aisles",
         "warehouse_cross")  # fmt: skip


def turned(folder: Path, name: str, yaw: float, unknown: str = "obstacle") -> Path:
    """``problems/maps/<name>.yaml`` with its map turned by ``yaw`` about the map's origin."""
    src = REPO / "problems" / "maps" / f"{name}.yaml"
    doc = yaml.safe_load(src.read_text())
    grid_yaml = src.parent / doc["map"]
    grid = yaml.safe_load(grid_yaml.read_text())
    shutil.copy(grid_yaml.parent / grid["image"], folder / grid["image"])
    ox, oy = grid["origin"][:2]
    grid["origin"] = [ox, oy, yaw]
    (folder / f"{name}_{yaw}_map.yaml").write_text(json.dumps(grid))
    c, s = math.cos(yaw), math.sin(yaw)

    def move(p):
        dx, dy = p[0] - ox, p[1] - oy
        return [ox + c * dx - s * dy, oy + s * dx + c * dy]

    doc.update(map={"file": f"{name}_{yaw}_map.yaml", "unknown": unknown},
               start=move(doc["start"]), goal=move(doc["goal"]))  # fmt: skip
    path = folder / f"{name}_{yaw}_{unknown}.yaml"
    path.write_text(json.dumps(doc))
    return path


def per_call(fn, n: int) -> float:
    """Microseconds per call of ``fn(i)`` over ``i < n``."""
    t = time.perf_counter()
    for i in range(n):
        fn(i)
    return (time.perf_counter() - t) / n * 1e6


def checks(folder: Path) -> list[str]:
    """The check costs on the warehouse: unturned, turned boxes, turned squares as polygons."""
    flat = load_problem(REPO / "problems" / "maps" / "warehouse_aisles.yaml")
    turn = load_problem(turned(folder, "warehouse_aisles", YAW))
    m = turn.map
    worlds = {
        "unturned (boxes)": lambda: World.from_problem(flat),
        "turned: boxes in grid coordinates": lambda: World.from_problem(turn),
        "turned: squares as polygons": lambda: World(
            turn.bounds, polygons=[*m.frame.box_corners(m.boxes),
                                   *(np.asarray(p.points) for p in turn.map_outside)],
            robot_radius=turn.robot.radius),
    }  # fmt: skip
    rng = np.random.default_rng(0)
    rows = ["| world | build (s) | motion check (us) | point check (us) "
            "| vectorised (us/segment) |", "|---|---:|---:|---:|---:|"]  # fmt: skip
    for label, build in worlds.items():
        t = time.perf_counter()
        w = build()
        built = time.perf_counter() - t
        (x0, y0), (x1, y1) = w.bounds
        n = 20_000
        a = rng.uniform([x0, y0], [x1, y1], (n, 2))
        b = a + rng.normal(0.0, 1.0, (n, 2))
        motion = per_call(lambda i, a=a, b=b, w=w: w.motion_free(*a[i], *b[i]), n)
        point = per_call(lambda i, a=a, w=w: w.point_free(*a[i]), n)
        t = time.perf_counter()
        w.segments_free(a, b)
        vec = (time.perf_counter() - t) / n * 1e6
        rows.append(f"| {label} | {built:.3f} | {motion:.1f} | {point:.1f} | {vec:.1f} |")
    return rows


def optimum(folder: Path, names) -> list[str]:
    rows = ["| problem | unturned: length (s) | turned: length (s) "
            "| turned, `unknown: free`: length (s) | unturned, `unknown: free`: length |",
            "|---|---|---|---|---|"]  # fmt: skip
    for name in names:
        cells = []
        for path in (REPO / "problems" / "maps" / f"{name}.yaml", turned(folder, name, YAW),
                     turned(folder, name, YAW, "free"), turned(folder, name, 0.0, "free")):
            t = time.perf_counter()
            r = shortest_path(load_problem(path))
            cells.append(f"{r.length:.6f} ({time.perf_counter() - t:.2f})")
        cells[-1] = cells[-1].split()[0]
        rows.append(f"| {name} | " + " | ".join(cells) + " |")
    return rows


def planner(folder: Path, names, seeds) -> list[str]:
    rows = ["| problem | optimum | RRTstarPSO 1 s, unturned | RRTstarPSO 1 s, turned |",
            "|---|---:|---:|---:|"]  # fmt: skip
    for name in names:
        flat = load_problem(REPO / "problems" / "maps" / f"{name}.yaml")
        turn = load_problem(turned(folder, name, YAW))
        best = shortest_path(flat).length
        medians = []
        for p in (flat, turn):
            lengths = [solve(p, "RRTstarPSO", time_limit=1.0, seed=s).length for s in seeds]
            ok = [v for v in lengths if v is not None]
            medians.append(f"{statistics.median(ok):.2f} ({len(ok)}/{len(seeds)} solved)"
                           if ok else "none")  # fmt: skip
        rows.append(f"| {name} | {best:.2f} | {medians[0]} | {medians[1]} |")
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two problems, one seed, no file")
    args = ap.parse_args()
    names = NAMES[:1] + NAMES[2:3] if args.quick else NAMES
    seeds = (1,) if args.quick else (1, 2, 3)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        parts = [
            "## Exact checks on the warehouse (696 merged boxes)", "", *checks(folder), "",
            f"## Exact optimum, turned by {YAW} rad", "", *optimum(folder, names), "",
            f"## RRTstarPSO, turned by {YAW} rad (median of seeds {', '.join(map(str, seeds))})",
            "", *planner(folder, names, seeds), "",
        ]  # fmt: skip
    minutes = (time.perf_counter() - t0) / 60
    head = (f"# Turned maps\n\nGenerated by `python benchmarks/turned_maps.py` on "
            f"{platform.machine()}, Python {platform.python_version()}, {minutes:.1f} min. What "
            "a map whose origin yaw is not 0 costs ([problem-format.md]"
            "(problem-format.md#turned-maps)): the same problems as shipped and turned by "
            f"{YAW} rad about the map's origin, start and goal with it.\n")  # fmt: skip
    text = head + "\n" + "\n".join(parts)
    print(text)
    if not args.quick:
        (REPO / "docs" / "turned-maps.md").write_text(text)


if __name__ == "__main__":
    main()
