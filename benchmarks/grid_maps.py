"""MovingAI-like occupancy grids for benchmarks: mazes and city blocks (True = blocked, image
order, row 0 on top), written as map_server maps, with point-to-point queries.

A lab generator kept beside the benchmarks that use it (``benchmarks/optimum_scaling.py``); every
draw comes from the ``numpy.random.Generator`` it is given, so a seed gives the same map.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy import ndimage

__all__ = ["KINDS", "city", "maze", "queries", "rooms", "write_map"]


def maze(rng: np.random.Generator, size: int = 128, corridor: int = 2, wall: int = 1):
    """A perfect maze (depth-first) of corridors ``corridor`` cells wide between walls ``wall``
    cells thick, filling a ``size`` x ``size`` grid."""
    step = corridor + wall
    n = (size - wall) // step
    g = np.ones((n * step + wall, n * step + wall), bool)
    seen = np.zeros((n, n), bool)
    stack = [(0, 0)]
    seen[0, 0] = True
    g[wall : wall + corridor, wall : wall + corridor] = False
    while stack:
        i, j = stack[-1]
        nb = [(i + di, j + dj) for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0))
              if 0 <= i + di < n and 0 <= j + dj < n and not seen[i + di, j + dj]]  # fmt: skip
        if not nb:
            stack.pop()
            continue
        a, b = nb[rng.integers(len(nb))]
        seen[a, b] = True
        g[wall + a * step : wall + a * step + corridor,
          wall + b * step : wall + b * step + corridor] = False  # fmt: skip
        r0, c0 = wall + min(i, a) * step, wall + min(j, b) * step
        if a != i:
            g[r0 + corridor : r0 + step, c0 : c0 + corridor] = False
        else:
            g[r0 : r0 + corridor, c0 + corridor : c0 + step] = False
        stack.append((a, b))
    out = np.ones((size, size), bool)
    out[: g.shape[0], : g.shape[1]] = g
    return out


def rooms(rng: np.random.Generator, size: int = 128, room: int = 32, door=(2, 5), extra=0.5):
    """Square rooms of ``room`` cells behind one-cell walls, joined by doors (a spanning tree of
    the rooms, plus a door in each other wall with probability ``extra``)."""
    g = np.zeros((size, size), bool)
    g[::room, :] = True
    g[:, ::room] = True
    g[-1, :] = g[:, -1] = g[0, :] = g[:, 0] = True
    n = size // room
    walls = [(i, j, i + 1, j) for i in range(n - 1) for j in range(n)]
    walls += [(i, j, i, j + 1) for i in range(n) for j in range(n - 1)]
    order = rng.permutation(len(walls))
    parent = list(range(n * n))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for k in order:
        i, j, a, b = walls[k]
        ra, rb = find(i * n + j), find(a * n + b)
        if ra != rb or rng.random() < extra:
            parent[ra] = rb
            w = min(int(rng.integers(door[0], door[1] + 1)), room - 2)
            off = int(rng.integers(1, room - w))
            if a != i:
                g[(i + 1) * room, j * room + off : j * room + off + w] = False
            else:
                g[i * room + off : i * room + off + w, (j + 1) * room] = False
    return g


def city(rng: np.random.Generator, size: int = 128, street=(2, 6), min_block: int = 10):
    """City blocks cut by streets (recursive splits), with courtyards and gaps, and most often a
    diagonal avenue across them."""
    g = np.zeros((size, size), bool)

    def split(r0, c0, r1, c1, depth):
        h, w = r1 - r0, c1 - c0
        if (h < 2 * min_block and w < 2 * min_block) or depth > 8:
            b = np.ones((h, w), bool)
            for _ in range(int(rng.integers(0, 3))):
                rr = int(rng.integers(0, max(1, h - 2)))
                cc = int(rng.integers(0, max(1, w - 2)))
                b[rr : rr + int(rng.integers(1, 4)),
                  cc : cc + int(rng.integers(2, max(3, w // 2)))] = False  # fmt: skip
            g[r0:r1, c0:c1] = b
            return
        s = int(rng.integers(street[0], street[1] + 1))
        if h > w:
            cut = int(rng.integers(r0 + min_block, max(r0 + min_block + 1, r1 - min_block - s)))
            split(r0, c0, cut, c1, depth + 1)
            split(cut + s, c0, r1, c1, depth + 1)
        else:
            cut = int(rng.integers(c0 + min_block, max(c0 + min_block + 1, c1 - min_block - s)))
            split(r0, c0, r1, cut, depth + 1)
            split(r0, cut + s, r1, c1, depth + 1)

    m = int(rng.integers(2, 5))
    split(m, m, size - m, size - m, 0)
    if rng.random() < 0.7:
        yy, xx = np.mgrid[0:size, 0:size]
        a, c = rng.uniform(0.3, 1.2), rng.uniform(-0.3, 0.3) * size
        g[np.abs(yy - a * xx - c) / np.hypot(1, a) < rng.uniform(1.5, 3.5)] = False
    return g


KINDS = {
    "city": (city, {}),
    "rooms": (rooms, {"room": 32}),
    "maze-1": (maze, {"corridor": 1, "wall": 1}),
    "maze-4": (maze, {"corridor": 4, "wall": 1}),
}


def write_map(blocked: np.ndarray, folder: Path, name: str, res: float = 1.0) -> Path:
    """``name.pgm`` and ``name.yaml`` (map_server) in ``folder``; returns the YAML."""
    folder.mkdir(parents=True, exist_ok=True)
    h, w = blocked.shape
    img = np.where(blocked, 0, 254).astype(np.uint8)
    (folder / f"{name}.pgm").write_bytes(f"P5\n{w} {h}\n255\n".encode() + img.tobytes())
    path = folder / f"{name}.yaml"
    path.write_text(f"image: {name}.pgm\nresolution: {res}\norigin: [0.0, 0.0, 0.0]\n")
    return path


Query = tuple[tuple[float, float], tuple[float, float]]


def queries(rng: np.random.Generator, blocked: np.ndarray, n: int, radius_cells: float = 0.0,
            min_frac: float = 0.4) -> list[Query]:  # fmt: skip
    """``n`` start-goal pairs of cell centres in the largest 4-connected region with room for the
    robot, at least ``min_frac`` of the map's side apart (problem coordinates, 1 unit a cell)."""
    free = ~blocked
    if radius_cells > 0:
        free = ndimage.distance_transform_edt(free) > radius_cells + 0.71
    lab, k = ndimage.label(free)
    if k == 0:
        return []
    sizes = ndimage.sum(np.ones_like(lab), lab, range(1, k + 1))
    cells = np.argwhere(lab == int(np.argmax(sizes)) + 1)
    h = blocked.shape[0]
    out = []
    for _ in range(200 * n):
        if len(out) == n:
            break
        a, b = cells[rng.integers(len(cells), size=2)]
        if np.hypot(*(a - b)) >= min_frac * h:
            out.append(((a[1] + 0.5, h - a[0] - 0.5), (b[1] + 0.5, h - b[0] - 0.5)))
    return out
