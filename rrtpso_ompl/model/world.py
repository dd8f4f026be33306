"""The static world and exact collision checking for a disc robot.

A configuration (the robot's centre) is *free* when the robot disc of radius ``R`` does not overlap
any static obstacle, i.e. its distance to every obstacle is at least ``R``. A straight motion is
free when *every* point of the segment is free. Both tests are computed exactly, with no sampling:

* circle (centre ``c``, radius ``r``): distance from the segment to ``c`` minus ``r``;
* axis-aligned box (rectangles, the blocked cells of a map): zero when the segment meets the box,
  else the smallest of the distances from the segment's end points to the box and from the box's
  corners to the segment;
* polygon: zero when the segment crosses an edge or lies inside, else the smallest of the
  segment-to-edge distances (the distance between two non-crossing segments is attained at an
  end point of one of them). A segment that comes within ``R`` of no edge lies wholly inside or
  wholly outside the polygon, as its first point does.

A spatial index (:class:`~rrtpso_ompl.model.spatial.Grid`) hands every check only the obstacles
that can be within ``R`` of it, so a check costs about the same among 10 obstacles as among
10,000. A polygon is indexed as its edges, each on its own, and its interior (by its bounding
box, looked at only for a segment's first point): a check near a 100,000-vertex polygon looks at
the few edges near it, not at all of them. Two implementations of the same formulas serve two
callers:

* :meth:`World.motion_free` / :meth:`World.point_free` are scalar pure Python: OMPL asks for one
  segment at a time, and for a few candidates plain floats beat building numpy arrays (an index
  cell crowded with hundreds of a polygon's edges goes through the numpy formulas instead).
* :meth:`World.segments_free`, :meth:`World.segment_violation` and friends are vectorised numpy
  over many segments at once: the PSO evaluates whole swarms of paths per iteration.

A turned map (an origin yaw other than 0) keeps its merged cells as axis-aligned boxes in the
map's grid coordinates (:class:`~rrtpso_ompl.model.geometry.GridFrame`, ``box_frame``): each check
turns its point or segment into them before the box formulas, which stay exact (a rotation keeps
distances), and the index registers each box by the bounding box of its turned square.

Touching at exactly the robot radius is allowed, up to a tolerance of ``1e-9`` times the scale of
the workspace (floating-point round-off; :func:`~rrtpso_ompl.model.problem.touch_tolerance`).
"""

from __future__ import annotations

import functools
import itertools
import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager

import numpy as np
import shapely

from .geometry import (
    GridFrame,
    point_segment_distance,
    point_segment_distance_xy,
    segments_cross,
)
from .problem import Circle, Polygon, Problem, clearance_threshold, touch_tolerance
from .raster import Lattice, MapRaster
from .spatial import Grid

# clearance_threshold: the rule lives in problem (the loader shares it).
__all__ = ["MarkingStopped", "World", "clearance_threshold"]

Bounds = tuple[tuple[float, float], tuple[float, float]]

#: Worlds with at most this many obstacles are checked without the index: for a handful of
#: obstacles a loop with bounding-box rejection beats walking grid cells.
SMALL_WORLD = 24
#: Most (segment, obstacle) pairs one vectorised step evaluates at once (memory bound).
_PAIR_CHUNK = 1_000_000
#: (Cell, item) pairs a lattice marking measures between two looks at its stop condition: about
#: 7 ms of work, so a marking stopped by a deadline ends within that of it.
_MARK_CHUNK = 262_144


class MarkingStopped(Exception):
    """A lattice marking was stopped by the condition of :meth:`World.marking_stops` (a
    caller's deadline): the cells are not known, so nothing is returned."""


#: Kinds of the items in the index, in the order of their ids: circles, boxes, the edges of the
#: polygons, the polygons' interiors.
_CIRCLE, _BOX, _EDGE, _INTERIOR = 0, 1, 2, 3
#: Cells holding more items than this are checked with numpy in the scalar checks (the edges of
#: a detailed polygon crowd every cell next to it); fewer go through the Python loop, which is
#: cheaper for a handful.
_CROWDED = 256
#: Polygons with more vertices than this are tested for containing a point by shapely (a
#: prepared geometry, about 8 us whatever its size) instead of a Python loop over the vertices.
_SHAPELY_INSIDE = 64


class World:
    """Static obstacles, workspace bounds and a robot radius, prepared for fast exact checks.

    Parameters
    ----------
    bounds : ((float, float), (float, float))
        ``((xmin, ymin), (xmax, ymax))``: where the robot's centre may be.
    circles : sequence of (cx, cy, r)
        Circular obstacles.
    polygons : sequence of (m, 2) array_like
        Simple polygons, each a ring of vertices without the closing repeat.
    robot_radius : float
        Radius ``R`` of the robot disc (its safety zone), in the same unit.
    boxes : sequence of (xmin, ymin, xmax, ymax)
        Axis-aligned rectangles (a map's blocked cells, merged; rectangles of a problem file), in
        the coordinates of ``box_frame`` when one is given.
    raster : MapRaster, optional
        The occupancy grid the last ``raster_boxes`` boxes were merged from, for lattice queries
        (:meth:`free_cells`). Not with a ``box_frame``.
    raster_boxes : int
        How many of the boxes (the last ones) come from ``raster``.
    box_frame : GridFrame, optional
        The grid frame of a turned map: every box is a square of it (circles, polygons and the
        bounds stay in the world's coordinates).
    """

    def __init__(
        self,
        bounds: Bounds,
        circles: Sequence[Sequence[float]] = (),
        polygons: Sequence[np.ndarray | Sequence[Sequence[float]]] = (),
        robot_radius: float = 0.0,
        boxes: Sequence[Sequence[float]] = (),
        raster: MapRaster | None = None,
        raster_boxes: int = 0,
        box_frame: GridFrame | None = None,
    ) -> None:
        if raster is not None and box_frame is not None:
            raise ValueError("a raster is a lattice of the world's axes: not with a box frame")
        (xmin, ymin), (xmax, ymax) = bounds
        self.bounds = ((float(xmin), float(ymin)), (float(xmax), float(ymax)))
        self.robot_radius = float(robot_radius)
        #: Absolute tolerance for "touching is allowed" comparisons (floating-point round-off).
        self.tol = touch_tolerance(self.bounds)
        #: Distance to every obstacle that a free configuration or segment needs.
        self.threshold = clearance_threshold(self.robot_radius, self.tol)

        self.circles = np.asarray(circles, dtype=float).reshape(-1, 3)
        self.boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
        self.polygons = [np.asarray(p, dtype=float).reshape(-1, 2) for p in polygons]
        self._n_circles = len(self.circles)
        self._n_boxes = len(self.boxes)
        #: The grid frame the boxes are in (None: the world's own axes).
        self.box_frame = box_frame
        #: ``time.perf_counter()`` after which :meth:`motion_free` and :meth:`segments_free`
        #: answer "blocked" unchecked (None: never); see :meth:`refusing_motions_after`.
        self.refuse_after: float | None = None
        #: Checked between chunks of a lattice marking; see :meth:`marking_stops`.
        self.mark_stop: Callable[[], bool] | None = None
        self._prepare_polygons()
        #: Ids of the index's items: circles, boxes, polygon edges, polygon interiors.
        self._first_edge = self._n_circles + self._n_boxes
        self._first_interior = self._first_edge + len(self._edges)
        self._n_items = self._first_interior + len(self.polygons)
        self._prepare_scalar()
        self._prepare_index()
        self.raster = raster
        self._raster_boxes = int(raster_boxes) if raster is not None else 0

    # ------------------------------------------------------------------------------------------
    @classmethod
    def from_problem(
        cls,
        problem: Problem,
        obstacles: Sequence[Circle | Polygon] | None = None,
        robot_radius: float | None = None,
        *,
        lattice: bool = True,
    ) -> World:
        """Build the static world of a :class:`~rrtpso_ompl.model.Problem` (moving obstacles
        are not part of it; a map's blocked cells are boxes, in its grid frame when it is
        turned, and the unknown space around a turned map polygons).

        ``obstacles`` (default the problem's) and ``robot_radius`` (default its robot's) replace
        the problem's, over the same map and bounds (a detour among sweeps of moving obstacles).
        ``lattice=False`` leaves out the map's lattice view (:class:`MapRaster`, for the corridor
        stage; a turned map never has one: its cells are no lattice of the world's axes).
        """
        occupancy = getattr(problem, "map", None)
        frame = getattr(problem, "map_frame", None)
        raster = None
        if occupancy is not None and frame is None and lattice:
            o = occupancy
            raster = MapRaster.from_image(o.blocked, o.origin, o.resolution, o.unknown_blocks)
        shapes = [*(problem.obstacles if obstacles is None else obstacles),
                  *getattr(problem, "map_outside", ())]  # fmt: skip
        radius = problem.robot.radius if robot_radius is None else robot_radius
        return cls.from_obstacles(problem.bounds, shapes, radius,
                                  getattr(problem, "map_boxes", None), raster, frame)  # fmt: skip

    @classmethod
    def from_obstacles(
        cls,
        bounds: Bounds,
        obstacles: Sequence[Circle | Polygon],
        robot_radius: float,
        boxes: np.ndarray | None = None,
        raster: MapRaster | None = None,
        box_frame: GridFrame | None = None,
    ) -> World:
        """A world of the problem model's obstacles (:class:`~rrtpso_ompl.model.Circle`,
        :class:`~rrtpso_ompl.model.Polygon`; axis-aligned rectangles become boxes, unless the
        boxes are in a ``box_frame``) and extra ``boxes``."""
        circles = [(*o.center, o.radius) for o in obstacles if isinstance(o, Circle)]
        polys = [o for o in obstacles if isinstance(o, Polygon)]
        as_box = [box_frame is None and _is_box(o) for o in polys]
        rects = [_box_of(o) for o, b in zip(polys, as_box, strict=True) if b]
        polygons = [np.asarray(o.points) for o, b in zip(polys, as_box, strict=True) if not b]
        extra = np.asarray(boxes if boxes is not None else (), dtype=float).reshape(-1, 4)
        all_boxes = np.vstack([np.asarray(rects, dtype=float).reshape(-1, 4), extra])
        return cls(bounds, circles, polygons, robot_radius, all_boxes, raster, len(extra),
                   box_frame)  # fmt: skip

    @contextmanager
    def refusing_motions_after(self, deadline: float | None) -> Iterator[None]:
        """While the block runs, :meth:`motion_free` and :meth:`segments_free` (hence
        :meth:`path_valid`) answer "blocked" at once after ``deadline`` (``time.perf_counter()``
        seconds; None changes nothing).

        For work that must end by a deadline but cannot poll it inside a check: OMPL's path
        simplifier polls only between whole passes, and the swarm's shortcuts test a vertex's
        whole view at once; near a detailed polygon either can take longer than the time left.
        A refused motion is a shortcut not taken, so a path stays valid, and the work ends in
        microseconds."""
        saved = self.refuse_after
        self.refuse_after = deadline
        try:
            yield
        finally:
            self.refuse_after = saved

    @contextmanager
    def marking_stops(self, stop: Callable[[], bool] | None) -> Iterator[None]:
        """While the block runs, a lattice marking (:meth:`free_cells`, :meth:`centres_free`)
        raises :class:`MarkingStopped` once ``stop()`` is true (None changes nothing).

        Marking costs what the obstacles' detail costs: a polygon of 100,000 vertices makes a
        lattice of a few thousand cells take a second, more than a real-time budget. The
        marking looks at ``stop`` every :data:`_MARK_CHUNK` measured pairs, so a deadline holds
        whatever the obstacles."""
        worlds = [self] if self._non_raster is self else [self, self._non_raster]
        saved = [w.mark_stop for w in worlds]
        for w in worlds:
            w.mark_stop = stop
        try:
            yield
        finally:
            for w, old in zip(worlds, saved, strict=True):
                w.mark_stop = old

    def with_robot_radius(self, robot_radius: float) -> World:
        """The same obstacles for another robot radius."""
        return World(self.bounds, self.circles, self.polygons, robot_radius, self.boxes,
                     self.raster, self._raster_boxes, self.box_frame)  # fmt: skip

    # ------------------------------------------------------------------------------------------
    # Lattice queries (the corridor search)
    # ------------------------------------------------------------------------------------------
    def lattice(self, max_cells: int, split: int = 4) -> Lattice:
        """A lattice of about ``max_cells`` square cells inside the bounds: aligned with the map's
        cells when the world has one (a map cell split in at most ``split`` per side), else
        square cells centred in the bounds."""
        if self.raster is not None:
            if self.robot_radius <= 0.0 and not self._non_raster.n_obstacles:
                split = 1  # a point robot's free space is a union of map cells: finer adds nothing
            return self.raster.lattice(self.bounds, max_cells, split)
        (xmin, ymin), (xmax, ymax) = self.bounds
        h = math.sqrt((xmax - xmin) * (ymax - ymin) / max(max_cells, 1))
        lat = Lattice.over(self.bounds, h)
        while lat.n_cells > max_cells:  # rounding may add a row or column
            h *= 1.01
            lat = Lattice.over(self.bounds, h)
        return lat

    def free_cells(self, lat: Lattice, within: np.ndarray | None = None) -> np.ndarray:
        """(nx, ny) booleans: the lattice cells every point of which is a free configuration
        (for a point robot: cells no obstacle enters, which may touch one), conservatively.

        A map answers exactly (:meth:`MapRaster.free_cells`); circles, polygons and a problem's
        rectangles through the exact clearance at each cell's centre, which the whole square
        keeps up to ``h / sqrt(2)``. With ``within`` ((nx, ny) booleans) only those cells are
        asked about (the others come back False), and only obstacles near them are measured.
        """
        margin = self.threshold if self.robot_radius > 0.0 else 0.0
        free = np.ones((lat.nx, lat.ny), dtype=bool) if within is None else within.copy()
        if self.raster is not None:
            free &= self.raster.free_cells(lat, margin, self.bounds)
        shapes = self._non_raster
        if shapes.n_obstacles and free.any():
            free &= shapes._clear_cells(lat, margin + lat.h * math.sqrt(0.5), free)
        return free

    def point_free_cells(self, lat: Lattice) -> np.ndarray | None:
        """(nx, ny) booleans: the cells no obstacle enters, for a map with nothing but its cells
        (exact); None for any other world. The free space of a disc robot is these cells shrunk
        by its radius: a channel of them, with every corner it bends round wrapped at the radius,
        holds the robot's shortest path where the corridors are wider than the robot."""
        if self.raster is None or self._non_raster.n_obstacles:
            return None
        return self.raster.free_cells(lat, 0.0, self.bounds)

    def centres_free(self, lat: Lattice) -> np.ndarray:
        """(nx, ny) booleans: the lattice cells whose centre is a free configuration (exact;
        says nothing about the rest of the cell)."""
        return self._clear_cells(lat, self.threshold)

    def _clear_cells(self, lat: Lattice, need: float, asked=None) -> np.ndarray:
        """(nx, ny) booleans: cells whose centre is at least ``need`` from every obstacle.

        Each obstacle marks the cells near it (its bounding box grown by ``need``), with the
        exact distance from their centres: the work grows with the area the obstacles cover,
        not with the number of cells times the number of obstacles. With ``asked`` ((nx, ny)
        booleans) obstacles none of whose cells is asked about are skipped.
        """
        clear = np.ones((lat.nx, lat.ny), dtype=bool)
        (ox, oy), h = lat.origin, lat.h
        boxes = self._item_boxes() + np.array([-1.0, -1.0, 1.0, 1.0]) * need
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
        box_ids = np.arange(self._n_circles, self._n_circles + self._n_boxes)
        if self.box_frame is not None:
            box_ids = box_ids[:0]
        corners_of = self._mark_box_crosses(clear, lat, need, box_ids[ni[box_ids] > 0])
        counts = ni * nj
        counts[box_ids] = 0
        self._mark_pairs(clear, lat, need, i0, j0, nj, counts, asked)
        if corners_of:
            c_ids, c_i0, c_j0, c_nj, c_n = corners_of
            self._mark_pairs(clear, lat, need, c_i0, c_j0, c_nj, c_n, asked, c_ids)
        return clear

    def _mark_box_crosses(self, clear, lat: Lattice, need: float, ids: np.ndarray):
        """Mark the cells whose centre lies in a box grown by ``need`` along one axis (close to
        it, exactly); return the corner windows still to measure, as (ids, i0, j0, nj, counts).
        The index ranges lean inwards, so a cell on a boundary goes to the measured corners."""
        if not len(ids):
            return None
        (ox, oy), h = lat.origin, lat.h
        b = self.boxes[ids - self._n_circles]
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

    def _mark_pairs(self, clear, lat: Lattice, need: float, i0, j0, nj, counts, asked=None,
                    ids=None) -> None:  # fmt: skip
        """Measure (cell, obstacle) pairs: obstacle ``ids[m]`` (default ``m``) against the
        ``counts[m]`` cells of its window from ``(i0[m], j0[m])``, ``nj[m]`` cells a column;
        mark the close ones."""
        (ox, oy), h = lat.origin, lat.h
        if ids is None:
            ids = np.arange(len(counts))
        ends = np.searchsorted(np.cumsum(counts), np.arange(0, counts.sum(), _MARK_CHUNK))
        cuts = np.unique(np.concatenate([ends, [len(counts)]]))
        for a, b in itertools.pairwise(np.concatenate([[0], cuts])):
            if a >= b:
                continue
            if self.mark_stop is not None and self.mark_stop():
                raise MarkingStopped
            c = counts[a:b]
            which = np.repeat(np.arange(a, b), c)
            k = np.arange(c.sum()) - np.repeat(np.cumsum(c) - c, c)
            ci = i0[which] + k // nj[which]
            cj = j0[which] + k % nj[which]
            keep = clear[ci, cj] if asked is None else clear[ci, cj] & asked[ci, cj]
            ci, cj, obj = ci[keep], cj[keep], ids[which[keep]]
            pts = np.column_stack([ox + h * (ci + 0.5), oy + h * (cj + 0.5)])
            d = self._pair_distance(np.arange(len(obj)), obj, pts, pts)
            close = d < need
            clear[ci[close], cj[close]] = False

    @functools.cached_property
    def _non_raster(self) -> World:
        """The obstacles that do not come from the map raster (all of them without one)."""
        if self.raster is None:
            return self
        keep = self._n_boxes - self._raster_boxes
        return World(self.bounds, self.circles, self.polygons, self.robot_radius,
                     self.boxes[:keep], box_frame=self.box_frame)  # fmt: skip

    @property
    def n_obstacles(self) -> int:
        """Number of static obstacles (circles, boxes and polygons)."""
        return self._n_circles + self._n_boxes + len(self.polygons)

    @property
    def polygon_edges(self) -> np.ndarray:
        """Every edge of the polygons and boxes as a row ``(ax, ay, bx, by)``: ``(n_edges, 4)``."""
        return self._all_edges

    def in_polygons(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Whether each point ``(x[i], y[i])`` lies in (or on) a polygon or a box (circles are
        not counted)."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        p = np.column_stack([x.ravel(), y.ravel()])
        out = np.zeros(len(p), dtype=bool)
        if self._poly_union is not None:
            out |= shapely.intersects_xy(self._poly_union, p[:, 0], p[:, 1])
        if self._n_boxes:
            q, ids = self._pairs_near_points(p, 0.0, kind=_BOX)
            b = self.boxes[ids - self._n_circles]
            g = self._in_box_frame(p[q])
            inside = (g[:, 0] >= b[:, 0]) & (g[:, 0] <= b[:, 2])
            inside &= (g[:, 1] >= b[:, 1]) & (g[:, 1] <= b[:, 3])
            out[q[inside]] = True
        return out.reshape(x.shape)

    # ------------------------------------------------------------------------------------------
    # Preparation
    # ------------------------------------------------------------------------------------------
    def _prepare_polygons(self) -> None:
        """Polygon edges (with their polygon's id), shapes for inside tests."""
        if self.polygons:
            a = np.concatenate(self.polygons)
            b = np.concatenate([np.roll(p, -1, axis=0) for p in self.polygons])
            self._edges = np.hstack([a, b])
            sizes = np.array([len(p) for p in self.polygons])
            self._edge_start = np.concatenate([[0], np.cumsum(sizes)])
            self._shapes = shapely.polygons([shapely.linearrings(p) for p in self.polygons])
            shapely.prepare(self._shapes)  # each answers "inside?" through its own index
            self._poly_union = shapely.union_all(self._shapes)
            shapely.prepare(self._poly_union)
        else:
            self._edges = np.empty((0, 4))
            self._edge_start = np.zeros(1, dtype=np.intp)
            self._shapes = np.empty(0, dtype=object)
            self._poly_union = None
        # The boxes' edges in world coordinates: all first sides, then all second sides, ...
        c = self._box_corners()
        box_edges = np.concatenate([np.hstack([c[:, k], c[:, (k + 1) % 4]]) for k in range(4)])
        self._all_edges = np.vstack([self._edges, box_edges.reshape(-1, 4)])

    def _box_corners(self) -> np.ndarray:
        """World corners ``(n_boxes, 4, 2)`` of the boxes, counter-clockwise from the first."""
        if self.box_frame is not None:
            return self.box_frame.box_corners(self.boxes)
        b = self.boxes
        return np.stack([b[:, [0, 1]], b[:, [2, 1]], b[:, [2, 3]], b[:, [0, 3]]], axis=1)

    def _in_box_frame(self, p: np.ndarray) -> np.ndarray:
        """Points ``(..., 2)`` in the boxes' coordinates (themselves without a box frame)."""
        return p if self.box_frame is None else self.box_frame.to_grid(p)

    def _box_bounding_boxes(self) -> np.ndarray:
        """``(n_boxes, 4)`` world bounding boxes of the boxes (the boxes themselves without a
        box frame)."""
        if self.box_frame is None:
            return self.boxes
        c = self._box_corners()
        return np.hstack([c.min(axis=1), c.max(axis=1)]).reshape(-1, 4)

    def _item_boxes(self) -> np.ndarray:
        """Bounding box of every item of the index, in id order: circles, boxes, polygon edges,
        polygon interiors."""
        c = self.circles
        circ = np.column_stack([c[:, 0] - c[:, 2], c[:, 1] - c[:, 2],
                                c[:, 0] + c[:, 2], c[:, 1] + c[:, 2]])  # fmt: skip
        e = self._edges
        edge = np.hstack([np.minimum(e[:, :2], e[:, 2:]), np.maximum(e[:, :2], e[:, 2:])])
        poly = np.array([[p[:, 0].min(), p[:, 1].min(), p[:, 0].max(), p[:, 1].max()]
                         for p in self.polygons]).reshape(-1, 4)  # fmt: skip
        return np.vstack([circ.reshape(-1, 4), self._box_bounding_boxes(), edge.reshape(-1, 4),
                          poly])  # fmt: skip

    def _prepare_scalar(self) -> None:
        """Plain Python data for the scalar checks (no numpy scalars in the hot loop)."""
        r = self.threshold
        self._py: list[tuple] = []
        for cx, cy, rad in self.circles.tolist():
            self._py.append((_CIRCLE, cx, cy, rad + r, (rad + r) ** 2))
        for x0, y0, x1, y1 in self.boxes.tolist():
            self._py.append((_BOX, x0, y0, x1, y1))
        for cx, cy, dx, dy in self._edges.tolist():
            # The edge's bounding box grown by the threshold: a quick rejection.
            reach = (min(cx, dx) - r, min(cy, dy) - r, max(cx, dx) + r, max(cy, dy) + r)
            self._py.append((_EDGE, cx, cy, dx, dy, reach))
        for k, p in enumerate(self.polygons):
            xs, ys = tuple(p[:, 0].tolist()), tuple(p[:, 1].tolist())
            shape = self._shapes[k] if len(xs) > _SHAPELY_INSIDE else None
            self._py.append((_INTERIOR, xs, ys, (min(xs), min(ys), max(xs), max(ys)), shape))

    def _prepare_index(self) -> None:
        """The grid over every item grown by its reach (the threshold and a margin)."""
        n = self._n_items
        self._all_ids = tuple(range(n))
        self._reach = self.threshold + 4.0 * self.tol  # a margin: grazing is never missed
        boxes = self._item_boxes()
        boxes[:, :2] -= self._reach
        boxes[:, 2:] += self._reach
        (xmin, ymin), (xmax, ymax) = self.bounds
        lo = np.array([xmin, ymin]) - self._reach
        hi = np.array([xmax, ymax]) + self._reach
        if n:
            lo = np.minimum(lo, boxes[:, :2].min(axis=0))
            hi = np.maximum(hi, boxes[:, 2:].max(axis=0))
        self._grid = Grid(lo, hi, boxes)
        self._indexed = n > SMALL_WORLD
        self._reach_boxes = boxes
        self._crowd: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # cell -> (ids, their boxes)

    # ------------------------------------------------------------------------------------------
    # Scalar checks (OMPL callbacks)
    # ------------------------------------------------------------------------------------------
    def in_bounds(self, x: float, y: float) -> bool:
        """Whether the point lies in the bounds (inclusive, with tolerance)."""
        (xmin, ymin), (xmax, ymax) = self.bounds
        t = self.tol
        return xmin - t <= x <= xmax + t and ymin - t <= y <= ymax + t

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
            if kind == _CIRCLE:
                dx, dy = x - item[1], y - item[2]
                if dx * dx + dy * dy < item[4]:
                    return False
            elif kind == _BOX:
                ex = max(item[1] - gx, 0.0, gx - item[3])
                ey = max(item[2] - gy, 0.0, gy - item[4])
                if ex * ex + ey * ey < r * r:
                    return False
            elif kind == _EDGE:
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
            if kind == _CIRCLE:
                _, cx, cy, rr, rr2 = item
                # Bounding-box rejection first: most candidates are far from a short edge.
                if cx + rr < sx0 or cx - rr > sx1 or cy + rr < sy0 or cy - rr > sy1:
                    continue
                t = ((cx - ax) * dx + (cy - ay) * dy) / len2 if len2 > 0.0 else 0.0
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
                ex, ey = ax + t * dx - cx, ay + t * dy - cy
                if ex * ex + ey * ey < rr2:
                    return False
            elif kind == _BOX:
                _, x0, y0, x1, y1 = item
                if gx1 < x0 - r or gx0 > x1 + r or gy1 < y0 - r or gy0 > y1 + r:
                    continue
                if _segment_box_distance(gax, gay, gbx, gby, x0, y0, x1, y1) < r:
                    return False
            elif kind == _EDGE:
                x0, y0, x1, y1 = item[5]
                if sx1 < x0 or sx0 > x1 or sy1 < y0 or sy0 > y1:
                    continue
                if _segment_segment_distance(ax, ay, bx, by, *item[1:5]) < r:
                    return False
            elif first and _inside(ax, ay, item):
                return False
        return True

    # ------------------------------------------------------------------------------------------
    # Vectorised checks (PSO, validation of whole paths)
    # ------------------------------------------------------------------------------------------
    def point_clearance(self, points: np.ndarray, cap: float | None = None) -> np.ndarray:
        """Distance from each point to the nearest static obstacle (0 inside one).

        Parameters
        ----------
        points : (n, 2) array_like
        cap : float, optional
            Only distances up to ``cap`` matter: larger ones may be returned as ``inf`` (through
            the index, much faster among many obstacles).

        Returns
        -------
        (n,) ndarray
            ``inf`` when the world has no obstacles.
        """
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        return self.segment_distance(p, p, cap)

    def segment_distance(
        self, a: np.ndarray, b: np.ndarray, cap: float | None = None
    ) -> np.ndarray:
        """Exact distance from each segment ``a[i]-b[i]`` to the nearest static obstacle.

        Parameters
        ----------
        a, b : (..., 2) array_like
            End points; any leading shape, broadcast together.
        cap : float, optional
            Only distances up to ``cap`` matter: larger ones may come back as ``inf``. With a cap
            the obstacles come from the index; without one every obstacle is measured.

        Returns
        -------
        ndarray of shape ``(...)``
            0 where a segment touches or enters an obstacle; ``inf`` with no obstacles.
        """
        a, b, shape = _flat_pair(a, b)
        return self._distance(a, b, cap)[0].reshape(shape)

    def _distance(
        self, a: np.ndarray, b: np.ndarray, cap: float | None, stop_at: float | None = None
    ) -> tuple[np.ndarray, int]:
        """:meth:`segment_distance` of flat ``(n, 2)`` end points, and how many of the segments
        were measured: all of them, unless ``time.perf_counter()`` passed ``stop_at`` between
        two chunks (the segments from that count on are then unmeasured, ``inf``)."""
        d = np.full(len(a), np.inf)
        if cap is None or not self._indexed:
            chunks = self._all_pairs(len(a))
        else:
            chunks = self._index_pairs(a, b, max(cap - self.threshold, 0.0))
        for s0, seg, ids in chunks:
            if stop_at is not None and time.perf_counter() >= stop_at:
                return d, s0
            np.minimum.at(d, seg, self._pair_distance(seg, ids, a, b))
        return d, len(a)

    def segment_violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """How far each segment intrudes into the robot's safety zone, summed over obstacles.

        ``sum_k max(0, R - d_k)`` over the circles and boxes (so that a path crossing two
        obstacles is worse than one crossing one) plus ``max(0, R - d)`` for the union of
        polygons. Zero exactly when the segment is free (up to the tolerance). Shape as
        :meth:`segment_distance`.
        """
        a, b, shape = _flat_pair(a, b)
        v = np.zeros(len(a))
        poly_d = np.full(len(a), np.inf)
        pairs = self._index_pairs(a, b, 0.0) if self._indexed else self._all_pairs(len(a))
        for _, seg, ids in pairs:
            d = self._pair_distance(seg, ids, a, b)
            is_poly = ids >= self._first_edge
            np.add.at(v, seg[~is_poly], np.maximum(0.0, self.threshold - d[~is_poly]))
            np.minimum.at(poly_d, seg[is_poly], d[is_poly])
        v += np.maximum(0.0, self.threshold - poly_d)
        return v.reshape(shape)

    def segments_free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Boolean array: whether each segment ``a[i]-b[i]`` is free (bounds not checked).

        When the segments cross many index cells in all, long segments are checked a stretch at
        a time from ``a``, each stretch twice as long as
        the one before (4 index cells, then 8, 16, ...), and a segment leaves as soon as one
        stretch is blocked. In a cluttered world most long segments are blocked within a few
        cells, so they cost a few cells instead of their whole length; a free segment costs
        ``log2`` of its length in rounds. A segment is free exactly when all its stretches are.
        """
        a, b, shape = _flat_pair(a, b)
        thr = self.threshold
        stop = self.refuse_after
        d = b - a
        length = np.hypot(d[:, 0], d[:, 1])
        if not self._indexed or not len(a) or length.sum() <= 4096.0 * self._grid.h:
            # Few cells in all: one pass is cheaper. What the deadline left unmeasured is blocked.
            dist, done = self._distance(a, b, thr, stop)
            free = dist >= thr
            free[done:] = False
            return free.reshape(shape)
        ok = np.ones(len(a), dtype=bool)
        done = np.zeros(len(a))  # fraction of each segment already known to be free
        alive = np.arange(len(a))
        span = 4.0 * self._grid.h
        while len(alive):
            t0 = done[alive]
            n = length[alive]
            t1 = np.where(n > span, np.minimum(1.0, t0 + span / np.where(n > 0, n, 1.0)), 1.0)
            # The last stretch ends exactly at b, so no rounding moves the end point.
            pb = np.where((t1 >= 1.0)[:, None], b[alive], a[alive] + t1[:, None] * d[alive])
            pa = np.where((t0 <= 0.0)[:, None], a[alive], a[alive] + t0[:, None] * d[alive])
            dist, measured = self._distance(pa, pb, thr, stop)
            free = dist >= thr
            free[measured:] = False  # unmeasured by the deadline: blocked
            ok[alive[~free]] = False
            done[alive] = t1
            alive = alive[free & (t1 < 1.0)]
            span *= 2.0
        return ok.reshape(shape)

    def points_in_bounds(self, points: np.ndarray) -> np.ndarray:
        """Boolean array: whether each point lies in the bounds (inclusive, with tolerance)."""
        p = np.asarray(points, dtype=float)
        (xmin, ymin), (xmax, ymax) = self.bounds
        t = self.tol
        return (
            (p[..., 0] >= xmin - t)
            & (p[..., 0] <= xmax + t)
            & (p[..., 1] >= ymin - t)
            & (p[..., 1] <= ymax + t)
        )

    def path_valid(self, path: np.ndarray) -> bool:
        """Whether a polyline is valid: every waypoint in bounds and every segment free.

        The bounds are a box, hence convex, so segments between in-bounds waypoints stay in bounds.
        """
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(p) == 0 or not np.all(np.isfinite(p)):
            return False
        if not self.points_in_bounds(p).all():
            return False
        if len(p) == 1:
            return bool(self.segments_free(p, p)[0])
        return bool(self.segments_free(p[:-1], p[1:]).all())

    def path_clearance(self, path: np.ndarray) -> float:
        """Smallest distance from the polyline to any obstacle (``inf`` without obstacles).

        Asked through the index with a reach that doubles until some obstacle is within it (a
        path's clearance is usually small), so a long path among thousands of boxes costs its
        neighbourhood, not every (segment, obstacle) pair.
        """
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        a, b = (p, p) if len(p) == 1 else (p[:-1], p[1:])
        (xmin, ymin), (xmax, ymax) = self.bounds
        extent = max(xmax - xmin, ymax - ymin)
        reach = max(self.threshold, 1e-3 * extent)
        while self._indexed and reach < extent:
            d = float(self.segment_distance(a, b, cap=reach).min())
            if d <= reach - self.threshold:
                return d
            reach *= 4.0
        return float(self.segment_distance(a, b).min())

    def local_model(self, seg_lo: np.ndarray, seg_hi: np.ndarray,
                    deadline: float | None = None) -> LocalViolation | None:  # fmt: skip
        """A violation model for paths whose segment ``s`` lies in the box ``seg_lo[s]..seg_hi[s]``.

        Only obstacles within the robot radius of a segment's box can touch that segment, so the
        model checks just those (exact for every path that respects the boxes, and much cheaper
        in clutter). Used by the PSO, which confines each waypoint to a box per round.

        Its cost grows with the index's registrations in the boxes (a microsecond or so each:
        boxes over a polygon of 100,000 vertices hold hundreds of thousands), and it cannot be
        cut short: with a ``deadline`` (``time.perf_counter()`` seconds) it is built only when
        that many registrations, at the rate measured on this machine's earlier builds, end in
        time; else None.
        """
        seg_lo, seg_hi = np.asarray(seg_lo, float), np.asarray(seg_hi, float)
        pairs = int(self._grid.registrations_in_boxes(seg_lo, seg_hi).sum()) if len(seg_lo) else 0
        t = time.perf_counter()
        if deadline is not None and t + pairs * _LOCAL_BUILD.seconds_per_pair > deadline:
            return None
        model = LocalViolation(self, seg_lo, seg_hi)
        _LOCAL_BUILD.measured(pairs, time.perf_counter() - t)
        return model

    # ------------------------------------------------------------------------------------------
    # Pairs of (segment, obstacle) and their distances
    # ------------------------------------------------------------------------------------------
    def _all_pairs(self, n_segments: int):
        """Every (segment, item) pair, in chunks of bounded size: ``(first segment, segments,
        items)``."""
        n = self._n_items
        if not n or not n_segments:
            return
        step = max(1, _PAIR_CHUNK // n)
        ids = np.arange(n)
        for s0 in range(0, n_segments, step):
            seg = np.repeat(np.arange(s0, min(s0 + step, n_segments)), n)
            yield s0, seg, np.tile(ids, len(seg) // n)

    def _index_pairs(self, a: np.ndarray, b: np.ndarray, extra: float):
        """The (segment, item) pairs the index finds within the reach (plus ``extra``) of each
        segment, in chunks of consecutive segments: ``(first segment, segments, items)``.

        A chunk meets about :data:`_PAIR_CHUNK` / (the most items a cell holds) cells, so its
        pairs stay bounded also next to a polygon whose edges crowd every cell (a single
        segment's pairs are bounded by the index's registrations)."""
        if not self._n_items or not len(a):
            return
        h = self._grid.h
        if extra > 0.0:
            lo = np.minimum(a, b) - extra
            hi = np.maximum(a, b) + extra
            side = np.minimum(
                np.floor(hi / h) - np.floor(lo / h) + 1.0, [self._grid.nx, self._grid.ny]
            )
            cells = side[:, 0] * side[:, 1]
        else:
            cells = 9.0 * (np.ceil(np.hypot(*(b - a).T) / h) + 1.0)  # 3 x 3 around each sample
        per_chunk = max(1.0, _PAIR_CHUNK / max(self._grid.max_items, 1))
        bounds = np.searchsorted(np.cumsum(cells), np.arange(0, cells.sum(), per_chunk))
        starts = np.unique(np.concatenate([bounds, [len(a)]]))
        for s0, s1 in itertools.pairwise(starts):
            if extra > 0.0:
                seg, ids = self._grid.pairs_in_boxes(lo[s0:s1], hi[s0:s1])
            else:
                seg, ids = self._grid.pairs_on_segments(a[s0:s1], b[s0:s1])
            yield s0, seg + s0, ids

    def _pairs_near_points(self, p: np.ndarray, extra: float, kind: int):
        """(point, item) pairs of the items of one kind near each point."""
        seg, ids = self._grid.pairs_in_boxes(p - extra, p + extra)
        keep = self._kind_of(ids) == kind
        return seg[keep], ids[keep]

    def _kind_of(self, ids: np.ndarray) -> np.ndarray:
        """The kind of each item id (:data:`_CIRCLE`, :data:`_BOX`, :data:`_EDGE`,
        :data:`_INTERIOR`)."""
        starts = np.array([self._n_circles, self._first_edge, self._first_interior])
        return np.searchsorted(starts, ids, side="right")

    def _pair_distance(self, seg: np.ndarray, ids: np.ndarray, a: np.ndarray, b: np.ndarray):
        """Exact distance of segment ``seg[k]`` to item ``ids[k]``, for every pair: a polygon's
        edge, or its interior (0 when the segment's first point lies in it, else ``inf``)."""
        d = np.empty(len(seg))
        kind = self._kind_of(ids)
        c = kind == _CIRCLE
        if c.any():
            circ = self.circles[ids[c]]
            dc = point_segment_distance(circ[:, :2], a[seg[c]], b[seg[c]]) - circ[:, 2]
            d[c] = np.maximum(dc, 0.0)
        x = kind == _BOX
        if x.any():
            ga, gb = self._in_box_frame(a[seg[x]]), self._in_box_frame(b[seg[x]])
            d[x] = _segment_box_distance_v(ga, gb, self.boxes[ids[x] - self._n_circles])
        e = kind == _EDGE
        if e.any():
            edges = self._edges[ids[e] - self._first_edge]
            d[e] = _segment_segment_distance_v(a[seg[e]], b[seg[e]], edges)
        i = kind == _INTERIOR
        if i.any():
            d[i] = self._interior_distance(a[seg[i]], ids[i] - self._first_interior)
        return d

    def _interior_distance(self, p: np.ndarray, poly: np.ndarray) -> np.ndarray:
        """0 where point ``p[k]`` lies in (or on) polygon ``poly[k]``, else ``inf``.

        A segment that comes within the threshold of none of a polygon's edges lies wholly
        inside or wholly outside it, as its first point does; one that comes within it is
        blocked by that edge anyway."""
        inside = shapely.intersects_xy(self._shapes[poly], p[:, 0], p[:, 1])
        return np.where(inside, 0.0, np.inf)


class _BuildRate:
    """Seconds a :class:`LocalViolation` takes per registration of the index in its boxes: a
    prior on the slow side (1-1.6 µs measured on the reference machine for large builds), then
    what this process measures on builds large enough to time."""

    def __init__(self, prior: float = 2e-6, timed: int = 20_000) -> None:
        self.seconds_per_pair = prior
        self.timed = timed

    def measured(self, pairs: int, seconds: float) -> None:
        if pairs >= self.timed:
            self.seconds_per_pair = 0.5 * (self.seconds_per_pair + seconds / pairs)


_LOCAL_BUILD = _BuildRate()


class LocalViolation:
    """:meth:`World.segment_violation` for a fixed number of segments confined to boxes.

    Candidate obstacles per segment come from the index once (padded with an obstacle that is never
    near, so the per-call work is one dense broadcast over ``(paths, segments, candidates)``).
    """

    def __init__(self, world: World, seg_lo: np.ndarray, seg_hi: np.ndarray) -> None:
        self.world = world
        n_seg = len(seg_lo)
        far = 1e6 * max(1.0, *(abs(v) for b in world.bounds for v in b))
        if world.n_obstacles:
            seg, ids = world._grid.pairs_in_boxes(seg_lo, seg_hi)
        else:
            seg, ids = np.empty(0, dtype=np.intp), np.empty(0, dtype=np.intp)
        kind = world._kind_of(ids)
        c = kind == _CIRCLE
        self.circles = _gather(seg[c], world.circles[ids[c]], n_seg, np.array([far, far, 0.0]))
        x = kind == _BOX
        self.boxes = _gather(seg[x], world.boxes[ids[x] - world._n_circles], n_seg,
                             np.array([far, far, far, far]))  # fmt: skip
        # Polygons: the edges near each segment's box, and the interiors that could hold its
        # first point (per segment: a segment near a large polygon has many edges, the rest few).
        p = kind >= _EDGE
        self.polygon_segments = np.unique(seg[p]).tolist()
        order = np.argsort(seg[p], kind="stable")
        p_seg, p_ids, p_kind = seg[p][order], ids[p][order], kind[p][order]
        cut = np.searchsorted(p_seg, np.arange(n_seg + 1))
        self._edges: list[np.ndarray] = []
        self._edge_lo: list[np.ndarray] = []  # their bounding boxes
        self._edge_hi: list[np.ndarray] = []
        self._edge_mid: list[np.ndarray] = []  # their mid-points and half lengths
        self._edge_half: list[np.ndarray] = []
        self._interiors: list[np.ndarray] = []
        for s in range(n_seg):
            mine, kinds = p_ids[cut[s] : cut[s + 1]], p_kind[cut[s] : cut[s + 1]]
            edges = world._edges[mine[kinds == _EDGE] - world._first_edge]
            self._edges.append(edges)
            self._edge_lo.append(np.minimum(edges[:, :2], edges[:, 2:]))
            self._edge_hi.append(np.maximum(edges[:, :2], edges[:, 2:]))
            self._edge_mid.append(0.5 * (edges[:, :2] + edges[:, 2:]))
            self._edge_half.append(0.5 * np.hypot(*(edges[:, 2:] - edges[:, :2]).T))
            self._interiors.append(mine[kinds == _INTERIOR] - world._first_interior)

    def violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Same as :meth:`World.segment_violation` for ``a, b`` of shape ``(P, S, 2)``."""
        world = self.world
        r_need = world.threshold
        v = np.zeros(a.shape[:2])
        A = a[:, :, None, :]
        B = b[:, :, None, :]
        if self.circles.shape[1]:
            c = self.circles[None, :, :, :2]
            d = point_segment_distance(c, A, B) - self.circles[None, :, :, 2]
            v += np.maximum(0.0, r_need - np.maximum(d, 0.0)).sum(axis=2)
        if self.boxes.shape[1]:
            shape = (a.shape[0], a.shape[1], self.boxes.shape[1])
            GA, GB = world._in_box_frame(A), world._in_box_frame(B)  # once per (path, segment)
            d = _segment_box_distance_v(
                np.broadcast_to(GA, (*shape, 2)).reshape(-1, 2),
                np.broadcast_to(GB, (*shape, 2)).reshape(-1, 2),
                np.broadcast_to(self.boxes[None], (*shape, 4)).reshape(-1, 4),
            ).reshape(shape)
            v += np.maximum(0.0, r_need - d).sum(axis=2)
        n = a.shape[0]
        for s in self.polygon_segments:
            best = np.full(n, np.inf)
            edges = self._edges[s]
            if len(edges):
                # Only an edge whose box comes within the threshold of a particle's segment's box
                # can be nearer than the threshold: a cheap test before the exact distances (a
                # segment's box may hold thousands of edges of a detailed polygon).
                lo = np.minimum(a[:, s], b[:, s]) - r_need
                hi = np.maximum(a[:, s], b[:, s]) + r_need
                e_lo, e_hi = self._edge_lo[s], self._edge_hi[s]
                near = (e_lo[None, :, 0] <= hi[:, None, 0]) & (e_hi[None, :, 0] >= lo[:, None, 0])
                near &= (e_lo[None, :, 1] <= hi[:, None, 1]) & (e_hi[None, :, 1] >= lo[:, None, 1])
                p_idx, e_idx = np.nonzero(near)
                # Then an edge whose mid-point lies farther than the threshold plus half the
                # edge from the segment cannot come within the threshold either.
                d_mid = point_segment_distance(self._edge_mid[s][e_idx], a[p_idx, s], b[p_idx, s])
                keep = d_mid <= r_need + self._edge_half[s][e_idx]
                p_idx, e_idx = p_idx[keep], e_idx[keep]
                d = _segment_segment_distance_v(a[p_idx, s], b[p_idx, s], edges[e_idx])
                np.minimum.at(best, p_idx, d)
            for poly in self._interiors[s].tolist():
                best = np.minimum(best, world._interior_distance(a[:, s], np.full(n, poly)))
            v[:, s] += np.maximum(0.0, r_need - best)
        return v


def _gather(seg: np.ndarray, rows: np.ndarray, n_seg: int, pad: np.ndarray) -> np.ndarray:
    """(S, K, m) array of the rows of each segment (``seg[k]`` owns ``rows[k]``), padded."""
    counts = np.bincount(seg, minlength=n_seg) if len(seg) else np.zeros(n_seg, dtype=np.intp)
    k = max(1, int(counts.max()) if n_seg else 1)
    out = np.broadcast_to(pad, (n_seg, k, len(pad))).copy()
    if len(seg):
        order = np.argsort(seg, kind="stable")
        s = seg[order]
        slot = np.arange(len(s)) - np.repeat(np.cumsum(counts) - counts, counts)
        out[s, slot] = rows[order]
    return out


def _flat_pair(a, b) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return a.reshape(-1, 2), b.reshape(-1, 2), a.shape[:-1]


def _is_box(polygon: Polygon) -> bool:
    """Whether a polygon is an axis-aligned rectangle (checked exactly by the box formulas)."""
    if len(polygon.points) != 4:
        return False
    xs = sorted({p[0] for p in polygon.points})
    ys = sorted({p[1] for p in polygon.points})
    corners = {(x, y) for x in xs for y in ys}
    return len(xs) == 2 and len(ys) == 2 and set(polygon.points) == corners


def _box_of(polygon: Polygon) -> tuple[float, float, float, float]:
    xs = [p[0] for p in polygon.points]
    ys = [p[1] for p in polygon.points]
    return min(xs), min(ys), max(xs), max(ys)


# ----------------------------------------------------------------------------------------------
# Box distances
# ----------------------------------------------------------------------------------------------
def _segment_box_distance(ax, ay, bx, by, x0, y0, x1, y1) -> float:
    """Exact distance from segment a-b to the closed box [x0, x1] x [y0, y1] (0 when they meet)."""
    # Liang-Barsky: does the segment meet the box?
    dx, dy = bx - ax, by - ay
    t0, t1 = 0.0, 1.0
    hit = True
    for p, q in ((-dx, ax - x0), (dx, x1 - ax), (-dy, ay - y0), (dy, y1 - ay)):
        if p == 0.0:
            if q < 0.0:
                hit = False
                break
        else:
            t = q / p
            if p < 0.0:
                t0 = t if t > t0 else t0
            else:
                t1 = t if t < t1 else t1
            if t0 > t1:
                hit = False
                break
    if hit:
        return 0.0
    # Otherwise the distance is attained at an end point of the segment or a corner of the box.
    ex = max(x0 - ax, 0.0, ax - x1)
    ey = max(y0 - ay, 0.0, ay - y1)
    fx = max(x0 - bx, 0.0, bx - x1)
    fy = max(y0 - by, 0.0, by - y1)
    d = min(math.sqrt(ex * ex + ey * ey), math.sqrt(fx * fx + fy * fy))
    for cx, cy in ((x0, y0), (x1, y0), (x1, y1), (x0, y1)):
        d = min(d, point_segment_distance_xy(cx, cy, ax, ay, bx, by))
    return d


def _segment_box_distance_v(a: np.ndarray, b: np.ndarray, box: np.ndarray) -> np.ndarray:
    """:func:`_segment_box_distance` for arrays: ``a, b`` (k, 2), ``box`` (k, 4)."""
    d = b - a
    t0 = np.zeros(len(a))
    t1 = np.ones(len(a))
    ok = np.ones(len(a), dtype=bool)
    for p, q in ((-d[:, 0], a[:, 0] - box[:, 0]), (d[:, 0], box[:, 2] - a[:, 0]),
                 (-d[:, 1], a[:, 1] - box[:, 1]), (d[:, 1], box[:, 3] - a[:, 1])):  # fmt: skip
        zero = p == 0.0
        ok &= ~(zero & (q < 0.0))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            t = np.where(zero, 0.0, q / np.where(zero, 1.0, p))
        t0 = np.where(~zero & (p < 0.0), np.maximum(t0, t), t0)
        t1 = np.where(~zero & (p > 0.0), np.minimum(t1, t), t1)
    hit = ok & (t0 <= t1)

    def to_box(pt: np.ndarray) -> np.ndarray:
        ex = np.maximum(np.maximum(box[:, 0] - pt[:, 0], 0.0), pt[:, 0] - box[:, 2])
        ey = np.maximum(np.maximum(box[:, 1] - pt[:, 1], 0.0), pt[:, 1] - box[:, 3])
        return np.hypot(ex, ey)

    out = np.minimum(to_box(a), to_box(b))
    for ix, iy in ((0, 1), (2, 1), (2, 3), (0, 3)):
        corner = np.column_stack([box[:, ix], box[:, iy]])
        out = np.minimum(out, point_segment_distance(corner, a, b))
    return np.where(hit, 0.0, out)


# ----------------------------------------------------------------------------------------------
# Scalar polygon primitives (pure Python floats)
# ----------------------------------------------------------------------------------------------
def _inside(x: float, y: float, item: tuple) -> bool:
    """Whether the point lies in the polygon of an interior item (its boundary may go either
    way: the edges' distance test catches it)."""
    _, xs, ys, (x0, y0, x1, y1), shape = item
    if x < x0 or x > x1 or y < y0 or y > y1:
        return False
    if shape is not None:
        return bool(shapely.intersects_xy(shape, x, y))
    return _point_in_polygon(x, y, xs, ys)


def _point_in_polygon(x: float, y: float, xs: tuple[float, ...], ys: tuple[float, ...]) -> bool:
    """Even-odd ray casting (boundary points may go either way; callers also test distance)."""
    inside = False
    n = len(xs)
    j = n - 1
    for i in range(n):
        xi, yi, xj, yj = xs[i], ys[i], xs[j], ys[j]
        if (yi > y) != (yj > y) and x < (xj - xi) * (y - yi) / (yj - yi) + xi:
            inside = not inside
        j = i
    return inside


def _segment_segment_distance(
    ax: float, ay: float, bx: float, by: float, cx: float, cy: float, dx: float, dy: float
) -> float:
    """Exact distance between the segments a-b and c-d (0 when they cross)."""
    d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    if d1 * d2 < 0.0 and d3 * d4 < 0.0:
        return 0.0
    # Otherwise the distance is attained at an end point of one of them.
    return min(
        point_segment_distance_xy(ax, ay, cx, cy, dx, dy),
        point_segment_distance_xy(bx, by, cx, cy, dx, dy),
        point_segment_distance_xy(cx, cy, ax, ay, bx, by),
        point_segment_distance_xy(dx, dy, ax, ay, bx, by),
    )


def _segment_segment_distance_v(a: np.ndarray, b: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`_segment_segment_distance` for arrays: ``a, b`` (k, 2), edges ``e`` (k, 4)."""
    e0, e1 = e[:, :2], e[:, 2:]
    d = np.minimum(
        np.minimum(point_segment_distance(a, e0, e1), point_segment_distance(b, e0, e1)),
        np.minimum(point_segment_distance(e0, a, b), point_segment_distance(e1, a, b)),
    )
    d[segments_cross(a, b, e0, e1)] = 0.0
    return d
