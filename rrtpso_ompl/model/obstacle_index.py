"""The static obstacles as items of a spatial index, and their exact distances to segments.

Every obstacle of a :class:`~rrtpso_ompl.model.world.World` becomes one or more *items*, with
ids in this order: circles, axis-aligned boxes, the edges of the polygons (each on its own), the
polygons' interiors (by their bounding boxes). A :class:`~rrtpso_ompl.model.spatial.Grid`
registers each item by its bounding box grown by the *reach* (the clearance threshold plus a
margin), so a query gets only the items that can be within the threshold of it: a check near a
100,000-vertex polygon looks at the few edges near it, not at all of them.

:meth:`ObstacleIndex.pair_distance` measures (segment, item) pairs exactly with the vectorised
formulas of :mod:`~rrtpso_ompl.model.geometry`: a circle's distance minus its radius (never
below 0), the segment-box and segment-edge distances, and for a polygon's interior 0 when the
segment's first point lies in it (``inf`` otherwise: a segment that comes within the threshold
of none of a polygon's edges lies wholly inside or wholly outside it, as its first point does).

A turned map's boxes are squares of a :class:`~rrtpso_ompl.model.geometry.GridFrame`: points
are turned into the grid's coordinates before the box formulas (a rotation keeps distances).
All lengths are in the problem's unit.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterator, Sequence

import numpy as np
import shapely

from .geometry import (
    GridFrame,
    point_segment_distance,
    segment_box_distance,
    segment_segment_distance,
)
from .spatial import Grid

__all__ = ["BOX", "CIRCLE", "EDGE", "INTERIOR", "SMALL_WORLD", "ObstacleIndex"]

#: Kinds of the items in the index, in the order of their ids: circles, boxes, the edges of the
#: polygons, the polygons' interiors.
CIRCLE, BOX, EDGE, INTERIOR = 0, 1, 2, 3
#: Worlds with at most this many obstacles are checked without the index: for a handful of
#: obstacles a loop with bounding-box rejection beats walking grid cells.
SMALL_WORLD = 24
#: Most (segment, obstacle) pairs one vectorised step evaluates at once (memory bound).
_PAIR_CHUNK = 1_000_000

Bounds = tuple[tuple[float, float], tuple[float, float]]
#: Chunks of (segment, item) pairs: ``(first segment, segments, items)``.
Pairs = Iterator[tuple[int, np.ndarray, np.ndarray]]


class ObstacleIndex:
    """Circles, boxes and polygons as the items of a spatial index, measured exactly.

    Parameters
    ----------
    bounds : ((float, float), (float, float))
        The workspace bounds (the index covers them and every item).
    circles : (n, 3) ndarray
        ``(cx, cy, r)`` rows.
    boxes : (m, 4) ndarray
        ``(xmin, ymin, xmax, ymax)`` rows, in the coordinates of ``box_frame`` when given.
    polygons : list of (k, 2) ndarray
        Simple rings without the closing repeat.
    threshold : float
        Distance to every obstacle a free configuration needs (the robot radius less the touch
        tolerance).
    tol : float
        The touch tolerance (floating-point round-off allowed), for the index's margin.
    box_frame : GridFrame, optional
        The grid frame the boxes are squares of (None: the world's own axes).

    Attributes
    ----------
    edges : (e, 4) ndarray
        The polygons' edges ``(ax, ay, bx, by)``, ring after ring.
    shapes : ndarray of shapely.Polygon
        The polygons, prepared for "inside?" tests.
    n_circles, n_boxes, first_edge, first_interior, n_items : int
        The layout of the item ids.
    grid : Grid
        The spatial index over every item grown by :attr:`reach`.
    indexed : bool
        Whether queries go through the grid (more than :data:`SMALL_WORLD` items).
    reach_boxes : (n_items, 4) ndarray
        Each item's bounding box grown by :attr:`reach`.
    """

    def __init__(
        self,
        bounds: Bounds,
        circles: np.ndarray,
        boxes: np.ndarray,
        polygons: Sequence[np.ndarray],
        threshold: float,
        tol: float,
        box_frame: GridFrame | None = None,
    ) -> None:
        self.bounds = bounds
        self.circles = circles
        self.boxes = boxes
        self.polygons = polygons
        self.threshold = threshold
        self.box_frame = box_frame
        self.n_circles = len(circles)
        self.n_boxes = len(boxes)
        self._prepare_polygons()
        self.first_edge = self.n_circles + self.n_boxes
        self.first_interior = self.first_edge + len(self.edges)
        self.n_items = self.first_interior + len(polygons)
        #: Margin of every item's registration: the threshold and a hair (grazing is never missed).
        self.reach = threshold + 4.0 * tol
        self._prepare_grid()

    @property
    def n_obstacles(self) -> int:
        """Number of obstacles (circles, boxes and polygons)."""
        return self.n_circles + self.n_boxes + len(self.polygons)

    # ------------------------------------------------------------------------------------------
    # Preparation
    # ------------------------------------------------------------------------------------------
    def _prepare_polygons(self) -> None:
        """Polygon edges and shapes for inside tests."""
        if self.polygons:
            a = np.concatenate(self.polygons)
            b = np.concatenate([np.roll(p, -1, axis=0) for p in self.polygons])
            self.edges = np.hstack([a, b])
            self.shapes = shapely.polygons([shapely.linearrings(p) for p in self.polygons])
            shapely.prepare(self.shapes)  # each answers "inside?" through its own index
            self._poly_union = shapely.union_all(self.shapes)
            shapely.prepare(self._poly_union)
        else:
            self.edges = np.empty((0, 4))
            self.shapes = np.empty(0, dtype=object)
            self._poly_union = None

    @property
    def all_edges(self) -> np.ndarray:
        """Every edge of the polygons and boxes, ``(ax, ay, bx, by)`` rows: the polygons' first,
        then the boxes' first sides, second sides, ... (made on each call: on a map of millions
        of cells it is 80 MB that no check needs)."""
        c = self.box_corners()
        box_edges = np.concatenate([np.hstack([c[:, k], c[:, (k + 1) % 4]]) for k in range(4)])
        return np.vstack([self.edges, box_edges.reshape(-1, 4)])

    def _prepare_grid(self) -> None:
        """The grid over every item grown by its reach."""
        boxes = self.item_boxes()
        boxes[:, :2] -= self.reach
        boxes[:, 2:] += self.reach
        (xmin, ymin), (xmax, ymax) = self.bounds
        lo = np.array([xmin, ymin]) - self.reach
        hi = np.array([xmax, ymax]) + self.reach
        if self.n_items:
            lo = np.minimum(lo, boxes[:, :2].min(axis=0))
            hi = np.maximum(hi, boxes[:, 2:].max(axis=0))
        self.grid = Grid(lo, hi, boxes)
        self.indexed = self.n_items > SMALL_WORLD
        self.reach_boxes = boxes

    def box_corners(self) -> np.ndarray:
        """World corners ``(n_boxes, 4, 2)`` of the boxes, counter-clockwise from the first."""
        if self.box_frame is not None:
            return self.box_frame.box_corners(self.boxes)
        b = self.boxes
        return np.stack([b[:, [0, 1]], b[:, [2, 1]], b[:, [2, 3]], b[:, [0, 3]]], axis=1)

    def in_box_frame(self, p: np.ndarray) -> np.ndarray:
        """Points ``(..., 2)`` in the boxes' coordinates (themselves without a box frame)."""
        return p if self.box_frame is None else self.box_frame.to_grid(p)

    def _box_bounding_boxes(self) -> np.ndarray:
        """``(n_boxes, 4)`` world bounding boxes of the boxes (the boxes themselves without a
        box frame)."""
        if self.box_frame is None:
            return self.boxes
        c = self.box_corners()
        return np.hstack([c.min(axis=1), c.max(axis=1)]).reshape(-1, 4)

    def item_boxes(self) -> np.ndarray:
        """Bounding box ``(xmin, ymin, xmax, ymax)`` of every item, in id order: circles, boxes,
        polygon edges, polygon interiors."""
        c = self.circles
        circ = np.column_stack([c[:, 0] - c[:, 2], c[:, 1] - c[:, 2],
                                c[:, 0] + c[:, 2], c[:, 1] + c[:, 2]])  # fmt: skip
        e = self.edges
        edge = np.hstack([np.minimum(e[:, :2], e[:, 2:]), np.maximum(e[:, :2], e[:, 2:])])
        poly = np.array([[p[:, 0].min(), p[:, 1].min(), p[:, 0].max(), p[:, 1].max()]
                         for p in self.polygons]).reshape(-1, 4)  # fmt: skip
        return np.vstack([circ.reshape(-1, 4), self._box_bounding_boxes(), edge.reshape(-1, 4),
                          poly])  # fmt: skip

    # ------------------------------------------------------------------------------------------
    # Items and their distances
    # ------------------------------------------------------------------------------------------
    def kind_of(self, ids: np.ndarray) -> np.ndarray:
        """The kind of each item id (:data:`CIRCLE`, :data:`BOX`, :data:`EDGE`,
        :data:`INTERIOR`)."""
        starts = np.array([self.n_circles, self.first_edge, self.first_interior])
        return np.searchsorted(starts, ids, side="right")

    def pair_distance(self, seg: np.ndarray, ids: np.ndarray, a: np.ndarray, b: np.ndarray):
        """Exact distance of segment ``a[seg[k]]-b[seg[k]]`` to item ``ids[k]``, for every pair
        (``(len(seg),)`` array): a polygon's edge, or its interior (0 when the segment's first
        point lies in it, else ``inf``)."""
        d = np.empty(len(seg))
        kind = self.kind_of(ids)
        c = kind == CIRCLE
        if c.any():
            circ = self.circles[ids[c]]
            dc = point_segment_distance(circ[:, :2], a[seg[c]], b[seg[c]]) - circ[:, 2]
            d[c] = np.maximum(dc, 0.0)
        x = kind == BOX
        if x.any():
            ga, gb = self.in_box_frame(a[seg[x]]), self.in_box_frame(b[seg[x]])
            d[x] = segment_box_distance(ga, gb, self.boxes[ids[x] - self.n_circles])
        e = kind == EDGE
        if e.any():
            edges = self.edges[ids[e] - self.first_edge]
            d[e] = segment_segment_distance(a[seg[e]], b[seg[e]], edges)
        i = kind == INTERIOR
        if i.any():
            d[i] = self.interior_distance(a[seg[i]], ids[i] - self.first_interior)
        return d

    def interior_distance(self, p: np.ndarray, poly: np.ndarray) -> np.ndarray:
        """0 where point ``p[k]`` lies in (or on) polygon ``poly[k]``, else ``inf``.

        A segment that comes within the threshold of none of a polygon's edges lies wholly
        inside or wholly outside it, as its first point does; one that comes within it is
        blocked by that edge anyway."""
        inside = shapely.intersects_xy(self.shapes[poly], p[:, 0], p[:, 1])
        return np.where(inside, 0.0, np.inf)

    def in_polygons(self, p: np.ndarray) -> np.ndarray:
        """Whether each point of ``p`` ``(n, 2)`` lies in (or on) a polygon or a box (circles are
        not counted): ``(n,)`` booleans."""
        out = np.zeros(len(p), dtype=bool)
        if self._poly_union is not None:
            out |= shapely.intersects_xy(self._poly_union, p[:, 0], p[:, 1])
        if self.n_boxes:
            q, ids = self._pairs_near_points(p, 0.0, kind=BOX)
            b = self.boxes[ids - self.n_circles]
            g = self.in_box_frame(p[q])
            inside = (g[:, 0] >= b[:, 0]) & (g[:, 0] <= b[:, 2])
            inside &= (g[:, 1] >= b[:, 1]) & (g[:, 1] <= b[:, 3])
            out[q[inside]] = True
        return out

    # ------------------------------------------------------------------------------------------
    # Measuring many segments
    # ------------------------------------------------------------------------------------------
    def distance(
        self, a: np.ndarray, b: np.ndarray, cap: float | None, stop_at: float | None = None
    ) -> tuple[np.ndarray, int]:
        """Exact distance ``(n,)`` of each segment ``a[k]-b[k]`` (flat ``(n, 2)`` end points) to
        the nearest item, and how many of the segments were measured: all of them, unless
        ``time.perf_counter()`` passed ``stop_at`` between two chunks (the segments from that
        count on are then unmeasured, ``inf``).

        With a ``cap`` the items come from the index, and distances beyond ``cap`` may come
        back as ``inf``; without one every item is measured."""
        d = np.full(len(a), np.inf)
        if cap is None or not self.indexed:
            chunks = self._all_pairs(len(a))
        else:
            chunks = self._index_pairs(a, b, max(cap - self.threshold, 0.0))
        for s0, seg, ids in chunks:
            if stop_at is not None and time.perf_counter() >= stop_at:
                return d, s0
            np.minimum.at(d, seg, self.pair_distance(seg, ids, a, b))
        return d, len(a)

    def violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``sum_k max(0, threshold - d_k)`` over the circles and boxes plus
        ``max(0, threshold - d)`` for the union of the polygons, for each segment of flat
        ``(n, 2)`` end points (:meth:`World.segment_violation`)."""
        v = np.zeros(len(a))
        poly_d = np.full(len(a), np.inf)
        pairs = self._index_pairs(a, b, 0.0) if self.indexed else self._all_pairs(len(a))
        for _, seg, ids in pairs:
            d = self.pair_distance(seg, ids, a, b)
            is_poly = ids >= self.first_edge
            np.add.at(v, seg[~is_poly], np.maximum(0.0, self.threshold - d[~is_poly]))
            np.minimum.at(poly_d, seg[is_poly], d[is_poly])
        v += np.maximum(0.0, self.threshold - poly_d)
        return v

    def _all_pairs(self, n_segments: int) -> Pairs:
        """Every (segment, item) pair, in chunks of bounded size: ``(first segment, segments,
        items)``."""
        n = self.n_items
        if not n or not n_segments:
            return
        step = max(1, _PAIR_CHUNK // n)
        ids = np.arange(n)
        for s0 in range(0, n_segments, step):
            seg = np.repeat(np.arange(s0, min(s0 + step, n_segments)), n)
            yield s0, seg, np.tile(ids, len(seg) // n)

    def _index_pairs(self, a: np.ndarray, b: np.ndarray, extra: float) -> Pairs:
        """The (segment, item) pairs the index finds within the reach (plus ``extra``) of each
        segment, in chunks of consecutive segments: ``(first segment, segments, items)``.

        A chunk meets about :data:`_PAIR_CHUNK` / (the most items a cell holds) cells, so its
        pairs stay bounded also next to a polygon whose edges crowd every cell (a single
        segment's pairs are bounded by the index's registrations)."""
        if not self.n_items or not len(a):
            return
        h = self.grid.h
        if extra > 0.0:
            lo = np.minimum(a, b) - extra
            hi = np.maximum(a, b) + extra
            side = np.minimum(
                np.floor(hi / h) - np.floor(lo / h) + 1.0, [self.grid.nx, self.grid.ny]
            )
            cells = side[:, 0] * side[:, 1]
        else:
            cells = 9.0 * (np.ceil(np.hypot(*(b - a).T) / h) + 1.0)  # 3 x 3 around each sample
        per_chunk = max(1.0, _PAIR_CHUNK / max(self.grid.max_items, 1))
        bounds = np.searchsorted(np.cumsum(cells), np.arange(0, cells.sum(), per_chunk))
        starts = np.unique(np.concatenate([bounds, [len(a)]]))
        for s0, s1 in itertools.pairwise(starts):
            if extra > 0.0:
                seg, ids = self.grid.pairs_in_boxes(lo[s0:s1], hi[s0:s1])
            else:
                seg, ids = self.grid.pairs_on_segments(a[s0:s1], b[s0:s1])
            yield s0, seg + s0, ids

    def _pairs_near_points(self, p: np.ndarray, extra: float, kind: int):
        """(point, item) pairs of the items of one kind near each point."""
        seg, ids = self.grid.pairs_in_boxes(p - extra, p + extra)
        keep = self.kind_of(ids) == kind
        return seg[keep], ids[keep]
