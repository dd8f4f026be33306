"""Make the occupancy-grid maps of problems/maps/ and the problems on them (seeded, so the same
files come out every time).

Three maps in ROS map_server's format, drawn the way a mapping tool leaves them (occupied 0, free
254, unknown 205; walls a few cells thick, unexplored space beyond the walls, scan speckle):

- ``office``: 30 m x 20 m at 5 cm (600 x 400 cells, PGM P5): a corridor, eight rooms with 0.9 m
  doors, desks, and an unexplored wing (unknown);
- ``warehouse``: 50 m x 85 m at 5 cm (1,000 x 1,700 cells = 1.7 million, PNG): racks in long
  rows with cross aisles, pallets, speckle from the scanner, a loading bay that was never
  mapped;
- ``lab``: 12 m x 10 m at 2.5 cm (480 x 400 cells, PNG with an alpha channel: transparent pixels
  are unknown): benches, round tables, equipment carts and chairs in clutter.

Usage::

    python benchmarks/make_maps.py   # writes problems/maps/ (maps in problems/maps/grids/)
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from PIL import Image

OUT = Path(__file__).resolve().parent.parent / "problems" / "maps"
GRIDS = OUT / "grids"  # the maps themselves, beside the problems that use them
FREE, OCC, UNK = 254, 0, 205


def _box(img, res, x0, y0, x1, y1, value=OCC):
    """Fill the cells of the rectangle [x0, x1] x [y0, y1] (metres, y up) with ``value``."""
    h = img.shape[0]
    c0, c1 = round(x0 / res), round(x1 / res)
    r0, r1 = h - round(y1 / res), h - round(y0 / res)
    img[max(r0, 0) : max(r1, 0), max(c0, 0) : max(c1, 0)] = value


def _disc(img, res, cx, cy, r, value=OCC):
    h, w = img.shape
    yy, xx = np.mgrid[0:h, 0:w]
    x = (xx + 0.5) * res
    y = (h - yy - 0.5) * res
    img[(x - cx) ** 2 + (y - cy) ** 2 <= r * r] = value


def office(rng) -> np.ndarray:
    res = 0.05
    img = np.full((400, 600), UNK, np.uint8)
    _box(img, res, 0.5, 0.5, 29.5, 19.5, FREE)  # the mapped building
    t = 0.15  # wall thickness
    for x0, y0, x1, y1 in [(0.5, 0.5, 29.5, 0.5 + t), (0.5, 19.5 - t, 29.5, 19.5),
                           (0.5, 0.5, 0.5 + t, 19.5), (29.5 - t, 0.5, 29.5, 19.5)]:  # fmt: skip
        _box(img, res, x0, y0, x1, y1)
    # Corridor between y = 8.5 and 11.5; rooms below and above, four a side.
    for y in (8.5, 11.5):
        _box(img, res, 0.5, y - t / 2, 29.5, y + t / 2)
    for k in range(1, 4):
        x = 0.5 + k * 29.0 / 4
        _box(img, res, x - t / 2, 0.5, x + t / 2, 8.5)
        _box(img, res, x - t / 2, 11.5, x + t / 2, 19.5)
    # Doors, 0.9 m, at random places along each room's corridor wall.
    for k in range(4):
        x0 = 0.5 + k * 29.0 / 4
        for y in (8.5, 11.5):
            d = x0 + rng.uniform(1.0, 29.0 / 4 - 2.0)
            _box(img, res, d, y - t, d + 0.9, y + t, FREE)
    # Desks in the rooms (not in front of doors: keep 1.2 m from the corridor walls).
    for k in range(4):
        x0 = 0.5 + k * 29.0 / 4
        for ylo, yhi in ((1.0, 7.2), (12.8, 19.0)):
            for _ in range(3):
                w, hgt = rng.uniform(1.2, 1.8), rng.uniform(0.6, 0.8)
                x = rng.uniform(x0 + 0.6, x0 + 29.0 / 4 - w - 0.6)
                y = rng.uniform(ylo, yhi - hgt)
                _box(img, res, x, y, x + w, y + hgt)
    # The east wing beyond x = 26 above the corridor was never mapped.
    _box(img, res, 26.0, 11.5 + t, 29.5 - t, 19.5 - t, UNK)
    for name in ("office_corridor", "office_rooms"):  # keep the problems' ends clear of desks
        for cx, cy in PROBLEMS[name][1:3]:
            _box(img, res, cx - 0.5, cy - 0.5, cx + 0.5, cy + 0.5, FREE)
    return img


def warehouse(rng, w_m: float = 50.0, h_m: float = 85.0, res: float = 0.05) -> np.ndarray:
    """A warehouse of ``w_m`` x ``h_m`` metres at ``res`` metres per cell; the pallets, speckle
    and unmapped bay scale with its area."""
    img = np.full((round(h_m / res), round(w_m / res)), FREE, np.uint8)
    t = 0.2
    for x0, y0, x1, y1 in [(0, 0, w_m, t), (0, h_m - t, w_m, h_m), (0, 0, t, h_m),
                           (w_m - t, 0, w_m, h_m)]:  # fmt: skip
        _box(img, res, x0, y0, x1, y1)
    # Racks: 1.1 m deep, in rows along y, 2.8 m aisles, broken by cross aisles every 14 m.
    x = 4.0
    while x + 1.1 < w_m - 4.0:
        y = 6.0
        while y < h_m - 10.0:
            length = min(12.0, h_m - 10.0 - y)
            _box(img, res, x, y, x + 1.1, y + length)
            y += length + 2.5
        x += 1.1 + 2.8
    # Pallets in the aisles and the staging area.
    area = w_m * h_m / (50.0 * 85.0)
    for _ in range(round(60 * area)):
        px, py = rng.uniform(1.0, w_m - 2.0), rng.uniform(1.0, h_m - 2.0)
        _box(img, res, px, py, px + 1.0, py + 1.2)
    # Scanner speckle: isolated occupied cells.
    n = round(700 * area)
    rows = rng.integers(0, img.shape[0], n)
    cols = rng.integers(0, img.shape[1], n)
    img[rows, cols] = OCC
    # The loading bay (north-east) was never mapped.
    _box(img, res, 0.76 * w_m, 0.87 * h_m, w_m - t, h_m - t, UNK)
    return img


def lab(rng) -> tuple[np.ndarray, np.ndarray]:
    res = 0.025
    img = np.full((400, 480), FREE, np.uint8)
    alpha = np.full(img.shape, 255, np.uint8)
    t = 0.1
    for x0, y0, x1, y1 in [(0, 0, 12, t), (0, 10 - t, 12, 10), (0, 0, t, 10), (12 - t, 0, 12, 10)]:
        _box(img, res, x0, y0, x1, y1)
    # Benches along the walls.
    _box(img, res, t, 2.0, 0.8, 8.0)
    _box(img, res, 11.2, 1.0, 12 - t, 6.0)
    _box(img, res, 3.0, 10 - t - 0.7, 9.0, 10 - t)
    # Round tables, carts and chairs in the middle (kept off start and goal corners).
    for _ in range(9):
        cx, cy = rng.uniform(2.0, 10.0), rng.uniform(1.5, 8.0)
        _disc(img, res, cx, cy, rng.uniform(0.3, 0.55))
    for _ in range(25):
        cx, cy = rng.uniform(1.5, 10.5), rng.uniform(1.0, 8.5)
        s = rng.uniform(0.2, 0.45)
        _box(img, res, cx, cy, cx + s, cy + s * rng.uniform(0.8, 1.6))
    # Behind the bench on the east wall: a storage nook nobody scanned (transparent pixels).
    rows = slice(400 - round(6.0 / res), 400 - round(1.0 / res))
    alpha[rows, round(11.2 / res) : round((12 - t) / res)] = 0
    # and a patch of glass the laser saw through, unknown as well
    alpha[400 - round(9.0 / res) : 400 - round(8.4 / res), round(5.0 / res) : round(6.5 / res)] = 0
    for cx, cy in ((0.9, 0.9), (11.0, 9.0), (1.2, 9.0), (10.8, 0.8)):
        _box(img, res, cx - 0.5, cy - 0.5, cx + 0.5, cy + 0.5, FREE)  # clear the corners
    return img, alpha


def _yaml(name: str, image: str, res: float, extra: str = "") -> str:
    return (
        f"# {name}: made by benchmarks/make_maps.py (ROS map_server format)\n"
        f"image: {image}\nresolution: {res}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        f"occupied_thresh: 0.65\nfree_thresh: 0.196\n{extra}"
    )


PROBLEMS = {
    "office_corridor": ("office.yaml", (1.5, 2.0), (22.5, 17.0), 0.25, "south room to north room"),
    "office_rooms": ("office.yaml", (2.0, 17.5), (27.5, 3.0), 0.3, "across the floor, two doors"),
    "warehouse_aisles": ("warehouse.yaml", (2.0, 2.0), (46.0, 70.0), 0.35, "through the racks"),
    "warehouse_cross": ("warehouse.yaml", (47.5, 3.0), (2.5, 82.0), 0.35, "corner to corner"),
    "lab_clutter": ("lab.yaml", (0.9, 0.9), (11.0, 9.0), 0.2, "between benches, tables and carts"),
    "lab_diagonal": ("lab.yaml", (1.2, 9.0), (10.8, 0.8), 0.15, "the other diagonal"),
}  # fmt: skip


def main() -> int:
    GRIDS.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(20261124)
    img = office(rng)
    with open(GRIDS / "office.pgm", "wb") as fh:
        fh.write(b"P5\n# CREATOR: rrtpso-ompl make_maps.py 0.050 m/pix\n600 400\n255\n")
        fh.write(img.tobytes())
    (GRIDS / "office.yaml").write_text(_yaml("office", "office.pgm", 0.05))
    Image.fromarray(warehouse(rng), mode="L").save(GRIDS / "warehouse.png", optimize=True)
    text = _yaml("warehouse", "warehouse.png", 0.05, "mode: trinary\n")
    (GRIDS / "warehouse.yaml").write_text(text)
    grey, alpha = lab(rng)
    Image.fromarray(np.dstack([grey, alpha]), mode="LA").save(GRIDS / "lab.png", optimize=True)
    (GRIDS / "lab.yaml").write_text(_yaml("lab", "lab.png", 0.025))
    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.model import load_problem

    for name, (mp, start, goal, radius, what) in PROBLEMS.items():
        body = (
            f"name: {name}\ndescription: {what} ({mp[:-5]} map)\nmap: grids/{mp}\n"
            f"start: [{start[0]}, {start[1]}]\ngoal: [{goal[0]}, {goal[1]}]\n"
            f"robot:\n  radius: {radius}\n  wheel_radius: 0.05\n  track_width: 0.3\n"
            f"  speed: 0.5\n  sample_time: 0.1\n"
            f"planner:\n  time_limit: 2.0\n  seed: 1\n"
        )
        path = OUT / f"{name}.yaml"
        path.write_text(body)
        best = shortest_path(load_problem(path))
        path.write_text(
            f"# Made by benchmarks/make_maps.py. Shortest collision-free path: "
            f"{best.length:.4f} m\n# exactly (`rrtpso optimum`; straight line "
            f"{math.dist(start, goal):.2f} m).\n{body}"
        )
    print(f"wrote {OUT}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
