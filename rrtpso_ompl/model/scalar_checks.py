"""Exact point and motion checks one at a time, in plain Python floats (OMPL's callbacks).

OMPL asks for one state or one segment at a time (``isValid``, ``checkMotion``); for the few
obstacles near it, plain floats beat building numpy arrays. :class:`ScalarChecks` holds each
item of an :class:`~rrtpso_ompl.model.obstacle_index.ObstacleIndex` as a tuple of Python floats
and runs the same closed forms as the vectorised checks (:mod:`~rrtpso_ompl.model.geometry`'s
``*_xy`` twins), with a bounding-box rejection first. An index cell crowded with hundreds of a
polygon's edges goes through the vectorised formulas instead (:data:`_CROWDED`).

A configuration is free when its distance to every obstacle is at least the threshold (the
robot radius less the touch tolerance); a motion when every point of the segment is. Lengths are
in the problem's unit.
"""

from __future__ import annotations

import time

import numpy as np
import shapely

from ..gc_pause import cyclic_gc_paused
from .geometry import (
    point_in_polygon_xy,
    point_segment_distance_xy,
    segment_box_distance_xy,
    segment_segment_distance_xy,
)
from .obstacle_index import BOX, CIRCLE, EDGE, INTERIOR, ObstacleIndex

__all__ = ["ScalarChecks"]

#: Cells holding more items than this are checked with numpy in the scalar checks (the edges of
#: a detailed polygon crowd every cell next to it); fewer go through the Python loop, which is
#: cheaper for a handful.
_CROWDED = 256
#: Polygons with more vertices than this are tested for containing a point by shapely (a
#: prepared geometry, about 8 us whatever its size) instead of a Python loop over the vertices.
_SHAPELY_INSIDE = 64


class ScalarChecks:
    """:meth:`point_free` and :meth:`motion_free` over the items of an index.

    The base of :class:`~rrtpso_ompl.model.world.World`, whose scalar checks these are: OMPL
    calls them millions of times, so they are the world's own methods (a delegating call would
    add a tenth of a microsecond to each).

    Parameters
    ----------
    index : ObstacleIndex
        The obstacles, their index and the threshold.
    """

    def __init__(self, index: ObstacleIndex) -> None:
        #: ``time.perf_counter()`` after which :meth:`motion_free` answers "blocked" unchecked
        #: (None: never; :meth:`World.refusing_motions_after`).
        self.refuse_after: float | None = None
        # Plain attributes of this object (no lookups through the index in the hot loops).
        self.threshold = index.threshold
        self.box_frame = index.box_frame
        self._grid = index.grid
        self._indexed = index.indexed
        # Every item, for a world too small for its index (a tuple of millions costs 25 MB).
        self._all_ids = () if index.indexed else tuple(range(index.n_items))
        self._reach_boxes = index.reach_boxes
        self._first_interior = index.first_interior
        self._pair_distance = index.pair_distance
        self._crowd: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # cell -> (ids, their boxes)
        with cyclic_gc_paused():  # a tuple per item: 620,000 on a 4-million-cell map
            self._py = _python_items(index)

    def point_free(self, x: float, y: float) -> bool:
        """Whether the robot disc centred at ``(x, y)`` overlaps no obstacle (bounds unchecked)."""
        ids = self._grid.items(self._grid.cell_of(x, y)) if self._indexed else self._all_ids
        if len(ids) > _CROWDED and self._indexed:
            return self._clear_crowded(self._grid.cell_of(x, y), x, y, x, y, True)
        r = self.threshold
        py = self._py
        gx, gy = (x, y) if self.box_frame is None else self.box_frame.to_grid_xy(x, y)
        for k in ids:
            item = py[k]
            kind = item[0]
            if kind == CIRCLE:
                dx, dy = x - item[1], y - item[2]
                if dx * dx + dy * dy < item[4]:
                    return False
            elif kind == BOX:
                ex = max(item[1] - gx, 0.0, gx - item[3])
                ey = max(item[2] - gy, 0.0, gy - item[4])
                if ex * ex + ey * ey < r * r:
                    return False
            elif kind == EDGE:
                x0, y0, x1, y1 = item[5]
                inside_reach = x0 <= x <= x1 and y0 <= y <= y1
                if inside_reach and point_segment_distance_xy(x, y, *item[1:5]) < r:
                    return False
            elif _inside(x, y, item):
                return False
        return True

    def motion_free(self, ax: float, ay: float, bx: float, by: float) -> bool:
        """Whether every point of the segment ``(ax, ay)-(bx, by)`` is free (exact); False
        without a check after :attr:`refuse_after`."""
        if self.refuse_after is not None and time.perf_counter() >= self.refuse_after:
            return False
        if not self._indexed:
            return self._segment_clear(self._all_ids, ax, ay, bx, by, True)
        grid = self._grid
        first = grid.cell_of(ax, ay)
        # The first cell holds the interior of every polygon that could contain a; the segment
        # can only enter one elsewhere by crossing an edge, which the edges' cells hold.
        if not self._cell_clear(first, ax, ay, bx, by, True):
            return False
        if first == grid.cell_of(bx, by):
            return True
        # Cells in order from a to b, so a blocked motion usually stops within a cell or two.
        # An obstacle registered in several cells is looked at again in each: its bounding-box
        # rejection is cheaper than keeping a set of those already seen.
        clear = self._cell_clear
        for cell in grid.cells_on_segment(ax, ay, bx, by):
            if cell != first and not clear(cell, ax, ay, bx, by, False):
                return False
        return True

    def _cell_clear(self, cell: int, ax: float, ay: float, bx: float, by: float, first: bool):
        """:meth:`_segment_clear` for the items of one index cell, through numpy when it is
        crowded."""
        items = self._grid.items(cell)
        if len(items) > _CROWDED:
            return self._clear_crowded(cell, ax, ay, bx, by, first)
        return self._segment_clear(items, ax, ay, bx, by, first)

    def _clear_crowded(
        self, cell: int, ax: float, ay: float, bx: float, by: float, first: bool
    ) -> bool:
        """:meth:`_segment_clear` over a crowded cell in numpy: the items whose box grown by
        the reach meets the segment's box, then their exact distances (the vectorised formulas,
        the same closed forms)."""
        got = self._crowd.get(cell)
        if got is None:
            ids = np.asarray(self._grid.items(cell), dtype=np.intp)
            got = self._crowd[cell] = (ids, self._reach_boxes[ids])
        ids, box = got
        near = (box[:, 0] <= max(ax, bx)) & (box[:, 2] >= min(ax, bx))
        near &= (box[:, 1] <= max(ay, by)) & (box[:, 3] >= min(ay, by))
        cand = ids[near]
        if not first:
            cand = cand[cand < self._first_interior]
        if not len(cand):
            return True
        a, b = np.array([[ax, ay]]), np.array([[bx, by]])
        d = self._pair_distance(np.zeros(len(cand), dtype=np.intp), cand, a, b)
        return bool(d.min() >= self.threshold)

    def _segment_clear(self, ids, ax: float, ay: float, bx: float, by: float, first: bool) -> bool:
        """Whether the segment keeps the threshold from each obstacle of ``ids``; a polygon's
        interior is looked at only when ``first`` (the cell of ``a``, or every item)."""
        dx, dy = bx - ax, by - ay
        len2 = dx * dx + dy * dy
        sx0, sx1 = (ax, bx) if ax <= bx else (bx, ax)
        sy0, sy1 = (ay, by) if ay <= by else (by, ay)
        # The segment in the boxes' coordinates, and its bounding box there.
        if self.box_frame is None:
            gax, gay, gbx, gby, gx0, gx1, gy0, gy1 = ax, ay, bx, by, sx0, sx1, sy0, sy1
        else:
            gax, gay = self.box_frame.to_grid_xy(ax, ay)
            gbx, gby = self.box_frame.to_grid_xy(bx, by)
            gx0, gx1 = (gax, gbx) if gax <= gbx else (gbx, gax)
            gy0, gy1 = (gay, gby) if gay <= gby else (gby, gay)
        r = self.threshold
        py = self._py
        for k in ids:
            item = py[k]
            kind = item[0]
            if kind == CIRCLE:
                _, cx, cy, rr, rr2 = item
                # Bounding-box rejection first: most candidates are far from a short edge.
                if cx + rr < sx0 or cx - rr > sx1 or cy + rr < sy0 or cy - rr > sy1:
                    continue
                t = ((cx - ax) * dx + (cy - ay) * dy) / len2 if len2 > 0.0 else 0.0
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
                ex, ey = ax + t * dx - cx, ay + t * dy - cy
                if ex * ex + ey * ey < rr2:
                    return False
            elif kind == BOX:
                _, x0, y0, x1, y1 = item
                if gx1 < x0 - r or gx0 > x1 + r or gy1 < y0 - r or gy0 > y1 + r:
                    continue
                if segment_box_distance_xy(gax, gay, gbx, gby, x0, y0, x1, y1) < r:
                    return False
            elif kind == EDGE:
                x0, y0, x1, y1 = item[5]
                if sx1 < x0 or sx0 > x1 or sy1 < y0 or sy0 > y1:
                    continue
                if segment_segment_distance_xy(ax, ay, bx, by, *item[1:5]) < r:
                    return False
            elif first and _inside(ax, ay, item):
                return False
        return True


def _python_items(index: ObstacleIndex) -> list[tuple]:
    """Each item of the index as a tuple of plain Python data, in id order (no numpy scalars in
    the hot loop): ``(CIRCLE, cx, cy, r + threshold, (r + threshold)^2)``, ``(BOX, x0, y0, x1,
    y1)``, ``(EDGE, ax, ay, bx, by, its bounding box grown by the threshold)``, ``(INTERIOR, xs,
    ys, bounding box, prepared shapely polygon or None)``."""
    r = index.threshold
    py: list[tuple] = []
    for cx, cy, rad in index.circles.tolist():
        py.append((CIRCLE, cx, cy, rad + r, (rad + r) ** 2))
    for x0, y0, x1, y1 in index.boxes.tolist():
        py.append((BOX, x0, y0, x1, y1))
    for cx, cy, dx, dy in index.edges.tolist():
        # The edge's bounding box grown by the threshold: a quick rejection.
        reach = (min(cx, dx) - r, min(cy, dy) - r, max(cx, dx) + r, max(cy, dy) + r)
        py.append((EDGE, cx, cy, dx, dy, reach))
    for k, p in enumerate(index.polygons):
        xs, ys = tuple(p[:, 0].tolist()), tuple(p[:, 1].tolist())
        shape = index.shapes[k] if len(xs) > _SHAPELY_INSIDE else None
        py.append((INTERIOR, xs, ys, (min(xs), min(ys), max(xs), max(ys)), shape))
    return py


def _inside(x: float, y: float, item: tuple) -> bool:
    """Whether the point lies in the polygon of an interior item (its boundary may go either
    way: the edges' distance test catches it)."""
    _, xs, ys, (x0, y0, x1, y1), shape = item
    if x < x0 or x > x1 or y < y0 or y > y1:
        return False
    if shape is not None:
        return bool(shapely.intersects_xy(shape, x, y))
    return point_in_polygon_xy(x, y, xs, ys)
