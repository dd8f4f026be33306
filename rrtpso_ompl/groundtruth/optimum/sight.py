"""How far a straight segment from a point can run on a map's lattice: the reach that makes a
disc's tangent search local in a maze.

Among a map's cells alone, the candidates for a circle's free tangents were every circle of the
round's ellipse whose bounds leave room, and on a long path the room is hundreds of cells: a
maze of 1024 x 1024 cells gave 30,000 candidates per circle, most behind walls. A tangent is
free for the disc (clearance at least ``R - tol`` from the cells) only if the segment between the
two circles' centres goes no deeper than ``tol`` into a blocked cell: each point of it is within
``R`` of a point of the tangent (the centres are ``R`` from the tangent points; the start and the
goal are their own centres). :class:`Reach` bounds how far such a segment can run from a point
in each of four directions, and :meth:`Reach.may_see` keeps a centre only where it could.

A segment heading right with a slope of at most 1 crosses each column of cells it passes whole
with a rise of at most one cell, through free cells of that column (a blocked one would hold a
point of it deeper than ``tol``, grazing aside). So the heights where it can leave a column lie
within one cell of those where it entered, and within the free rows of the column; when a column
has no free row within reach of the entering heights, no such segment crosses it. Sweeping the
columns with the hull of those heights gives an upper bound on the run (the hull, and forgetting
that the slope is constant, only loosen it). Left, up and down are the same sweep on the lattice
mirrored or transposed. A segment is either mostly horizontal (then it heads left or right, and
rises no more than it runs) or mostly vertical. Lengths are in cells.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Reach"]

#: Columns a sweep follows before it gives up bounding (the run counts as unbounded: open
#: space, where the ellipse's filters do the work).
MAX_SWEEP = 64


class Reach:
    """The runs of straight segments from points over the free cells of a lattice.

    Parameters
    ----------
    free : (ny, nx) ndarray of bool
        The free cells, rows from the bottom; cell ``(i, j)`` is ``[i, i + 1] x [j, j + 1]``.
    slack : float
        How deep a segment may go into a blocked cell, cells (the touch tolerance, and room for
        round-off).
    """

    def __init__(self, free: np.ndarray, slack: float) -> None:
        free = np.asarray(free, dtype=bool)
        self.ny, self.nx = free.shape
        self.slack = float(slack)
        # Each direction as a sweep to the right over the columns of a lattice: right, left
        # (mirrored in x), up and down (transposed, then mirrored).
        self._lattices = (free, free[:, ::-1], free.T, free.T[:, ::-1])
        self._tables: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def runs(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """``(n, 4)``: how far a segment from each point ``(x, y)`` (cells, inside the lattice)
        can run to the right, left, up and down (``inf``: more than :data:`MAX_SWEEP` cells)."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        out = np.empty((len(x), 4))
        starts = ((x, y), (self.nx - x, y), (y, x), (self.ny - y, x))
        for k, (u, v) in enumerate(starts):
            out[:, k] = self._sweep(k, u, v)
        return out

    def may_see(self, runs: np.ndarray, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """Whether a segment from a point with ``runs`` (rows of :meth:`runs`) to the point
        ``dx, dy`` cells away can go nowhere deeper than the slack into a blocked cell (False is
        a proof that it cannot)."""
        e = 4.0 * self.slack + 1e-9
        ax, ay = np.abs(dx), np.abs(dy)
        flat = ay <= ax + e  # mostly horizontal: right or left
        steep = ax <= ay + e
        right = flat & (dx >= 0.0) & (dx <= runs[:, 0] + e)
        left = flat & (dx <= 0.0) & (-dx <= runs[:, 1] + e)
        up = steep & (dy >= 0.0) & (dy <= runs[:, 2] + e)
        down = steep & (dy <= 0.0) & (-dy <= runs[:, 3] + e)
        return right | left | up | down

    # ------------------------------------------------------------------------------------------
    def _table(self, k: int) -> tuple[np.ndarray, ...]:
        """Per column ``c`` and row ``r`` of lattice ``k``, ``(nx, ny)`` each: the lowest free
        row at or above ``r`` (``ny``: none), the highest at or below (-1: none), and the first
        and last rows of the run of free rows holding ``r`` (for a free ``r``)."""
        table = self._tables.get(k)
        if table is None:
            g = self._lattices[k].T  # [column, row]
            n = g.shape[1]
            kind = np.int16 if n < 2**15 - 1 else np.int32
            rows = np.arange(n, dtype=kind)
            free_up = np.minimum.accumulate(np.where(g, rows, n).astype(kind)[:, ::-1],
                                            axis=1)[:, ::-1]  # fmt: skip
            free_down = np.maximum.accumulate(np.where(g, rows, -1).astype(kind), axis=1)
            run_lo = np.maximum.accumulate(np.where(g, -1, rows).astype(kind), axis=1) + 1
            run_hi = np.minimum.accumulate(np.where(g, n, rows).astype(kind)[:, ::-1],
                                           axis=1)[:, ::-1]  # fmt: skip
            table = self._tables[k] = tuple(
                np.ascontiguousarray(t) for t in (free_up, free_down, run_lo, run_hi)
            )
        return table

    def _sweep(self, k: int, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """How far right segments from ``(x, y)`` run over lattice ``k`` (its own axes)."""
        free_up, free_down, run_lo, run_hi = self._table(k)
        n_cols, n_rows = free_up.shape
        e = 2.0 * self.slack + 1e-9
        run = np.full(len(x), np.inf)
        # A point inside a column crosses what is left of it with a rise of at most one cell
        # unchecked; a point on a column's edge (a corner) starts at that column's check.
        col = np.where(x == np.floor(x), x, np.floor(x) + 1.0).astype(np.intp)
        inner = x != np.floor(x)
        lo = np.where(inner, y - 1.0, y)
        hi = np.where(inner, y + 1.0, y)
        alive = np.arange(len(x))
        for _ in range(MAX_SWEEP):
            done = col[alive] >= n_cols
            run[alive[done]] = n_cols - x[alive[done]]  # the lattice's edge: the bounds
            alive = alive[~done]
            if not len(alive):
                break
            c, a, b = col[alive], lo[alive], hi[alive]
            # The free rows meeting the entering heights [a, b] (row r holds [r, r + 1]).
            first = free_up[c, np.clip(np.ceil(a - e) - 1.0, 0, n_rows - 1).astype(np.intp)]
            last = free_down[c, np.clip(np.floor(b + e), 0, n_rows - 1).astype(np.intp)]
            crosses = (first <= last) & (first < n_rows) & (last >= 0)
            stop = alive[~crosses]
            run[stop] = col[stop] + 1.0 - x[stop]  # it cannot leave this column on the right
            keep = np.flatnonzero(crosses)
            alive, c, a, b = alive[keep], c[keep], a[keep], b[keep]
            first, last = first[keep].astype(np.intp), last[keep].astype(np.intp)
            # Leaving heights: within a cell of the entering ones, in the runs of free rows
            # they entered.
            lo[alive] = np.maximum(np.maximum(a - 1.0, run_lo[c, first] - e), 0.0)
            hi[alive] = np.minimum(np.minimum(b + 1.0, run_hi[c, last] + e), n_rows)
            col[alive] += 1
        return run
