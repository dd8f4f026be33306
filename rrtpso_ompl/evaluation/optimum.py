"""The exact shortest path for a disc robot among circles and polygons (the reference optimum).

The robot is a disc of radius ``R`` whose centre must stay in the bounds. In its configuration
space every obstacle grows by ``R``: a circle of radius ``r`` becomes a circle of radius ``r + R``
and a polygon becomes the polygon with rounded corners, each convex vertex the centre of a circle
of radius ``R``. A shortest path in such a space consists of straight segments tangent to these
circles and arcs along them (the classic tangent or "reduced visibility" graph; see e.g. LaValle,
*Planning Algorithms*, 2006, section 6.2.4 and Latombe 1991 for the polygonal case). So:

1. **Circles**: the start and the goal (radius 0), every obstacle circle (``r + R``) and every
   convex polygon vertex (``R``).
2. **Tangent segments**: for every pair of circles the up to four common tangents (two outer, two
   inner), kept when both tangent points are free and in bounds and the whole segment is free
   (exact segment distance, :meth:`rrtpso_ompl.model.World.segments_free`).
3. **Arcs**: on each circle, the tangent points sorted by angle, joined to their neighbours by
   arcs, kept when the arc is free: its exact distance to every circle and polygon edge, its
   extent against the bounds.
4. **Dijkstra** from the start to the goal over segments and arcs.

Every edge of the graph is a piece of a valid path (touching an obstacle is allowed, as everywhere
in this package), so the result is never shorter than the true optimum; and the true optimum is a
path of the graph, so the result is exact up to floating-point round-off. The box bounds add no
circles: from inside, the box is convex, and so is every corner where an obstacle meets it, and
a shortest path bends only around corners that are convex seen from the obstacle.

The free configuration space is closed (touching allowed). For a point robot (``R = 0``) a path
grazing a polygon corner would touch it with zero clearance, which the package's segment test
counts as entering; the corners are therefore rounded with a radius of twice the touch tolerance
(``2e-9`` of the workspace size), which changes the length by less than that.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from ..errors import RrtpsoError
from ..model.geometry import point_segment_distance
from ..model.problem import Circle, Polygon, Problem
from ..model.world import World

__all__ = ["OptimumResult", "Piece", "shortest_path"]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class Piece:
    """One piece of the optimal path: a straight segment or an arc.

    Attributes
    ----------
    kind : str
        ``"line"`` or ``"arc"``.
    start, end : (float, float)
        End points, problem units.
    center : (float, float) or None
        Arc centre (an obstacle centre or a polygon vertex).
    radius : float
        Arc radius (obstacle radius plus robot radius), 0 for a line.
    angle : float
        Angle of ``start`` seen from ``center``, radians.
    sweep : float
        Signed angle the arc turns through, radians (positive counter-clockwise).
    """

    kind: str
    start: tuple[float, float]
    end: tuple[float, float]
    center: tuple[float, float] | None = None
    radius: float = 0.0
    angle: float = 0.0
    sweep: float = 0.0

    @property
    def length(self) -> float:
        """Length of the piece, problem units."""
        if self.kind == "arc":
            return abs(self.sweep) * self.radius
        return math.dist(self.start, self.end)

    def points(self, max_angle: float = math.radians(2.0)) -> np.ndarray:
        """The piece as a polyline from ``start`` to ``end`` that never comes closer to an arc's
        centre than its radius.

        An arc becomes the polygon *circumscribed* about it: its vertices lie at radius
        ``rho / cos(delta / 2)`` between the tangent points, every ``delta <= max_angle``, so each
        of its segments is tangent to the circle (chords would cut into the robot's safety zone
        by up to ``rho (1 - cos(delta / 2))``). It is longer than the arc by a factor of at most
        ``tan(delta / 2) / (delta / 2)`` (1.0001 at 2 degrees).
        """
        if self.kind != "arc" or self.radius == 0.0:
            return np.array([self.start, self.end], dtype=float)
        n = max(1, math.ceil(abs(self.sweep) / max_angle))
        delta = self.sweep / n
        a = self.angle + delta * (np.arange(n) + 0.5)
        rho = self.radius / math.cos(0.5 * delta)
        middle = np.column_stack(
            [self.center[0] + rho * np.cos(a), self.center[1] + rho * np.sin(a)]
        )
        return np.vstack([self.start, middle, self.end])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        d: dict[str, Any] = {"kind": self.kind, "start": list(self.start), "end": list(self.end)}
        if self.kind == "arc":
            d.update(center=list(self.center), radius=self.radius, sweep=self.sweep)
        d["length"] = self.length
        return d


@dataclass(frozen=True)
class OptimumResult:
    """The shortest path of a problem, or the proof that there is none.

    Attributes
    ----------
    problem : str
        Problem name.
    length : float or None
        Length of the shortest path, problem units; None when start and goal are not connected.
    pieces : list of Piece
        The path as tangent segments and arcs.
    exact : bool
        False only with a ``goal_tolerance`` disc that is not wholly free, where the length is
        that of the best path to the goal point's tangents (an upper bound).
    n_nodes, n_edges : int
        Size of the tangent graph.
    time : float
        Seconds spent.
    """

    problem: str
    length: float | None
    pieces: list[Piece] = field(default_factory=list)
    exact: bool = True
    n_nodes: int = 0
    n_edges: int = 0
    time: float = 0.0

    @property
    def found(self) -> bool:
        """Whether a path exists."""
        return self.length is not None

    def polyline(self, max_angle: float = math.radians(2.0)) -> np.ndarray:
        """The path as an (m, 2) polyline: tangent segments, and arcs as their circumscribed
        polygons (:meth:`Piece.points`), so the robot keeps its radius along every segment.

        Its length exceeds :attr:`length` by a relative ``1e-4`` at most (at 2 degrees); use
        :attr:`pieces` for the exact geometry.
        """
        if not self.pieces:
            return np.empty((0, 2))
        parts = [self.pieces[0].points(max_angle)[:1]]
        parts += [p.points(max_angle)[1:] for p in self.pieces]
        pts = np.concatenate(parts)
        keep = np.ones(len(pts), dtype=bool)
        keep[1:] = np.any(np.diff(pts, axis=0) != 0.0, axis=1)
        return pts[keep]

    def valid_polyline(self, world: World) -> np.ndarray:
        """:meth:`polyline`, finer where needed until the exact check accepts it.

        An arc's circumscribed polygon bulges out by ``rho (1 / cos(delta / 2) - 1)``; where the
        path runs that close to a second obstacle, smaller angles shrink the bulge. The finest
        try is returned either way (valid in every case but a path squeezed between two
        obstacles that touch it at one point).
        """
        pts = self.polyline()
        for degrees in (1.0, 0.5, 0.25, 0.125):
            if not len(pts) or world.path_valid(pts):
                return pts
            pts = self.polyline(math.radians(degrees))
        return pts

    def to_dict(self, world: World | None = None) -> dict[str, Any]:
        """JSON-ready dictionary: the contract's ``length`` and ``path`` first (with ``world``,
        the path is refined until the exact check accepts it, :meth:`valid_polyline`)."""
        path = self.valid_polyline(world) if world is not None else self.polyline()
        return {
            "length": self.length,
            "path": path.tolist(),
            "problem": self.problem,
            "exact": self.exact,
            "pieces": [p.to_dict() for p in self.pieces],
            "graph": {"nodes": self.n_nodes, "edges": self.n_edges},
            "time": self.time,
        }


#: Most circles (start, goal, inflated circles and convex corners) the tangent graph is built on:
#: its candidate tangents grow with the square of their number (about 0.5 GB at 1,000).
MAX_NODE_CIRCLES = 2_002


class OptimumTooLarge(RrtpsoError):
    """The problem has too many obstacles for the exact optimum to be computed here."""


def _estimated_gib(n: int) -> float:
    return 0.47 * (n / 1000.0) ** 2


# ----------------------------------------------------------------------------------------------
def shortest_path(problem: Problem, world: World | None = None) -> OptimumResult:
    """The shortest collision-free path of ``problem`` for its disc robot (moving obstacles
    ignored).

    Parameters
    ----------
    problem : Problem
        A validated problem.
    world : World, optional
        Its static world, when already built.

    Returns
    -------
    OptimumResult
        ``length`` None when no path exists.

    Raises
    ------
    OptimumTooLarge
        For more than :data:`MAX_NODE_CIRCLES` circles and convex corners.
    """
    t0 = time.perf_counter()
    world = world or World.from_problem(problem)
    tol = world.tol
    radius = max(world.robot_radius, 2.0 * tol)  # see the module docstring for R = 0
    if radius != world.robot_radius:
        world = world.with_robot_radius(radius)
    start = np.asarray(problem.start[:2], dtype=float)
    goal = np.asarray(problem.goal[:2], dtype=float)
    goal_tol = float(problem.goal_tolerance)

    if math.dist(start, goal) <= goal_tol or np.array_equal(start, goal):
        still = Piece("line", tuple(map(float, start)), tuple(map(float, start)))
        return OptimumResult(problem.name, 0.0, [still], True, 1, 0, time.perf_counter() - t0)
    circles = _node_circles(problem, start, goal, radius)
    if len(circles) > MAX_NODE_CIRCLES:
        raise OptimumTooLarge(
            f"{problem.source}: the exact optimum of {len(circles) - 2:,} circles and convex "
            f"corners would take about {_estimated_gib(len(circles)):.0f} GiB of memory; this "
            f"version computes it for at most {MAX_NODE_CIRCLES - 2:,}"
        )
    graph = _TangentGraph(world, circles, goal_tol)
    graph.build()
    dist, pred = dijkstra(
        graph.matrix, directed=False, indices=graph.start_node, return_predecessors=True
    )
    # Goal nodes: the goal point's tangent points, or with a tolerance the points where the legs
    # towards the goal enter its disc (graph.goal_cost holds the leg's length, possibly 0).
    costs = dist[graph.goal_nodes] + graph.goal_cost
    exact = goal_tol == 0.0 or bool(
        world.point_clearance(goal[None])[0] >= goal_tol + world.threshold
    )
    elapsed = time.perf_counter() - t0
    if not len(costs) or not np.isfinite(costs.min()):
        return OptimumResult(problem.name, None, [], exact, graph.n_nodes, graph.n_edges, elapsed)
    best = int(np.argmin(costs))
    chain = [int(graph.goal_nodes[best])]
    while chain[-1] != graph.start_node:
        chain.append(int(pred[chain[-1]]))
    chain.reverse()
    pieces = [graph.piece(u, v) for u, v in itertools.pairwise(chain)]
    tail = graph.goal_piece(best)
    if tail is not None:
        pieces.append(tail)
    pieces = _merge_arcs([p for p in pieces if p.length > 0.0] or pieces[:1])
    return OptimumResult(
        problem=problem.name,
        length=float(costs[best]),
        pieces=pieces,
        exact=exact,
        n_nodes=graph.n_nodes,
        n_edges=graph.n_edges,
        time=time.perf_counter() - t0,
    )


def _merge_arcs(pieces: list[Piece]) -> list[Piece]:
    """Join consecutive arcs on the same circle (the path passed a tangent point it did not use)."""
    out: list[Piece] = []
    for p in pieces:
        q = out[-1] if out else None
        if q and p.kind == q.kind == "arc" and p.center == q.center and p.radius == q.radius:
            out[-1] = Piece("arc", q.start, p.end, q.center, q.radius, q.angle, q.sweep + p.sweep)
        else:
            out.append(p)
    return out


def _node_circles(
    problem: Problem, start: np.ndarray, goal: np.ndarray, radius: float
) -> np.ndarray:
    """(k, 3) circles ``(cx, cy, rho)``: start, goal, inflated obstacle circles, convex vertices."""
    rows = [(*start, 0.0), (*goal, 0.0)]
    for obstacle in problem.obstacles:
        if isinstance(obstacle, Circle):
            rows.append((*obstacle.center, obstacle.radius + radius))
        elif isinstance(obstacle, Polygon):
            p = np.asarray(obstacle.points, dtype=float)
            prev, nxt = np.roll(p, 1, axis=0), np.roll(p, -1, axis=0)
            e0, e1 = p - prev, nxt - p
            turn = e0[:, 0] * e1[:, 1] - e0[:, 1] * e1[:, 0]
            area2 = np.sum(p[:, 0] * nxt[:, 1] - nxt[:, 0] * p[:, 1])
            # Convex vertices turn the way the ring runs; only they can bend a shortest path.
            convex = turn * np.sign(area2) > 0.0
            rows.extend((x, y, radius) for x, y in p[convex])
    return np.asarray(rows, dtype=float)


class _TangentGraph:
    """Nodes are tangent points on the circles; edges are free tangent segments and free arcs."""

    def __init__(self, world: World, circles: np.ndarray, goal_tol: float) -> None:
        self.world = world
        self.circles = circles
        self.goal_tol = goal_tol

    # ------------------------------------------------------------------------------------------
    def build(self) -> None:
        p, q, ci, cj, ai, aj = self._tangent_segments()
        # Every segment end is a node: node 2k is segment k's start, 2k+1 its end.
        n_seg = len(p)
        self.node_xy = np.empty((2 * n_seg, 2))
        self.node_xy[0::2], self.node_xy[1::2] = p, q
        self.node_circle = np.empty(2 * n_seg, dtype=int)
        self.node_circle[0::2], self.node_circle[1::2] = ci, cj
        self.node_angle = np.empty(2 * n_seg)
        self.node_angle[0::2], self.node_angle[1::2] = ai, aj
        seg_u = np.arange(0, 2 * n_seg, 2)
        seg_w = np.hypot(*(q - p).T)
        arc_u, arc_v, arc_s = self._arcs()
        arc_w = self.circles[self.node_circle[arc_u], 2] * arc_s

        u = np.concatenate([seg_u, arc_u])
        v = np.concatenate([seg_u + 1, arc_v])
        w = np.concatenate([seg_w, arc_w])
        kind = np.concatenate([np.zeros(n_seg, int), np.ones(len(arc_u), int)])
        # Parallel edges (two arcs joining the same pair of nodes) must not be summed: keep the
        # shortest. scipy's graphs also drop explicit zeros, so zero lengths get a tiny weight.
        lo, hi = np.minimum(u, v), np.maximum(u, v)
        order = np.lexsort((w, hi, lo))
        lo, hi, w, kind, u = lo[order], hi[order], w[order], kind[order], u[order]
        first = np.ones(len(lo), dtype=bool)
        first[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
        lo, hi, w, kind, u = lo[first], hi[first], w[first], kind[first], u[first]
        # Per edge: whether it is an arc, and the node its counter-clockwise sweep starts from.
        self.edges = {
            (int(a), int(b)): (bool(k), int(s)) for a, b, k, s in zip(lo, hi, kind, u, strict=True)
        }
        n = max(len(self.node_xy), 1)
        self.matrix = sp.csr_array((np.maximum(w, 1e-300), (lo, hi)), shape=(n, n))
        self.n_nodes = len(self.node_xy)
        self.n_edges = len(lo)

        on_start = np.flatnonzero(self.node_circle == 0)
        self.start_node = int(on_start[0]) if len(on_start) else 0
        self._goal_targets()

    # ------------------------------------------------------------------------------------------
    def _tangent_segments(self) -> tuple[np.ndarray, ...]:
        """All free common tangents of all pairs of circles."""
        c = self.circles
        i, j = np.triu_indices(len(c), k=1)
        ri, rj = c[i, 2], c[j, 2]
        d_vec = c[j, :2] - c[i, :2]
        d = np.hypot(*d_vec.T)
        base = np.arctan2(d_vec[:, 1], d_vec[:, 0])
        out = []
        # Outer tangents: normal at angle base +- acos((ri - rj) / d) on both circles. Inner ones:
        # base +- acos((ri + rj) / d), with the normal reversed on circle j. For a circle of
        # radius 0 the inner tangents repeat the outer ones, and for two points both coincide.
        for inner, sign in ((False, 1.0), (False, -1.0), (True, 1.0), (True, -1.0)):
            if inner:
                ok = (ri > 0) & (rj > 0) & (d > ri + rj)
                cos_a = np.divide(ri + rj, d, out=np.ones_like(d), where=d > 0)
            else:
                ok = d > np.abs(ri - rj)
                if sign < 0:
                    ok &= (ri > 0) | (rj > 0)
                cos_a = np.divide(ri - rj, d, out=np.ones_like(d), where=d > 0)
            ang = base + sign * np.arccos(np.clip(cos_a, -1.0, 1.0))
            n = np.column_stack([np.cos(ang), np.sin(ang)])
            p = c[i, :2] + ri[:, None] * n
            q = c[j, :2] + (-1.0 if inner else 1.0) * rj[:, None] * n
            aj = ang + math.pi if inner else ang
            out.append((p[ok], q[ok], i[ok], j[ok], ang[ok], aj[ok]))
        p, q, ci, cj, ai, aj = (np.concatenate(parts) for parts in zip(*out, strict=True))
        ai = np.where(c[ci, 2] > 0, np.mod(ai, _TWO_PI), 0.0)
        aj = np.where(c[cj, 2] > 0, np.mod(aj, _TWO_PI), 0.0)

        w = self.world
        # Chunks bound the (segments x obstacles) temporaries to a few MB.
        chunk = max(1, 200_000 // max(1, len(w.circles) + len(w.polygon_edges)))
        pts = np.concatenate([p, q])
        point_ok = w.points_in_bounds(pts)
        for s in range(0, len(pts), chunk):
            point_ok[s : s + chunk] &= w.point_clearance(pts[s : s + chunk]) >= w.threshold
        ok = point_ok[: len(p)] & point_ok[len(p) :]
        idx = np.flatnonzero(ok)
        free = np.zeros(len(idx), dtype=bool)
        for s in range(0, len(idx), chunk):
            k = idx[s : s + chunk]
            free[s : s + chunk] = w.segments_free(p[k], q[k])
        keep = idx[free]
        return p[keep], q[keep], ci[keep], cj[keep], ai[keep], aj[keep]

    # ------------------------------------------------------------------------------------------
    def _arcs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Free arcs between angular neighbours on every circle: (u, v, sweep), counter-clockwise
        from node u to node v."""
        circle, angle = self.node_circle, self.node_angle
        order = np.lexsort((angle, circle))
        c_sorted, a_sorted = circle[order], angle[order]
        same = np.flatnonzero(c_sorted[1:] == c_sorted[:-1])
        u, v = order[same], order[same + 1]
        sweep = a_sorted[same + 1] - a_sorted[same]
        # Close each circle's ring: last node back to the first, the rest of the way round.
        starts = np.flatnonzero(np.r_[True, c_sorted[1:] != c_sorted[:-1]])
        ends = np.r_[starts[1:], len(order)] - 1
        ring = ends > starts
        u = np.concatenate([u, order[ends[ring]]])
        v = np.concatenate([v, order[starts[ring]]])
        sweep = np.concatenate([sweep, _TWO_PI - (a_sorted[ends[ring]] - a_sorted[starts[ring]])])
        a0 = angle[u]
        rho = self.circles[circle[u], 2]
        sweep = np.where(rho > 0, sweep, 0.0)
        free = np.zeros(len(u), dtype=bool)
        # Chunks bound the (arcs x obstacles) temporaries to a few tens of MB.
        chunk = max(1, 200_000 // max(1, len(self.world.circles) + len(self.world.polygon_edges)))
        centers = self.circles[circle[u], :2]
        for s in range(0, len(u), chunk):
            k = slice(s, s + chunk)
            free[k] = self._arcs_free(centers[k], rho[k], a0[k], sweep[k])
        return u[free], v[free], sweep[free]

    def _arcs_free(
        self, center: np.ndarray, rho: np.ndarray, a0: np.ndarray, sweep: np.ndarray
    ) -> np.ndarray:
        """Exact test of counter-clockwise arcs against the obstacles and the bounds."""
        w = self.world
        ok = np.ones(len(rho), dtype=bool)
        if not len(rho):
            return ok
        # Bounds: the arc's extreme points are its ends and the axis directions it passes.
        ends = [a0, a0 + sweep]
        xs = [center[:, 0] + rho * np.cos(a) for a in ends]
        ys = [center[:, 1] + rho * np.sin(a) for a in ends]
        for axis in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
            inside = _in_sweep(axis, a0, sweep)
            px = np.where(inside, center[:, 0] + rho * math.cos(axis), xs[0])
            py = np.where(inside, center[:, 1] + rho * math.sin(axis), ys[0])
            xs.append(px)
            ys.append(py)
        ok &= (
            w.points_in_bounds(np.stack([np.concatenate(xs), np.concatenate(ys)], axis=1))
            .reshape(-1, len(rho))
            .all(axis=0)
        )

        if len(w.circles):
            obs = w.circles
            d = _arc_point_distance(
                center[:, None, :], rho[:, None], a0[:, None], sweep[:, None], obs[None, :, :2]
            )
            ok &= np.all(d >= obs[None, :, 2] + w.threshold, axis=1)
        if len(w.polygon_edges):
            e = w.polygon_edges
            d = _arc_segment_distance(
                center[:, None, :],
                rho[:, None],
                a0[:, None],
                sweep[:, None],
                e[None, :, :2],
                e[None, :, 2:],
            )
            ok &= np.all(d >= w.threshold, axis=1)
            # An arc clear of every edge is wholly inside or outside each polygon.
            mid = a0 + 0.5 * sweep
            inside = w.in_polygons(
                center[:, 0] + rho * np.cos(mid), center[:, 1] + rho * np.sin(mid)
            )
            ok &= ~inside
        return ok

    # ------------------------------------------------------------------------------------------
    def _goal_targets(self) -> None:
        """Goal nodes and the length still to go from each (0 without a goal tolerance)."""
        on_goal = np.flatnonzero(self.node_circle == 1)
        if self.goal_tol == 0.0 or not len(self.node_xy):
            self.goal_nodes = on_goal
            self.goal_cost = np.zeros(len(on_goal))
            self._goal_end = None
            return
        # With a tolerance, the path ends where the leg towards the goal point enters the disc of
        # radius goal_tol: the nearest point of the disc, exact when the disc is free (a shortest
        # path to a free convex target ends perpendicular to it, on a tangent to the goal point).
        goal = self.circles[1, :2]
        xy = self.node_xy
        to_goal = goal - xy
        dist = np.hypot(*to_goal.T)
        frac = np.clip(1.0 - self.goal_tol / np.where(dist > 0, dist, 1.0), 0.0, 1.0)
        end = xy + frac[:, None] * to_goal
        free = self.world.segments_free(xy, end) & self.world.points_in_bounds(end)
        self.goal_nodes = np.flatnonzero(free)
        self.goal_cost = np.maximum(dist - self.goal_tol, 0.0)[free]
        self._goal_end = end[free]

    def goal_piece(self, k: int) -> Piece | None:
        """The final leg into the goal disc from goal node number ``k``, if any."""
        if self._goal_end is None:
            return None
        a = tuple(map(float, self.node_xy[self.goal_nodes[k]]))
        return Piece("line", a, tuple(map(float, self._goal_end[k])))

    def piece(self, a: int, b: int) -> Piece:
        """The graph edge between nodes ``a`` and ``b``, oriented from ``a`` to ``b``."""
        is_arc, ccw_from = self.edges[(min(a, b), max(a, b))]
        pa = tuple(map(float, self.node_xy[a]))
        pb = tuple(map(float, self.node_xy[b]))
        if not is_arc:
            return Piece("line", pa, pb)
        c = self.circles[self.node_circle[a]]
        rho = float(c[2])
        ang_a, ang_b = float(self.node_angle[a]), float(self.node_angle[b])
        if ccw_from == a:
            sweep = float(np.mod(ang_b - ang_a, _TWO_PI))
        else:
            sweep = -float(np.mod(ang_a - ang_b, _TWO_PI))
        return Piece("arc", pa, pb, (float(c[0]), float(c[1])), rho, ang_a, sweep)


# ----------------------------------------------------------------------------------------------
def _in_sweep(phi: Any, a0: np.ndarray, sweep: np.ndarray) -> np.ndarray:
    """Whether angle ``phi`` lies on the counter-clockwise arc from ``a0`` through ``sweep``."""
    return np.mod(phi - a0, _TWO_PI) <= sweep


def _arc_point_distance(
    c: np.ndarray, rho: np.ndarray, a0: np.ndarray, sweep: np.ndarray, p: np.ndarray
) -> np.ndarray:
    """Exact distance from points ``p`` to arcs (broadcast; ``c`` and ``p`` have a last axis 2)."""
    dx, dy = p[..., 0] - c[..., 0], p[..., 1] - c[..., 1]
    r = np.hypot(dx, dy)
    on = _in_sweep(np.arctan2(dy, dx), a0, sweep)
    e0 = np.hypot(dx - rho * np.cos(a0), dy - rho * np.sin(a0))
    e1 = np.hypot(dx - rho * np.cos(a0 + sweep), dy - rho * np.sin(a0 + sweep))
    return np.where(on, np.abs(r - rho), np.minimum(e0, e1))


def _arc_segment_distance(
    c: np.ndarray,
    rho: np.ndarray,
    a0: np.ndarray,
    sweep: np.ndarray,
    s0: np.ndarray,
    s1: np.ndarray,
) -> np.ndarray:
    """Exact distance between arcs and segments ``s0-s1`` (broadcast).

    The minimum over the arc and the segment is at an end point of one of them (the four end
    cases), at a crossing (distance 0), or where the connecting line is normal to both: on the
    ray from the centre through the foot of the perpendicular on the segment's line.
    """
    e0 = np.stack([c[..., 0] + rho * np.cos(a0), c[..., 1] + rho * np.sin(a0)], axis=-1)
    e1 = np.stack(
        [c[..., 0] + rho * np.cos(a0 + sweep), c[..., 1] + rho * np.sin(a0 + sweep)], axis=-1
    )
    d = np.minimum(point_segment_distance(e0, s0, s1), point_segment_distance(e1, s0, s1))
    d = np.minimum(d, _arc_point_distance(c, rho, a0, sweep, s0))
    d = np.minimum(d, _arc_point_distance(c, rho, a0, sweep, s1))

    ab = s1 - s0
    den = np.sum(ab * ab, axis=-1)
    safe = np.where(den > 0, den, 1.0)
    t_foot = np.sum((c - s0) * ab, axis=-1) / safe
    foot = s0 + t_foot[..., None] * ab
    fx, fy = foot[..., 0] - c[..., 0], foot[..., 1] - c[..., 1]
    h = np.hypot(fx, fy)
    use = (t_foot >= 0) & (t_foot <= 1) & _in_sweep(np.arctan2(fy, fx), a0, sweep)
    d = np.where(use, np.minimum(d, np.abs(h - rho)), d)
    # Crossings of the circle with the segment, on the arc: distance 0.
    half = np.sqrt(np.maximum(rho**2 - h**2, 0.0)) / np.sqrt(safe)
    for t in (t_foot - half, t_foot + half):
        pt = s0 + t[..., None] * ab
        hit = (
            (h <= rho)
            & (den > 0)
            & (t >= 0)
            & (t <= 1)
            & _in_sweep(np.arctan2(pt[..., 1] - c[..., 1], pt[..., 0] - c[..., 0]), a0, sweep)
        )
        d = np.where(hit, 0.0, d)
    return d
