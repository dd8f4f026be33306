"""The static world and exact collision checking for a disc robot.

A configuration (the robot's centre) is *free* when the robot disc of radius ``R`` does not overlap
any static obstacle, i.e. its distance to every obstacle is at least ``R``. A straight motion is
free when *every* point of the segment is free. Both tests are computed exactly, with no sampling:

* circle (centre ``c``, radius ``r``): distance from the segment to ``c`` minus ``r``;
* polygon: zero when the segment crosses an edge or lies inside, else the smallest of the
  point-to-segment distances between the segment's end points and the edges and between the
  polygon's vertices and the segment (the distance between two non-crossing segments is attained
  at an end point of one of them).

Two implementations of the same formulas serve two callers:

* :meth:`World.motion_free` / :meth:`World.point_free` are scalar pure Python: OMPL asks for one
  segment at a time, and for a handful of obstacles a Python loop with bounding-box rejection is
  about 20x faster than building numpy arrays per call.
* :meth:`World.segment_distance` and friends are vectorised numpy over many segments at once: the
  PSO evaluates whole swarms of paths per iteration.

Touching at exactly the robot radius is allowed, up to a tolerance of ``1e-9`` times the size of
the workspace (floating-point round-off).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely

from .geometry import point_segment_distance, point_segment_distance_xy, segments_cross
from .problem import Circle, Polygon, Problem, clearance_threshold, touch_tolerance

__all__ = ["World", "clearance_threshold"]  # the rule lives in problem (the loader shares it)


@dataclass(frozen=True, eq=False)
class _PolygonData:
    """Prepared per-polygon data for the scalar checks."""

    xs: tuple[float, ...]
    ys: tuple[float, ...]
    bbox: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax


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
    """

    def __init__(
        self,
        bounds: tuple[tuple[float, float], tuple[float, float]],
        circles: Sequence[Sequence[float]] = (),
        polygons: Sequence[np.ndarray | Sequence[Sequence[float]]] = (),
        robot_radius: float = 0.0,
    ) -> None:
        (xmin, ymin), (xmax, ymax) = bounds
        self.bounds = ((float(xmin), float(ymin)), (float(xmax), float(ymax)))
        self.robot_radius = float(robot_radius)
        #: Absolute tolerance for "touching is allowed" comparisons (floating-point round-off).
        self.tol = touch_tolerance(self.bounds)

        circ = np.asarray(circles, dtype=float).reshape(-1, 3)
        self.circles = circ
        self.polygons = [np.asarray(p, dtype=float).reshape(-1, 2) for p in polygons]

        # --- vectorised data -------------------------------------------------------------------
        # Every polygon edge a->b as one row; the PSO checks (segments x edges) in one broadcast.
        if self.polygons:
            a = np.concatenate(self.polygons)
            b = np.concatenate([np.roll(p, -1, axis=0) for p in self.polygons])
            self._edges = np.hstack([a, b])
            self._vertices = a
            self._poly_union = shapely.union_all([shapely.Polygon(p) for p in self.polygons])
            shapely.prepare(self._poly_union)
        else:
            self._edges = np.empty((0, 4))
            self._vertices = np.empty((0, 2))
            self._poly_union = None

        #: Distance to every obstacle that a free configuration or segment needs.
        self.threshold = clearance_threshold(self.robot_radius, self.tol)

        # --- scalar data (plain Python floats: no numpy scalars in the hot loop) -----------------
        r_need = self.threshold
        self._circles_py = [
            (float(cx), float(cy), float(r) + r_need, (float(r) + r_need) ** 2)
            for cx, cy, r in circ
        ]
        self._polys_py = []
        for p in self.polygons:
            self._polys_py.append(
                _PolygonData(
                    xs=tuple(float(v) for v in p[:, 0]),
                    ys=tuple(float(v) for v in p[:, 1]),
                    bbox=(
                        float(p[:, 0].min()) - r_need,
                        float(p[:, 1].min()) - r_need,
                        float(p[:, 0].max()) + r_need,
                        float(p[:, 1].max()) + r_need,
                    ),
                )
            )

    # ------------------------------------------------------------------------------------------
    @classmethod
    def from_problem(cls, problem: Problem) -> World:
        """Build the static world of a :class:`~rrtpso_ompl.model.Problem` (moving obstacles
        are not part of it)."""
        return cls.from_obstacles(problem.bounds, problem.obstacles, problem.robot.radius)

    @classmethod
    def from_obstacles(
        cls,
        bounds: tuple[tuple[float, float], tuple[float, float]],
        obstacles: Sequence[Circle | Polygon],
        robot_radius: float,
    ) -> World:
        """A world of the problem model's obstacles (:class:`~rrtpso_ompl.model.Circle`,
        :class:`~rrtpso_ompl.model.Polygon`)."""
        circles = [(*o.center, o.radius) for o in obstacles if isinstance(o, Circle)]
        polygons = [np.asarray(o.points) for o in obstacles if isinstance(o, Polygon)]
        return cls(bounds, circles, polygons, robot_radius)

    def with_robot_radius(self, robot_radius: float) -> World:
        """The same obstacles for another robot radius."""
        return World(self.bounds, self.circles, self.polygons, robot_radius)

    @property
    def polygon_edges(self) -> np.ndarray:
        """Every polygon edge as a row ``(ax, ay, bx, by)``: shape ``(n_edges, 4)``."""
        return self._edges

    def in_polygons(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Whether each point ``(x[i], y[i])`` lies in (or on) a polygon (circles not counted)."""
        x = np.asarray(x, dtype=float)
        if self._poly_union is None:
            return np.zeros(x.shape, dtype=bool)
        return shapely.intersects_xy(self._poly_union, x, np.asarray(y, dtype=float))

    @property
    def n_obstacles(self) -> int:
        """Number of static obstacles."""
        return len(self.circles) + len(self.polygons)

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
        for cx, cy, _, rr2 in self._circles_py:
            dx, dy = x - cx, y - cy
            if dx * dx + dy * dy < rr2:
                return False
        if self._polys_py:
            r_need = self.threshold
            for poly in self._polys_py:
                x0, y0, x1, y1 = poly.bbox
                if x < x0 or x > x1 or y < y0 or y > y1:
                    continue
                if _point_in_polygon(x, y, poly.xs, poly.ys):
                    return False
                if _point_polygon_boundary_distance(x, y, poly.xs, poly.ys) < r_need:
                    return False
        return True

    def motion_free(self, ax: float, ay: float, bx: float, by: float) -> bool:
        """Whether every point of the segment ``(ax, ay)-(bx, by)`` is free (exact)."""
        dx, dy = bx - ax, by - ay
        len2 = dx * dx + dy * dy
        sx0, sx1 = (ax, bx) if ax <= bx else (bx, ax)
        sy0, sy1 = (ay, by) if ay <= by else (by, ay)
        for cx, cy, rr, rr2 in self._circles_py:
            # Bounding-box rejection first: most obstacles are far from a short RRT* edge.
            if cx + rr < sx0 or cx - rr > sx1 or cy + rr < sy0 or cy - rr > sy1:
                continue
            if len2 > 0.0:
                t = ((cx - ax) * dx + (cy - ay) * dy) / len2
                t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
            else:
                t = 0.0
            ex, ey = ax + t * dx - cx, ay + t * dy - cy
            if ex * ex + ey * ey < rr2:
                return False
        if self._polys_py:
            r_need = self.threshold
            for poly in self._polys_py:
                x0, y0, x1, y1 = poly.bbox
                if sx1 < x0 or sx0 > x1 or sy1 < y0 or sy0 > y1:
                    continue
                if _segment_polygon_distance(ax, ay, bx, by, poly.xs, poly.ys) < r_need:
                    return False
        return True

    # ------------------------------------------------------------------------------------------
    # Vectorised checks (PSO, validation of whole paths)
    # ------------------------------------------------------------------------------------------
    def point_clearance(self, points: np.ndarray) -> np.ndarray:
        """Distance from each point to the nearest static obstacle (0 inside one).

        Parameters
        ----------
        points : (n, 2) array_like

        Returns
        -------
        (n,) ndarray
            ``inf`` when the world has no obstacles.
        """
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        return self.segment_distance(p, p)

    def segment_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Exact distance from each segment ``a[i]-b[i]`` to the nearest static obstacle.

        Parameters
        ----------
        a, b : (..., 2) array_like
            End points; any leading shape, broadcast together.

        Returns
        -------
        ndarray of shape ``(...)``
            0 where a segment touches or enters an obstacle; ``inf`` with no obstacles.
        """
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        a, b = np.broadcast_arrays(a, b)
        shape = a.shape[:-1]
        a = a.reshape(-1, 2)
        b = b.reshape(-1, 2)
        d = np.full(a.shape[0], np.inf)
        if len(self.circles):
            d = np.minimum(d, self._segment_circle_distance(a, b).min(axis=1))
        if len(self.polygons):
            d = np.minimum(d, self._segment_polygon_distance(a, b))
        return d.reshape(shape)

    def segment_violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """How far each segment intrudes into the robot's safety zone, summed over obstacles.

        ``sum_k max(0, R - d_k)`` for circles (so that a path crossing two obstacles is worse than
        one crossing one) plus ``max(0, R - d)`` for the union of polygons. Zero exactly when the
        segment is free (up to the tolerance). Shape as :meth:`segment_distance`.
        """
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        a, b = np.broadcast_arrays(a, b)
        shape = a.shape[:-1]
        a = a.reshape(-1, 2)
        b = b.reshape(-1, 2)
        r_need = self.threshold
        v = np.zeros(a.shape[0])
        if len(self.circles):
            v += np.maximum(0.0, r_need - self._segment_circle_distance(a, b)).sum(axis=1)
        if len(self.polygons):
            v += np.maximum(0.0, r_need - self._segment_polygon_distance(a, b))
        return v.reshape(shape)

    def segments_free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Boolean array: whether each segment ``a[i]-b[i]`` is free (bounds not checked)."""
        return self.segment_distance(a, b) >= self.threshold

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
        """Smallest distance from the polyline to any obstacle (``inf`` without obstacles)."""
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(p) == 1:
            return float(self.point_clearance(p)[0])
        return float(self.segment_distance(p[:-1], p[1:]).min())

    def local_model(self, seg_lo: np.ndarray, seg_hi: np.ndarray) -> LocalViolation:
        """A violation model for paths whose segment ``s`` lies in the box ``seg_lo[s]..seg_hi[s]``.

        Only obstacles within the robot radius of a segment's box can touch that segment, so the
        model checks just those (exact for every path that respects the boxes, and much cheaper
        in clutter). Used by the PSO, which confines each waypoint to a box per round.
        """
        return LocalViolation(self, np.asarray(seg_lo, float), np.asarray(seg_hi, float))

    # ------------------------------------------------------------------------------------------
    def _segment_circle_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(n, m) distance from n segments to the boundaries of m circles (0 when inside)."""
        c = self.circles[:, :2]
        return np.maximum(
            0.0,
            point_segment_distance(c[None, :, :], a[:, None, :], b[:, None, :])
            - self.circles[None, :, 2],
        )

    def _segment_polygon_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(n,) distance from n segments to the union of the polygons (0 when touching/inside)."""
        e0 = self._edges[None, :, :2]
        e1 = self._edges[None, :, 2:]
        A = a[:, None, :]
        B = b[:, None, :]
        # Distance between two non-crossing segments is attained at one of the four end points.
        d = np.minimum(
            np.minimum(point_segment_distance(A, e0, e1), point_segment_distance(B, e0, e1)),
            np.minimum(point_segment_distance(e0, A, B), point_segment_distance(e1, A, B)),
        )
        d[segments_cross(A, B, e0, e1)] = 0.0
        d = d.min(axis=1)
        # A segment with no edge crossing is either wholly inside or wholly outside a polygon.
        inside = shapely.intersects_xy(self._poly_union, a[:, 0], a[:, 1])
        d[inside] = 0.0
        return d


class LocalViolation:
    """:meth:`World.segment_violation` for a fixed number of segments confined to boxes.

    Candidate obstacles per segment are gathered once (padded with an obstacle that is never
    near, so the per-call work is one dense broadcast over ``(paths, segments, candidates)``).
    """

    def __init__(self, world: World, seg_lo: np.ndarray, seg_hi: np.ndarray) -> None:
        self.world = world
        r_need = world.threshold
        n_seg = len(seg_lo)
        far = 1e6 * max(1.0, *(abs(v) for b in world.bounds for v in b))

        # Circles: box-to-centre distance below r + R.
        circ = world.circles
        if len(circ):
            c = circ[:, :2][None, :, :]
            gap = np.maximum(0.0, np.maximum(seg_lo[:, None, :] - c, c - seg_hi[:, None, :]))
            near = np.hypot(gap[..., 0], gap[..., 1]) < circ[None, :, 2] + r_need
            self.circles = _gather(near, circ, np.array([far, far, 0.0]))
        else:
            self.circles = np.zeros((n_seg, 0, 3))

        # Polygon edges: edge bounding box overlapping the segment box grown by R.
        edges = world._edges
        if len(edges):
            e_lo = np.minimum(edges[:, :2], edges[:, 2:])
            e_hi = np.maximum(edges[:, :2], edges[:, 2:])
            near = np.all(
                (e_lo[None] <= seg_hi[:, None] + r_need) & (e_hi[None] >= seg_lo[:, None] - r_need),
                axis=-1,
            )
            self.edges = _gather(near, edges, np.array([far, far, far, far]))
            self.edge_segments = np.flatnonzero(near.any(axis=1))
            # A box with no polygon edge within R of it lies wholly inside or wholly outside the
            # polygons; one point (its centre) tells which, and inside means full violation.
            lone = np.flatnonzero(~near.any(axis=1))
            mid = 0.5 * (seg_lo[lone] + seg_hi[lone])
            self.buried_segments = lone[
                shapely.intersects_xy(world._poly_union, mid[:, 0], mid[:, 1])
            ]
        else:
            self.edges = np.zeros((n_seg, 0, 4))
            self.edge_segments = np.zeros(0, dtype=int)
            self.buried_segments = np.zeros(0, dtype=int)

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
        if len(self.edge_segments):
            # Only the segments that have candidate edges at all.
            idx = self.edge_segments
            A, B = A[:, idx], B[:, idx]
            e0 = self.edges[None, idx, :, :2]
            e1 = self.edges[None, idx, :, 2:]
            d = np.minimum(
                np.minimum(point_segment_distance(A, e0, e1), point_segment_distance(B, e0, e1)),
                np.minimum(point_segment_distance(e0, A, B), point_segment_distance(e1, A, B)),
            )
            d = np.where(segments_cross(A, B, e0, e1), 0.0, d).min(axis=2)
            start = a[:, idx]
            inside = shapely.intersects_xy(world._poly_union, start[..., 0], start[..., 1])
            v[:, idx] += np.maximum(0.0, r_need - np.where(inside, 0.0, d))
        if len(self.buried_segments):
            v[:, self.buried_segments] += r_need
        return v


def _gather(near: np.ndarray, rows: np.ndarray, pad: np.ndarray) -> np.ndarray:
    """(S, K, m) array of the rows flagged in each line of ``near`` (S, N), padded with ``pad``."""
    k = max(1, int(near.sum(axis=1).max()) if near.size else 1)
    out = np.broadcast_to(pad, (near.shape[0], k, len(pad))).copy()
    for s, idx in enumerate(near):
        sel = rows[idx]
        out[s, : len(sel)] = sel
    return out


# ----------------------------------------------------------------------------------------------
# Scalar polygon primitives (pure Python floats)
# ----------------------------------------------------------------------------------------------
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


def _point_polygon_boundary_distance(
    x: float, y: float, xs: tuple[float, ...], ys: tuple[float, ...]
) -> float:
    n = len(xs)
    return min(
        point_segment_distance_xy(x, y, xs[i - 1], ys[i - 1], xs[i], ys[i]) for i in range(n)
    )


def _segment_polygon_distance(
    ax: float, ay: float, bx: float, by: float, xs: tuple[float, ...], ys: tuple[float, ...]
) -> float:
    """Exact distance from segment a-b to a simple polygon (0 when crossing or inside)."""
    best = math.inf
    n = len(xs)
    for i in range(n):
        cx, cy, dx, dy = xs[i - 1], ys[i - 1], xs[i], ys[i]
        d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
        d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
        d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
        if d1 * d2 < 0.0 and d3 * d4 < 0.0:
            return 0.0
        d = min(
            point_segment_distance_xy(ax, ay, cx, cy, dx, dy),
            point_segment_distance_xy(bx, by, cx, cy, dx, dy),
            point_segment_distance_xy(cx, cy, ax, ay, bx, by),
            point_segment_distance_xy(dx, dy, ax, ay, bx, by),
        )
        if d < best:
            best = d
    if _point_in_polygon(ax, ay, xs, ys):
        return 0.0
    return best
