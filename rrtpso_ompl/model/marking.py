"""Marking the free cells of a lattice (the corridor search's view of a world).

A :class:`~rrtpso_ompl.model.raster.Lattice` of square cells of side ``h`` covers the bounds;
:func:`free_cells` says which cells hold only free configurations, conservatively: a map's cells
exactly (:meth:`~rrtpso_ompl.model.raster.MapRaster.free_cells`), circles, polygons and a
problem's rectangles through the exact clearance at each cell's centre, which the whole square
keeps up to ``h / sqrt(2)``.

Each obstacle marks the cells near it (its bounding box grown by the clearance needed), with the
exact distance from their centres (:meth:`~rrtpso_ompl.model.obstacle_index.ObstacleIndex.
pair_distance`): the work grows with the area the obstacles cover, not with the number of cells
times the number of obstacles. A box marks the cross of rows and columns it covers wholesale, by
slicing; only the corners of its grown box need distances. The marking looks at a stop
condition every :data:`_MARK_CHUNK` measured pairs and raises :class:`MarkingStopped` when it
fires, so a caller's deadline holds whatever the obstacles' detail. Lengths are in the problem's
unit.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np

from .obstacle_index import ObstacleIndex
from .raster import Lattice, MapRaster

__all__ = ["MarkingStopped", "clear_cells", "free_cells", "lattice_of"]

Bounds = tuple[tuple[float, float], tuple[float, float]]

#: (Cell, item) pairs a lattice marking measures between two looks at its stop condition: about
#: 7 ms of work, so a marking stopped by a deadline ends within that of it.
_MARK_CHUNK = 262_144


class MarkingStopped(Exception):
    """A lattice marking was stopped by the condition of
    :meth:`~rrtpso_ompl.model.world.World.marking_stops` (a caller's deadline): the cells are not
    known, so nothing is returned."""


def lattice_of(bounds: Bounds, max_cells: int, split: int = 4,
               raster: MapRaster | None = None) -> Lattice:  # fmt: skip
    """A lattice of about ``max_cells`` square cells inside ``bounds``: aligned with the map's
    cells with a ``raster`` (a map cell split in at most ``split`` per side), else square cells
    centred in the bounds."""
    if raster is not None:
        return raster.lattice(bounds, max_cells, split)
    (xmin, ymin), (xmax, ymax) = bounds
    h = math.sqrt((xmax - xmin) * (ymax - ymin) / max(max_cells, 1))
    lat = Lattice.over(bounds, h)
    while lat.n_cells > max_cells:  # rounding may add a row or column
        h *= 1.01
        lat = Lattice.over(bounds, h)
    return lat


def free_cells(
    lat: Lattice,
    margin: float,
    raster: MapRaster | None,
    shapes: ObstacleIndex,
    within: np.ndarray | None = None,
    stop: Callable[[], bool] | None = None,
) -> np.ndarray:
    """(nx, ny) booleans: the lattice cells every point of which is at least ``margin`` from
    the map's blocked cells (``raster``, exactly) and from the obstacles of ``shapes`` (through
    the clearance at each cell's centre, which the square keeps up to ``h / sqrt(2)``),
    conservatively. With ``within`` only those cells are asked about (the others come back
    False); ``stop`` as for :func:`clear_cells`."""
    free = np.ones((lat.nx, lat.ny), dtype=bool) if within is None else within.copy()
    if raster is not None:
        free &= raster.free_cells(lat, margin, shapes.bounds)
    if shapes.n_obstacles and free.any():
        free &= clear_cells(shapes, lat, margin + lat.h * math.sqrt(0.5), free, stop)
    return free


def clear_cells(
    index: ObstacleIndex,
    lat: Lattice,
    need: float,
    asked: np.ndarray | None = None,
    stop: Callable[[], bool] | None = None,
) -> np.ndarray:
    """(nx, ny) booleans: cells whose centre is at least ``need`` from every item of ``index``.

    With ``asked`` ((nx, ny) booleans) obstacles none of whose cells is asked about are
    skipped. Raises :class:`MarkingStopped` when ``stop()`` is true between two chunks.
    """
    clear = np.ones((lat.nx, lat.ny), dtype=bool)
    (ox, oy), h = lat.origin, lat.h
    boxes = index.item_boxes() + np.array([-1.0, -1.0, 1.0, 1.0]) * need
    i0 = np.clip(np.floor((boxes[:, 0] - ox) / h - 0.5), 0, lat.nx).astype(np.int64)
    i1 = np.clip(np.ceil((boxes[:, 2] - ox) / h - 0.5) + 1, 0, lat.nx).astype(np.int64)
    j0 = np.clip(np.floor((boxes[:, 1] - oy) / h - 0.5), 0, lat.ny).astype(np.int64)
    j1 = np.clip(np.ceil((boxes[:, 3] - oy) / h - 0.5) + 1, 0, lat.ny).astype(np.int64)
    ni, nj = np.maximum(i1 - i0, 0), np.maximum(j1 - j0, 0)
    if asked is not None:
        # Asked cells in each obstacle's box, from a summed-area table.
        sat = np.zeros((lat.nx + 1, lat.ny + 1), dtype=np.int64)
        sat[1:, 1:] = asked.cumsum(axis=0).cumsum(axis=1)
        inside = sat[i1, j1] - sat[i0, j1] - sat[i1, j0] + sat[i0, j0]
        ni = np.where(inside > 0, ni, 0)
    # A box's cross (its own rows grown by `need` up and down, its own columns grown left
    # and right) is close wholesale: marked by slicing, no distances; only the corners of
    # its grown box need them.
    # (Not for the turned squares of a box frame: they are measured as every other item.)
    box_ids = np.arange(index.n_circles, index.n_circles + index.n_boxes)
    if index.box_frame is not None:
        box_ids = box_ids[:0]
    corners_of = _mark_box_crosses(index, clear, lat, need, box_ids[ni[box_ids] > 0])
    counts = ni * nj
    counts[box_ids] = 0
    pairs = _PairMarker(index, clear, lat, need, asked, stop)
    pairs.mark(i0, j0, nj, counts)
    if corners_of:
        c_ids, c_i0, c_j0, c_nj, c_n = corners_of
        pairs.mark(c_i0, c_j0, c_nj, c_n, c_ids)
    return clear


def _mark_box_crosses(index: ObstacleIndex, clear, lat: Lattice, need: float, ids: np.ndarray):
    """Mark the cells whose centre lies in a box grown by ``need`` along one axis (close to
    it, exactly); return the corner windows still to measure, as (ids, i0, j0, nj, counts).
    The index ranges lean inwards, so a cell on a boundary goes to the measured corners."""
    if not len(ids):
        return None
    (ox, oy), h = lat.origin, lat.h
    b = index.boxes[ids - index.n_circles]
    eps = 1e-9 * h

    def lo(v, origin, n):  # first cell whose centre is >= v
        return np.clip(np.ceil((v - origin) / h - 0.5 - eps), 0, n).astype(np.int64)

    def hi(v, origin, n):  # past the last cell whose centre is <= v
        return np.clip(np.floor((v - origin) / h - 0.5 + eps) + 1, 0, n).astype(np.int64)

    xi0, xi1 = lo(b[:, 0], ox, lat.nx), hi(b[:, 2], ox, lat.nx)
    yj0, yj1 = lo(b[:, 1], oy, lat.ny), hi(b[:, 3], oy, lat.ny)
    gi0, gi1 = lo(b[:, 0] - need, ox, lat.nx), hi(b[:, 2] + need, ox, lat.nx)
    gj0, gj1 = lo(b[:, 1] - need, oy, lat.ny), hi(b[:, 3] + need, oy, lat.ny)
    for k in range(len(ids)):
        clear[xi0[k] : xi1[k], gj0[k] : gj1[k]] = False
        clear[gi0[k] : gi1[k], yj0[k] : yj1[k]] = False
    # Corner windows (a cell or so of slack round each corner square), measured exactly.
    out_ids, out_i0, out_j0, out_nj, out_n = [], [], [], [], []
    for ci0, ci1 in ((gi0 - 1, xi0 + 1), (xi1 - 1, gi1 + 1)):
        for cj0, cj1 in ((gj0 - 1, yj0 + 1), (yj1 - 1, gj1 + 1)):
            a0 = np.clip(ci0, 0, lat.nx)
            a1 = np.clip(ci1, 0, lat.nx)
            c0 = np.clip(cj0, 0, lat.ny)
            c1 = np.clip(cj1, 0, lat.ny)
            out_ids.append(ids)
            out_i0.append(a0)
            out_j0.append(c0)
            out_nj.append(np.maximum(c1 - c0, 0))
            out_n.append(np.maximum(a1 - a0, 0) * np.maximum(c1 - c0, 0))
    cat = np.concatenate
    return cat(out_ids), cat(out_i0), cat(out_j0), cat(out_nj), cat(out_n)


class _PairMarker:
    """Measures (cell, item) pairs of one marking and marks the close cells of ``clear``."""

    def __init__(self, index: ObstacleIndex, clear: np.ndarray, lat: Lattice, need: float,
                 asked: np.ndarray | None, stop: Callable[[], bool] | None) -> None:  # fmt: skip
        self.index, self.clear, self.lat, self.need = index, clear, lat, need
        self.asked, self.stop = asked, stop

    def mark(self, i0, j0, nj, counts, ids=None) -> None:
        """Measure item ``ids[m]`` (default ``m``) against the ``counts[m]`` cells of its window
        from ``(i0[m], j0[m])``, ``nj[m]`` cells a column; mark the close ones."""
        clear, asked = self.clear, self.asked
        (ox, oy), h = self.lat.origin, self.lat.h
        if ids is None:
            ids = np.arange(len(counts))
        ends = np.searchsorted(np.cumsum(counts), np.arange(0, counts.sum(), _MARK_CHUNK))
        cuts = np.unique(np.concatenate([ends, [len(counts)]]))
        for a, b in itertools.pairwise(np.concatenate([[0], cuts])):
            if a >= b:
                continue
            if self.stop is not None and self.stop():
                raise MarkingStopped
            c = counts[a:b]
            which = np.repeat(np.arange(a, b), c)
            k = np.arange(c.sum()) - np.repeat(np.cumsum(c) - c, c)
            ci = i0[which] + k // nj[which]
            cj = j0[which] + k % nj[which]
            keep = clear[ci, cj] if asked is None else clear[ci, cj] & asked[ci, cj]
            ci, cj, obj = ci[keep], cj[keep], ids[which[keep]]
            pts = np.column_stack([ox + h * (ci + 0.5), oy + h * (cj + 0.5)])
            d = self.index.pair_distance(np.arange(len(obj)), obj, pts, pts)
            close = d < self.need
            clear[ci[close], cj[close]] = False
