"""Generated occupancy-grid maps that look like real ones (``rrtpso generate rooms_map``, ...).

Six kinds, each a ROS map_server map (:mod:`rrtpso_ompl.model.occupancy`: a YAML file and an 8-bit
PGM, free 254, occupied 0) with a problem on it:

* ``rooms_map``: an office or home floor plan: rooms of random sizes joined by doors over a
  spanning tree plus extra doors, walls a few cells thick, furniture against the walls
  (:class:`RoomsMapOptions`);
* ``maze_map``: a maze carved on corridors ``corridor`` cells wide between walls ``wall_cells``
  thick, perfect or braided (:class:`MazeMapOptions`);
* ``city_map``: blocks between streets of several widths, built up with buildings, alleys,
  courtyards and setbacks, open squares, sometimes a diagonal avenue (:class:`CityMapOptions`);
* ``warehouse_map``: rows of racks between aisles, cross aisles lined up across the rows, a
  loading area with pallets (:class:`WarehouseMapOptions`);
* ``caves_map``: cellular-automaton caves, the largest open region kept (:class:`CavesMapOptions`);
* ``random_map``: random blocked cells at a density (:class:`RandomMapOptions`).

Each kind is its options (a :class:`~.map_problem.MapKindOptions`) and the function drawing its
cells (True blocked, image order, every loop bounded by the map's size); what they share, the
query on the map and its certificate, is :mod:`.map_problem`'s, the files :mod:`.map_files`'.

The map is ``cells x cells`` cells over the workspace ``[0, size]^2`` (cell side ``size /
cells``, units m) and depends on the seed only; start and goal are drawn on it from a second
stream (``query``), and certified (:mod:`.map_problem`).

**Python API.** :func:`~rrtpso_ompl.groundtruth.generate.generate` returns the problem dictionary
(its ``map`` the relative name ``<name>_map.yaml``);
:func:`~rrtpso_ompl.groundtruth.generate.generate_map` returns a :class:`GeneratedMap`: that
dictionary, the image and the map YAML dictionary, which :meth:`GeneratedMap.write` writes (the
problem file, ``<stem>_map.yaml`` and ``<stem>_map.pgm`` beside it, all or nothing).
:func:`~rrtpso_ompl.groundtruth.generate.generate_to_file` does both.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from scipy import ndimage

from ..errors import GenerationError
from ..params import Rule, declared, param
from .kinds import register_kind
from .map_files import GeneratedMap, map_output_paths
from .map_problem import MAX_MAP_CELLS, MapKindOptions

__all__ = [
    "MAX_MAP_CELLS",
    "CavesMapOptions",
    "CityMapOptions",
    "GeneratedMap",
    "MapKindOptions",
    "MazeMapOptions",
    "RandomMapOptions",
    "RoomsMapOptions",
    "WarehouseMapOptions",
    "map_output_paths",
]


# ----------------------------------------------------------------------------------------------
# The kinds
# ----------------------------------------------------------------------------------------------
def _range_rule(name: str, low: int) -> Rule:
    return Rule((name,), lambda v: low <= v[0] <= v[1], f"{low} <= {name} min <= max")


@register_kind
@declared(rules=(_range_rule("room", 4), _range_rule("door", 1)))
class RoomsMapOptions(MapKindOptions):
    """Rooms joined by doors: an office or home floor plan (``rrtpso generate rooms_map``)."""

    KIND: ClassVar[str] = "rooms_map"

    room: tuple[int, int] = param((14, 26), "Least and largest room side, cells.", low=4,
                                  high=MAX_MAP_CELLS)  # fmt: skip
    door: tuple[int, int] = param((2, 5), "Least and largest door width, cells.", low=1,
                                  high=MAX_MAP_CELLS)  # fmt: skip
    wall_cells: int = param(2, "Wall thickness, cells.", low=1, high=64)
    extra_doors: float = param(
        0.3,
        "Share of the walls between two rooms that get a door beyond those of a spanning tree "
        "(0: one route between any two rooms).",
        low=0.0,
        high=1.0,
    )
    clutter: float = param(
        2.0, "Furniture against the walls: pieces per room (never in front of a door).",
        low=0.0, high=10.0,
    )  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _rooms(rng, self.cells, self.room, self.door, self.wall_cells, self.extra_doors,
                      self.clutter)  # fmt: skip

    def what(self) -> str:
        return (
            f"A floor plan: rooms {self.room[0]}-{self.room[1]} cells a side, walls "
            f"{self.wall_cells} cells thick, doors {self.door[0]}-{self.door[1]} cells wide over a "
            f"spanning tree plus {self.extra_doors:.0%} extra doors, {self.clutter:g} pieces of "
            "furniture per room against the walls."
        )


@register_kind
@declared
class MazeMapOptions(MapKindOptions):
    """A maze of corridors ``corridor`` cells wide (``rrtpso generate maze_map``)."""

    KIND: ClassVar[str] = "maze_map"

    corridor: int = param(2, "Corridor width, cells.", low=1, high=256)
    wall_cells: int = param(1, "Wall thickness, cells.", low=1, high=64)
    loops: float = param(
        0.0,
        "Share of the walls left after carving that are opened too (0: a perfect maze, one "
        "route between any two places; more: a braid maze with several routes).",
        low=0.0,
        high=1.0,
    )

    def resolved(self) -> MazeMapOptions:
        if self.corridor + 2 * self.wall_cells > self.cells:
            raise GenerationError(
                f"corridor + 2 wall_cells ({self.corridor + 2 * self.wall_cells}) must be at most "
                f"cells ({self.cells})"
            )
        return super().resolved()

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _maze(rng, self.cells, self.corridor, self.wall_cells, self.loops)

    def what(self) -> str:
        kind = (
            "A perfect maze"
            if self.loops == 0
            else f"A braid maze ({self.loops:.0%} extra openings)"
        )
        return (
            f"{kind} carved by randomised depth-first search: corridors {self.corridor} cells "
            f"wide, walls {self.wall_cells} cells thick."
        )


@register_kind
@declared(rules=(_range_rule("street", 1), _range_rule("block", 6)))
class CityMapOptions(MapKindOptions):
    """City blocks between streets (``rrtpso generate city_map``; like MovingAI's city maps)."""

    KIND: ClassVar[str] = "city_map"

    street: tuple[int, int] = param((2, 6), "Least and largest street width, cells.", low=1,
                                    high=MAX_MAP_CELLS)  # fmt: skip
    block: tuple[int, int] = param((12, 30), "Least and largest block side, cells.", low=6,
                                   high=MAX_MAP_CELLS)  # fmt: skip
    plazas: float = param(0.08, "Chance that a block is an open square.", low=0.0, high=1.0)
    avenue: float = param(0.6, "Chance of a diagonal avenue across the city.", low=0.0, high=1.0)

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _city(rng, self.cells, self.street, self.block, self.avenue, self.plazas)

    def what(self) -> str:
        return (
            f"A city: blocks {self.block[0]}-{self.block[1]} cells a side between streets "
            f"{self.street[0]}-{self.street[1]} cells wide (recursive splits), buildings with "
            f"alleys, courtyards and setbacks, {self.plazas:.0%} of the blocks open squares, a "
            f"diagonal avenue with chance {self.avenue:g}."
        )


@register_kind
@declared(rules=(_range_rule("aisle", 1), _range_rule("run", 2), _range_rule("cross", 1)))
class WarehouseMapOptions(MapKindOptions):
    """Racks between aisles (``rrtpso generate warehouse_map``)."""

    KIND: ClassVar[str] = "warehouse_map"

    rack: int = param(2, "Rack depth, cells.", low=1, high=64)
    aisle: tuple[int, int] = param((3, 5), "Least and largest aisle width, cells.", low=1,
                                   high=MAX_MAP_CELLS)  # fmt: skip
    run: tuple[int, int] = param((16, 30), "Least and longest rack run between cross aisles, "
                                 "cells.", low=2, high=MAX_MAP_CELLS)  # fmt: skip
    cross: tuple[int, int] = param((3, 5), "Least and largest cross-aisle width, cells.", low=1,
                                   high=MAX_MAP_CELLS)  # fmt: skip
    pallets: float = param(0.003, "Pallets (2 x 2 cells) in the loading area per map cell.",
                           low=0.0, high=0.05)  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _warehouse(rng, self.cells, self.rack, self.aisle, self.run, self.cross,
                          self.pallets)  # fmt: skip

    def what(self) -> str:
        return (
            f"A warehouse: racks {self.rack} cells deep in runs of {self.run[0]}-{self.run[1]} "
            f"cells between aisles {self.aisle[0]}-{self.aisle[1]} cells wide, cross aisles "
            f"{self.cross[0]}-{self.cross[1]} cells wide lined up across the rows, a loading "
            "area with pallets along the top."
        )


@register_kind
@declared
class CavesMapOptions(MapKindOptions):
    """Cellular-automaton caves (``rrtpso generate caves_map``; game levels)."""

    KIND: ClassVar[str] = "caves_map"

    fill: float = param(0.45, "Share of cells blocked before smoothing.", low=0.0, high=0.9)
    steps: int = param(5, "Smoothing steps (a cell is blocked when 5 of its 3 x 3 are).", low=0,
                       high=50)  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _caves(rng, self.cells, self.fill, self.steps)

    def what(self) -> str:
        return (
            f"Caves: cells blocked with chance {self.fill:g}, smoothed {self.steps} times by the "
            "5-of-9 rule, only the largest open region kept."
        )


@register_kind
@declared
class RandomMapOptions(MapKindOptions):
    """Random blocked cells (``rrtpso generate random_map``; MovingAI's random maps)."""

    KIND: ClassVar[str] = "random_map"

    density: float = param(0.2, "Share of cells blocked, each independently.", low=0.0,
                           high=0.9)  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return rng.random((self.cells, self.cells)) < self.density

    def what(self) -> str:
        return f"Random cells, each blocked with chance {self.density:g}."


# ----------------------------------------------------------------------------------------------
# Drawing (True blocked, image order); every loop bounded by the map's size
# ----------------------------------------------------------------------------------------------
def _border(g: np.ndarray, t: int = 1) -> np.ndarray:
    g[:t, :] = g[-t:, :] = g[:, :t] = g[:, -t:] = True
    return g


def _spans(rng: np.random.Generator, total: int, lo: int, hi: int) -> list[int]:
    """Sizes drawn from ``[lo, hi]`` that sum to ``total`` (the last absorbs the rest, merged
    into its neighbour when below ``lo``)."""
    sizes: list[int] = []
    left = total
    while left > 0 and len(sizes) < total:
        s = int(rng.integers(lo, hi + 1))
        if left - s < lo:
            s = left
        sizes.append(s)
        left -= s
    return sizes


def _union_find(n: int):
    parent = list(range(n))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    return parent, find


def _maze(rng: np.random.Generator, size: int, corridor: int, wall: int, loops: float):
    step = corridor + wall
    n = max((size - wall) // step, 1)
    g = np.ones((size, size), dtype=bool)
    for i in range(n):
        for j in range(n):
            r, c = wall + i * step, wall + j * step
            g[r : r + corridor, c : c + corridor] = False

    def link(i: int, j: int, a: int, b: int) -> None:
        r, c = wall + min(i, a) * step, wall + min(j, b) * step
        if a != i:
            g[r + corridor : r + step, c : c + corridor] = False
        else:
            g[r : r + corridor, c + corridor : c + step] = False

    seen = np.zeros((n, n), dtype=bool)
    linked: set[tuple[int, int, int, int]] = set()
    i0, j0 = int(rng.integers(n)), int(rng.integers(n))
    seen[i0, j0] = True
    stack = [(i0, j0)]
    for _ in range(2 * n * n):  # each cell is pushed once and popped once
        if not stack:
            break
        i, j = stack[-1]
        nb = [(i + di, j + dj) for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0))
              if 0 <= i + di < n and 0 <= j + dj < n and not seen[i + di, j + dj]]  # fmt: skip
        if not nb:
            stack.pop()
            continue
        a, b = nb[int(rng.integers(len(nb)))]
        seen[a, b] = True
        link(i, j, a, b)
        linked.add((min(i, a), min(j, b), max(i, a), max(j, b)))
        stack.append((a, b))
    if loops > 0:  # open walls the tree left: a braid maze with several routes
        walls = [(i, j, i + 1, j) for i in range(n - 1) for j in range(n)]
        walls += [(i, j, i, j + 1) for i in range(n) for j in range(n - 1)]
        rest = [w for w in walls if w not in linked]
        opened = rng.random(len(rest)) < loops
        for w, o in zip(rest, opened.tolist(), strict=True):
            if o:
                link(*w)
    return g


def _rooms(rng, size: int, room, door, wall: int, extra: float, clutter: float):
    g = np.zeros((size, size), dtype=bool)
    inner = size - wall
    heights = _spans(rng, inner, room[0] + wall, room[1] + wall)
    widths = _spans(rng, inner, room[0] + wall, room[1] + wall)
    rows = np.concatenate([[0], np.cumsum(heights)])  # wall k starts at rows[k]
    cols = np.concatenate([[0], np.cumsum(widths)])
    for r in rows:
        g[r : r + wall, :] = True
    for c in cols:
        g[:, c : c + wall] = True
    _border(g, wall)
    nr, nc = len(heights), len(widths)
    keep = np.zeros_like(g)  # in front of doors: no furniture
    walls = [(i, j, i + 1, j) for i in range(nr - 1) for j in range(nc)]
    walls += [(i, j, i, j + 1) for i in range(nr) for j in range(nc - 1)]
    parent, find = _union_find(nr * nc)
    for k in rng.permutation(len(walls)).tolist():
        i, j, a, b = walls[k]
        ra, rb = find(i * nc + j), find(a * nc + b)
        if ra == rb and rng.random() >= extra:
            continue
        parent[ra] = rb
        if a != i:  # a door in the horizontal wall below room (i, j)
            lo, hi = cols[j] + wall, cols[j + 1]
        else:  # in the vertical wall right of it
            lo, hi = rows[i] + wall, rows[i + 1]
        w = min(int(rng.integers(door[0], door[1] + 1)), hi - lo)
        off = lo + int(rng.integers(0, hi - lo - w + 1))
        reach = w + 2
        if a != i:
            r = rows[i + 1]
            g[r : r + wall, off : off + w] = False
            keep[max(r - reach, 0) : r + wall + reach, max(off - 1, 0) : off + w + 1] = True
        else:
            c = cols[j + 1]
            g[off : off + w, c : c + wall] = False
            keep[max(off - 1, 0) : off + w + 1, max(c - reach, 0) : c + wall + reach] = True
    _furnish(rng, g, keep, rows, cols, wall, clutter)
    return g


def _furnish(rng, g: np.ndarray, keep: np.ndarray, rows, cols, wall: int, clutter: float):
    """Pieces of furniture (``clutter`` per room on average) against a wall of a random room,
    each kept out of the ``keep`` cells in front of the doors."""
    nr, nc = len(rows) - 1, len(cols) - 1
    pieces = int(rng.poisson(clutter * nr * nc)) if clutter > 0 else 0
    for _ in range(min(pieces, 10 * nr * nc)):  # furniture against a wall of a random room
        i, j = int(rng.integers(nr)), int(rng.integers(nc))
        r0, r1 = rows[i] + wall, rows[i + 1]
        c0, c1 = cols[j] + wall, cols[j + 1]
        h_room, w_room = r1 - r0, c1 - c0
        depth = int(rng.integers(1, max(2, min(h_room, w_room) // 4) + 1))
        side = int(rng.integers(4))
        along = h_room if side >= 2 else w_room
        length = int(rng.integers(2, max(3, along // 2) + 1))
        off = int(rng.integers(0, max(1, along - length + 1)))
        if side == 0:  # against the top wall
            box = (r0, r0 + depth, c0 + off, c0 + off + length)
        elif side == 1:  # bottom
            box = (r1 - depth, r1, c0 + off, c0 + off + length)
        elif side == 2:  # left
            box = (r0 + off, r0 + off + length, c0, c0 + depth)
        else:  # right
            box = (r0 + off, r0 + off + length, c1 - depth, c1)
        a0, a1, b0, b1 = box
        if not keep[a0:a1, b0:b1].any():
            g[a0:a1, b0:b1] = True


def _city_block(rng: np.random.Generator, h: int, w: int) -> np.ndarray:
    """A built-up block of ``h x w`` cells: lots along its longer side with one-cell alleys
    between some, perhaps a courtyard, and setbacks and notches on its edges."""
    b = np.ones((h, w), dtype=bool)
    along = w >= h  # lots along the longer side, an alley (1 cell) between some
    length = w if along else h
    x = 0
    for _ in range(length):
        if x >= length:
            break
        lot = int(rng.integers(4, 11))
        if rng.random() < 0.3 and x + lot < length:
            if along:
                b[:, x + lot : x + lot + 1] = False
            else:
                b[x + lot : x + lot + 1, :] = False
            x += 1
        x += lot
    if min(h, w) > 8 and rng.random() < 0.5:  # a courtyard
        ch, cw = int(rng.integers(2, h // 2)), int(rng.integers(2, w // 2))
        r, c = int(rng.integers(2, h - ch - 1)), int(rng.integers(2, w - cw - 1))
        b[r : r + ch, c : c + cw] = False
    for _ in range(int(rng.integers(0, 4))):  # setbacks and notches on the edges
        side = int(rng.integers(4))
        span = w if side < 2 else h
        d = int(rng.integers(1, 3))
        n = int(rng.integers(2, max(3, span // 2)))
        o = int(rng.integers(0, max(1, span - n)))
        if side == 0:
            b[:d, o : o + n] = False
        elif side == 1:
            b[h - d :, o : o + n] = False
        elif side == 2:
            b[o : o + n, :d] = False
        else:
            b[o : o + n, w - d :] = False
    return b


def _city(rng, size: int, street, block, avenue: float, plazas: float):
    """Blocks between streets: the map split recursively by streets until the blocks are small,
    each block built up (:func:`_city_block`) or left an open square; perhaps a diagonal
    avenue across it all."""
    g = np.zeros((size, size), dtype=bool)
    lo, hi = block
    m = int(rng.integers(1, 4))
    todo = [(m, m, size - m, size - m, 0)]  # rectangles still to split (an explicit stack)
    for _ in range(4 * size):  # each split makes two smaller rectangles
        if not todo:
            break
        r0, c0, r1, c1, depth = todo.pop()
        h, w = r1 - r0, c1 - c0
        s = int(rng.integers(street[0], street[1] + 1))
        if (h <= hi and w <= hi) or depth > 12 or max(h, w) < 2 * lo + s:
            if h > 2 and w > 2 and rng.random() >= plazas:
                g[r0:r1, c0:c1] = _city_block(rng, h, w)
            continue
        if h >= w:
            cut = int(rng.integers(r0 + lo, r1 - lo - s + 1))
            todo += [(cut + s, c0, r1, c1, depth + 1), (r0, c0, cut, c1, depth + 1)]
        else:
            cut = int(rng.integers(c0 + lo, c1 - lo - s + 1))
            todo += [(r0, cut + s, r1, c1, depth + 1), (r0, c0, r1, cut, depth + 1)]
    if rng.random() < avenue:
        yy, xx = np.mgrid[0:size, 0:size]
        a, c = rng.uniform(0.25, 1.5), rng.uniform(-0.3, 0.3) * size
        if rng.random() < 0.5:
            a, c = -a, c + size
        g[np.abs(yy - a * xx - c) / np.hypot(1.0, a) < rng.uniform(1.5, 3.0)] = False
    return g


def _warehouse(rng, size: int, rack: int, aisle, run, cross, pallets: float):
    g = _border(np.zeros((size, size), dtype=bool))
    margin = min(int(rng.integers(8, 14)), size // 3)  # the loading area along the top
    rows = []
    r = margin
    for _ in range(size):  # rack runs down the map, cross aisles between them
        if r >= size - 4:
            break
        n = int(rng.integers(run[0], run[1] + 1))
        rows.append((r, min(r + n, size - 3)))
        r += n + int(rng.integers(cross[0], cross[1] + 1))
    c = int(rng.integers(3, 6))
    for _ in range(size):  # rack columns across the map, aisles between them
        if c + rack >= size - 3:
            break
        for r0, r1 in rows:
            g[r0:r1, c : c + rack] = True
        c += rack + int(rng.integers(aisle[0], aisle[1] + 1))
    if margin > 5:
        n = min(int(rng.poisson(pallets * size * size)), size * size // 8)
        pr = rng.integers(2, margin - 3, size=n)
        pc = rng.integers(2, size - 4, size=n)
        for r, c in zip(pr.tolist(), pc.tolist(), strict=True):
            g[r : r + 2, c : c + 2] = True
    return g


def _caves(rng, size: int, fill: float, steps: int):
    g = rng.random((size, size)) < fill
    kernel = np.ones((3, 3), dtype=int)
    for _ in range(steps):
        g = ndimage.convolve(g.astype(int), kernel, mode="constant", cval=1) >= 5
    _border(g)
    labels, n = ndimage.label(~g)  # keep the largest open region (game levels are connected)
    if n > 1:
        sizes = np.bincount(labels.ravel())[1:]
        g |= labels != int(np.argmax(sizes)) + 1
    return g
