"""Geodesic distance fields on a grid of the static world (the DWA's map-grid critics).

Nav2's DWB controller scores a trajectory by how far its end lies from the local plan and from
the local goal, measured *through free space* (a wavefront over the costmap's free cells): a pose
just behind a wall from the path is far from it, so the controller is not lured into the wall,
the classic local minimum of a DWA at a door. :class:`NavGrid` is that grid for a
:class:`~rrtpso_ompl.model.world.World`: a cell is free when the robot's centre may stand on its
centre (exact clearance ``>= SR``), neighbours (8-connected, no corner cutting) are joined by
edges of their centre distance, and :meth:`NavGrid.field` runs one multi-source Dijkstra
(``scipy.sparse.csgraph``), cut off at a distance limit so that its cost stays local. Distances
are octile (at most 8 % above Euclidean in open space); the obstacle checks of the controller
itself stay exact.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import dijkstra

from ..model.grid_graph import MOVES_8, grid_graph, move_pairs, node_dtype, walk
from ..model.world import World

__all__ = ["MAX_CELLS", "OCTILE", "NavGrid"]

#: Most cells of a grid (its graph takes about 100 bytes a cell): a finer resolution over a
#: larger world is coarsened to this many.
MAX_CELLS = 1_000_000
#: Length given to the edges out of a cell blocked for one field (beyond any limit).
_BLOCKED = 1e300
#: Octile distances exceed Euclidean ones by at most this factor (1 / cos 22.5 degrees).
OCTILE = 1.0 / math.cos(math.pi / 8)


class NavGrid:
    """Free cells of a world for a robot of radius ``clearance`` and the graph joining them.

    Parameters
    ----------
    world : World
        The static obstacles and the bounds.
    clearance : float
        Least distance from a free cell's centre to any obstacle, units (the robot's radius).
    resolution : float
        Cell size, units (> 0); coarsened so that the grid has at most :data:`MAX_CELLS` cells.
    """

    def __init__(self, world: World, clearance: float, resolution: float) -> None:
        if not (resolution > 0 and math.isfinite(resolution)):
            raise ValueError(f"NavGrid resolution must be a finite number > 0, got {resolution}")
        (x0, y0), (x1, y1) = world.bounds
        h = float(resolution)
        h = max(h, math.sqrt(max(x1 - x0, h) * max(y1 - y0, h) / MAX_CELLS))
        self.h = h
        self.origin = np.array([x0, y0], dtype=float)
        self.nx = max(1, math.ceil((x1 - x0) / h))
        self.ny = max(1, math.ceil((y1 - y0) / h))
        ix, iy = np.meshgrid(np.arange(self.nx), np.arange(self.ny), indexing="ij")
        self.centres = self.origin + (np.stack([ix, iy], axis=-1).reshape(-1, 2) + 0.5) * h
        inside = world.points_in_bounds(self.centres)
        near = world.point_clearance(self.centres, cap=clearance + h)
        self.free = (inside & (near >= clearance)).reshape(self.nx, self.ny)
        self.graph = self._graph()

    def _graph(self) -> sparse.csr_matrix:
        """The symmetric adjacency of the free cells (8-connected; a diagonal step needs both
        cells beside it free, so the wavefront never slips between two blocked corners)."""
        nx, ny = self.nx, self.ny
        nodes = np.arange(nx * ny, dtype=node_dtype(nx * ny)).reshape(nx, ny)
        index = np.where(self.free, nodes, -1)
        pairs = [move_pairs(index, step, passed) for step, passed, _ in MOVES_8]
        weights = [np.full(len(a), self.h * math.hypot(*step))
                   for (a, _), (step, _, _) in zip(pairs, MOVES_8, strict=True)]  # fmt: skip
        return grid_graph(nx * ny, np.concatenate([a for a, _ in pairs]),
                          np.concatenate([b for _, b in pairs]), np.concatenate(weights),
                          symmetric=True)  # fmt: skip

    # -- queries ------------------------------------------------------------------------------
    def cell_of(self, points: np.ndarray) -> np.ndarray:
        """Flat index of the cell holding each point, -1 outside the grid."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        ij = np.floor((p - self.origin) / self.h).astype(np.int64)
        ok = (ij[:, 0] >= 0) & (ij[:, 0] < self.nx) & (ij[:, 1] >= 0) & (ij[:, 1] < self.ny)
        return np.where(ok, ij[:, 0] * self.ny + ij[:, 1], -1)

    def free_cell_near(self, point: np.ndarray) -> int:
        """The free cell nearest ``point`` among its cell and the 24 around it, -1 if none."""
        i, j = np.floor((np.asarray(point, dtype=float) - self.origin) / self.h).astype(int)
        di, dj = np.meshgrid(np.arange(-2, 3), np.arange(-2, 3), indexing="ij")
        ci, cj = (i + di).ravel(), (j + dj).ravel()
        ok = (ci >= 0) & (ci < self.nx) & (cj >= 0) & (cj < self.ny)
        ci, cj = ci[ok], cj[ok]
        ok = self.free[ci, cj]
        if not ok.any():
            return -1
        flat = ci[ok] * self.ny + cj[ok]
        d = np.hypot(*(self.centres[flat] - point).T)
        return int(flat[np.argmin(d)])

    def field(
        self, sources: np.ndarray, limit: float, discs: np.ndarray | None = None
    ) -> np.ndarray:
        """Geodesic distance from the nearest of ``sources`` (points, units) to every cell.

        Sources in blocked cells are skipped (a source with no free cell at all gives an
        all-``inf`` field). Cells farther than ``limit`` (units) are ``inf``. ``discs``, rows
        ``(x, y, r)``, block the cells whose centre lies in them for this field only (Nav2's
        obstacle layer: what the robot senses now): the wavefront may enter such a cell but
        not leave it.
        """
        cells = self.cell_of(sources)
        cells = cells[cells >= 0]
        cells = np.unique(cells[self.free.ravel()[cells]])
        if not len(cells):
            return np.full(self.nx * self.ny, np.inf)
        rows = self.cells_in_discs(discs) if discs is not None else np.empty(0, np.int64)
        if not len(rows):
            return dijkstra(self.graph, directed=True, indices=cells, min_only=True, limit=limit)
        # Every edge out of a blocked cell becomes too long to use, then is restored.
        g = self.graph
        starts = g.indptr[rows]
        counts = g.indptr[rows + 1] - starts
        edges = np.arange(counts.sum()) + np.repeat(starts - (np.cumsum(counts) - counts), counts)
        saved = g.data[edges].copy()
        g.data[edges] = _BLOCKED
        try:
            return dijkstra(g, directed=True, indices=cells, min_only=True, limit=limit)
        finally:
            g.data[edges] = saved

    def cells_in_discs(self, discs: np.ndarray) -> np.ndarray:
        """Flat indices of the cells whose centre lies in any disc ``(x, y, r)`` (unique)."""
        d = np.asarray(discs, dtype=float).reshape(-1, 3)
        if not len(d):
            return np.empty(0, np.int64)
        reach = math.ceil(float(d[:, 2].max()) / self.h) + 1
        off = np.arange(-reach, reach + 1)
        di, dj = (a.ravel() for a in np.meshgrid(off, off, indexing="ij"))
        ij = np.floor((d[:, :2] - self.origin) / self.h).astype(np.int64)
        ci, cj = ij[:, :1] + di[None], ij[:, 1:] + dj[None]  # (k, cells of the box)
        ok = (ci >= 0) & (ci < self.nx) & (cj >= 0) & (cj < self.ny)
        centre = self.origin + (np.stack([ci, cj], axis=-1) + 0.5) * self.h
        ok &= np.hypot(*(centre - d[:, None, :2]).transpose(2, 0, 1)) <= d[:, 2:]
        return np.unique(ci[ok] * self.ny + cj[ok])

    def value(
        self, field: np.ndarray, points: np.ndarray, direct: np.ndarray | None = None
    ) -> np.ndarray:
        """``field`` at each point: the least of ``field[c] + |p - c|`` over the four cell centres
        ``c`` around ``p`` (continuous, and ``inf`` only where all four are); shape of
        ``points[..., 0]``.

        ``direct``, the straight-line distances from the points to the field's sources, makes
        it exact in the open: where the grid's value is within the grid's own error of it
        (``OCTILE * direct + 2 h``: the octile metric, a source's cell, a point's cell), nothing
        is in the way, and ``direct`` is returned. Grid distances are anisotropic (exact along
        the axes and diagonals, 8 % long in between) and a source lies up to ``h / sqrt 2``
        from its cell's centre: without this, a critic would steer a robot off a straight line.
        """
        p = np.asarray(points, dtype=float)
        flat = p.reshape(-1, 2)
        g = (flat - self.origin) / self.h - 0.5
        i0 = np.floor(g).astype(np.int64)
        best = np.full(len(flat), np.inf)
        for di in (0, 1):
            for dj in (0, 1):
                i = np.clip(i0[:, 0] + di, 0, self.nx - 1)
                j = np.clip(i0[:, 1] + dj, 0, self.ny - 1)
                c = i * self.ny + j
                d = field[c] + np.hypot(*(flat - self.centres[c]).T)
                best = np.minimum(best, d)
        best = best.reshape(p.shape[:-1])
        if direct is not None:
            best = np.where(best <= OCTILE * direct + 2.0 * self.h, direct, best)
        return best

    def route(self, start: np.ndarray, goal: np.ndarray) -> np.ndarray | None:
        """The shortest grid route from ``start`` to ``goal`` through free cells (the cell
        centres, ``start`` and ``goal`` as the ends; collinear centres dropped), None when no
        free cell is near either or they are not connected. Nav2's NavFn planner, in short."""
        a, b = self.free_cell_near(start), self.free_cell_near(goal)
        if a < 0 or b < 0:
            return None
        _, pred = dijkstra(self.graph, directed=True, indices=b, return_predecessors=True)
        if a != b and pred[a] < 0:
            return None
        cells = walk(pred, a)[::-1]  # predecessors lead from a to the goal cell, the root
        pts = np.vstack([start, self.centres[cells], goal])
        d = np.diff(pts, axis=0)
        turn = np.abs(d[:-1, 0] * d[1:, 1] - d[:-1, 1] * d[1:, 0]) > 1e-12 * self.h**2
        keep = np.concatenate([[True], turn, [True]])
        return pts[keep]
