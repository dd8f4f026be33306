"""The free cells of a map as rectangles, and the pieces of their edges they share: the navigation
mesh of the interval search (:mod:`.intervals`).

Each row's maximal runs of free cells are *spans*; a span with a span of the same extent under it
joins that one's rectangle. A rectangle's left and right sides are therefore walls (a blocked
cell or the bounds) all along, and it meets its neighbours only along its top and bottom edges, in
*pieces*: the overlaps of its top span with the spans of the row above (and of its bottom span
with the row below). Everything is built with array operations: a map of 4 million cells in about
a second.

Coordinates are the grid's: cell ``(i, j)`` is the unit square ``[i, i + 1] x [j, j + 1]``, rows
from the bottom.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass

import numpy as np

__all__ = ["PAIRWISE_PIECES", "RectMesh"]

#: In the graph of :meth:`RectMesh.bounds_to`, the pieces of a rectangle with at most this many
#: are joined pairwise (their exact distance); those of a larger one through two hubs, its top
#: and bottom edge (the edges of a pairwise graph grow with the square of its pieces).
PAIRWISE_PIECES = 32

#: The weight of an edge of length 0 in a sparse graph (an explicit 0 would be no edge).
_ZERO = 1e-300


@dataclass(frozen=True)
class RectMesh:
    """Rectangles of free cells and the pieces they share.

    Attributes
    ----------
    x0, x1, y0, y1 : array of int
        Each rectangle's extent, cells (``array("q")``: Python ints when indexed).
    top, bottom : sequence of list of (int, int, int, int)
        Each rectangle's pieces along its top (bottom) edge, left to right: ``(p0, p1,
        neighbour, pid)``, the piece ``[p0, p1]`` of the edge shared with rectangle
        ``neighbour``, row ``pid`` of :attr:`pieces`.
    cell_rect : (ny, nx) ndarray of int32
        The rectangle of each free cell, -1 for a blocked one.
    corner : (ny + 1, nx + 1) ndarray of bool
        The grid points where exactly one of the four cells around is blocked (cells outside
        the grid count as blocked): the convex corners of the walls, where a shortest path may
        bend.
    pieces : (m, 5) ndarray of int64
        Every piece once: ``p0, p1, y, lower rectangle, upper rectangle``; the ``pid`` of
        :attr:`top` and :attr:`bottom` is its row.
    """

    x0: list
    x1: list
    y0: list
    y1: list
    top: _Edges
    bottom: _Edges
    cell_rect: np.ndarray
    corner: np.ndarray
    pieces: np.ndarray

    @classmethod
    def build(cls, free: np.ndarray) -> RectMesh:
        """The mesh of ``free`` ((ny, nx) booleans, rows from the bottom)."""
        free = np.asarray(free, dtype=bool)
        ny, nx = free.shape
        w = nx + 2
        pad = np.zeros((ny, nx + 2), dtype=np.int8)
        pad[:, 1:-1] = free
        d = np.diff(pad, axis=1)
        sj, sx0 = np.nonzero(d == 1)  # row-major: sorted by row, then x
        _, sx1 = np.nonzero(d == -1)
        sj, sx0, sx1 = (a.astype(np.int64) for a in (sj, sx0, sx1))
        n = len(sj)
        # The span of the same extent in the row below, if any: codes sort like the spans.
        code = (sj * w + sx0) * w + sx1
        target = ((sj - 1) * w + sx0) * w + sx1
        at = np.minimum(np.searchsorted(code, target), max(n - 1, 0))
        below = np.where(code[at] == target, at, -1) if n else at
        root = np.where(below >= 0, below, np.arange(n))
        while True:  # pointer doubling: at most log2(ny) rounds
            nxt = root[root]
            if np.array_equal(nxt, root):
                break
            root = nxt
        roots, rid = np.unique(root, return_inverse=True)
        rid = rid.astype(np.int64)
        y1 = np.zeros(len(roots), dtype=np.int64)
        np.maximum.at(y1, rid, sj + 1)
        cell_rect = np.full(ny * nx, -1, dtype=np.int32)
        lengths = sx1 - sx0
        first = np.repeat(sj * nx + sx0 - np.cumsum(lengths) + lengths, lengths)
        cell_rect[first + np.arange(int(lengths.sum()))] = np.repeat(rid, lengths)
        pieces = _pieces(sj, sx0, sx1, rid, w)
        top = _per_rect(pieces, 3, 4, len(roots))
        bottom = _per_rect(pieces, 4, 3, len(roots))
        blocked = np.pad(~free, 1, constant_values=True)
        count = (blocked[:-1, :-1].astype(np.int8) + blocked[:-1, 1:] + blocked[1:, :-1]
                 + blocked[1:, 1:])  # fmt: skip
        return cls(_ints(sx0[roots]), _ints(sx1[roots]), _ints(sj[roots]), _ints(y1), top, bottom,
                   cell_rect.reshape(ny, nx), count == 1, pieces)  # fmt: skip

    def bounds_to(self, x: float, y: float) -> np.ndarray:
        """Lower bounds on the length of every free path from each piece to the point ``(x,
        y)`` (``inf`` when none reaches it): Dijkstra's distances over a graph of the pieces.

        A path from a piece to the point crosses a chain of pieces, consecutive ones on the
        edges of one rectangle, and ends in a rectangle holding the point: it is no shorter
        than the sum of the distances between them. The graph's edges are those distances
        (or less: through a large rectangle's hubs, pieces of one edge are 0 apart and of
        opposite edges the rectangle's height), so its distances are lower bounds. In a maze
        they follow the corridors, where the straight distance cuts through the walls.
        """
        from scipy.sparse import csr_matrix
        from scipy.sparse.csgraph import dijkstra

        pc = self.pieces
        m, n_rects = len(pc), len(self.x0)
        owner = np.concatenate([pc[:, 3], pc[:, 4]])
        pid = np.concatenate([np.arange(m), np.arange(m)])
        on_top = np.concatenate([np.ones(m, dtype=bool), np.zeros(m, dtype=bool)])
        order = np.argsort(owner, kind="stable")
        owner, pid, on_top = owner[order], pid[order], on_top[order]
        size = np.bincount(owner, minlength=n_rects)
        small = size[owner] <= PAIRWISE_PIECES
        pos = np.arange(len(owner)) - (np.cumsum(size) - size)[owner]
        count = np.where(small, size[owner] - 1 - pos, 0)
        a = np.repeat(np.arange(len(owner)), count)
        b = a + 1 + (np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count))
        ia, ib = pid[a], pid[b]
        dx = np.maximum(np.maximum(pc[ib, 0] - pc[ia, 1], pc[ia, 0] - pc[ib, 1]), 0)
        pair_w = np.hypot(dx, pc[ia, 2] - pc[ib, 2])
        # Hubs of a large rectangle r: nodes m + 2 r (top) and m + 2 r + 1 (bottom).
        big = ~small
        hub = m + 2 * owner[big] + np.where(on_top[big], 0, 1)
        rects = np.unique(owner[big])
        height = np.asarray(self.y1)[rects] - np.asarray(self.y0)[rects]
        goal = m + 2 * n_rects
        near = [int(q) for q in self.rects_at(x, y)]
        gp = np.flatnonzero(np.isin(pc[:, 3], near) | np.isin(pc[:, 4], near))
        gdx = np.maximum(np.maximum(pc[gp, 0] - x, x - pc[gp, 1]), 0.0)
        tails = np.concatenate([ia, pid[big], m + 2 * rects, np.full(len(gp), goal)])
        heads = np.concatenate([ib, hub, m + 2 * rects + 1, gp])
        weights = np.concatenate([pair_w, np.zeros(len(hub)), height, np.hypot(gdx, pc[gp, 2] - y)])
        key = tails * (goal + 1) + heads
        first = np.lexsort((weights, key))  # an edge twice (two rectangles): the shorter
        keep = first[np.diff(key[first], prepend=-1) != 0]
        graph = csr_matrix((np.maximum(weights[keep], _ZERO), (tails[keep], heads[keep])),
                           shape=(goal + 1, goal + 1))  # fmt: skip
        return dijkstra(graph, directed=False, indices=goal)[:m]

    def rects_at(self, x: float, y: float) -> list[int]:
        """The rectangles holding the point ``(x, y)`` (on an edge or a corner: every one)."""
        ny, nx = self.cell_rect.shape
        i0, j0 = max(math.ceil(x) - 1, 0), max(math.ceil(y) - 1, 0)
        i1, j1 = min(math.floor(x), nx - 1), min(math.floor(y), ny - 1)
        return sorted({r for r in self.cell_rect[j0 : j1 + 1, i0 : i1 + 1].ravel().tolist()
                       if r >= 0})  # fmt: skip


def _ints(a: np.ndarray) -> array:
    """``a`` as an array of machine integers whose items are Python ints: indexed as fast as a
    list by the search, at 8 bytes an item rather than about 36 (a list of 680,000 rectangles'
    extents costs 100 MB as lists)."""
    out = array("q")
    out.frombytes(np.ascontiguousarray(a, dtype=np.int64).tobytes())
    return out


def _pieces(sj, sx0, sx1, rid, w: int) -> np.ndarray:
    """Every piece: the overlap of spans in consecutive rows that belong to different
    rectangles, as rows ``p0, p1, y, lower rectangle, upper rectangle``."""
    key0, key1 = sj * w + sx0, sj * w + sx1
    lo = np.searchsorted(key1, (sj + 1) * w + sx0, side="right")  # above: x1 > this x0
    hi = np.searchsorted(key0, (sj + 1) * w + sx1, side="left")  # above: x0 < this x1
    count = np.maximum(hi - lo, 0)
    s = np.repeat(np.arange(len(sj)), count)
    t = np.repeat(lo, count) + (np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count,
                                                                           count))  # fmt: skip
    apart = rid[s] != rid[t]
    s, t = s[apart], t[apart]
    return np.column_stack([np.maximum(sx0[s], sx0[t]), np.minimum(sx1[s], sx1[t]), sj[s] + 1,
                            rid[s], rid[t]]).astype(np.int64)  # fmt: skip


def _per_rect(pieces: np.ndarray, owner_col: int, other_col: int, n_rects: int) -> _Edges:
    """``[(p0, p1, other, pid), ...]`` per rectangle (owning the pieces' column ``owner_col``),
    left to right, made as the search asks."""
    owner = pieces[:, owner_col]
    order = np.lexsort((pieces[:, 0], owner))
    rows = np.column_stack([pieces[:, 0], pieces[:, 1], pieces[:, other_col],
                            np.arange(len(pieces))])[order]  # fmt: skip
    return _Edges(rows, np.searchsorted(owner[order], np.arange(n_rects + 1)))


class _Edges:
    """The pieces of one edge of every rectangle, as lists of tuples made on first use (a
    search touches a part of a large map's rectangles, and Python tuples of them all cost
    seconds and hundreds of megabytes on 4 million cells)."""

    def __init__(self, rows: np.ndarray, bounds: np.ndarray) -> None:
        self._rows, self._bounds = rows, bounds
        self._made: dict[int, list] = {}

    def __getitem__(self, q: int) -> list:
        made = self._made.get(q)
        if made is None:
            rows = self._rows[self._bounds[q] : self._bounds[q + 1]].tolist()
            made = self._made[q] = [tuple(r) for r in rows]
        return made

    def __len__(self) -> int:
        return len(self._bounds) - 1
