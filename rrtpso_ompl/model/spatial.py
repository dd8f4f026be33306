"""A uniform grid over the plane: which obstacles can be near a point, a segment or a box.

Every obstacle is registered in the grid cells its *inflated* bounding box meets: its box grown by
the distance a check cares about (the robot's radius, plus a margin for round-off). So an obstacle
that comes within that distance of a point lies in the point's cell, and one that comes within it
of a segment lies in one of the cells the segment passes through. The exact checks then look only
at those candidates: a check in a world of 10,000 obstacles looks at the few near it.

A uniform grid, not an R-tree (``shapely.STRtree``): the obstacles of a planning problem are spread
over a bounded workspace, often of similar size, and the scalar queries OMPL makes one segment at
a time cost a few microseconds with a grid (an index lookup per cell) against tens of
microseconds through an R-tree's Python call. ``benchmarks/scaling.py`` measures both cases the
project has: random circles and map cells.

The cell lists are kept as CSR arrays (offsets, ids) for vectorised queries, and as Python tuples,
built on first use, for the scalar ones.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterator

import numpy as np

__all__ = ["Grid"]

#: Most grid cells (memory: two ints per cell plus the registrations).
MAX_CELLS = 4_000_000
#: Most (cell, obstacle) registrations before the cells are made coarser: about 100 MB of index
#: while it is built (a polygon of 100,000 vertices with a robot much wider than its edges needs
#: them coarser; a world of 10,000 circles has some 40,000).
MAX_REGISTRATIONS = 4_000_000


class Grid:
    """Obstacles registered by inflated bounding box in the cells of a uniform grid.

    Parameters
    ----------
    lo, hi : (2,) array_like
        The area the grid covers (queries outside it find nothing).
    boxes : (n, 4) array_like
        Inflated bounding boxes ``(xmin, ymin, xmax, ymax)`` of the obstacles, one per id.
    cell : float, optional
        Cell size; by default about one obstacle per cell.
    """

    def __init__(self, lo, hi, boxes: np.ndarray, cell: float | None = None) -> None:
        boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
        self.x0, self.y0 = float(lo[0]), float(lo[1])
        w = max(float(hi[0]) - self.x0, 1e-12)
        h = max(float(hi[1]) - self.y0, 1e-12)
        if cell is None:
            cell = math.sqrt(w * h / max(len(boxes), 1))
        cell = max(cell, math.sqrt(w * h / MAX_CELLS), 1e-12)
        while True:
            self.h = cell
            self.nx = max(1, math.ceil(w / cell))
            self.ny = max(1, math.ceil(h / cell))
            i0, i1, j0, j1 = self._ranges(boxes)
            counts = (i1 - i0 + 1) * (j1 - j0 + 1)
            if counts.sum() <= MAX_REGISTRATIONS:
                break
            cell *= 2.0  # huge obstacles over a fine grid: fewer, larger cells
        self.n_items = len(boxes)
        self.offsets, self.ids = _csr(i0, i1, j0, j1, counts, self.nx, self.nx * self.ny)
        #: The most items one cell holds (sizes the chunks of the vectorised queries).
        self.max_items = int(np.diff(self.offsets).max(initial=0))
        self._tuples: dict[int, tuple[int, ...]] = {}

    # -- geometry --------------------------------------------------------------------------------
    def _ranges(self, boxes: np.ndarray) -> tuple[np.ndarray, ...]:
        i0 = self._clip_i(np.floor((boxes[:, 0] - self.x0) / self.h))
        i1 = self._clip_i(np.floor((boxes[:, 2] - self.x0) / self.h))
        j0 = self._clip_j(np.floor((boxes[:, 1] - self.y0) / self.h))
        j1 = self._clip_j(np.floor((boxes[:, 3] - self.y0) / self.h))
        return i0, i1, j0, j1

    def _clip_i(self, i: np.ndarray) -> np.ndarray:
        return np.clip(i, 0, self.nx - 1).astype(np.intp)

    def _clip_j(self, j: np.ndarray) -> np.ndarray:
        return np.clip(j, 0, self.ny - 1).astype(np.intp)

    def cell_of(self, x: float, y: float) -> int:
        """The cell of a point (points outside the grid: the nearest border cell)."""
        i = int((x - self.x0) // self.h)
        j = int((y - self.y0) // self.h)
        i = 0 if i < 0 else (self.nx - 1 if i >= self.nx else i)
        j = 0 if j < 0 else (self.ny - 1 if j >= self.ny else j)
        return j * self.nx + i

    # -- scalar queries ------------------------------------------------------------------------
    def items(self, cell: int) -> tuple[int, ...]:
        """The ids registered in ``cell`` (a tuple, cached)."""
        got = self._tuples.get(cell)
        if got is None:
            got = tuple(self.ids[self.offsets[cell] : self.offsets[cell + 1]].tolist())
            self._tuples[cell] = got
        return got

    def cells_on_segment(self, ax: float, ay: float, bx: float, by: float) -> Iterator[int]:
        """Every cell the segment passes through (Amanatides-Woo traversal), in order, lazily
        (a check that stops at the first blocked cell never walks the rest).

        Obstacles are registered with a margin beyond their reach, so a segment that grazes a
        cell corner exactly, and may be attributed to either neighbour, misses nothing.
        """
        h, nx, ny = self.h, self.nx, self.ny
        fx, fy = (ax - self.x0) / h, (ay - self.y0) / h
        gx, gy = (bx - self.x0) / h, (by - self.y0) / h
        i, j = math.floor(fx), math.floor(fy)
        i_end, j_end = math.floor(gx), math.floor(gy)
        dx, dy = gx - fx, gy - fy
        step_i = 1 if dx > 0 else -1
        step_j = 1 if dy > 0 else -1
        t_dx = abs(1.0 / dx) if dx != 0 else math.inf
        t_dy = abs(1.0 / dy) if dy != 0 else math.inf
        t_x = ((i + 1 - fx) if dx > 0 else (fx - i)) * t_dx if dx != 0 else math.inf
        t_y = ((j + 1 - fy) if dy > 0 else (fy - j)) * t_dy if dy != 0 else math.inf
        for _ in range(abs(i_end - i) + abs(j_end - j) + 1):
            if 0 <= i < nx and 0 <= j < ny:
                yield j * nx + i
            if t_x < t_y:
                t_x += t_dx
                i += step_i
            else:
                t_y += t_dy
                j += step_j

    # -- vectorised queries ----------------------------------------------------------------------
    def pairs_in_boxes(self, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(query, id)`` pairs, without repeats, of the ids registered in the cells that each
        query box ``lo[q]..hi[q]`` meets."""
        lo = np.asarray(lo, dtype=float).reshape(-1, 2)
        hi = np.asarray(hi, dtype=float).reshape(-1, 2)
        i0, i1, j0, j1 = self._ranges(np.hstack([lo, hi]))
        ni, nj = i1 - i0 + 1, j1 - j0 + 1
        counts = ni * nj
        query = np.repeat(np.arange(len(lo)), counts)
        k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        cells = (j0[query] + k // ni[query]) * self.nx + i0[query] + k % ni[query]
        return self._expand(query, cells)

    def registrations_in_boxes(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Per query box ``lo[q]..hi[q]``, the registrations in the cells it meets: the work
        :meth:`pairs_in_boxes` does for it, and an upper bound on its pairs (an item registered
        in several of those cells counts once for each). O(1) per box, from a summed-area
        table of the cells' registrations."""
        lo = np.asarray(lo, dtype=float).reshape(-1, 2)
        hi = np.asarray(hi, dtype=float).reshape(-1, 2)
        i0, i1, j0, j1 = self._ranges(np.hstack([lo, hi]))
        sat = self._registration_table
        return sat[j1 + 1, i1 + 1] - sat[j0, i1 + 1] - sat[j1 + 1, i0] + sat[j0, i0]

    @functools.cached_property
    def _registration_table(self) -> np.ndarray:
        """``(ny + 1, nx + 1)`` summed-area table of the registrations per cell."""
        per_cell = np.diff(self.offsets).reshape(self.ny, self.nx)
        sat = np.zeros((self.ny + 1, self.nx + 1), dtype=np.int64)
        sat[1:, 1:] = per_cell.cumsum(axis=0).cumsum(axis=1)
        return sat

    def pairs_on_segments(self, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(segment, id)`` pairs, without repeats, of the ids registered in the cells each
        segment ``a[s]-b[s]`` passes through.

        Points are sampled along each segment at most a cell apart; every cell the segment
        passes through holds a sample or is next to a cell that does, so the 3 x 3 blocks around
        the samples' cells cover them all.
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        length = np.hypot(*(b - a).T)
        n = np.ceil(length / self.h).astype(np.intp) + 1
        seg = np.repeat(np.arange(len(a)), n)
        k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        t = k / np.maximum(n[seg] - 1, 1)
        p = a[seg] + t[:, None] * (b - a)[seg]
        i = np.floor((p[:, 0] - self.x0) / self.h).astype(np.intp)
        j = np.floor((p[:, 1] - self.y0) / self.h).astype(np.intp)
        di = np.tile(np.array([-1, 0, 1, -1, 0, 1, -1, 0, 1]), len(i))
        dj = np.tile(np.array([-1, -1, -1, 0, 0, 0, 1, 1, 1]), len(i))
        seg = np.repeat(seg, 9)
        ii = np.repeat(i, 9) + di
        jj = np.repeat(j, 9) + dj
        inside = (ii >= 0) & (ii < self.nx) & (jj >= 0) & (jj < self.ny)
        cells = jj[inside] * self.nx + ii[inside]
        return self._expand(seg[inside], cells)

    def _expand(self, query: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(query, cell) pairs to unique (query, id) pairs through the CSR arrays."""
        if not len(cells):
            return np.empty(0, dtype=np.intp), np.empty(0, dtype=np.intp)
        key = _unique_ints(query.astype(np.int64) * (self.nx * self.ny) + cells)
        query, cells = np.divmod(key, self.nx * self.ny)
        start, stop = self.offsets[cells], self.offsets[cells + 1]
        counts = stop - start
        q = np.repeat(query, counts)
        k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        ids = self.ids[np.repeat(start, counts) + k]
        n = max(self.n_items, 1)
        queries = np.unique(query)
        if len(queries) * n <= 8 * len(ids):
            # Few queries, each meeting many cells (large boxes): a mark per (query, item) is
            # cheaper than sorting the repeats away, and takes no more memory than the pairs.
            mark = np.zeros((len(queries), n), dtype=bool)
            mark[np.searchsorted(queries, q), ids] = True
            row, ids = np.nonzero(mark)
            return queries[row].astype(np.intp), ids.astype(np.intp)
        key = _unique_ints(q * n + ids)
        q, ids = np.divmod(key, n)
        return q.astype(np.intp), ids.astype(np.intp)


def _unique_ints(key: np.ndarray) -> np.ndarray:
    """``np.unique`` of an integer array, by sorting: numpy 2's hash-based ``np.unique`` is an
    order of magnitude slower on the millions of keys a bulk query makes (4.8 s against 0.3 s for
    2 million int64, numpy 2.4), and it was the exact optimum's hot spot."""
    if len(key) < 2:
        return key.copy()
    key = np.sort(key)
    keep = np.empty(len(key), dtype=bool)
    keep[0] = True
    np.not_equal(key[1:], key[:-1], out=keep[1:])
    return key[keep]


def _csr(i0, i1, j0, j1, counts, nx: int, n_cells: int) -> tuple[np.ndarray, np.ndarray]:
    """Offsets (n_cells + 1) and ids of the items registered per cell."""
    item = np.repeat(np.arange(len(counts)), counts)
    ni = (i1 - i0 + 1)[item]
    k = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    cells = (j0[item] + k // ni) * nx + i0[item] + k % ni
    order = np.argsort(cells, kind="stable")
    offsets = np.searchsorted(cells[order], np.arange(n_cells + 1)).astype(np.intp)
    return offsets, item[order].astype(np.intp)
