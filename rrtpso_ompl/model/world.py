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

* :meth:`World.motion_free` / :meth:`World.point_free` are scalar pure Python
  (:mod:`.scalar_checks`): OMPL asks for one segment at a time, and for a few candidates plain
  floats beat building numpy arrays (an index cell crowded with hundreds of a polygon's edges
  goes through the numpy formulas instead).
* :meth:`World.segments_free`, :meth:`World.segment_violation` and friends are vectorised numpy
  over many segments at once (:mod:`.obstacle_index`): the PSO evaluates whole swarms of paths
  per iteration (:meth:`World.local_model`, :mod:`.local_violation`, culls them to boxes).

The lattice queries of the corridor stage (:meth:`World.free_cells` and friends) live in
:mod:`.marking`; the distance formulas in :mod:`.geometry`.

A turned map (an origin yaw other than 0) keeps its merged cells as axis-aligned boxes in the
map's grid coordinates (:class:`~rrtpso_ompl.model.geometry.GridFrame`, ``box_frame``): each check
turns its point or segment into them before the box formulas, which stay exact (a rotation keeps
distances), and the index registers each box by the bounding box of its turned square.

Touching at exactly the robot radius is allowed, up to a tolerance of ``1e-9`` times the scale of
the workspace (floating-point round-off; :func:`~rrtpso_ompl.model.problem.touch_tolerance`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager

import numpy as np

from .geometry import GridFrame, bounding_box, is_axis_aligned_rectangle
from .local_violation import LocalViolation, local_model
from .marking import MarkingStopped, clear_cells, free_cells, lattice_of
from .obstacle_index import SMALL_WORLD, ObstacleIndex
from .problem_types import Circle, Polygon, Problem, clearance_threshold, touch_tolerance
from .raster import Lattice, MapRaster
from .scalar_checks import ScalarChecks

# clearance_threshold: the rule lives in problem (the loader shares it). MarkingStopped and
# SMALL_WORLD live with the marking and the index; callers know them from here.
__all__ = ["SMALL_WORLD", "MarkingStopped", "World", "clearance_threshold"]

Bounds = tuple[tuple[float, float], tuple[float, float]]


class World(ScalarChecks):
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
        #: The grid frame the boxes are in (None: the world's own axes).
        self.box_frame = box_frame
        #: Checked between chunks of a lattice marking; see :meth:`marking_stops`.
        self.mark_stop: Callable[[], bool] | None = None
        #: The obstacles as items of a spatial index, measured exactly (:mod:`.obstacle_index`).
        self.index = ObstacleIndex(self.bounds, self.circles, self.boxes, self.polygons,
                                   self.threshold, self.tol, box_frame)  # fmt: skip
        # point_free and motion_free: the inherited scalar checks over the index. Sets
        # refuse_after: the time after which motion_free and segments_free answer "blocked"
        # unchecked (None: never; refusing_motions_after).
        ScalarChecks.__init__(self, self.index)
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
        as_box = [box_frame is None and is_axis_aligned_rectangle(o.points) for o in polys]
        rects = [bounding_box(o.points) for o, b in zip(polys, as_box, strict=True) if b]
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
        marking (:mod:`.marking`) looks at ``stop`` every ``_MARK_CHUNK`` measured pairs, so a
        deadline holds whatever the obstacles."""
        saved = self.mark_stop
        self.mark_stop = stop
        try:
            yield
        finally:
            self.mark_stop = saved

    def with_robot_radius(self, robot_radius: float) -> World:
        """The same obstacles for another robot radius."""
        return World(self.bounds, self.circles, self.polygons, robot_radius, self.boxes,
                     self.raster, self._raster_boxes, self.box_frame)  # fmt: skip

    # ------------------------------------------------------------------------------------------
    # Lattice queries (the corridor search; :mod:`.marking`)
    # ------------------------------------------------------------------------------------------
    def lattice(self, max_cells: int, split: int = 4) -> Lattice:
        """A lattice of about ``max_cells`` square cells inside the bounds: aligned with the map's
        cells when the world has one (a map cell split in at most ``split`` per side), else
        square cells centred in the bounds."""
        point_robot_on_cells = self.robot_radius <= 0.0 and self.raster is not None
        if point_robot_on_cells and not self.non_raster_index.n_obstacles:
            split = 1  # a point robot's free space is a union of map cells: finer adds nothing
        return lattice_of(self.bounds, max_cells, split, self.raster)

    def free_cells(self, lat: Lattice, within: np.ndarray | None = None) -> np.ndarray:
        """(nx, ny) booleans: the lattice cells every point of which is a free configuration
        (for a point robot: cells no obstacle enters, which may touch one), conservatively.

        A map answers exactly (:meth:`MapRaster.free_cells`); circles, polygons and a problem's
        rectangles through the exact clearance at each cell's centre, which the whole square
        keeps up to ``h / sqrt(2)``. With ``within`` ((nx, ny) booleans) only those cells are
        asked about (the others come back False), and only obstacles near them are measured.
        """
        margin = self.threshold if self.robot_radius > 0.0 else 0.0
        shapes = self.non_raster_index
        return free_cells(lat, margin, self.raster, shapes, within, self.mark_stop)

    def point_free_cells(self, lat: Lattice) -> np.ndarray | None:
        """(nx, ny) booleans: the cells no obstacle enters, for a map with nothing but its cells
        (exact); None for any other world. The free space of a disc robot is these cells shrunk
        by its radius: a channel of them, with every corner it bends round wrapped at the radius,
        holds the robot's shortest path where the corridors are wider than the robot."""
        if self.raster is None or self.non_raster_index.n_obstacles:
            return None
        return self.raster.free_cells(lat, 0.0, self.bounds)

    def centres_free(self, lat: Lattice) -> np.ndarray:
        """(nx, ny) booleans: the lattice cells whose centre is a free configuration (exact;
        says nothing about the rest of the cell)."""
        return clear_cells(self.index, lat, self.threshold, None, self.mark_stop)

    @functools.cached_property
    def non_raster_index(self) -> ObstacleIndex:
        """The obstacles that do not come from the map raster (all of them without one), as an
        index: what a lattice marking measures besides the raster's own cells."""
        if self.raster is None:
            return self.index
        keep = len(self.boxes) - self._raster_boxes
        return ObstacleIndex(self.bounds, self.circles, self.boxes[:keep], self.polygons,
                             self.threshold, self.tol, self.box_frame)  # fmt: skip

    @property
    def n_obstacles(self) -> int:
        """Number of static obstacles (circles, boxes and polygons)."""
        return self.index.n_obstacles

    @property
    def polygon_edges(self) -> np.ndarray:
        """Every edge of the polygons and boxes as a row ``(ax, ay, bx, by)``: ``(n_edges, 4)``."""
        return self.index.all_edges

    def in_polygons(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Whether each point ``(x[i], y[i])`` lies in (or on) a polygon or a box (circles are
        not counted)."""
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        p = np.column_stack([x.ravel(), y.ravel()])
        return self.index.in_polygons(p).reshape(x.shape)

    # ------------------------------------------------------------------------------------------
    # Scalar checks (OMPL callbacks): point_free and motion_free, of ScalarChecks
    # ------------------------------------------------------------------------------------------
    def in_bounds(self, x: float, y: float) -> bool:
        """Whether the point lies in the bounds (inclusive, with tolerance)."""
        (xmin, ymin), (xmax, ymax) = self.bounds
        t = self.tol
        return xmin - t <= x <= xmax + t and ymin - t <= y <= ymax + t

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
        return self.index.distance(a, b, cap)[0].reshape(shape)

    def segment_violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """How far each segment intrudes into the robot's safety zone, summed over obstacles.

        ``sum_k max(0, R - d_k)`` over the circles and boxes (so that a path crossing two
        obstacles is worse than one crossing one) plus ``max(0, R - d)`` for the union of
        polygons. Zero exactly when the segment is free (up to the tolerance). Shape as
        :meth:`segment_distance`.
        """
        a, b, shape = _flat_pair(a, b)
        return self.index.violation(a, b).reshape(shape)

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
        index = self.index
        if not index.indexed or not len(a) or length.sum() <= 4096.0 * index.grid.h:
            # Few cells in all: one pass is cheaper. What the deadline left unmeasured is blocked.
            dist, done = self.index.distance(a, b, thr, stop)
            free = dist >= thr
            free[done:] = False
            return free.reshape(shape)
        ok = np.ones(len(a), dtype=bool)
        done = np.zeros(len(a))  # fraction of each segment already known to be free
        alive = np.arange(len(a))
        span = 4.0 * index.grid.h
        while len(alive):
            t0 = done[alive]
            n = length[alive]
            t1 = np.where(n > span, np.minimum(1.0, t0 + span / np.where(n > 0, n, 1.0)), 1.0)
            # The last stretch ends exactly at b, so no rounding moves the end point.
            pb = np.where((t1 >= 1.0)[:, None], b[alive], a[alive] + t1[:, None] * d[alive])
            pa = np.where((t0 <= 0.0)[:, None], a[alive], a[alive] + t0[:, None] * d[alive])
            dist, measured = self.index.distance(pa, pb, thr, stop)
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
        while self.index.indexed and reach < extent:
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
        return local_model(self.index, seg_lo, seg_hi, deadline)


def _flat_pair(a, b) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
    """End points broadcast together and flattened to ``(n, 2)``, and their leading shape."""
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return a.reshape(-1, 2), b.reshape(-1, 2), a.shape[:-1]
