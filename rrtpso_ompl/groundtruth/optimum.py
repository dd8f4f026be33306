r"""The exact shortest path for a disc robot among circles, polygons and map cells (the reference
optimum).

The robot is a disc of radius ``R`` whose centre must stay in the bounds. In its configuration
space every obstacle grows by ``R``: a circle of radius ``r`` becomes a circle of radius ``r + R``
and a polygon (a box, a map's blocked cells) becomes the polygon with rounded corners, each convex
corner the centre of a circle of radius ``R``. A shortest path in such a space consists of straight
segments tangent to these circles and arcs along them (the tangent or "reduced visibility" graph;
LaValle, *Planning Algorithms*, 2006, section 6.2.4; Latombe 1991 for the polygonal case):

1. **Circles**: the start and the goal (radius 0), every obstacle circle (``r + R``), every convex
   vertex of a polygon and every convex corner of the union of the boxes (``R``; for a map, the
   corners where exactly one of the four cells around a grid point is blocked).
2. **A\* over tangents, built as it goes.** A node is a tangent point on a circle and the sense
   (clockwise or counter-clockwise) in which the path wraps that circle; from it the path follows
   the circle in that sense and leaves along a common tangent (two outer and two inner per pair of
   circles) to another circle. An edge (arc, then tangent) is kept when the arc and the tangent
   segment are free: exact distances to the candidate obstacles the spatial index names, the
   bounds for the arc's extreme points. The heuristic is the straight distance to the goal.
3. **Pruning that keeps exactness.** A valid path of length ``C`` (the grid certificate of
   :func:`~rrtpso_ompl.groundtruth.certify.grid_path`) bounds the optimum, so a circle that cannot
   touch the ellipse ``|x - start| + |x - goal| <= C`` is never a candidate, and an edge whose end
   already needs more than ``C`` is never checked. Only the tangents of the circles A\* expands are
   ever built, instead of those of every pair: 10,000 circles take seconds, not terabytes.

Every edge is a piece of a valid path (touching an obstacle is allowed, as everywhere in this
package), so the result is never shorter than the true optimum; and the true optimum is a path of
this graph, which A\* with a consistent heuristic searches exactly, so the result is exact up to
floating-point round-off. The box bounds add no circles: from inside, the box is convex, and so is
every corner where an obstacle meets it, and a shortest path bends only around corners that are
convex seen from the obstacle.

The free configuration space is closed (touching allowed). For a point robot (``R = 0``) a path
grazing a polygon corner would touch it with zero clearance, which the package's segment test
counts as entering; the corners are therefore rounded with a radius of twice the touch tolerance
(``2e-9`` of the workspace size), which changes the length by less than that.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import RrtpsoError
from ..model.geometry import point_segment_distance
from ..model.problem import Problem
from ..model.world import World

__all__ = ["MAX_NODES", "OptimumResult", "OptimumTooLarge", "Piece", "shortest_path"]

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


#: Most tangent nodes one search may create (memory: a few hundred bytes each).
MAX_NODES = 5_000_000


class OptimumTooLarge(RrtpsoError):
    """The search for the exact optimum would need more memory than it is allowed."""


# ----------------------------------------------------------------------------------------------
def shortest_path(
    problem: Problem, world: World | None = None, upper_bound: float | None = None
) -> OptimumResult:
    """The shortest collision-free path of ``problem`` for its disc robot (moving obstacles
    ignored).

    Parameters
    ----------
    problem : Problem
        A validated problem.
    world : World, optional
        Its static world, when already built.
    upper_bound : float, optional
        The length of any valid path (it prunes the search); by default the grid certificate's.

    Returns
    -------
    OptimumResult
        ``length`` None when no path exists.

    Raises
    ------
    OptimumTooLarge
        When the search would create more than :data:`MAX_NODES` tangent nodes.
    """
    t0 = time.perf_counter()
    world = world or World.from_problem(problem)
    radius = max(world.robot_radius, 2.0 * world.tol)  # see the module docstring for R = 0
    if radius != world.robot_radius:
        world = world.with_robot_radius(radius)
    start = np.asarray(problem.start[:2], dtype=float)
    goal = np.asarray(problem.goal[:2], dtype=float)
    goal_tol = float(problem.goal_tolerance)
    if math.dist(start, goal) <= goal_tol or np.array_equal(start, goal):
        still = Piece("line", tuple(map(float, start)), tuple(map(float, start)))
        return OptimumResult(problem.name, 0.0, [still], True, 1, 0, time.perf_counter() - t0)
    if upper_bound is None:
        upper_bound = _grid_bound(problem, world)
    circles = _node_circles(problem, world, start, goal, radius)
    search = _TangentSearch(world, circles, goal_tol, upper_bound, problem.source)
    found = search.run()
    exact = goal_tol == 0.0 or bool(
        world.point_clearance(goal[None])[0] >= goal_tol + world.threshold
    )
    if found is None:
        return OptimumResult(problem.name, None, [], exact, search.n_nodes, search.n_edges,
                             time.perf_counter() - t0)  # fmt: skip
    length, pieces = found
    pieces = _merge_arcs([p for p in pieces if p.length > 0.0] or pieces[:1])
    return OptimumResult(
        problem=problem.name,
        length=length,
        pieces=pieces,
        exact=exact,
        n_nodes=search.n_nodes,
        n_edges=search.n_edges,
        time=time.perf_counter() - t0,
    )


def _grid_bound(problem: Problem, world: World) -> float:
    """The length of a certified grid path (an upper bound on the optimum), or ``inf``."""
    from .certify import GRID_POINTS, grid_path

    (xmin, ymin), (xmax, ymax) = problem.bounds
    side = max(xmax - xmin, ymax - ymin)
    for factor in (1, 2, 4):
        try:
            path = grid_path(problem, side / (GRID_POINTS * factor))
        except RrtpsoError:  # a grid that fine would be too large
            break
        if path is not None and world.path_valid(path):
            return float(np.hypot(*np.diff(path, axis=0).T).sum())
    return math.inf


def _merge_arcs(pieces: list[Piece]) -> list[Piece]:
    """Join consecutive arcs on the same circle (the path passed a tangent point it did not use)."""
    out: list[Piece] = []
    for p in pieces:
        last = out[-1] if out else None
        if (p.kind == "arc" and last is not None and last.kind == "arc"
                and last.center == p.center and last.radius == p.radius
                and math.copysign(1.0, last.sweep) == math.copysign(1.0, p.sweep)):  # fmt: skip
            out[-1] = Piece("arc", last.start, p.end, last.center, last.radius, last.angle,
                            last.sweep + p.sweep)  # fmt: skip
        else:
            out.append(p)
    return out


def _node_circles(problem: Problem, world: World, start, goal, radius: float) -> np.ndarray:
    """(k, 3) circles ``(cx, cy, rho)``: start, goal, inflated obstacle circles, the convex
    vertices of polygons and the convex corners of the union of the boxes."""
    rows = [np.array([[*start, 0.0], [*goal, 0.0]])]
    c = world.circles
    rows.append(np.column_stack([c[:, :2], c[:, 2] + radius]))
    for p in world.polygons:
        prev, nxt = np.roll(p, 1, axis=0), np.roll(p, -1, axis=0)
        e0, e1 = p - prev, nxt - p
        turn = e0[:, 0] * e1[:, 1] - e0[:, 1] * e1[:, 0]
        area2 = np.sum(p[:, 0] * nxt[:, 1] - nxt[:, 0] * p[:, 1])
        # Convex vertices turn the way the ring runs; only they can bend a shortest path.
        convex = p[turn * np.sign(area2) > 0.0]
        rows.append(np.column_stack([convex, np.full(len(convex), radius)]))
    corners = _convex_box_corners(world)
    rows.append(np.column_stack([corners, np.full(len(corners), radius)]))
    return np.vstack(rows)


def _convex_box_corners(world: World) -> np.ndarray:
    """Corners of boxes where exactly one of the four quadrants around them is covered by boxes:
    the convex corners of their union (shared edges and inner corners drop out)."""
    b = world.boxes
    if not len(b):
        return np.empty((0, 2))
    corners = np.unique(np.vstack([b[:, [0, 1]], b[:, [2, 1]], b[:, [2, 3]], b[:, [0, 3]]]),
                        axis=0)  # fmt: skip
    eps = 1e-6 * float(np.min(np.minimum(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1])))
    covered = np.zeros(len(corners), dtype=int)
    boxes_only = World(world.bounds, boxes=world.boxes)  # circles and polygons do not count
    for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        x, y = corners[:, 0] + sx * eps, corners[:, 1] + sy * eps
        covered += boxes_only.in_polygons(x, y)
    return corners[covered == 1]


class _TangentSearch:
    """A* over tangent nodes, built as it goes (see the module docstring)."""

    def __init__(self, world: World, circles: np.ndarray, goal_tol: float, bound: float,
                 source: str) -> None:  # fmt: skip
        self.world = world
        self.goal_tol = goal_tol
        self.source = source
        start, goal = circles[0, :2], circles[1, :2]
        self.start, self.goal = start, goal
        self.bound = bound * (1.0 + 1e-9) + 10.0 * world.tol if math.isfinite(bound) else math.inf
        # Only circles that can touch the ellipse |x - start| + |x - goal| <= bound matter.
        reach = np.hypot(*(circles[:, :2] - start).T) + np.hypot(*(circles[:, :2] - goal).T)
        keep = reach - 2.0 * circles[:, 2] <= self.bound
        keep[:2] = True
        self.circles = circles[keep]
        self.n_nodes = 0
        self.n_edges = 0
        # Node arrays grow as nodes are created.
        self.xy: list[tuple[float, float]] = []
        self.circle: list[int] = []
        self.angle: list[float] = []
        self.sense: list[int] = []
        self.g: list[float] = []
        self.parent: list[int] = []
        self.leave: list[tuple[float, float]] = []  # the tangent's start on the parent's circle
        self.sweep: list[float] = []  # the parent's arc to it, signed (counter-clockwise > 0)
        self.goal_end: list[tuple[float, float] | None] = []
        self.key: dict[int, int] = {}  # (from circle, to circle, which tangent) -> node
        self._cache: dict[int, _Tangents] = {}  # circle -> its usable free tangents

    # ------------------------------------------------------------------------------------------
    def run(self) -> tuple[float, list[Piece]] | None:
        start = self._add(-1, tuple(self.circles[0, :2]), 0, 0.0, 0, 0.0, -1,
                          (0.0, 0.0), 0.0)  # fmt: skip
        heap = [(self._h(start), start)]
        closed: set[int] = set()
        while heap:
            f, u = heapq.heappop(heap)
            if u in closed or f > self.g[u] + self._h(u) + 1e-12:
                continue
            closed.add(u)
            if self.circle[u] == 1:
                return self.g[u], self._pieces(u)
            for v in self._expand(u):
                heapq.heappush(heap, (self.g[v] + self._h(v), v))
        return None

    def _h(self, u: int) -> float:
        d = math.dist(self.xy[u], self.goal)
        return max(d - self.goal_tol, 0.0)

    def _add(self, key, xy, circle, angle, sense, g, parent, leave, sweep, goal_end=None) -> int:
        k = len(self.xy)
        if k >= MAX_NODES:
            raise OptimumTooLarge(
                f"{self.source}: the search for the exact optimum passed {MAX_NODES:,} tangent "
                "nodes; the problem is too large for it"
            )
        self.key[key] = k
        for store, value in ((self.xy, xy), (self.circle, circle), (self.angle, angle),
                             (self.sense, sense), (self.g, g), (self.parent, parent),
                             (self.leave, leave), (self.sweep, sweep),
                             (self.goal_end, goal_end)):  # fmt: skip
            store.append(value)
        self.n_nodes = k + 1
        return k

    # ------------------------------------------------------------------------------------------
    def _expand(self, u: int) -> list[int]:
        """Create or improve the nodes reached from ``u`` by an arc and a free tangent."""
        i = self.circle[u]
        cand = self._free_tangents(i)
        if not len(cand.j):
            return []
        # The path keeps wrapping circle i the way it arrived, then leaves on the tangent.
        rho_i = self.circles[i, 2]
        if rho_i > 0:
            cand = cand.take(np.flatnonzero(cand.sense_i == self.sense[u]))
            sweep = np.mod(self.sense[u] * (cand.angle_i - self.angle[u]), _TWO_PI)
        else:
            sweep = np.zeros(len(cand.j))
        g = self.g[u] + rho_i * sweep + cand.seg
        idx = np.flatnonzero(g + cand.h <= self.bound)
        if not len(idx):
            return []
        # No better than a node already reached by this tangent: nothing to do.
        keys = cand.key[idx].tolist()
        best = np.array([self.g[self.key[k]] if k in self.key else math.inf for k in keys])
        better = g[idx] < best - 1e-12
        idx = idx[better]
        if rho_i > 0 and len(idx):
            idx = idx[self._arcs_ok(u, sweep[idx])]
        self.n_edges += len(idx)
        out = []
        for k in idx.tolist():
            key = int(cand.key[k])
            leave = (float(cand.p[k, 0]), float(cand.p[k, 1]))
            signed = float(self.sense[u] * sweep[k]) if rho_i > 0 else 0.0
            if key in self.key:
                v = self.key[key]
                self.g[v], self.parent[v], self.leave[v], self.sweep[v] = g[k], u, leave, signed
            else:
                xy = (float(cand.q[k, 0]), float(cand.q[k, 1]))
                v = self._add(key, xy, int(cand.j[k]), float(cand.angle_j[k]),
                              int(cand.sense_j[k]), float(g[k]), u, leave, signed)  # fmt: skip
            out.append(v)
        return out

    def _free_tangents(self, i: int) -> _Tangents:
        """The tangents from circle ``i`` that some path within the bound could use and that are
        free (segment and end points in bounds), computed once per circle.

        Whether a tangent segment is free does not depend on the node it leaves from, so each
        circle's are found once: drop those no path within the bound can use (start to the
        tangent, the tangent, the straight line on to the goal: already longer), then those
        the obstacles next to circle ``i`` surely block (:func:`_occluded`, a cheap angular
        test), then test the rest exactly.
        """
        cached = self._cache.get(i)
        if cached is not None:
            return cached
        cand = _tangents_from(self.circles, i)
        cand.q = self._ends(cand, cand.j == 1)
        cand.seg = np.hypot(*(cand.q - cand.p).T)
        cand.h = np.maximum(np.hypot(*(cand.q - self.goal).T) - self.goal_tol, 0.0)
        lower = np.hypot(*(cand.p - self.start).T) + cand.seg + cand.h
        cand = cand.take(np.flatnonzero(lower <= self.bound))
        if len(cand.j):
            cand = cand.take(np.flatnonzero(~self._occluded(i, cand)))
        if len(cand.j):
            w = self.world
            ok = w.points_in_bounds(cand.p) & w.points_in_bounds(cand.q)
            idx = np.flatnonzero(ok)
            idx = idx[w.segments_free(cand.p[idx], cand.q[idx])]
            cand = cand.take(idx)
        cand.key = (i * len(self.circles) + cand.j.astype(np.int64)) * 4 + cand.t
        self._cache[i] = cand
        return cand

    def _occluded(self, i: int, cand: _Tangents) -> np.ndarray:
        """Tangents from circle ``i`` surely blocked by a disc next to it (booleans).

        A tangent leaving circle ``i`` (centre ``c``, radius ``rho``) in direction ``phi`` with
        sense ``s`` runs on the line ``cross(x - c, u(phi)) = s rho``. A disc of radius ``r`` at
        distance ``D`` and bearing ``theta`` from ``c`` cuts that line where
        ``|D sin(phi - theta) - s rho| < r``, an interval of directions; the nearest point of
        the line to the disc's centre lies ``D cos(phi - theta) <= D`` ahead. So a tangent
        whose direction falls in the interval (with ``cos >= 0``) and that is at least ``D``
        long passes closer than ``r`` to the centre: blocked. The discs are the inflated
        circles near ``i`` and the discs inscribed in the inflated boxes near it; their
        intervals, merged per sense into the least ``D`` over each piece of the circle of
        directions, answer every tangent in one ``searchsorted``.
        """
        w = self.world
        ci, rho = self.circles[i, :2], float(self.circles[i, 2])
        discs = self._near_discs(ci, rho)
        blocked = np.zeros(len(cand.j), dtype=bool)
        if not len(discs):
            return blocked
        rel = discs[:, :2] - ci
        dist = np.hypot(rel[:, 0], rel[:, 1])
        # Circle i's own obstacle (at distance 0) blocks nothing a tangent to it could use.
        discs, rel, dist = discs[dist > 0], rel[dist > 0], dist[dist > 0]
        theta = np.arctan2(rel[:, 1], rel[:, 0])
        if not len(discs):
            return blocked
        r = discs[:, 2] - 2.0 * w.tol  # strictly inside: grazing tangents stay candidates
        d = cand.q - cand.p
        phi = np.mod(np.arctan2(d[:, 1], d[:, 0]), _TWO_PI)
        for s in (-1, 1) if rho > 0 else (0,):
            mine = np.flatnonzero(cand.sense_i == s) if rho > 0 else np.arange(len(phi))
            if not len(mine):
                continue
            lo = np.clip((s * rho - r) / dist, -1.0, 1.0)
            hi = np.clip((s * rho + r) / dist, -1.0, 1.0)
            use = (r > 0) & (hi > lo)
            a0 = np.mod(theta[use] + np.arcsin(lo[use]), _TWO_PI)
            width = np.arcsin(hi[use]) - np.arcsin(lo[use])
            need = _least_over_intervals(a0, width, dist[use], phi[mine])
            blocked[mine] = cand.seg[mine] >= need
        return blocked

    def _near_discs(self, c: np.ndarray, rho: float) -> np.ndarray:
        """(k, 3) discs inside the inflated obstacles within a few index cells of a circle."""
        w = self.world
        if not w.n_obstacles:
            return np.empty((0, 3))
        reach = rho + 2.0 * w._grid.h
        _, ids = w._grid.pairs_in_boxes(c - reach, c + reach)
        kind = w._kind_of(ids)
        circ = w.circles[ids[kind == 0]]
        out = [np.column_stack([circ[:, :2], circ[:, 2] + w.threshold])]
        box = w.boxes[ids[kind == 1] - w._n_circles]
        if len(box):
            half = 0.5 * np.minimum(box[:, 2] - box[:, 0], box[:, 3] - box[:, 1])
            mid = 0.5 * (box[:, :2] + box[:, 2:])
            out.append(np.column_stack([mid, half + w.threshold]))
        return np.vstack(out)

    def _arcs_ok(self, u: int, sweep: np.ndarray) -> np.ndarray:
        """Which arcs along node ``u``'s circle, from its angle through ``sweep``, are free."""
        ok = np.ones(len(sweep), dtype=bool)
        arcs = np.flatnonzero(sweep > 0)
        if len(arcs):
            s = sweep[arcs]
            i = self.circle[u]
            a0 = self.angle[u] if self.sense[u] > 0 else self.angle[u] - s
            center = np.broadcast_to(self.circles[i, :2], (len(arcs), 2))
            rho = np.full(len(arcs), self.circles[i, 2])
            ok[arcs] = _arcs_free(self.world, center, rho, np.broadcast_to(a0, s.shape), s)
        return ok

    def _ends(self, cand, to_goal: np.ndarray) -> np.ndarray:
        """Where each tangent ends: its tangent point, or inside a goal tolerance, the point where
        it enters the goal disc."""
        end = cand.q.copy()
        if self.goal_tol > 0 and to_goal.any():
            d = cand.q[to_goal] - cand.p[to_goal]
            n = np.hypot(*d.T)
            frac = np.clip(1.0 - self.goal_tol / np.where(n > 0, n, 1.0), 0.0, 1.0)
            end[to_goal] = cand.p[to_goal] + frac[:, None] * d
        return end

    def _pieces(self, v: int) -> list[Piece]:
        """The path from the start to node ``v`` as arcs and tangent segments."""
        chain = []
        while v != -1:
            chain.append(v)
            v = self.parent[v]
        chain.reverse()
        pieces: list[Piece] = []
        for u, v in itertools.pairwise(chain):
            leave = self.leave[v]
            if self.sweep[v] != 0.0:
                c = self.circles[self.circle[u]]
                pieces.append(Piece("arc", self.xy[u], leave, (float(c[0]), float(c[1])),
                                    float(c[2]), self.angle[u], self.sweep[v]))  # fmt: skip
            pieces.append(Piece("line", leave, self.xy[v]))
        return pieces


class _Tangents:
    """The common tangents from one circle to many: arrays of the same length.

    ``q`` is where each tangent ends (its tangent point, or where it enters the goal disc);
    ``seg``, ``h`` and ``key`` (the tangent's length, its end's distance to the goal and the key
    of the node it reaches) are filled in by the search.
    """

    _FIELDS = ("j", "t", "p", "q", "angle_i", "angle_j", "sense_i", "sense_j", "seg", "h", "key")

    def __init__(self, j, t, p, q, angle_i, angle_j, sense_i, sense_j) -> None:
        self.j, self.t, self.p, self.q = j, t, p, q
        self.angle_i, self.angle_j = angle_i, angle_j
        self.sense_i, self.sense_j = sense_i, sense_j
        self.seg = self.h = self.key = None

    def take(self, idx: np.ndarray) -> _Tangents:
        out = _Tangents.__new__(_Tangents)
        for name in self._FIELDS:
            value = getattr(self, name)
            setattr(out, name, None if value is None else value[idx])
        return out


def _least_over_intervals(
    a0: np.ndarray, width: np.ndarray, value: np.ndarray, phi: np.ndarray
) -> np.ndarray:
    """For each angle ``phi`` in [0, 2 pi), the least ``value`` of the intervals
    ``[a0, a0 + width]`` (angles modulo 2 pi, open at both ends) that contain it; ``inf`` where
    none does."""
    if not len(a0):
        return np.full(len(phi), np.inf)
    # Each interval also once shifted down a turn, so those that wrap past 2 pi are found.
    lo = np.concatenate([a0, a0 - _TWO_PI])
    hi = lo + np.concatenate([width, width])
    val = np.concatenate([value, value])
    edges = np.unique(np.concatenate([lo, hi, [0.0, _TWO_PI]]))
    mids = 0.5 * (edges[:-1] + edges[1:])
    inside = (lo[None, :] < mids[:, None]) & (mids[:, None] < hi[None, :])
    least = np.where(inside, val[None, :], np.inf).min(axis=1)
    piece = np.clip(np.searchsorted(edges, phi, side="right") - 1, 0, len(mids) - 1)
    # An angle on a piece's edge may lie on an interval's open end: count it as outside.
    on_edge = np.isin(phi, edges)
    return np.where(on_edge, np.inf, least[piece])


def _tangents_from(circles: np.ndarray, i: int) -> _Tangents:
    """Every common tangent from circle ``i`` to the others (not back to the start), with the
    sense in which a path along it wraps each circle (+1 counter-clockwise, -1 clockwise, 0 for
    a point)."""
    c = circles
    j = np.arange(len(c))
    j = j[(j != i) & (j != 0)]
    ri, rj = c[i, 2], c[j, 2]
    d_vec = c[j, :2] - c[i, :2]
    d = np.hypot(*d_vec.T)
    base = np.arctan2(d_vec[:, 1], d_vec[:, 0])
    parts = []
    # Outer tangents: normal at angle base +- acos((ri - rj) / d) on both circles. Inner ones:
    # base +- acos((ri + rj) / d), with the normal reversed on circle j. A radius of 0 makes
    # the inner tangents repeat the outer ones, and two points have one tangent.
    for t, (inner, sign) in enumerate(((False, 1.0), (False, -1.0), (True, 1.0), (True, -1.0))):
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
        p = c[i, :2] + ri * n
        q = c[j, :2] + (-1.0 if inner else 1.0) * rj[:, None] * n
        aj = ang + math.pi if inner else ang
        parts.append((j[ok], np.full(int(ok.sum()), t), p[ok], q[ok], ang[ok], aj[ok]))
    jj, tt, p, q, ai, aj = (np.concatenate(x) for x in zip(*parts, strict=True))
    direction = q - p
    sense_i = _sense(direction, c[i, :2] - p) if ri > 0 else np.zeros(len(jj), dtype=int)
    sense_j = np.where(c[jj, 2] > 0, _sense(direction, c[jj, :2] - q), 0)
    return _Tangents(jj, tt, p, q, np.mod(ai, _TWO_PI), np.mod(aj, _TWO_PI), sense_i, sense_j)


def _sense(direction: np.ndarray, to_center: np.ndarray) -> np.ndarray:
    """+1 when the centre lies to the left of the direction of travel (counter-clockwise)."""
    z = direction[:, 0] * to_center[:, 1] - direction[:, 1] * to_center[:, 0]
    return np.where(z > 0, 1, -1)


def _arcs_free(world: World, center, rho, a0, sweep) -> np.ndarray:
    """Exact test of counter-clockwise arcs (from ``a0`` through ``sweep``) against the bounds and
    the obstacles the index names near each arc's circle."""
    ok = np.ones(len(rho), dtype=bool)
    # Bounds: the arc's extreme points are its ends and the axis directions it passes.
    xs = [center[:, 0] + rho * np.cos(a) for a in (a0, a0 + sweep)]
    ys = [center[:, 1] + rho * np.sin(a) for a in (a0, a0 + sweep)]
    for axis in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
        inside = _in_sweep(axis, a0, sweep)
        xs.append(np.where(inside, center[:, 0] + rho * math.cos(axis), xs[0]))
        ys.append(np.where(inside, center[:, 1] + rho * math.sin(axis), ys[0]))
    pts = np.stack([np.concatenate(xs), np.concatenate(ys)], axis=1)
    ok &= world.points_in_bounds(pts).reshape(-1, len(rho)).all(axis=0)
    # Obstacles near each arc's circle (its bounding box, grown by the reach in the index).
    lo = center - rho[:, None]
    hi = center + rho[:, None]
    arc, ids = world._grid.pairs_in_boxes(lo, hi) if world.n_obstacles else (np.empty(0, int),) * 2
    kind = world._kind_of(ids)
    c = kind == 0
    if c.any():
        obs = world.circles[ids[c]]
        k = arc[c]
        d = _arc_point_distance(center[k], rho[k], a0[k], sweep[k], obs[:, :2])
        bad = d < obs[:, 2] + world.threshold
        ok[np.unique(k[bad])] = False
    e_arc, edges = _edges_of(world, arc, ids, kind)
    if len(e_arc):
        d = _arc_segment_distance(center[e_arc], rho[e_arc], a0[e_arc], sweep[e_arc],
                                  edges[:, :2], edges[:, 2:])  # fmt: skip
        ok[np.unique(e_arc[d < world.threshold])] = False
    # An arc clear of every edge is wholly inside or outside each polygon and box.
    mid = a0 + 0.5 * sweep
    ok &= ~world.in_polygons(center[:, 0] + rho * np.cos(mid), center[:, 1] + rho * np.sin(mid))
    return ok


def _edges_of(world: World, arc: np.ndarray, ids: np.ndarray, kind: np.ndarray):
    """(arc, edge) pairs for the boxes and polygon edges among the candidates (the world indexes
    a polygon by its edges, and its interior, which :meth:`World.in_polygons` covers)."""
    arcs, edges = [], []
    x = kind == 1
    if x.any():
        b = world.boxes[ids[x] - world._n_circles]
        for e in (b[:, [0, 1, 2, 1]], b[:, [2, 1, 2, 3]], b[:, [2, 3, 0, 3]], b[:, [0, 3, 0, 1]]):
            arcs.append(arc[x])
            edges.append(e)
    p = kind == 2
    if p.any():
        arcs.append(arc[p])
        edges.append(world._edges[ids[p] - world._first_edge])
    if not arcs:
        return np.empty(0, dtype=int), np.empty((0, 4))
    return np.concatenate(arcs), np.vstack(edges)


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
