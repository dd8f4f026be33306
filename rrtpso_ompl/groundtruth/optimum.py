r"""The exact shortest path for a disc robot among circles, polygons and map cells (the reference
optimum).

The robot is a disc of radius ``R`` whose centre must stay in the bounds. In its configuration
space every obstacle grows by ``R``: a circle of radius ``r`` becomes a circle of radius ``r + R``
and a polygon (a box, a map's blocked cells) becomes the polygon with rounded corners, each convex
corner the centre of a circle of radius ``R``. A shortest path in such a space consists of straight
segments tangent to these circles and arcs along them (the tangent or "reduced visibility" graph;
LaValle, *Planning Algorithms*, 2006, section 6.2.4; Latombe 1991 for the polygonal case):

1. **Circles**: the start and the goal (radius 0), every obstacle circle (``r + R``), every convex
   vertex of a polygon and every convex corner of the union of the boxes (``R``). When the boxes
   lie on one lattice (a map's merged cells), the corners come straight from the cells: the grid
   points where exactly one of the four cells around is blocked. A vertex's circle carries its
   *cone*: a path wraps it only between the outward normals of its two edges (a quarter circle
   at a map corner), elsewhere it would enter an edge's offset. The cone's ends belong to it,
   with room for round-off: a path along an edge leaves and reaches its vertices exactly there.
2. **A\* over tangents, built as it goes.** A node is a tangent point on a circle and the sense
   (clockwise or counter-clockwise) in which the path wraps that circle; from it the path follows
   the circle in that sense and leaves along a common tangent (two outer and two inner per pair of
   circles) to another circle. An edge (arc, then tangent) is kept when the arc and the tangent
   segment are free: exact distances to the candidate obstacles the spatial index names, the
   bounds for the arc's extreme points (no test where nothing else is near the circle).
3. **A conservative raster** (:mod:`.free_grid`): the cells that may hold a free configuration,
   a superset of the free space. Breadth-first step counts over them from the start's cell and
   the goal's give *geodesic lower bounds* (a maze's corridors, not the straight line), used as
   A\*'s heuristic and for pruning; they also prove a problem unsolvable when the goal's cell is
   not reached. The heuristic is admissible but not consistent, so a node whose cost improves
   after its expansion is expanded again; A\* with an admissible heuristic and re-expansion
   returns the optimum.
4. **Pruning that keeps exactness.** The search runs in rounds of growing bounds ``C`` (multiples
   of the lower bound at the start): a circle that no path within ``C`` can touch (the geodesic
   ellipse ``LB_start + LB_goal <= C``) is never a candidate, nor is a tangent that no path within
   ``C`` can use; a round that finds nothing proves the optimum longer than its bound, and the
   next looks further. A tangent is free or not whatever node leaves along it, so each circle's
   free tangents are found once, for a batch of circles at a time (those A\* will likely expand
   next), through filters that each drop only what could not be used, cheapest first: circle pairs
   beyond the bound; pairs whose step counts differ by more than a free segment between them
   allows (the counts change by at most a step per cell along a free segment); directions
   outside the cones; pairs in the shadow of the discs near the first circle; tangents beyond the
   bound; then the exact tests (obstacles near the circle first, then the world's), with the
   raster's sound rejection (a sample in a cell where nothing is free) in between on maps.
5. **Dominance.** Where a circle's arc is free, a node reached at no more cost earlier on the
   arc, in the same sense, covers a later one: the later one is not expanded.

Every edge is a piece of a valid path (touching an obstacle is allowed, as everywhere in this
package), so the result is never shorter than the true optimum; and the true optimum is a path of
this graph, which the search covers within its final bound, so the result is exact up to
floating-point round-off. The box bounds add no circles: from inside, the box is convex, and so is
every corner where an obstacle meets it, and a shortest path bends only around corners that are
convex seen from the obstacle.

The free configuration space is closed (touching allowed). For a point robot (``R = 0``) a path
grazing a polygon corner would touch it with zero clearance, which the package's segment test
counts as entering; the corners are therefore rounded with a radius of twice the touch tolerance
(``2e-9`` of the workspace size), which changes the length by less than that. Two map cells that
touch only at a corner therefore close the diagonal between them.

A turned map (its cells squares of a :class:`~rrtpso_ompl.model.geometry.GridFrame`) is solved
in its grid coordinates when every free configuration lies in the map's rectangle (unknown space
blocks and the map lies in the bounds: the frame's ``confined``): there the rectangle is the
bounds, the cells keep their lattice, and the circles and polygons turn with the query; a
rotation keeps lengths, and the pieces of the path turn back. Otherwise the turned cells become
polygons in the world's coordinates: as exact, slower on large maps (no lattice).

Nothing here imports OMPL: :func:`shortest_path_in_world` needs only a
:class:`~rrtpso_ompl.model.World` and a query.
"""

from __future__ import annotations

import heapq
import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..errors import RrtpsoError
from ..model.geometry import point_segment_distance
from ..model.problem import Problem
from ..model.world import World
from .free_grid import FreeGrid, Stopped

__all__ = [
    "MAX_NODES",
    "OptimumResult",
    "OptimumTooLarge",
    "Piece",
    "shortest_path",
    "shortest_path_in_world",
]

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
        Size of the tangent graph of the last round.
    time : float
        Seconds spent.
    stopped : bool
        The search was stopped (its ``terminate`` callback) before it knew: ``length`` is None
        and says nothing.
    rounds : int
        Rounds of growing bounds the search took (module docstring).
    """

    problem: str
    length: float | None
    pieces: list[Piece] = field(default_factory=list)
    exact: bool = True
    n_nodes: int = 0
    n_edges: int = 0
    time: float = 0.0
    stopped: bool = False
    rounds: int = 0

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
            "graph": {"nodes": self.n_nodes, "edges": self.n_edges, "rounds": self.rounds},
            "time": self.time,
        }


#: Most tangent nodes one search may create (memory: a few hundred bytes each).
MAX_NODES = 5_000_000


class OptimumTooLarge(RrtpsoError):
    """The search for the exact optimum would need more memory than it is allowed."""


# ----------------------------------------------------------------------------------------------
def shortest_path(
    problem: Problem,
    world: World | None = None,
    upper_bound: float | None = None,
    *,
    terminate: Callable[[], bool] | None = None,
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
        The length of any valid path, or ``inf``: the search never looks beyond it. By default
        none is needed: the search runs in rounds of growing bounds (module docstring).
    terminate : callable, optional
        Polled between expansions; when it returns True the search stops and the result has
        ``stopped`` set and no path.

    Returns
    -------
    OptimumResult
        ``length`` None when no path exists (or when stopped).

    Raises
    ------
    OptimumTooLarge
        When the search would create more than :data:`MAX_NODES` tangent nodes.
    """
    world = world or World.from_problem(problem)
    return shortest_path_in_world(
        world, problem.start[:2], problem.goal[:2], float(problem.goal_tolerance),
        upper_bound=upper_bound, terminate=terminate, name=problem.name, source=problem.source,
    )  # fmt: skip


def shortest_path_in_world(
    world: World,
    start,
    goal,
    goal_tolerance: float = 0.0,
    *,
    upper_bound: float | None = None,
    terminate: Callable[[], bool] | None = None,
    name: str = "",
    source: str = "<world>",
) -> OptimumResult:
    """:func:`shortest_path` for a :class:`~rrtpso_ompl.model.World` and a query (what the
    ``Exact`` planner has: no problem file).

    Parameters
    ----------
    world : World
        Obstacles, bounds and robot radius.
    start, goal : (float, float)
        The query, problem units.
    goal_tolerance : float
        Radius of the goal disc (0: the goal point).
    upper_bound, terminate
        As for :func:`shortest_path`.
    name, source : str
        The problem's name (for the result) and where it came from (for messages).
    """
    frame = world.box_frame
    if frame is not None and frame.confined is not None:
        local = shortest_path_in_world(
            _grid_frame_world(world), frame.to_grid(np.asarray(start, dtype=float)[:2]),
            frame.to_grid(np.asarray(goal, dtype=float)[:2]), goal_tolerance,
            upper_bound=upper_bound, terminate=terminate, name=name, source=source,
        )  # fmt: skip
        return replace(local, pieces=[_turned(p, frame) for p in local.pieces])
    if frame is not None:
        world = _boxes_as_polygons(world)
    t0 = time.perf_counter()
    radius = max(world.robot_radius, 2.0 * world.tol)  # see the module docstring for R = 0
    if radius != world.robot_radius:
        world = world.with_robot_radius(radius)
    start = np.asarray(start, dtype=float)[:2]
    goal = np.asarray(goal, dtype=float)[:2]
    goal_tol = float(goal_tolerance)
    exact = goal_tol == 0.0 or bool(
        world.point_clearance(goal[None])[0] >= goal_tol + world.threshold
    )
    if math.dist(start, goal) <= goal_tol or np.array_equal(start, goal):
        still = Piece("line", tuple(map(float, start)), tuple(map(float, start)))
        return OptimumResult(name, 0.0, [still], True, 1, 0, time.perf_counter() - t0)
    stop = terminate if terminate is not None else (lambda: False)
    if stop():
        return OptimumResult(name, None, [], exact, 0, 0, time.perf_counter() - t0, True, 0)
    try:
        grid = FreeGrid.for_world(world, start, goal, goal_tol, terminate)
    except Stopped:
        return OptimumResult(name, None, [], exact, 0, 0, time.perf_counter() - t0, True, 0)

    def result(found, search=None, stopped=False, rounds=0) -> OptimumResult:
        nodes, edges = (search.n_nodes, search.n_edges) if search is not None else (0, 0)
        if found is None:
            return OptimumResult(name, None, [], exact, nodes, edges,
                                 time.perf_counter() - t0, stopped, rounds)  # fmt: skip
        length, pieces = found
        pieces = _merge_arcs([p for p in pieces if p.length > 0.0] or pieces[:1])
        return OptimumResult(name, length, pieces, exact, nodes, edges,
                             time.perf_counter() - t0, False, rounds)  # fmt: skip

    if not grid.connected:  # a proof: no chain of possibly-free cells joins them
        return result(None)
    if stop():
        return result(None, stopped=True)
    nodes = _NodeCircles.build(world, grid, start, goal, radius)
    cap = math.inf if upper_bound is None else float(upper_bound)
    lower = float(grid.lower_bound(1, start[None])[0])
    search = None
    kind = "lattice" if grid.blocked is not None else "generic"
    for k, bound in enumerate(_bounds(lower, cap, world.tol, kind)):
        search = _TangentSearch(world, grid, nodes, goal_tol, bound, source, terminate)
        found = search.run()
        if search.stopped:
            return result(None, search, stopped=True, rounds=k + 1)
        if found is not None or bound >= cap:
            return result(found, search, rounds=k + 1)
    return result(None, search)  # pragma: no cover - the last bound is the cap


def _grid_frame_world(world: World) -> World:
    """The world of a turned map in its grid coordinates, where its free configurations are
    the same (the frame's ``confined`` holds them all, module docstring): the map's rectangle as
    the bounds, the boxes as they are, the circles and polygons turned into grid coordinates."""
    f = world.box_frame
    x0, y0, x1, y1 = f.confined
    circles = np.column_stack([f.to_grid(world.circles[:, :2]), world.circles[:, 2]])
    polygons = [f.to_grid(p) for p in world.polygons]
    return World(((x0, y0), (x1, y1)), circles, polygons, world.robot_radius, world.boxes)


def _boxes_as_polygons(world: World) -> World:
    """The world of a turned map with its boxes as polygons (their turned squares) in the world's
    coordinates: the search below treats boxes as axis-aligned."""
    squares = list(world.box_frame.box_corners(world.boxes))
    return World(world.bounds, world.circles, [*world.polygons, *squares], world.robot_radius)


def _turned(piece: Piece, frame) -> Piece:
    """A piece found in grid coordinates, in the world's."""

    def back(p):
        return tuple(frame.to_world(np.asarray(p, dtype=float)).tolist())

    if piece.kind != "arc":
        return replace(piece, start=back(piece.start), end=back(piece.end))
    return replace(piece, start=back(piece.start), end=back(piece.end),
                   center=back(piece.center), angle=piece.angle + frame.yaw)  # fmt: skip


#: The rounds' bounds, as multiples of the lower bound on the optimum: a round that finds no
#: path within its bound proves the optimum longer, and the next one looks further. On a map's
#: lattice the geodesic bound is a few percent short (it counts cells) and a loose bound costs
#: little (the step counts and the raster bound the candidates); among circles and polygons it
#: is often within a fraction of a percent, and the width of the ellipse drives the cost.
_ROUND_FACTORS = {
    "lattice": (1.08, 1.3, 2.0, 4.0, 8.0),
    "generic": (1.005, 1.02, 1.08, 1.3, 2.0, 4.0, 8.0),
}


def _bounds(lower: float, cap: float, tol: float, kind: str):
    """The bound of each round, ending with ``cap``."""
    for factor in _ROUND_FACTORS[kind]:
        b = lower * factor + 10.0 * tol
        if b >= cap:
            break
        yield b
    yield cap


def _loosen(bound: float, tol: float) -> float:
    """A bound with room for round-off (lengths add up over many pieces)."""
    return bound * (1.0 + 1e-9) + 10.0 * tol if math.isfinite(bound) else math.inf


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


# ----------------------------------------------------------------------------------------------
@dataclass
class _NodeCircles:
    """The circles a shortest path can wrap, with what is known of their free arcs.

    Attributes
    ----------
    circles : (k, 3) ndarray
        ``(cx, cy, rho)``: start and goal (radius 0) first, then the inflated obstacle circles,
        the convex polygon vertices and the convex corners of the boxes or map cells.
    lo, width : (k,) ndarray
        The arc a path may wrap starts at angle ``lo`` and runs counter-clockwise through
        ``width`` (``2 pi``: the whole circle). At a convex vertex it is the cone of the outward
        normals of its two edges: a path that wraps the vertex elsewhere would enter an edge's
        offset.
    sure : (k,) bool
        Every point of that arc is free (nothing but the circle's own obstacle is within its
        reach), so arcs need no exact test.
    """

    circles: np.ndarray
    lo: np.ndarray
    width: np.ndarray
    sure: np.ndarray

    @classmethod
    def build(cls, world: World, grid: FreeGrid, start, goal, radius: float) -> _NodeCircles:
        rows = [np.array([[*start, 0.0], [*goal, 0.0]])]
        lo, width = [np.zeros(2)], [np.full(2, _TWO_PI)]
        c = world.circles
        rows.append(np.column_stack([c[:, :2], c[:, 2] + radius]))
        lo.append(np.zeros(len(c)))
        width.append(np.full(len(c), _TWO_PI))
        circle_sure = _lonely_circles(world)
        for p in world.polygons:
            if np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]) < 0:
                p = p[::-1]  # counter-clockwise
            e0 = p - np.roll(p, 1, axis=0)
            e1 = np.roll(p, -1, axis=0) - p
            turn = e0[:, 0] * e1[:, 1] - e0[:, 1] * e1[:, 0]
            convex = turn > 0.0  # only convex vertices can bend a shortest path
            # Outward normals of a counter-clockwise ring point to the right of each edge.
            a0 = np.arctan2(-e0[convex, 0], e0[convex, 1])
            a1 = np.arctan2(-e1[convex, 0], e1[convex, 1])
            rows.append(np.column_stack([p[convex], np.full(int(convex.sum()), radius)]))
            lo.append(np.mod(a0, _TWO_PI))
            width.append(np.mod(a1 - a0, _TWO_PI))
        n_fixed = sum(len(r) for r in rows)
        if grid.blocked is not None:
            corners, q_lo, sure = _lattice_corners(grid, radius, world.tol)
            if len(world.circles) or world.polygons:
                sure[:] = False  # other obstacles may be near the arcs
        else:
            corners, q_lo = _convex_box_corners(world)
            sure = np.zeros(len(corners), dtype=bool)
        rows.append(np.column_stack([corners, np.full(len(corners), radius)]))
        lo.append(q_lo)
        width.append(np.full(len(corners), 0.5 * math.pi))
        others = np.zeros(n_fixed - 2 - len(circle_sure), dtype=bool)  # polygon vertices
        all_sure = np.concatenate([np.ones(2, dtype=bool), circle_sure, others, sure])
        return cls(np.vstack(rows), np.concatenate(lo), np.concatenate(width), all_sure)


def _lonely_circles(world: World) -> np.ndarray:
    """Which obstacle circles no other obstacle comes near and whose grown circle lies in the
    bounds: that whole circle is free, so arcs along it need no exact test (any box or polygon
    in reach counts as near)."""
    c = world.circles
    if not len(c):
        return np.zeros(0, dtype=bool)
    thr = world.threshold
    reach = (c[:, 2] + 2.0 * thr + 8.0 * world.tol)[:, None]
    query, ids = world.index.grid.pairs_in_boxes(c[:, :2] - reach, c[:, :2] + reach)
    other = ids != query  # circles come first among the ids: id == own index
    query, ids = query[other], ids[other]
    kind = world.index.kind_of(ids)
    near = np.zeros(len(c), dtype=bool)
    near[query[kind != 0]] = True
    k = kind == 0
    q, o = query[k], ids[k]
    gap = np.hypot(*(c[o, :2] - c[q, :2]).T) - c[q, 2] - c[o, 2]
    near[q[gap < 2.0 * thr + 8.0 * world.tol]] = True
    # And the grown circle must lie in the bounds (an arc may not leave them).
    (xmin, ymin), (xmax, ymax) = world.bounds
    rho = c[:, 2] + world.robot_radius
    inside = (c[:, 0] - rho >= xmin) & (c[:, 0] + rho <= xmax)
    inside &= (c[:, 1] - rho >= ymin) & (c[:, 1] + rho <= ymax)
    return ~near & inside


def _lattice_corners(grid: FreeGrid, radius: float, tol: float):
    """Convex corners of the blocked cells of a lattice raster (a map's), straight from the
    cells: the grid points where exactly one of the four cells around is blocked (cells outside
    the raster count as free).

    Returns the corners, the angle where the quarter of free directions starts (the normals
    of the blocked cell's two edges at the corner) and whether nothing else is blocked within
    twice the radius (the corner's arc is then free: no exact arc test is needed).
    """
    blocked = grid.blocked
    b = np.pad(blocked, 1, constant_values=False)
    sw, se, nw, ne = b[:-1, :-1], b[:-1, 1:], b[1:, :-1], b[1:, 1:]
    count = sw.astype(np.int8) + se + nw + ne
    j, i = np.nonzero(count == 1)
    # The free quarter is opposite the blocked cell: SW blocked -> normals east to north, etc.
    q_lo = np.select([sw[j, i], se[j, i], ne[j, i]], [0.0, 0.5 * math.pi, math.pi], 1.5 * math.pi)
    h = grid.h
    corners = np.column_stack([grid.x0 + i * h, grid.y0 + j * h])
    # Blocked cells within 2 R of a corner (a window of w cells each way): only its own?
    w = max(1, math.ceil((2.0 * radius + 4.0 * tol) / h))
    sat = np.pad(np.cumsum(np.cumsum(blocked, axis=0), axis=1), ((1, 0), (1, 0)))
    ny, nx = blocked.shape
    j0, j1 = np.clip(j - w, 0, ny), np.clip(j + w, 0, ny)
    i0, i1 = np.clip(i - w, 0, nx), np.clip(i + w, 0, nx)
    inside = sat[j1, i1] - sat[j0, i1] - sat[j1, i0] + sat[j0, i0]
    return corners, q_lo, inside == 1


def _convex_box_corners(world: World) -> tuple[np.ndarray, np.ndarray]:
    """Corners of boxes where exactly one of the four quadrants around them is covered by boxes:
    the convex corners of their union (shared edges and inner corners drop out), with the angle
    where their quarter of free directions starts."""
    b = world.boxes
    if not len(b):
        return np.empty((0, 2)), np.empty(0)
    corners = np.unique(np.vstack([b[:, [0, 1]], b[:, [2, 1]], b[:, [2, 3]], b[:, [0, 3]]]),
                        axis=0)  # fmt: skip
    eps = 1e-6 * float(np.min(np.minimum(b[:, 2] - b[:, 0], b[:, 3] - b[:, 1])))
    covered = np.zeros(len(corners), dtype=int)
    q_lo = np.zeros(len(corners))
    boxes_only = World(world.bounds, boxes=world.boxes)  # circles and polygons do not count
    # Quadrants NE, NW, SW, SE; the free quarter is opposite the covered one.
    quadrants = ((1, 1), (-1, 1), (-1, -1), (1, -1))
    opposites = (math.pi, 1.5 * math.pi, 0.0, 0.5 * math.pi)
    for (sx, sy), opposite in zip(quadrants, opposites, strict=True):
        x, y = corners[:, 0] + sx * eps, corners[:, 1] + sy * eps
        inside = boxes_only.in_polygons(x, y)
        covered += inside
        q_lo[inside] = opposite
    keep = covered == 1
    return corners[keep], q_lo[keep]


class _TangentSearch:
    """A* over tangent nodes within one bound, built as it goes (see the module docstring)."""

    def __init__(self, world: World, grid: FreeGrid, nodes: _NodeCircles, goal_tol: float,
                 bound: float, source: str, terminate) -> None:  # fmt: skip
        self.world = world
        self.grid = grid
        self.goal_tol = goal_tol
        self.source = source
        self.terminate = terminate
        self.stopped = False
        self.bound = _loosen(bound, world.tol)
        self.eps = 1e-12 * max(1.0, bound if math.isfinite(bound) else 1.0)
        c = nodes.circles
        start, goal = c[0, :2], c[1, :2]
        self.start, self.goal = start, goal
        # Only circles on which a path within the bound can pass: the geodesic ellipse.
        lb_s = grid.circle_lower_bound(0, c)
        lb_g = grid.circle_lower_bound(1, c)
        through = lb_s + lb_g  # inf: the circle cannot be reached at all
        keep = np.flatnonzero(((through <= self.bound) & np.isfinite(through))
                              | (np.arange(len(c)) < 2))  # fmt: skip
        self.circles = c[keep]
        self.lo, self.width, self.sure = nodes.lo[keep], nodes.width[keep], nodes.sure[keep]
        self.lb_s, self.lb_g = lb_s[keep], lb_g[keep]
        self.steps = grid.step_ranges(self.circles)
        self._cache: dict[int, _Tangents] = {}
        self._cached = np.zeros(len(self.circles), dtype=bool)
        self._cached[1] = True  # the goal: never expanded
        self._cells_only = (grid.band_ok(world.threshold) and not len(world.circles)
                            and not world.polygons)  # fmt: skip
        self.n_nodes = 0
        self.n_edges = 0
        cap = 1024
        self.g = np.empty(cap)
        self.h = np.empty(cap)
        # Per node: (x, y), circle, angle, sense, parent, leave point, signed sweep.
        self.xy: list[tuple[float, float]] = []
        self.circle: list[int] = []
        self.angle: list[float] = []
        self.sense: list[int] = []
        self.parent: list[int] = []
        self.leave: list[tuple[float, float]] = []
        self.sweep: list[float] = []
        self._expanded: dict[tuple[int, int], list[tuple[float, float]]] = {}

    # ------------------------------------------------------------------------------------------
    def run(self) -> tuple[float, list[Piece]] | None:
        h0 = float(self.grid.lower_bound(1, self.start[None])[0])
        xy = (float(self.start[0]), float(self.start[1]))
        s = self._add(xy, 0, 0.0, 0, 0.0, -1, (0.0, 0.0), 0.0, h0)
        heap = [(self.h[s], s)]
        done = np.full(1024, math.inf)  # g at which each node was last expanded
        while heap:
            f, u = heapq.heappop(heap)
            g_u = self.g[u]
            if f > g_u + self.h[u] + self.eps:
                continue  # a stale entry: the node was improved since
            if u < len(done) and done[u] <= g_u + self.eps:
                continue  # expanded already with this g (the heuristic is not consistent)
            if self.terminate is not None and self.terminate():
                self.stopped = True
                return None
            if self.circle[u] == 1:
                return float(g_u), self._pieces(u)
            if self._dominated(u):
                continue
            if u >= len(done):
                done = np.concatenate([done, np.full(len(done), math.inf)])
            done[u] = g_u
            for v in self._expand(u):
                heapq.heappush(heap, (self.g[v] + self.h[v], v))
        return None

    def _dominated(self, u: int) -> bool:
        """Whether a node expanded earlier on the same circle and sense reaches ``u``'s point along
        a free arc at no more cost (then everything ``u`` leads to, it led to already)."""
        i, s = self.circle[u], self.sense[u]
        if not self.sure[i] or self.width[i] >= _TWO_PI:
            return False
        key = (i, s)
        rho = float(self.circles[i, 2])
        pos = float(_cone_pos(self.angle[u], self.lo[i]))
        g = float(self.g[u])
        seen = self._expanded.setdefault(key, [])
        for g_a, pos_a in seen:
            ahead = (pos - pos_a) * s
            if ahead >= -1e-12 and g_a + rho * max(ahead, 0.0) <= g + self.eps:
                return True
        seen.append((g, pos))
        return False

    def _add(self, xy, circle, angle, sense, g, parent, leave, sweep, h) -> int:
        k = self.n_nodes
        if k >= MAX_NODES:
            raise OptimumTooLarge(
                f"{self.source}: the search for the exact optimum passed {MAX_NODES:,} tangent "
                "nodes; the problem is too large for it"
            )
        if k >= len(self.g):
            self.g = np.concatenate([self.g, np.empty(len(self.g))])
            self.h = np.concatenate([self.h, np.empty(len(self.h))])
        self.g[k], self.h[k] = g, h
        self.xy.append(xy)
        self.circle.append(circle)
        self.angle.append(angle)
        self.sense.append(sense)
        self.parent.append(parent)
        self.leave.append(leave)
        self.sweep.append(sweep)
        self.n_nodes = k + 1
        return k

    # ------------------------------------------------------------------------------------------
    def _expand(self, u: int) -> list[int]:
        """Create or improve the nodes reached from ``u`` by an arc and a free tangent."""
        i = self.circle[u]
        cand = self._free_tangents(i, float(self.g[u]), float(self.g[u] + self.h[u]))
        if not len(cand.j):
            return []
        rho_i = float(self.circles[i, 2])
        s = self.sense[u]
        if rho_i > 0:
            idx = np.flatnonzero(cand.sense_i == s)
            if self.width[i] < _TWO_PI:
                # The arc stays on the circle's free arc: from u's point on, in u's sense.
                pos_u = _cone_pos(self.angle[u], self.lo[i])
                ahead = s * (cand.pos_i[idx] - pos_u)
                idx = idx[ahead >= -_ANGLE_TOL]
                sweep = np.maximum(s * (cand.pos_i[idx] - pos_u), 0.0)
            else:
                # Leaving where it arrived is no turn, whichever way round-off goes.
                turn = s * (cand.angle_i[idx] - self.angle[u]) + _ANGLE_TOL
                sweep = np.maximum(np.mod(turn, _TWO_PI) - _ANGLE_TOL, 0.0)
        else:
            idx = np.arange(len(cand.j))
            sweep = np.zeros(len(idx))
        g = self.g[u] + rho_i * sweep + cand.seg[idx]
        ok = g + cand.h[idx] <= self.bound
        idx, g, sweep = idx[ok], g[ok], sweep[ok]
        if not len(idx):
            return []
        # No better than a node already reached by this tangent: nothing to do.
        node = cand.node[idx]
        best = np.where(node >= 0, self.g[np.maximum(node, 0)], math.inf)
        better = g < best - self.eps
        idx, g, sweep, node = idx[better], g[better], sweep[better], node[better]
        if rho_i > 0 and len(idx) and not self.sure[i]:
            ok = self._arcs_ok(u, sweep)
            idx, g, sweep, node = idx[ok], g[ok], sweep[ok], node[ok]
        self.n_edges += len(idx)
        out = []
        for k, gk, sw, v in zip(idx.tolist(), g.tolist(), sweep.tolist(), node.tolist(),
                                strict=True):  # fmt: skip
            leave = (float(cand.p[k, 0]), float(cand.p[k, 1]))
            signed = s * sw if rho_i > 0 else 0.0
            if v >= 0:
                self.g[v] = gk
                self.parent[v], self.leave[v], self.sweep[v] = u, leave, signed
            else:
                v = self._add((float(cand.q[k, 0]), float(cand.q[k, 1])), int(cand.j[k]),
                              float(cand.angle_j[k]), int(cand.sense_j[k]), gk, u, leave,
                              signed, float(cand.h[k]))  # fmt: skip
                cand.node[k] = v
            out.append(v)
        return out

    def _free_tangents(self, i: int, g: float, f: float) -> _Tangents:
        """The tangents from circle ``i`` that some path within the bound could use and that are
        free (segment and end points in bounds), computed once per circle.

        Whether a tangent segment is free does not depend on the node it leaves from, so each
        circle's are found once, and together with those of the circles the search will likely
        expand next (up to :data:`_BATCH` in one vectorised pass, which costs little more than
        a pass over one): those whose lower bound from the start is nearest to ``g`` and whose
        lower bound through them is below or near ``f``.
        """
        cached = self._cache.get(i)
        if cached is not None:
            return cached
        todo = np.flatnonzero(~self._cached)
        todo = todo[todo != i]
        if len(todo) >= _BATCH:
            key = np.abs(self.lb_s[todo] - g) + np.maximum(
                self.lb_s[todo] + self.lb_g[todo] - f, 0.0)  # fmt: skip
            todo = todo[np.argpartition(key, _BATCH - 2)[: _BATCH - 1]]
        self._prepare(np.concatenate([[i], todo]).astype(np.intp))
        return self._cache[i]

    def _prepare(self, batch: np.ndarray) -> None:
        """Fill the cache of each circle of ``batch`` with its usable free tangents.

        The filters, cheapest first, each exact or dropping only what no path within the bound
        can use: circle pairs too far apart for the bound; tangents leaving or reaching a vertex
        outside its cone of free directions; tangents no path within the bound can use (lower
        bounds from the start to the tangent and from its end to the goal); tangents with a
        sample in a core cell of the raster; then the exact test, first against the obstacles
        near the circle they leave (where most blocked tangents are blocked), then the world's
        test of the whole segment.
        """
        c = self.circles
        ci = c[batch]
        # A first sieve over the whole (batch x circles) matrix, with cheap over-estimates of
        # distances (|dx| + |dy|) and under-estimates (max(|dx|, |dy|)): the bound through the
        # pair, and the 8-connected step counts to the goal (see FreeGrid.step_ranges).
        dx = np.abs(c[None, :, 0] - ci[:, None, 0])
        dy = np.abs(c[None, :, 1] - ci[:, None, 1])
        spread = ci[:, None, 2] + c[None, :, 2]
        reach = np.maximum(dx, dy) + self.lb_g[None, :] <= (
            self.bound - self.lb_s[batch])[:, None] + spread  # fmt: skip
        n = (dx + dy + 2.0 * spread) * (1.0 / self.grid.H) + 2.0
        lo_i, hi_i = self.steps[batch, 2, 0][:, None], self.steps[batch, 2, 1][:, None]
        lo_j, hi_j = self.steps[None, :, 2, 0], self.steps[None, :, 2, 1]
        with np.errstate(invalid="ignore"):  # inf - inf: a circle no free path reaches: drop
            reach &= (lo_j - hi_i <= n) & (lo_i - hi_j <= n)
        reach[:, 0] = False
        reach[np.arange(len(batch)), batch] = False
        row, j = np.nonzero(reach)
        # Then the exact distances and every step count, pair by pair.
        i = batch[row]
        d = c[j, :2] - c[i, :2]
        spread = c[i, 2] + c[j, 2]
        gap = np.hypot(d[:, 0], d[:, 1]) - spread
        ok = self.lb_s[i] + np.maximum(gap, 0.0) + self.lb_g[j] <= self.bound
        ok &= self.grid.visible_pairs(self.steps[i], self.steps[j], np.abs(d[:, 0]) + spread,
                                      np.abs(d[:, 1]) + spread)  # fmt: skip
        row, j = self._directions_ok(batch, row[ok], j[ok])
        row, j = self._shadowed(batch, row, j)
        cand = _tangents_from(c, batch[row], j)
        i = cand.i
        cand.pos_i = _cone_pos(cand.angle_i, self.lo[i])
        wi, wj = self.width[i], self.width[cand.j]
        pos_j = _cone_pos(cand.angle_j, self.lo[cand.j])
        cone = ((wi >= _TWO_PI) | (cand.pos_i <= wi + _ANGLE_TOL)) & (
            (wj >= _TWO_PI) | (pos_j <= wj + _ANGLE_TOL))  # fmt: skip
        cand = cand.take(np.flatnonzero(cone))
        cand.q = self._ends(cand, cand.j == 1)
        cand.seg = np.hypot(*(cand.q - cand.p).T)
        cand.h = self.grid.lower_bound(1, cand.q)
        lower = self.grid.lower_bound(0, cand.p) + cand.seg + cand.h
        w = self.world
        ok = lower <= self.bound
        ok &= w.points_in_bounds(cand.p) & w.points_in_bounds(cand.q)
        cand = cand.take(np.flatnonzero(ok))
        if len(cand.j) and self.grid.core_share >= _RASTER_WORTH:
            cand = cand.take(np.flatnonzero(~self.grid.blocked_segments(cand.p, cand.q)))
        if len(cand.j) and self._cells_only:
            # A world of the lattice's cells alone: the exact test straight from the cells.
            near = self.grid.segments_near_blocked(cand.p, cand.q, w.threshold)
            cand = cand.take(np.flatnonzero(~near))
        else:
            if len(cand.j):
                cand = cand.take(np.flatnonzero(~self._blocked_near(cand)))
            if len(cand.j):
                cand = cand.take(np.flatnonzero(w.segments_free(cand.p, cand.q)))
        cand.node = np.full(len(cand.j), -1, dtype=np.intp)
        order = np.argsort(cand.i, kind="stable")
        cand = cand.take(order)
        cuts = np.searchsorted(cand.i, batch, side="left"), np.searchsorted(cand.i, batch, "right")
        for k, circle in enumerate(batch.tolist()):
            self._cache[circle] = cand.take(slice(int(cuts[0][k]), int(cuts[1][k])))
        self._cached[batch] = True

    def _directions_ok(self, batch: np.ndarray, row: np.ndarray, j: np.ndarray):
        """The pairs ``(batch[row], j)`` that can have a tangent leaving the first circle and
        reaching the second within their cones of free directions.

        A path wrapping a circle at the outward normal ``n`` travels along ``n +- pi / 2``, so a
        tangent leaving a vertex whose cone is ``[lo, lo + w]`` heads into one of the two arcs of
        directions ``[lo + pi / 2, lo + w + pi / 2]`` and ``[lo - pi / 2, lo + w - pi / 2]``,
        and it arrives at the other circle in the same way. The tangent's direction differs from
        that of the line of centres by at most ``asin((rho_i + rho_j) / d)``.
        """
        i = batch[row]
        c = self.circles
        d = c[j, :2] - c[i, :2]
        dist = np.hypot(d[:, 0], d[:, 1])
        slack = np.arcsin(np.clip((c[i, 2] + c[j, 2]) / np.maximum(dist, 1e-300), 0.0, 1.0))
        slack += 1e-7
        phi = np.arctan2(d[:, 1], d[:, 0])
        ok = np.ones(len(i), dtype=bool)
        for k in (i, j):
            w = self.width[k]
            cone = w < _TWO_PI
            if not cone.any():
                continue
            inside = np.zeros(len(i), dtype=bool)
            for turn in (0.5 * math.pi, -0.5 * math.pi):
                off = np.mod(phi - (self.lo[k] + turn) + slack, _TWO_PI)
                inside |= off <= w + 2.0 * slack
            ok &= ~cone | inside
        return row[ok], j[ok]

    def _shadowed(self, batch: np.ndarray, row: np.ndarray, j: np.ndarray):
        """The pairs ``(batch[row], j)`` not wholly in the shadow of the obstacles near the first
        circle.

        A tangent leaving circle ``i`` (centre ``c``, radius ``rho``) in direction ``phi``, in
        the sense ``s``, runs on the line ``cross(x - c, u(phi)) = s rho``, whose distance to a
        disc centre at distance ``D`` and bearing ``theta`` from ``c`` is
        ``|D sin(phi - theta) - s rho|``; the foot of that distance lies ``D cos(phi - theta)
        <= D`` ahead. So a disc of radius ``r`` (a circle obstacle, or the disc inscribed in a
        box, grown by the clearance threshold) blocks every tangent of sense ``s`` whose
        direction has ``|D sin(phi - theta) - s rho| < r`` (and ``cos >= 0``) once it is ``D``
        long: an interval of directions per disc and sense. The least of those lengths over the
        intervals that cover a whole bin of directions bounds how far a free tangent can go in
        that bin. The tangents to circle ``j`` lie within ``asin((rho + rho_j) / d)`` of the
        line of centres and are at least the gap between the circles long, so when that gap
        reaches the largest bound over those bins, in both senses, none of them is free.
        """
        if not len(row):
            return row, j
        c = self.circles
        i = batch[row]
        d = c[j, :2] - c[i, :2]
        dist = np.hypot(d[:, 0], d[:, 1])
        gap = dist - c[i, 2] - c[j, 2]
        beta = np.arcsin(np.clip((c[i, 2] + c[j, 2]) / np.maximum(dist, 1e-300), 0.0, 1.0))
        phi = np.mod(np.arctan2(d[:, 1], d[:, 0]), _TWO_PI)
        # Profiles only for the circles with many pairs (else the tangent-level filters are
        # cheaper than the table).
        count = np.bincount(row, minlength=len(batch))
        busy = np.flatnonzero(count >= _SHADOW_WORTH)
        if not len(busy):
            return row, j
        tables = self._shadow_tables(batch[busy])  # (senses, busy, levels, bins)
        slot = np.full(len(batch), -1, dtype=np.intp)
        slot[busy] = np.arange(len(busy))
        mine = np.flatnonzero(slot[row] >= 0)
        lo = np.floor((phi[mine] - beta[mine] - 1e-9) / _SHADOW_BIN).astype(np.intp)
        hi = np.floor((phi[mine] + beta[mine] + 1e-9) / _SHADOW_BIN).astype(np.intp)
        reach = np.max([_range_max(t, slot[row[mine]], lo, hi) for t in tables], axis=0)
        keep = np.ones(len(row), dtype=bool)
        keep[mine] = gap[mine] < reach
        return row[keep], j[keep]

    def _shadow_tables(self, circles: np.ndarray) -> list[np.ndarray]:
        """Range-maximum tables of each circle's bound per bin of directions, one per sense:
        arrays ``(circles, levels, bins)`` (:meth:`_shadowed`)."""
        w = self.world
        c, rho = self.circles[circles, :2], self.circles[circles, 2]
        bins = np.full((2, len(circles), _SHADOW_BINS), np.inf)
        if w.n_obstacles:
            reach = (rho + _SHADOW_CELLS * w.index.grid.h)[:, None]
            query, ids = w.index.grid.pairs_in_boxes(c - reach, c + reach)
            kind = w.index.kind_of(ids)
            disc = np.empty((len(ids), 3))
            x = kind == 0
            disc[x] = w.circles[ids[x]]
            disc[x, 2] += w.threshold
            x = kind == 1
            box = w.boxes[ids[x] - w.index.n_circles]
            disc[x, :2] = 0.5 * (box[:, :2] + box[:, 2:])
            disc[x, 2] = 0.5 * np.minimum(box[:, 2] - box[:, 0], box[:, 3] - box[:, 1])
            disc[x, 2] += w.threshold
            # Polygons (their edges and interiors, whose rows above stay unset) cast no shadow
            # here.
            use = kind <= 1
            # Strictly inside (grazing tangents stay candidates); the circle's own obstacle, at
            # distance 0, blocks nothing a tangent to it could use.
            rel = disc[:, :2] - c[query]
            dist = np.hypot(rel[:, 0], rel[:, 1])
            r = disc[:, 2] - 4.0 * w.tol
            use &= (r > 0) & (dist > 0)
            q, theta = query[use], np.arctan2(rel[use, 1], rel[use, 0])
            dist, r, rq = dist[use], r[use], rho[query[use]]
            for k, sense in enumerate((1.0, -1.0)):
                lo = np.clip((sense * rq - r) / dist, -1.0, 1.0)
                hi = np.clip((sense * rq + r) / dist, -1.0, 1.0)
                ok = hi > lo
                first = np.ceil((theta[ok] + np.arcsin(lo[ok])) / _SHADOW_BIN + 1e-9)
                last = np.floor((theta[ok] + np.arcsin(hi[ok])) / _SHADOW_BIN - 1e-9) - 1
                first, last = first.astype(np.intp), last.astype(np.intp)
                n = np.maximum(last - first + 1, 0)
                if not n.sum():
                    continue
                step = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
                cell = np.repeat(q[ok], n) * _SHADOW_BINS + np.mod(np.repeat(first, n) + step,
                                                                   _SHADOW_BINS)  # fmt: skip
                np.minimum.at(bins[k].reshape(-1), cell, np.repeat(dist[ok], n))
        return [_sparse_max(bins[0]), _sparse_max(bins[1])]

    def _blocked_near(self, cand: _Tangents) -> np.ndarray:
        """Tangents that come too close to an obstacle near the circle they leave (booleans; the
        world's exact distance formulas, against the obstacles the index holds within a few
        index cells of that circle)."""
        w = self.world
        blocked = np.zeros(len(cand.j), dtype=bool)
        if w.n_obstacles <= _NEAR_ALL:
            return blocked  # few obstacles: the world's own test is as cheap
        circles, inverse = np.unique(cand.i, return_inverse=True)
        c, rho = self.circles[circles, :2], self.circles[circles, 2]
        reach = (rho + 2.0 * w.index.grid.h)[:, None]
        query, ids = w.index.grid.pairs_in_boxes(c - reach, c + reach)
        count = np.bincount(query, minlength=len(circles))
        first = np.concatenate([[0], np.cumsum(count)])[:-1]
        n = count[inverse]
        if not n.sum() or n.sum() > _NEAR_PAIRS:
            return blocked
        seg = np.repeat(np.arange(len(cand.j)), n)
        k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        obs = ids[np.repeat(first[inverse], n) + k]
        d = w.index.pair_distance(seg, obs, cand.p, cand.q)
        blocked[seg[d < w.threshold]] = True
        return blocked

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


#: Worlds with at most this many obstacles skip the near-obstacle pass (the world's own test,
#: without an index, is as cheap).
_NEAR_ALL = 24
#: Most (tangent, obstacle) pairs of the near-obstacle pass.
_NEAR_PAIRS = 2_000_000
#: Most circles whose tangents one vectorised pass finds.
_BATCH = 32
#: Bins of directions of a circle's shadow profile, and how far (index cells) its discs are.
_SHADOW_BINS = 1024
_SHADOW_BIN = _TWO_PI / _SHADOW_BINS
_SHADOW_CELLS = 8.0
#: A circle's shadow profile is built when it has at least this many candidate pairs.
_SHADOW_WORTH = 100
#: The raster's rejection is run when at least this share of its cells is core.
_RASTER_WORTH = 0.02


def _sparse_max(values: np.ndarray) -> np.ndarray:
    """Range-maximum tables of circular arrays ``(n, bins)``: ``(n, levels, bins)``, level k
    holding the maxima of windows of 2^k."""
    m = values.shape[-1]
    rows = [values]
    step = 1
    while 2 * step <= m:
        prev = rows[-1]
        ahead = np.concatenate([prev[:, step:], prev[:, :step]], axis=1)
        rows.append(np.maximum(prev, ahead))
        step *= 2
    return np.stack(rows, axis=1)


def _range_max(table: np.ndarray, which: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Maxima of the circular arrays ``which`` over the index ranges ``lo..hi`` (``hi >= lo``;
    a range of the whole circle or more gives the maximum of all)."""
    m = table.shape[-1]
    length = hi - lo + 1
    out = table[:, -1].max(axis=1)[which]
    part = length < m
    if part.any():
        k = np.floor(np.log2(length[part])).astype(np.intp)
        a = np.mod(lo[part], m)
        b = np.mod(hi[part] - (1 << k) + 1, m)
        w = which[part]
        out[part] = np.maximum(table[w, k, a], table[w, k, b])
    return out


class _Tangents:
    """The common tangents from one circle to many: arrays of the same length.

    ``q`` is where each tangent ends (its tangent point, or where it enters the goal disc);
    ``pos_i`` is the tangent point's angle from the start of circle i's free arc; ``seg``, ``h``
    and ``node`` (the tangent's length, the lower bound from its end to the goal, and the node
    it reaches, -1 before it is reached) are filled in by the search.
    """

    _FIELDS = ("i", "j", "t", "p", "q", "angle_i", "angle_j", "sense_i", "sense_j", "pos_i",
               "seg", "h", "node")  # fmt: skip

    def __init__(self, i, j, t, p, q, angle_i, angle_j, sense_i, sense_j) -> None:
        self.i, self.j, self.t, self.p, self.q = i, j, t, p, q
        self.angle_i, self.angle_j = angle_i, angle_j
        self.sense_i, self.sense_j = sense_i, sense_j
        self.pos_i = self.seg = self.h = self.node = None

    def take(self, idx: np.ndarray) -> _Tangents:
        out = _Tangents.__new__(_Tangents)
        for name in self._FIELDS:
            value = getattr(self, name)
            setattr(out, name, None if value is None else value[idx])
        return out


def _tangents_from(circles: np.ndarray, i: np.ndarray, j: np.ndarray) -> _Tangents:
    """Every common tangent from circle ``i[k]`` to circle ``j[k]``, for each pair, with the sense
    in which a path along it wraps each circle (+1 counter-clockwise, -1 clockwise, 0 for a
    point)."""
    c = circles
    i = np.asarray(i, dtype=np.intp)
    j = np.asarray(j, dtype=np.intp)
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
        p = c[i, :2] + ri[:, None] * n
        q = c[j, :2] + (-1.0 if inner else 1.0) * rj[:, None] * n
        aj = ang + math.pi if inner else ang
        parts.append((i[ok], j[ok], np.full(int(ok.sum()), t), p[ok], q[ok], ang[ok], aj[ok]))
    ii, jj, tt, p, q, ai, aj = (np.concatenate(x) for x in zip(*parts, strict=True))
    direction = q - p
    sense_i = np.where(c[ii, 2] > 0, _sense(direction, c[ii, :2] - p), 0)
    sense_j = np.where(c[jj, 2] > 0, _sense(direction, c[jj, :2] - q), 0)
    return _Tangents(ii, jj, tt, p, q, np.mod(ai, _TWO_PI), np.mod(aj, _TWO_PI), sense_i,
                     sense_j)  # fmt: skip


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
    if world.n_obstacles:
        arc, ids = world.index.grid.pairs_in_boxes(lo, hi)
    else:
        arc, ids = (np.empty(0, int),) * 2
    kind = world.index.kind_of(ids)
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
    """(arc, edge) pairs for the boxes and polygons among the candidates."""
    arcs, edges = [], []
    x = kind == 1
    if x.any():
        b = world.boxes[ids[x] - world.index.n_circles]
        for e in (b[:, [0, 1, 2, 1]], b[:, [2, 1, 2, 3]], b[:, [2, 3, 0, 3]], b[:, [0, 3, 0, 1]]):
            arcs.append(arc[x])
            edges.append(e)
    p = kind == 2
    if p.any():
        arcs.append(arc[p])
        edges.append(world.index.edges[ids[p] - world.index.first_edge])
    if not arcs:
        return np.empty(0, dtype=int), np.empty((0, 4))
    return np.concatenate(arcs), np.vstack(edges)


# ----------------------------------------------------------------------------------------------
#: Round-off allowed on angles at a cone's ends, radians: a tangent along a polygon's edge leaves
#: and reaches its end vertices exactly at their cones' ends, and which side of them its computed
#: angles fall on is chance. (A tangent that far outside a cone comes nearer the edge by
#: ``rho (1 - cos(1e-7))``, about ``5e-15 rho``: far below the touch tolerance.)
_ANGLE_TOL = 1e-7


def _cone_pos(angle: Any, lo: Any) -> Any:
    """Angle from the start of a circle's free arc, counter-clockwise.

    Parameters
    ----------
    angle, lo : float or ndarray
        Angles of the points and of the free arc's start, radians.

    Returns
    -------
    float or ndarray
        Radians, in ``[-_ANGLE_TOL, 2 pi - _ANGLE_TOL)``: an angle a hair before the start stays
        a hair before it (a plain ``mod`` puts it a whole turn ahead, outside every cone, and
        the search refused the tangents along half of the polygons' edges).
    """
    return np.mod(angle - lo + _ANGLE_TOL, _TWO_PI) - _ANGLE_TOL


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
