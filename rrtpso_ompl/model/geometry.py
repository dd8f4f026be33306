"""Plane geometry that every stage uses: polyline lengths, shortcutting, and the exact distances
of the collision checks (point to segment, segment to segment, segment to axis-aligned box).

Vectorised functions take numpy arrays with any leading shape (or ``(k, 2)`` rows) and
coordinates in the last axis; the scalar ``*_xy`` twins take plain floats, for OMPL's
one-segment-at-a-time callbacks, where building arrays would cost more than the arithmetic.
Every length is in the unit of the coordinates (the problem's, metres for maps).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "GridFrame",
    "bounding_box",
    "cross",
    "cumulative_length",
    "dedupe",
    "is_axis_aligned_rectangle",
    "path_length",
    "point_in_polygon_xy",
    "point_segment_distance",
    "point_segment_distance_xy",
    "segment_box_distance",
    "segment_box_distance_xy",
    "segment_lengths",
    "segment_segment_distance",
    "segment_segment_distance_xy",
    "segments_cross",
    "shortcut",
    "turning_angles",
    "wrap_angle",
]

#: Segments per vectorised visibility call in :func:`shortcut` (bounds its temporary arrays).
_CHUNK = 4096


@dataclass(frozen=True)
class GridFrame:
    """The frame in which a rotated occupancy grid's cells are axis-aligned squares.

    A map_server map whose YAML says ``origin: [x, y, yaw]`` lays its image with the lower-left
    corner of its lower-left cell at ``pivot = (x, y)`` and its rows along the direction ``yaw``
    (nav_msgs/MapMetaData: the origin is the pose of that corner, the image turned about it). In
    *grid coordinates* every cell is the square it would be with ``yaw = 0``: a world point ``p``
    has grid coordinates ``pivot + R(-yaw) (p - pivot)``. A rotation keeps distances, so a
    distance computed exactly in grid coordinates is the exact distance in the world (up to the
    round-off of the turn, about ``1e-16`` of the coordinates, far inside the touch tolerance).

    Attributes
    ----------
    pivot : (float, float)
        The point the grid is turned about (the map's origin), world units; the same point in
        both frames.
    yaw : float
        The grid's turn, radians, counter-clockwise.
    confined : (xmin, ymin, xmax, ymax) or None
        A box in grid coordinates that holds every free configuration of the world this frame
        belongs to, when one is known: the map's rectangle, when unknown space blocks and the map
        lies within the bounds (everything else is blocked). The exact optimum then plans in grid
        coordinates, where the map's cells keep their lattice.
    """

    pivot: tuple[float, float]
    yaw: float
    confined: tuple[float, float, float, float] | None = None
    _cos: float = field(init=False, repr=False, compare=False)
    _sin: float = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "pivot", (float(self.pivot[0]), float(self.pivot[1])))
        object.__setattr__(self, "yaw", float(self.yaw))
        object.__setattr__(self, "_cos", math.cos(self.yaw))
        object.__setattr__(self, "_sin", math.sin(self.yaw))

    def to_grid(self, points) -> np.ndarray:
        """Grid coordinates of world points ``(..., 2)``."""
        p = np.asarray(points, dtype=float)
        px, py = self.pivot
        dx, dy = p[..., 0] - px, p[..., 1] - py
        c, s = self._cos, self._sin
        return np.stack([px + c * dx + s * dy, py - s * dx + c * dy], axis=-1)

    def to_world(self, points) -> np.ndarray:
        """World coordinates of grid points ``(..., 2)``."""
        q = np.asarray(points, dtype=float)
        px, py = self.pivot
        dx, dy = q[..., 0] - px, q[..., 1] - py
        c, s = self._cos, self._sin
        return np.stack([px + c * dx - s * dy, py + s * dx + c * dy], axis=-1)

    def to_grid_xy(self, x: float, y: float) -> tuple[float, float]:
        """:meth:`to_grid` of one point, in plain floats (the scalar checks)."""
        px, py = self.pivot
        dx, dy = x - px, y - py
        c, s = self._cos, self._sin
        return px + c * dx + s * dy, py - s * dx + c * dy

    def box_corners(self, boxes) -> np.ndarray:
        """World corners ``(k, 4, 2)`` of grid-coordinate boxes ``(k, 4)`` ``(xmin, ymin, xmax,
        ymax)``, counter-clockwise from ``(xmin, ymin)``."""
        b = np.asarray(boxes, dtype=float).reshape(-1, 4)
        corners = np.stack([b[:, [0, 1]], b[:, [2, 1]], b[:, [2, 3]], b[:, [0, 3]]], axis=1)
        return self.to_world(corners)


def segment_lengths(path: np.ndarray) -> np.ndarray:
    """Lengths of the segments of a polyline ``(n, 2)``: shape ``(n - 1,)``."""
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    d = np.diff(p, axis=0)
    return np.hypot(d[:, 0], d[:, 1])


def path_length(path: np.ndarray) -> float:
    """Euclidean length of a polyline ``(n, 2)`` (0 for fewer than two points)."""
    return float(segment_lengths(path).sum())


def cumulative_length(path: np.ndarray) -> np.ndarray:
    """Arc length at each vertex of a polyline: ``(n,)``, starting at 0."""
    return np.concatenate([[0.0], np.cumsum(segment_lengths(path))])


def dedupe(points: np.ndarray, tol: float = 0.0) -> np.ndarray:
    """Drop each point within ``tol`` of the one before it (``tol = 0``: exact repeats)."""
    p = np.asarray(points, dtype=float)
    if len(p) < 2:
        return p
    keep = np.concatenate([[True], segment_lengths(p) > tol])
    return p[keep]


def wrap_angle(a: float) -> float:
    """Angle in (-pi, pi], radians."""
    return math.atan2(math.sin(a), math.cos(a))


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Broadcast distance from points ``p`` to segments ``a-b`` (zero-length segments allowed).

    Written on the x and y components: for 2-D points this is several times faster than
    ``einsum`` over a trailing axis of length 2, and it is the swarm's inner loop.
    """
    abx = b[..., 0] - a[..., 0]
    aby = b[..., 1] - a[..., 1]
    apx = p[..., 0] - a[..., 0]
    apy = p[..., 1] - a[..., 1]
    len2 = abx * abx + aby * aby
    # A zero-length segment has a zero numerator too, so t = 0 there: the distance to a point.
    t = np.clip((apx * abx + apy * aby) / np.where(len2 > 0.0, len2, 1.0), 0.0, 1.0)
    qx = apx - t * abx
    qy = apy - t * aby
    return np.sqrt(qx * qx + qy * qy)


def point_segment_distance_xy(
    px: float, py: float, ax: float, ay: float, bx: float, by: float
) -> float:
    """:func:`point_segment_distance` for one point and one segment, in plain floats."""
    dx, dy = bx - ax, by - ay
    len2 = dx * dx + dy * dy
    if len2 > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / len2
        t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
    else:
        t = 0.0
    ex, ey = ax + t * dx - px, ay + t * dy - py
    return math.sqrt(ex * ex + ey * ey)


def cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z-component of (a - o) x (b - o), broadcast."""
    return (a[..., 0] - o[..., 0]) * (b[..., 1] - o[..., 1]) - (a[..., 1] - o[..., 1]) * (
        b[..., 0] - o[..., 0]
    )


def segments_cross(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Whether segments a-b and c-d cross properly (touching cases give distance 0 anyway)."""
    d1 = cross(a, b, c)
    d2 = cross(a, b, d)
    d3 = cross(c, d, a)
    d4 = cross(c, d, b)
    return (d1 * d2 < 0.0) & (d3 * d4 < 0.0)


def turning_angles(paths: np.ndarray) -> np.ndarray:
    """Turning angle (radians, in [0, pi]) at each interior vertex of ``(..., n, 2)`` polylines."""
    seg = np.diff(paths, axis=-2)
    a, b = seg[..., :-1, :], seg[..., 1:, :]
    z = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    dot = np.einsum("...i,...i->...", a, b)
    return np.abs(np.arctan2(z, dot))


def shortcut(
    path: np.ndarray,
    segments_free: Callable[[np.ndarray, np.ndarray], np.ndarray],
    terminate: Callable[[], bool] | None = None,
    window: int = 64,
) -> np.ndarray:
    """Greedy shortcutting: from each kept vertex jump to the farthest vertex in free sight.

    Parameters
    ----------
    path : (n, 2) array_like
        A valid polyline (each of its own segments free).
    segments_free : callable
        ``segments_free(a, b)`` for ``(m, 2)`` end points returns ``(m,)`` booleans (exact, e.g.
        :meth:`~rrtpso_ompl.model.World.segments_free`).
    terminate : callable, optional
        Polled before each kept vertex; when it returns True the rest of the path is kept as it
        is (still a valid path, just less shortened).
    window : int
        Vertices looked ahead at first (the window doubles while its far end is in sight): small
        for a path that is already nearly taut, where little lies in sight.

    Returns
    -------
    (k, 2) ndarray
        A subset of the input's vertices, end points kept: never longer, and valid whenever the
        input is, since every new segment passed ``segments_free``.

    Notes
    -----
    The doubling window keeps a long winding route (thousands of vertices) from being tested
    against every later vertex; the visibility calls are chunked to bound their memory.
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    if len(p) <= 2:
        return p.copy()
    keep = [0]
    i = 0
    last = len(p) - 1
    while i < last:
        if terminate is not None and terminate():
            keep.extend(range(i + 1, last + 1))
            break
        ahead = window
        while True:
            j = np.arange(i + 1, min(last, i + ahead) + 1)
            chunks = np.array_split(j, max(1, math.ceil(len(j) / _CHUNK)))
            sight = np.concatenate(
                [segments_free(np.broadcast_to(p[i], (len(c), 2)), p[c]) for c in chunks]
            )
            # The next vertex is in sight on a valid input; on an invalid one, step to it anyway.
            seen = np.flatnonzero(sight)
            best = int(j[seen[-1]]) if len(seen) else i + 1
            if best < i + ahead or best == last:
                break
            ahead *= 2
        i = best
        keep.append(i)
    return p[keep]


# ----------------------------------------------------------------------------------------------
# Exact distances to boxes and edges (the world's collision checks)
# ----------------------------------------------------------------------------------------------
def segment_box_distance_xy(ax, ay, bx, by, x0, y0, x1, y1) -> float:
    """Exact distance from segment a-b to the closed box [x0, x1] x [y0, y1] (0 when they meet)."""
    # Python floats: a segment a denormal long divides to inf, which the clipping handles, where a
    # numpy scalar would warn of an overflow.
    ax, ay, bx, by = float(ax), float(ay), float(bx), float(by)
    x0, y0, x1, y1 = float(x0), float(y0), float(x1), float(y1)
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


def segment_box_distance(a: np.ndarray, b: np.ndarray, box: np.ndarray) -> np.ndarray:
    """:func:`segment_box_distance_xy` for arrays: ``a, b`` (k, 2), ``box`` (k, 4)."""
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


def point_in_polygon_xy(x: float, y: float, xs: tuple[float, ...], ys: tuple[float, ...]) -> bool:
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


def segment_segment_distance_xy(
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


def segment_segment_distance(a: np.ndarray, b: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`segment_segment_distance_xy` for arrays: ``a, b`` (k, 2), edges ``e`` (k, 4)."""
    e0, e1 = e[:, :2], e[:, 2:]
    d = np.minimum(
        np.minimum(point_segment_distance(a, e0, e1), point_segment_distance(b, e0, e1)),
        np.minimum(point_segment_distance(e0, a, b), point_segment_distance(e1, a, b)),
    )
    d[segments_cross(a, b, e0, e1)] = 0.0
    return d


def is_axis_aligned_rectangle(points) -> bool:
    """Whether a ring of four ``(x, y)`` tuples is an axis-aligned rectangle (the world checks
    it exactly by the box formulas)."""
    if len(points) != 4:
        return False
    xs = sorted({p[0] for p in points})
    ys = sorted({p[1] for p in points})
    corners = {(x, y) for x in xs for y in ys}
    return len(xs) == 2 and len(ys) == 2 and set(points) == corners


def bounding_box(points) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` of ``(x, y)`` points, in their unit."""
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return min(xs), min(ys), max(xs), max(ys)
