r"""Lower bounds for a disc among a map's cells through the gates between the cells.

The raster's step counts (:mod:`.free_grid`) bound a path by the cells it passes and count a
turn round a wall's corner as one diagonal step: in a maze of one-cell corridors they are a
fifth short of a disc's path, and the tangent search expands every node within that slack
(docs/optimum-scaling.md). A disc's centre passes from a free cell to the next through a *gate*:
the points of their shared edge that keep the clearance ``thr`` from every blocked cell. Only
the cells at the two ends of a unit edge can come within ``thr`` of it (the two it separates are
free), so its gate is the edge less ``thr`` at each end where one of the two cells there is
blocked: exact for ``thr`` up to a cell, a superset beyond (which keeps every bound a bound).

Between two crossings a path stays in one cell, so it is at least as long as the shortest way
in that cell between the two gates it crossed there: a cell across, or round the corner the two
sides share, keeping ``thr`` from it (tangent, arc, tangent) when the cell diagonally across is
blocked. From a crossing of gate ``g`` on, a path to a target (the goal disc, or the start) is at
least the least sum of such ways over chains of gates from ``g`` to a cell of the target, plus
the distance from that cell's gate to it (:attr:`Gates.to`: a shortest-path search over the
gates). A path through a cell's corner crosses an edge at its end: two gates reach a corner only
when all four cells there are free, and then they are 0 apart, as the path's step is. In a
corridor the gates are its middle and the bound comes within a fraction of a percent of the
disc's path; in the open a chain slides along whole gates for nothing, and the raster's bound is
the better one. Both are bounds, so the search takes the larger.

The centre stays in the bounds: the gates serve only where the lattice covers them (no path goes
round the map). Obstacles besides the cells only lengthen paths. Units: cells, the lattice's
origin at 0.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MIN_PINCHED", "PINCHED", "Gates"]

# A cell's sides, in the order of the side tables: west, east, south, north.
_W, _E, _S, _N = range(4)
#: :meth:`Gates.where_pinched` builds the gates only where at least :data:`MIN_PINCHED` of them
#: are at most :data:`PINCHED` cells long. A chain of gates slides along each gate free of charge,
#: so the bound is as good as the gates are short: a disc of 0.4 cells in one-cell corridors
#: has gates of 0.2 and a bound within 0.3 % of its path (the raster's: 20 %); in four-cell
#: corridors and rooms most gates are whole and the bound near 0, and a point robot's gates are
#: all whole. The search over the gates costs 0.5 s per million cells.
MIN_PINCHED = 0.5
PINCHED = 0.5


class Gates:
    """The gates of a lattice's free cells for a disc, and the bounds through them to targets.

    Parameters
    ----------
    blocked : (ny, nx) ndarray of bool
        Blocked cells, row ``j`` from the bottom (cell ``(j, i)`` is ``[i, i + 1] x [j, j + 1]``).
    thr : float
        The clearance the centre keeps from every blocked cell, cells.
    targets : sequence of ((2,) array_like, float)
        The points bounds are to (the start, the goal) and the radius of the disc round each
        that a path may end in, cells.
    """

    def __init__(self, blocked: np.ndarray, thr: float, targets, gates=None) -> None:
        blocked = np.asarray(blocked, dtype=bool)
        self.ny, self.nx = blocked.shape
        self.targets = [(np.asarray(p, dtype=float), float(tol)) for p, tol in targets]
        self.lo, self.hi, self.side = gates if gates is not None else _gates(blocked, float(thr))
        self._corners = np.pad(blocked, 1, constant_values=False)  # padded: the diagonal cells
        self._thr = float(thr)
        self._home = [self._cells_near(p, tol) for p, tol in self.targets]
        #: Per target, a lower bound on the length of a path from a crossing of each gate to it.
        self.to = self._search()
        #: Per target and cell, the least bound over the cell's gates (0 in the target's cells).
        self.cell_bound = []
        for to, home in zip(self.to, self._home, strict=True):
            least = np.full(self.ny * self.nx, np.inf)
            for k in range(4):
                has = self.side[k] >= 0
                least[has] = np.minimum(least[has], to[self.side[k][has]])
            least[home] = 0.0
            self.cell_bound.append(least)

    @classmethod
    def where_pinched(cls, blocked: np.ndarray, thr: float, targets) -> Gates | None:
        """The gates, when at least :data:`MIN_PINCHED` of them are at most :data:`PINCHED`
        long (the bound is worth its search), else None."""
        gates = _gates(np.asarray(blocked, dtype=bool), float(thr))
        lo, hi = gates[0], gates[1]
        pinched = np.count_nonzero(hi - lo <= PINCHED)
        if not len(lo) or pinched < MIN_PINCHED * len(lo):
            return None
        return cls(blocked, thr, targets, gates)

    # ------------------------------------------------------------------------------------------
    def bound(self, which: int, p: np.ndarray) -> np.ndarray:
        """Lower bound on the length of a free path from each point ``(n, 2)`` to target
        ``which``, cells (``inf`` where the point's cell has no gate and no part of the
        target)."""
        p = np.asarray(p, dtype=float).reshape(-1, 2)
        i = np.clip(np.floor(p[:, 0]), 0, self.nx - 1).astype(np.intp)
        j = np.clip(np.floor(p[:, 1]), 0, self.ny - 1).astype(np.intp)
        cell = j * self.nx + i
        out = np.full(len(p), np.inf)
        for k in range(4):
            g = self.side[k][cell]
            has = np.flatnonzero(g >= 0)
            gk = g[has]
            d = _to_gate(k, gk, i[has], j[has], p[has, 0], p[has, 1], self.lo, self.hi)
            out[has] = np.minimum(out[has], d + self.to[which][gk])
        home = np.isin(cell, self._home[which])  # the path may end in its own cell
        (tx, ty), tol = self.targets[which]
        direct = np.maximum(np.hypot(p[:, 0] - tx, p[:, 1] - ty) - tol, 0.0)
        out[home] = np.minimum(out[home], direct[home])
        return out

    # ------------------------------------------------------------------------------------------
    def _cells_near(self, p: np.ndarray, tol: float) -> np.ndarray:
        """Flat indices of the cells within ``tol`` of ``p`` (its box, borders included)."""
        r = tol + 1e-9
        i = np.arange(
            max(int(np.floor(p[0] - r)), 0), min(int(np.floor(p[0] + r)), self.nx - 1) + 1
        )
        j = np.arange(
            max(int(np.floor(p[1] - r)), 0), min(int(np.floor(p[1] + r)), self.ny - 1) + 1
        )
        return (j[:, None] * self.nx + i[None, :]).ravel()

    def _search(self) -> list[np.ndarray]:
        """Shortest chains of gates to each target (scipy's Dijkstra, from a source per target
        joined to the gates of the target's cells by their distances to its disc)."""
        from scipy.sparse import csr_matrix
        from scipy.sparse.csgraph import dijkstra

        n, m = len(self.lo), len(self.targets)
        nbr, weight = _neighbours(self.side, self.lo, self.hi, self._corners, self._thr)
        ok = nbr >= 0
        counts, indices, data = [ok.sum(axis=1)], [nbr[ok]], [weight[ok]]
        for (point, tol), cells in zip(self.targets, self._home, strict=True):
            first = np.full(n, np.inf)  # each gate of the target's cells once, at its least cost
            for k in range(4):
                g = self.side[k][cells]
                has = g >= 0
                j, i = np.divmod(cells[has], self.nx)
                d = _to_gate(k, g[has], i, j, point[0], point[1], self.lo, self.hi)
                np.minimum.at(first, g[has], np.maximum(d - tol, 0.0))
            start = np.flatnonzero(np.isfinite(first))
            counts.append([len(start)])
            indices.append(start)
            data.append(first[start])
        indptr = np.zeros(n + m + 1, dtype=np.int64)
        np.cumsum(np.concatenate(counts), out=indptr[1:])
        graph = csr_matrix((np.concatenate(data), np.concatenate(indices).astype(np.int32),
                            indptr.astype(np.int32)), shape=(n + m, n + m))  # fmt: skip
        dist = dijkstra(graph, directed=True, indices=np.arange(n, n + m))
        return [row[:n] for row in np.atleast_2d(dist)]


def _to_gate(k: int, g, i, j, x, y, lo, hi) -> np.ndarray:
    """Distance from points ``(x, y)`` to gate ``g`` on side ``k`` of cells ``(j, i)``."""
    if k in (_W, _E):  # the edge x = i (+ 1), the gate y in [lo, hi]
        across = np.abs(x - (i + (k == _E)))
        along = np.maximum(np.maximum(lo[g] - y, y - hi[g]), 0.0)
    else:
        across = np.abs(y - (j + (k == _N)))
        along = np.maximum(np.maximum(lo[g] - x, x - hi[g]), 0.0)
    return np.hypot(across, along)


def _gates(blocked: np.ndarray, thr: float):
    """The gates of the edges between free cells: ``lo, hi`` (cells, along the edge: ``y`` on
    the vertical edges, numbered first, row by row, ``x`` on the horizontal ones) and, per cell,
    the gate on each side (``side`` ``(4, ny nx)``, -1 where there is none)."""
    ny, nx = blocked.shape
    free = ~blocked
    pad = np.pad(blocked, 1, constant_values=False)  # outside: no cell to keep clear of
    # Vertical edges x = i + 1 between cells (j, i) and (j, i + 1): (ny, nx - 1).
    jv = np.arange(ny, dtype=float)[:, None]
    below = pad[:-2, 1:-2] | pad[:-2, 2:-1]
    above = pad[2:, 1:-2] | pad[2:, 2:-1]
    v_lo = jv + thr * below
    v_hi = jv + 1.0 - thr * above
    v_ok = free[:, :-1] & free[:, 1:] & (v_lo <= v_hi)
    # Horizontal edges y = j + 1 between cells (j, i) and (j + 1, i): (ny - 1, nx).
    ih = np.arange(nx, dtype=float)[None, :]
    left = pad[1:-2, :-2] | pad[2:-1, :-2]
    right = pad[1:-2, 2:] | pad[2:-1, 2:]
    h_lo = ih + thr * left
    h_hi = ih + 1.0 - thr * right
    h_ok = free[:-1, :] & free[1:, :] & (h_lo <= h_hi)
    # Numbered as they come: the vertical gates row by row, then the horizontal ones.
    nv = int(np.count_nonzero(v_ok))
    lo = np.concatenate([v_lo[v_ok], h_lo[h_ok]])
    hi = np.concatenate([v_hi[v_ok], h_hi[h_ok]])
    vid = np.full((ny, nx - 1), -1, dtype=np.int32)
    vid[v_ok] = np.arange(nv, dtype=np.int32)
    hid = np.full((ny - 1, nx), -1, dtype=np.int32)
    hid[h_ok] = np.arange(nv, len(lo), dtype=np.int32)
    side = np.full((4, ny, nx), -1, dtype=np.int32)
    side[_W][:, 1:] = vid
    side[_E][:, :-1] = vid
    side[_S][1:, :] = hid
    side[_N][:-1, :] = hid
    return lo, hi, side.reshape(4, ny * nx)


def _neighbours(side: np.ndarray, lo: np.ndarray, hi: np.ndarray, pad: np.ndarray, thr: float):
    """Each gate's neighbours (the other gates of the two cells it separates) and its distance
    to each: ``(n, 6)`` arrays, -1 where there is none. ``pad`` is the blocked cells with a free
    border."""
    n = len(lo)
    nx = pad.shape[1] - 2
    nbr = np.full((n, 6), -1, dtype=np.int32)
    weight = np.zeros((n, 6))
    slot = np.zeros(n, dtype=np.int8)
    for a in range(4):
        ga = side[a]
        for b in range(4):
            if a == b:
                continue
            gb = side[b]
            both = np.flatnonzero((ga >= 0) & (gb >= 0))
            j, i = np.divmod(both, nx)
            w = _distance(a, b, ga[both], gb[both], lo, hi, i, j, pad, thr)
            rows = ga[both]
            nbr[rows, slot[rows]] = gb[both]
            weight[rows, slot[rows]] = w
            slot[rows] += 1
    return nbr, weight


def _distance(a: int, b: int, ga, gb, lo, hi, i, j, pad, thr: float) -> np.ndarray:
    """Length of the shortest way between gate ``ga`` on side ``a`` and ``gb`` on side ``b`` of
    cells ``(j, i)`` within the cell: a cell across, or round the corner the two sides share,
    which it keeps ``thr`` from when the cell diagonally across it is blocked (tangents and an
    arc; the least at the gates' ends nearest the corner, the way growing with either)."""
    if {a, b} in ({_W, _E}, {_S, _N}):  # opposite sides: a cell across, offset along
        gap = np.maximum(np.maximum(lo[gb] - hi[ga], lo[ga] - hi[gb]), 0.0)
        return np.hypot(1.0, gap)
    v, h = (ga, gb) if a in (_W, _E) else (gb, ga)  # the vertical side's gate, the horizontal's
    east = _E in (a, b)
    north = _N in (a, b)
    dy = (j + 1.0 - hi[v]) if north else (lo[v] - j)
    dx = (i + 1.0 - hi[h]) if east else (lo[h] - i)
    chord = np.hypot(dx, dy)
    corner = pad[j + 1 + (1 if north else -1), i + 1 + (1 if east else -1)]
    # The chord passes the corner closer than thr: round it (tangent, arc, tangent).
    tight = corner & (dx * dy < thr * chord) & (thr > 0.0)
    if not tight.any():
        return chord
    x, y = np.maximum(dx[tight], thr), np.maximum(dy[tight], thr)
    arc = 0.5 * np.pi - np.arccos(thr / x) - np.arccos(thr / y)
    chord[tight] = np.sqrt(x * x - thr * thr) + np.sqrt(y * y - thr * thr) + thr * arc
    return chord
