"""The corridor stage of RRTstarPSO: which way round the obstacles, decided before RRT* grows.

A sampling planner commits to a corridor (a homotopy class) by chance: its first path goes through
whichever door, aisle or gap its tree happened to cross first, and a local optimiser such as the
swarm can shorten a path but never move it to another corridor. This stage looks at every
corridor at once, at the resolution of a lattice:

1. **Lattice.** Square cells over the workspace (about ``max_cells`` of them; aligned with an
   occupancy map's own cells), each marked free when the robot's centre may be *anywhere* in it
   (:meth:`~rrtpso_ompl.model.World.free_cells`: exact for maps, conservative for circles and
   polygons; through the validity checker otherwise).
2. **Route.** Dijkstra's algorithm over the free cells, 16-connected (the 8 neighbours and the
   knight's moves, so a route deviates from a straight line by at most 2.7 % in length), from the
   start's cell to the goal's. A diagonal or knight's move needs the cells it passes free, so
   consecutive cells of a route always share an edge once the passed cells are inserted.
3. **Funnel.** The route's cells form a channel, a strip of squares each sharing an edge (a
   *portal*) with the next; the shortest path from start to goal inside the channel is found in
   one pass by the funnel algorithm (Lee and Preparata 1984; Mononen's "simple stupid funnel").
   It bends only at portal end points, the corners of the channel, exactly where a taut string
   would: on a map with 1-cell corridors it is the exact shortest path within 1e-4.

The path stays inside cells that are wholly free, so it is valid without further checks; it is
checked once anyway (exactly, or through the user's checker, whose lattice answers are not
conservative). Its cost is a few array operations and one sparse-graph search: milliseconds on a
map of 65,000 cells.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.sparse.csgraph import dijkstra

from ...model.geometry import path_length, shortcut
from ...model.grid_graph import MOVES_16, entry_cell, grid_graph, move_pairs, walk
from ...model.raster import Lattice
from ...model.world import MarkingStopped

#: Lattice cells the corridor stage builds, searches and funnels per second, on the safe side
#: (measured on the reference machine: 2-3 million on maps, fewer among many shapes).
CELLS_PER_SECOND = 1_000_000
#: The refinement searches the cells within this many coarse cells of the coarse path.
BAND_CELLS = 3.0
#: Lattice cells per second a map's cells are marked free or not (array work over the whole
#: lattice; the search itself stays in the band), on the safe side.
MARK_CELLS_PER_SECOND = 8_000_000
#: Lattice cells of a map routed (with alternatives) and funnelled whole per second, on the safe
#: side (measured 1.0-1.3 million on 256 x 256 mazes and random maps). A map whose lattice fits
#: in the time left at this rate is searched whole: pooling its cells into a coarse lattice opens
#: gaps through walls one cell thick, and the coarse routes then miss a maze's only corridor.
DIRECT_CELLS_PER_SECOND = 1_200_000
#: Lattice cells per second :func:`centre_route` builds and routes over among shapes, on the
#: safe side (measured 0.6-1 million among 10,000 circles).
CENTRE_CELLS_PER_SECOND = 600_000
#: Cells of the small lattice on which the cost of marking cells among shapes is measured.
MARKING_PROBE_CELLS = 1_600
#: The share of the stage's time the probe may take: obstacles so detailed that marking the
#: probe's cells takes longer leave no time for a lattice worth routing on (the stage gives up).
MARKING_PROBE_SHARE = 0.1
#: Among shapes, the share of the stage's time for the bands of wholly free cells; the rest is
#: kept for :func:`centre_route` in case they hold no route.
SHAPE_BAND_SHARE = 0.5
#: Among shapes, fine cells per coarse cell side in the bands.
SHAPE_SPLIT = 4

#: Most re-routings of :func:`centre_route` around segments that failed the check.
CENTRE_ROUTE_ROUNDS = 32
#: Most rounds of :func:`_wrapped_funnel` adding wall corners its path passed without a bend.
WRAP_REPAIRS = 8
#: The weight of a move found blocked: no route uses it while another exists.
_CUT = 1e12

#: Alternative routes are tried when their lattice length is within this share of the best's
#: (the lattice's error in length: up to 2.7 % for the moves, plus the cells' conservatism).
ALTERNATIVE_SLACK = 0.06
#: ... and when they pass this share of the lattice's diagonal away from the routes before.
ALTERNATIVE_APART = 0.03

__all__ = [
    "ALTERNATIVE_APART",
    "ALTERNATIVE_SLACK",
    "BAND_CELLS",
    "CELLS_PER_SECOND",
    "CENTRE_CELLS_PER_SECOND",
    "CENTRE_ROUTE_ROUNDS",
    "DIRECT_CELLS_PER_SECOND",
    "SHAPE_BAND_SHARE",
    "SHAPE_SPLIT",
    "CorridorResult",
    "alternative_routes",
    "channel",
    "corridor_path",
    "free_rectangles",
    "funnel",
    "lattice_route",
    "search",
]


@dataclass(frozen=True)
class CorridorResult:
    """Outcome of :func:`corridor_path`.

    Attributes
    ----------
    path : (n, 2) ndarray or None
        The funnel path from start to goal, valid; None when the lattice has no route.
    length : float
        Its length (``inf`` without one).
    lattice : Lattice or None
        The lattice searched.
    cells : int
        Free cells of the lattice.
    route_cells : int
        Cells of the route.
    time : float
        Seconds.
    reason : str
        Why there is no path (empty when there is one).
    stages : dict
        Seconds per step (``cells``, ``route``, ``funnel``).
    routes, chosen : int
        Routes tried and the one whose funnel path won (0: the shortest route).
    """

    path: np.ndarray | None
    length: float = math.inf
    lattice: Lattice | None = None
    cells: int = 0
    route_cells: int = 0
    time: float = 0.0
    reason: str = ""
    stages: dict[str, float] = field(default_factory=dict)
    routes: int = 0
    chosen: int = 0


def lattice_graph(free: np.ndarray):
    """The 16-connected graph of the free cells (CSR, undirected; cell ``(i, j)`` is node
    ``i * ny + j``; move lengths in cells)."""
    nx, ny = free.shape
    index = np.where(free, np.arange(nx * ny).reshape(nx, ny), -1)
    pairs = [move_pairs(index, step, passed) for step, passed, _ in MOVES_16]
    weights = [np.full(len(a), math.hypot(*step)) for (a, _), (step, _, _) in
               zip(pairs, MOVES_16, strict=True)]  # fmt: skip
    return grid_graph(nx * ny, np.concatenate([a for a, _ in pairs]),
                      np.concatenate([b for _, b in pairs]), np.concatenate(weights))  # fmt: skip


def lattice_route(free: np.ndarray, source: tuple[int, int], target: tuple[int, int]):
    """The shortest 16-connected route of free cells from ``source`` to ``target`` (cell lists),
    or None."""
    ny = free.shape[1]
    s = source[0] * ny + source[1]
    t = target[0] * ny + target[1]
    dist, pred = dijkstra(lattice_graph(free), directed=False, indices=s,
                          return_predecessors=True)  # fmt: skip
    if not np.isfinite(dist[t]):
        return None
    return [(v // ny, v % ny) for v in walk(pred, t)]


def alternative_routes(
    free: np.ndarray, source, target, count: int, slack: float, apart: float
) -> list[list[tuple[int, int]]]:
    """The shortest route and up to ``count`` others through different corridors.

    With Dijkstra distances from both ends, the best route through a cell ``v`` has length
    ``d_s(v) + d_t(v)``. An alternative goes through the cell of least such length that lies
    more than ``apart`` cells from every route taken so far, if that length is within ``slack``
    (relative) of the best: a different door, aisle or side of an obstacle (the *via-node* method
    of alternative route planning on road networks).
    """
    nx, ny = free.shape
    s = source[0] * ny + source[1]
    t = target[0] * ny + target[1]
    dist, pred = dijkstra(lattice_graph(free), directed=False, indices=[s, t],
                          return_predecessors=True)  # fmt: skip
    best = dist[0, t]
    if not np.isfinite(best):
        return []
    through = dist[0] + dist[1]
    routes = [walk(pred[0], t)]
    near = np.zeros(nx * ny, dtype=bool)
    for _ in range(count):
        mask = np.ones((nx, ny), dtype=bool)
        for r in routes[-1:]:
            near[np.asarray(r)] = True
        mask = ~near.reshape(nx, ny)
        far = ndimage.distance_transform_edt(mask) > apart
        ok = far.ravel() & (through <= best * (1.0 + slack))
        if not ok.any():
            break
        v = int(np.flatnonzero(ok)[np.argmin(through[ok])])
        routes.append(walk(pred[0], v) + walk(pred[1], v)[::-1][1:])
    return [[(v // ny, v % ny) for v in r] for r in routes]


def channel(route: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """The route with the cells its diagonal and knight's moves pass inserted: consecutive cells
    share an edge."""
    out = [route[0]]
    for (i0, j0), (i1, j1) in itertools.pairwise(route):
        di, dj = i1 - i0, j1 - j0
        for (mi, mj), _, via in MOVES_16:
            for sign in (1, -1):
                if (di, dj) == (sign * mi, sign * mj):
                    out.extend((i0 + sign * pi, j0 + sign * pj) for pi, pj in via)
        out.append((i1, j1))
    return out


def free_rectangles(free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Free cells merged into rectangles: ``(rects, label)``.

    ``rects[k] = (i0, i1, j0, j1)`` covers cells ``i0 <= i < i1``, ``j0 <= j < j1``; ``label``
    (nx, ny) holds each free cell's rectangle (-1 for blocked cells). Runs of free cells along x
    in each row, and equal runs in consecutive rows, become one rectangle (as a map's blocked
    cells are merged into boxes), in O(cells) array operations.
    """
    nx, ny = free.shape
    label = np.full((nx, ny), -1, dtype=np.int64)
    if not free.any():
        return np.empty((0, 4), dtype=np.int64), label
    pad = np.zeros((ny, nx + 2), dtype=np.int8)
    pad[:, 1:-1] = free.T
    step = np.diff(pad, axis=1)
    rows, c0 = np.nonzero(step == 1)
    _, c1 = np.nonzero(step == -1)
    order = np.lexsort((rows, c1, c0))
    rows, c0, c1 = rows[order], c0[order], c1[order]
    new = np.ones(len(rows), dtype=bool)
    new[1:] = (c0[1:] != c0[:-1]) | (c1[1:] != c1[:-1]) | (rows[1:] != rows[:-1] + 1)
    group = np.cumsum(new) - 1
    j1 = np.zeros(group[-1] + 1, dtype=np.int64)
    np.maximum.at(j1, group, rows + 1)
    rects = np.column_stack([c0[new], c1[new], rows[new], j1])
    # Label every cell of every run with its rectangle.
    length = c1 - c0
    cell_i = np.repeat(c0, length) + (
        np.arange(length.sum()) - np.repeat(np.cumsum(length) - length, length)
    )
    label[cell_i, np.repeat(rows, length)] = np.repeat(group, length)
    return rects, label


def _rectangle_channel(cells, label: np.ndarray) -> list[int]:
    """The rectangles an edge-connected cell sequence passes through, in order, without
    repeats (a rectangle entered twice cuts out the loop in between: it is convex)."""
    seq: list[int] = []
    where: dict[int, int] = {}
    for cell in cells:
        r = int(label[cell])
        if seq and seq[-1] == r:
            continue
        if r in where:  # back into a rectangle already passed: drop the detour
            for dropped in seq[where[r] + 1 :]:
                where.pop(dropped, None)
            del seq[where[r] + 1 :]
            continue
        where[r] = len(seq)
        seq.append(r)
    return seq


def _portals(seq: list[int], rects: np.ndarray, lat: Lattice, shrink: float):
    """(left, right) end points of the edge each rectangle shares with the next, seen in the
    direction of travel, each moved ``shrink`` towards the other."""
    (ox, oy), h = lat.origin, lat.h
    out = []
    for a, b in itertools.pairwise(seq):
        ai0, ai1, aj0, aj1 = rects[a]
        bi0, bi1, bj0, bj1 = rects[b]
        if ai1 == bi0 or bi1 == ai0:  # across a vertical edge
            x = ox + h * (ai1 if ai1 == bi0 else ai0)
            lo = oy + h * max(aj0, bj0) + shrink
            hi = oy + h * min(aj1, bj1) - shrink
            out.append(((x, hi), (x, lo)) if ai1 == bi0 else ((x, lo), (x, hi)))
        else:  # across a horizontal edge
            y = oy + h * (aj1 if aj1 == bj0 else aj0)
            lo = ox + h * max(ai0, bi0) + shrink
            hi = ox + h * min(ai1, bi1) - shrink
            out.append(((lo, y), (hi, y)) if aj1 == bj0 else ((hi, y), (lo, y)))
    return out


def _lift(path: np.ndarray, lat: Lattice, free: np.ndarray, step: float) -> np.ndarray:
    """Move each interior vertex ``step`` away from the blocked cells at its lattice corner.

    For a point robot the funnel's corners lie on the corners of blocked cells, and a segment
    between two corners of one wall runs along it: zero clearance, which counts as entering.
    Pushed diagonally off the corner, the path keeps a clearance of about ``step``.
    """
    out = path.copy()
    (ox, oy), h = lat.origin, lat.h
    for k in range(1, len(path) - 1):
        ci = round((path[k, 0] - ox) / h)
        cj = round((path[k, 1] - oy) / h)
        away = np.zeros(2)
        for di in (-1, 0):
            for dj in (-1, 0):
                i, j = ci + di, cj + dj
                if not (0 <= i < lat.nx and 0 <= j < lat.ny) or not free[i, j]:
                    away -= (di + 0.5, dj + 0.5)
        norm = math.hypot(*away)
        if norm > 0.0:
            out[k] += step * away / norm
    return out


def _area2(a, b, c) -> float:
    """Twice the signed area of triangle a, b, c (> 0 when c lies left of a -> b)."""
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def funnel(start, goal, portals) -> np.ndarray:
    """The shortest path from ``start`` to ``goal`` through ``portals`` ((left, right) pairs in
    order), by the funnel algorithm.

    The funnel is the wedge from the last path vertex (the apex) through the left and right ends
    of the portals seen so far; each new portal narrows it, and when one side would cross the
    other, that side's end becomes a path vertex and the new apex. A restart goes back to the
    portal after the new apex, so the total work is bounded by the number of portals squared
    (linear in practice).
    """
    pts = [(tuple(start), tuple(start)), *portals, (tuple(goal), tuple(goal))]
    path = [tuple(start)]
    apex = left = right = tuple(start)
    apex_i = left_i = right_i = 0
    i = 1
    n = len(pts)
    budget = n * n + 16  # the restarts cannot loop: each makes the apex index grow
    while i < n and budget > 0:
        budget -= 1
        new_left, new_right = pts[i]
        if _area2(apex, right, new_right) >= 0.0:  # the right side narrows the funnel
            if apex == right or _area2(apex, left, new_right) < 0.0:
                right, right_i = new_right, i
            else:  # it crosses the left side: the left end is a corner of the path
                path.append(left)
                apex, apex_i = left, left_i
                left = right = apex
                left_i = right_i = apex_i
                i = apex_i + 1
                continue
        if _area2(apex, left, new_left) <= 0.0:  # the left side narrows the funnel
            if apex == left or _area2(apex, right, new_left) > 0.0:
                left, left_i = new_left, i
            else:
                path.append(right)
                apex, apex_i = right, right_i
                left = right = apex
                left_i = right_i = apex_i
                i = apex_i + 1
                continue
        i += 1
    if path[-1] != tuple(goal):
        path.append(tuple(goal))
    return np.asarray(path, dtype=float)


def corridor_path(
    model: Any,
    start,
    goal,
    max_cells: int = 65_536,
    terminate=None,
    alternatives: int = 3,
    near=None,
) -> CorridorResult:
    """The shortest path through the best corridor of a lattice of about ``max_cells`` cells.

    Parameters
    ----------
    model : World or SpaceInformationCollisionModel
        Answers ``lattice``, ``free_cells``, ``segments_free`` and ``path_valid``.
    start, goal : (2,) array_like
        End points.
    max_cells : int
        Most lattice cells (memory and time grow linearly with it).
    terminate : callable, optional
        Polled between the steps; the search gives up (no path) when it returns True.
    alternatives : int
        Routes through other corridors to try besides the shortest (:func:`alternative_routes`);
        the shortest path after the funnel wins.
    near : ((n, 2) ndarray, float), optional
        A path and a distance: only cells within that distance of the path are searched (the
        corridor of a coarser search, refined on a finer lattice: :func:`refine`).

    Returns
    -------
    CorridorResult
    """
    t0 = time.perf_counter()
    stages: dict[str, float] = {}

    def done(reason: str, **kw) -> CorridorResult:
        return CorridorResult(None, time=time.perf_counter() - t0, reason=reason, stages=stages,
                              **kw)  # fmt: skip

    start = np.asarray(start, dtype=float)
    goal = np.asarray(goal, dtype=float)
    lat = model.lattice(max_cells)
    if lat.nx < 2 or lat.ny < 2:
        return done("the lattice is too small")
    free = model.free_cells(lat)
    if near is not None:
        free &= band(lat, *near)
    stages["cells"] = time.perf_counter() - t0
    if terminate is not None and terminate():
        return done("out of time", lattice=lat)
    return _route_and_funnel(model, lat, free, start, goal, alternatives, terminate, t0, stages)


def _route_and_funnel(model, lat, free, start, goal, alternatives, terminate, t0, stages,
                      routes=None) -> CorridorResult:  # fmt: skip
    """Route over ``free`` (or take ``routes``), funnel each route, keep the shortest valid."""

    def done(reason: str, **kw) -> CorridorResult:
        return CorridorResult(None, time=time.perf_counter() - t0, reason=reason, stages=stages,
                              **kw)  # fmt: skip

    n_free = int(free.sum())
    s_cell, s_hop = entry_cell(lat, free, start, 2, model.segments_free)
    g_cell, g_hop = entry_cell(lat, free, goal, 2, model.segments_free)
    if s_cell is None or g_cell is None:
        return done("start or goal is not next to a free lattice cell", lattice=lat,
                    cells=n_free)  # fmt: skip
    t1 = time.perf_counter()
    if routes is None:
        apart = max(3.0, ALTERNATIVE_APART * math.hypot(lat.nx, lat.ny))
        routes = alternative_routes(free, s_cell, g_cell, alternatives, ALTERNATIVE_SLACK, apart)
    stages["route"] = stages.get("route", 0.0) + time.perf_counter() - t1
    if not routes:
        return done("no route through the lattice", lattice=lat, cells=n_free)
    t2 = time.perf_counter()
    # Through a cell the end point lies in, the funnel starts at the point itself; entered from
    # outside, at the cell's centre (the segment there was checked).
    ends = _Ends(lat.centre(s_cell) if s_hop else start, lat.centre(g_cell) if g_hop else goal,
                 start, goal, s_hop, g_hop)  # fmt: skip
    best = _funnel_routes(model, lat, free, routes, ends, terminate)
    best = _pulled_taut(model, lat, free, routes, ends, terminate, best)
    stages["funnel"] = stages.get("funnel", 0.0) + time.perf_counter() - t2
    if best is None:
        return done("the corridor's path did not pass the check", lattice=lat, cells=n_free,
                    route_cells=len(routes[0]))  # fmt: skip
    path, length, n_route, which = best
    return CorridorResult(path, length, lat, n_free, n_route, time.perf_counter() - t0, "",
                          stages, len(routes), which)  # fmt: skip


@dataclass(frozen=True)
class _Ends:
    """Where a channel's funnel starts and ends (``a``, ``b``: the end points, or the centres of
    the cells they hop to when they lie outside every free cell) and the true end points."""

    a: np.ndarray
    b: np.ndarray
    start: np.ndarray
    goal: np.ndarray
    s_hop: bool
    g_hop: bool

    def path(self, inner: np.ndarray) -> np.ndarray:
        """``inner`` (from ``a`` to ``b``) with the hops to the true end points."""
        return np.vstack([self.start[None]] * self.s_hop + [inner] + [self.goal[None]] * self.g_hop)


def _funnel_routes(model, lat: Lattice, free, routes, ends: _Ends, terminate):
    """``(path, length, route cells, route index)`` of the shortest checked funnel path over
    ``routes`` (portals shrunk by the touch tolerance, then by a thousandth of a cell), or
    None."""
    rects, label = free_rectangles(free)
    best = None
    for k, route in enumerate(routes):
        if k and terminate is not None and terminate():
            break
        seq = _rectangle_channel(channel(route), label)
        for shrink in (max(1e-6 * lat.h, 16.0 * model.tol), 1e-3 * lat.h):
            inner = funnel(ends.a, ends.b, _portals(seq, rects, lat, shrink))
            if model.robot_radius <= 0.0:
                inner = _lift(inner, lat, free, 2.0 * shrink)
            candidate = ends.path(inner)
            if model.path_valid(candidate):
                length = path_length(candidate)
                if best is None or length < best[1]:
                    best = (candidate, length, len(route), k)
                break
    return best


def _pulled_taut(model, lat: Lattice, free, routes, ends: _Ends, terminate, best):
    """``best`` (see :func:`_funnel_routes`) improved or, when None, replaced: a disc robot's
    path pulled to the walls (:func:`_wrapped_funnel`, which may take the time kept for a
    corridor not found); with no checked funnel path (a point robot's grazing a corner it was
    not lifted off), the taut string round the corners at the touch tolerance, else the centres
    of the first channel's cells (segments inside free cells) greedily shortcut."""
    late = getattr(terminate, "grace", terminate)
    if best is not None and model.robot_radius > 0.0 and not (late and late()):
        wrapped = _wrapped_funnel(model, lat, free, routes[best[3]], ends, late)
        if wrapped is not None and path_length(wrapped) < best[1]:
            best = (wrapped, path_length(wrapped), *best[2:])
    if best is None and not (terminate and terminate()):
        wrapped = _wrapped_funnel(model, lat, free, routes[0], ends, terminate)
        if wrapped is not None:
            best = (wrapped, path_length(wrapped), len(routes[0]), 0)
    if best is None:
        centres = np.array([lat.centre(c) for c in channel(routes[0])])
        inner = centres[1 - ends.s_hop : len(centres) - 1 + ends.g_hop]
        candidate = np.vstack([ends.start[None], inner, ends.goal[None]])
        candidate = shortcut(candidate, model.segments_free, terminate, window=16)
        if model.path_valid(candidate):
            best = (candidate, path_length(candidate), len(routes[0]), 0)
    return best


def _wrapped_funnel(model, lat: Lattice, free, route, ends: _Ends, terminate=None):
    """A disc robot's path on a map through the same route, closer to the walls than the wholly
    free cells allow (they lose up to a cell along every wall).

    The funnel runs through the cells no obstacle enters, with each portal's end moved the
    robot's radius in where a blocked cell touches it; every wall corner the funnel bends round
    then becomes a circle of the robot's radius, and the path the taut string round those
    circles (:func:`_round_corners`). Checked; None when it fails (a gap narrower than the
    robot, a corner passed without a bend) or the world is not a map."""
    point = model.point_free_cells(lat) if hasattr(model, "point_free_cells") else None
    r = float(model.robot_radius) + 16.0 * model.tol
    if point is None:
        return None
    # The cells along the walls next to the wholly free ones (and no others: a band stays a band).
    point &= ndimage.binary_dilation(free, iterations=math.ceil(r / lat.h) + 1)
    rects, label = free_rectangles(point)
    seq = _rectangle_channel(channel(route), label)
    # Lattice points a blocked cell (or the lattice's edge) touches.
    pad = np.zeros((lat.nx + 2, lat.ny + 2), dtype=bool)
    pad[1:-1, 1:-1] = point
    walled = ~(pad[:-1, :-1] & pad[1:, :-1] & pad[:-1, 1:] & pad[1:, 1:])
    wall_portals = _wall_portals(_portals(seq, rects, lat, 0.0), lat, walled, r, 16.0 * model.tol)
    if wall_portals is None:
        return None  # narrower than the robot
    portals, corner_of = wall_portals
    inner = funnel(ends.a, ends.b, portals)
    corners = [corner_of.get((float(x), float(y))) for x, y in inner[1:-1]]
    (ox, oy), h = lat.origin, lat.h
    walls = np.column_stack([ox + h * np.nonzero(walled)[0], oy + h * np.nonzero(walled)[1]])
    for _ in range(WRAP_REPAIRS):
        if terminate is not None and terminate():
            return None
        rounded = _round_corners(inner, corners, r)
        if rounded is None:
            return None
        rounded, owner = rounded
        candidate = ends.path(rounded)
        if model.path_valid(candidate):
            return candidate
        # A wall corner the string passes without wrapping it (a side of the channel that is
        # free space, not wall, let the funnel pass it without a bend): it becomes a circle too.
        bad = np.flatnonzero(model.segment_violation(rounded[:-1], rounded[1:]) > 0.0)
        if not len(bad):
            return None  # the hops to the end points failed: nothing to repair here
        k = int(bad[0])
        corner = _nearest_wall(rounded[k], rounded[k + 1], walls, r)
        if corner is None:
            return None
        at = int(owner[k]) + 1  # after the circle the segment leaves
        d, e = rounded[k + 1] - rounded[k], corner - rounded[k]
        side = 1.0 if d[0] * e[1] - d[1] * e[0] > 0.0 else -1.0  # the corner's side of the path
        inner = np.insert(inner, at, corner, axis=0)
        corners.insert(at - 1, (corner, side))
    return None


def _wall_portals(portals, lat: Lattice, walled: np.ndarray, r: float, tol: float):
    """``portals`` with each end moved ``r`` towards the other where a wall touches it
    (``walled``: the lattice points a blocked cell touches), ``tol`` elsewhere; and, for every
    end moved ``r``, the wall corner it came from (keyed by the moved end). None when a portal
    is narrower than that."""
    (ox, oy), h = lat.origin, lat.h
    out, corner_of = [], {}
    for left, right in portals:
        pair = [np.asarray(left, dtype=float), np.asarray(right, dtype=float)]
        width = float(np.hypot(*(pair[1] - pair[0])))
        moved = []
        for e, other in ((pair[0], pair[1]), (pair[1], pair[0])):
            wall = walled[round((e[0] - ox) / h), round((e[1] - oy) / h)]
            step = r if wall else tol
            if 2.0 * step >= width:
                return None
            q = e + step * (other - e) / width
            if wall:
                corner_of[(float(q[0]), float(q[1]))] = e
            moved.append((float(q[0]), float(q[1])))
        out.append((moved[0], moved[1]))
    return out, corner_of


def _nearest_wall(a: np.ndarray, b: np.ndarray, walls: np.ndarray, r: float):
    """The point of ``walls`` nearest the segment ``a b`` if closer than ``r``, else None."""
    lo, hi = np.minimum(a, b) - r, np.maximum(a, b) + r
    near = walls[np.all((walls >= lo) & (walls <= hi), axis=1)]
    if not len(near):
        return None
    d = b - a
    f = np.clip(((near - a) @ d) / max(float(d @ d), 1e-300), 0.0, 1.0)
    dist = np.hypot(*(a + f[:, None] * d - near).T)
    k = int(np.argmin(dist))
    return near[k] if dist[k] < r else None


def _round_corners(path: np.ndarray, corners, r: float) -> np.ndarray | None:
    """The taut string from ``path[0]`` to ``path[-1]`` round circles of radius ``r`` at the
    ``corners`` (one per interior vertex: a point passed on the side the path turns to there,
    a ``(point, side)`` pair, side +1 for a corner on the left, or None for a vertex kept as a
    point); every arc replaced by the polygon circumscribed about it (:func:`_arc_polygon`), so
    no segment comes closer than ``r`` to a corner. Also returns, for every vertex, the index
    of the path vertex whose circle it lies on. None when two circles on opposite sides overlap
    or an arc would turn back (the corners do not make a taut string)."""
    centres, side = [path[0]], [0.0]
    for k, corner in enumerate(corners, start=1):
        d_in, d_out = path[k] - path[k - 1], path[k + 1] - path[k]
        turn = d_in[0] * d_out[1] - d_in[1] * d_out[0]
        if isinstance(corner, tuple):  # a corner given with its side
            centres.append(np.asarray(corner[0], dtype=float))
            side.append(corner[1])
        elif corner is None or turn == 0.0:
            centres.append(path[k])
            side.append(0.0)
        else:  # turning left: the corner is on the left, the path passes to its right
            centres.append(np.asarray(corner, dtype=float))
            side.append(1.0 if turn > 0 else -1.0)
    centres.append(path[-1])
    side.append(0.0)
    c, s = np.asarray(centres), np.asarray(side)
    d = np.diff(c, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    if not np.all(length > 0.0):
        return None
    u = d / length[:, None]
    # The common tangent of consecutive circles: travel t at angle phi to the line of centres,
    # sin(phi) = (s_k - s_k+1) r / L; the tangent points lie s r along t's right normal m.
    sin_phi = (s[:-1] - s[1:]) * r / length
    if np.any(np.abs(sin_phi) >= 1.0):
        return None
    t = np.sqrt(1.0 - sin_phi**2)[:, None] * u + sin_phi[:, None] * np.column_stack(
        [-u[:, 1], u[:, 0]]
    )
    m = np.column_stack([t[:, 1], -t[:, 0]])
    leave = c[:-1] + (s[:-1] * r)[:, None] * m
    arrive = c[1:] + (s[1:] * r)[:, None] * m
    out, owner = [c[0]], [0]
    for k in range(1, len(c) - 1):
        if s[k] == 0.0:
            out.append(c[k])
            owner.append(k)
            continue
        arc = _arc_polygon(c[k], r, arrive[k - 1], leave[k], s[k])
        if arc is None:
            return None
        out.extend(arc)
        owner.extend([k] * len(arc))
    out.append(c[-1])
    owner.append(len(c) - 1)
    return np.asarray(out), np.asarray(owner)


def _arc_polygon(centre, r: float, enter, leave, side: float) -> np.ndarray | None:
    """The polygon circumscribed about the arc of radius ``r`` round ``centre`` from ``enter``
    to ``leave`` (counter-clockwise for ``side`` +1), in pieces of at most 45 degrees, vertices
    at ``r / cos(delta / 2)``: its edges are tangent to the circle. None for an arc of more
    than half a turn (the string would turn back)."""
    a_in = math.atan2(enter[1] - centre[1], enter[0] - centre[0])
    a_out = math.atan2(leave[1] - centre[1], leave[0] - centre[0])
    sweep = (a_out - a_in) % (2.0 * math.pi)
    if side < 0:
        sweep -= 2.0 * math.pi
    if abs(sweep) > math.pi:
        return None
    pieces = max(1, math.ceil(abs(sweep) / (0.25 * math.pi)))
    delta = sweep / pieces
    ang = a_in + (np.arange(pieces) + 0.5) * delta
    return centre + (r / math.cos(0.5 * delta)) * np.column_stack([np.cos(ang), np.sin(ang)])


def centre_route(model: Any, start, goal, max_cells: int = 65_536, terminate=None,
                 lattice: Lattice | None = None, within=None):  # fmt: skip
    """A path through the centres of lattice cells whose centre is free, every segment checked:
    for free space too thin for any wholly free cell, where :func:`corridor_path` finds none.

    Dijkstra's algorithm over the cells with a free centre (16-connected, as
    :func:`corridor_path`), then every segment of the route through the model's exact check; a
    segment that fails is taken out of the graph and the route searched again, at most
    :data:`CENTRE_ROUTE_ROUNDS` times. The path is valid, not taut: it runs through cell centres.
    With ``lattice`` (and ``within``, booleans of its cells) only those cells are searched.
    """
    t0 = time.perf_counter()
    start = np.asarray(start, dtype=float)
    goal = np.asarray(goal, dtype=float)
    lat = lattice or model.lattice(max_cells, split=1)  # a map's own cells: their middles
    if lat.nx < 2 or lat.ny < 2:
        return CorridorResult(None, reason="the lattice is too small")
    free = model.centres_free(lat)
    if within is not None:
        free &= within
    s_cell, s_hop = entry_cell(lat, free, start, 2, model.segments_free)
    g_cell, g_hop = entry_cell(lat, free, goal, 2, model.segments_free)
    if s_cell is None or g_cell is None:
        return CorridorResult(None, lattice=lat, time=time.perf_counter() - t0,
                              reason="start or goal is not next to a free cell centre")  # fmt: skip
    ny = lat.ny
    graph = lattice_graph(free)
    graph.sort_indices()
    s, t = s_cell[0] * ny + s_cell[1], g_cell[0] * ny + g_cell[1]
    centres = lat.centres()
    for _ in range(CENTRE_ROUTE_ROUNDS):
        if terminate is not None and terminate():
            break
        dist, pred = dijkstra(graph, directed=False, indices=s, return_predecessors=True)
        if not dist[t] < _CUT:
            break
        nodes = np.array(walk(pred, t))
        ok = model.segments_free(centres[nodes[:-1]], centres[nodes[1:]])
        if ok.all():
            inner = centres[nodes]
            path = np.vstack([start[None]] * s_hop + [inner] + [goal[None]] * g_hop)
            if not s_hop:
                path[0] = start
            if not g_hop:
                path[-1] = goal
            # The inner segments passed above; only those to the end points moved.
            if not model.segments_free(path[[0, -2]], path[[1, -1]]).all():
                break
            route = [(v // ny, v % ny) for v in nodes.tolist()]
            # The funnel costs about as much as the check above: without time for it, the
            # checked path through the centres is the answer.
            taut = None if terminate is not None and terminate() else (
                _thin_funnel(model, lat, free, route, path, s_hop, g_hop))  # fmt: skip
            if taut is not None and path_length(taut) < path_length(path):
                path = taut
            return CorridorResult(path, path_length(path), lat, int(free.sum()), len(nodes),
                                  time.perf_counter() - t0, "", {}, 1, 0)  # fmt: skip
        _cut_edges(graph, nodes[:-1][~ok], nodes[1:][~ok])
    return CorridorResult(None, lattice=lat, cells=int(free.sum()), time=time.perf_counter() - t0,
                          reason="no checked route through free cell centres")  # fmt: skip


def _cut_edges(graph, tails, heads) -> None:
    """Give the edges ``tails[i] - heads[i]`` of the sorted CSR ``graph`` the weight
    :data:`_CUT`: no route uses them while another exists."""
    for a, b in zip(tails, heads, strict=True):
        for u, v in ((a, b), (b, a)):  # the edge is stored once, in either direction
            lo, hi = graph.indptr[u], graph.indptr[u + 1]
            at = lo + np.searchsorted(graph.indices[lo:hi], v)
            if at < hi and graph.indices[at] == v:
                graph.data[at] = _CUT  # as good as gone


def _thin_funnel(model, lat: Lattice, free: np.ndarray, route, path, s_hop: bool, g_hop: bool):
    """The funnel through a route of cells whose centres are free but whose sides are not, each
    corner it bends round wrapped at the robot's radius (:func:`_wrap`). Checked; None when the
    check fails."""
    rects = np.array([(i, i + 1, j, j + 1) for i, j in channel(route)])
    seq = list(range(len(rects)))
    start, goal = path[0], path[-1]
    a = path[1] if s_hop else start
    b = path[-2] if g_hop else goal
    inner = funnel(a, b, _portals(seq, rects, lat, 16.0 * model.tol))
    inner = _wrap(inner, lat, free, float(model.robot_radius) + 16.0 * model.tol)
    candidate = np.vstack([start[None]] * s_hop + [inner] + [goal[None]] * g_hop)
    return candidate if model.path_valid(candidate) else None


def _wrap(path: np.ndarray, lat: Lattice, free: np.ndarray, r: float) -> np.ndarray:
    """Replace each interior vertex that lies on a lattice corner with the polygon
    circumscribed about the arc of radius ``r`` round that corner, from the normal of the
    segment coming in to that of the segment going out (vertices at ``r / cos(delta / 2)``,
    ``delta`` at most 45 degrees): each of its segments is tangent to the circle, so none comes
    closer than ``r`` to the corner."""
    (ox, oy), h = lat.origin, lat.h
    out = [path[0]]
    for k in range(1, len(path) - 1):
        v, u, w = path[k], path[k - 1], path[k + 1]
        corner = np.array([ox + h * round((v[0] - ox) / h), oy + h * round((v[1] - oy) / h)])
        d_in, d_out = v - u, w - v
        n_in, n_out = np.hypot(*d_in), np.hypot(*d_out)
        if n_in == 0.0 or n_out == 0.0 or np.hypot(*(v - corner)) > 0.25 * h:
            out.append(v)
            continue
        turn = math.atan2(d_in[0] * d_out[1] - d_in[1] * d_out[0], float(d_in @ d_out))
        side = -math.copysign(1.0, turn)  # the path turns round the corner on this side
        # Normals pointing away from the corner, on the outside of the turn.
        a_in = math.atan2(d_in[1], d_in[0]) + side * 0.5 * math.pi
        pieces = max(1, math.ceil(abs(turn) / (0.25 * math.pi)))
        delta = turn / pieces
        rho = r / math.cos(0.5 * delta)
        for i in range(pieces):
            ang = a_in + (i + 0.5) * delta
            out.append(corner + rho * np.array([math.cos(ang), math.sin(ang)]))
    out.append(path[-1])
    return np.asarray(out)


def band(lat: Lattice, path: np.ndarray, width: float) -> np.ndarray:
    """(nx, ny) booleans: the cells whose centre lies within ``width`` of the polyline ``path``
    (up to half a cell: the cells the path passes, grown by a distance transform)."""
    path = np.asarray(path, dtype=float)
    seg = np.diff(path, axis=0)
    n = np.maximum(np.ceil(np.hypot(*seg.T) / (0.5 * lat.h)).astype(np.int64), 1)
    k = np.repeat(np.arange(len(seg)), n)
    t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / n[k]
    pts = np.vstack([path[:-1][k] + t[:, None] * seg[k], path[-1:]])
    i = np.clip(np.floor((pts[:, 0] - lat.origin[0]) / lat.h).astype(np.int64), 0, lat.nx - 1)
    j = np.clip(np.floor((pts[:, 1] - lat.origin[1]) / lat.h).astype(np.int64), 0, lat.ny - 1)
    on = np.ones((lat.nx, lat.ny), dtype=bool)
    on[i, j] = False
    return ndimage.distance_transform_edt(on) * lat.h <= width


def search(
    model: Any,
    start,
    goal,
    seconds: float | None,
    max_cells: int = 4_194_304,
    terminate=None,
    alternatives: int = 3,
    no_route_seconds: float | None = None,
) -> CorridorResult:
    """The corridor stage within ``seconds`` (None: no limit but ``max_cells``).

    A map whose fine lattice fits the time (:data:`DIRECT_CELLS_PER_SECOND`) is searched whole
    (:func:`_route_and_funnel`). Otherwise:

    1. **Coarse routes** on a lattice small enough to route on in a third of the time
       (:data:`CELLS_PER_SECOND`), its cells open generously (a map's when any fine cell they
       pool is wholly free; among shapes when their centre is free): no passage the fine cells
       keep is closed. The shortest route and ``alternatives`` through other corridors.
    2. **A fine route in each corridor**, best first: the fine cells within :data:`BAND_CELLS`
       coarse cells of it (marked in a box round the band: the work follows the band), the route
       over them and its funnel path. The shortest valid path wins.

    With no route yet, the search may go on until ``no_route_seconds`` (nothing is left for the
    later stages to refine meanwhile): a map's whole fine lattice if it fits, then, for free
    space too thin for any wholly free fine cell, :func:`centre_route`.

    Marking a lattice's cells stops at the deadline too (:meth:`World.marking_stops
    <rrtpso_ompl.model.World.marking_stops>`): a marking cut short gives no cells, and the
    stage ends with the best path it had.
    """
    t0 = time.perf_counter()
    end = None if seconds is None else t0 + seconds
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    stages: dict[str, float] = {}
    out_of_time = _Deadline(end, terminate)
    if end is not None and no_route_seconds is not None:
        out_of_time.grace_end = max(end, t0 + no_route_seconds)
    with _marking_stops(model, out_of_time):
        try:
            result = _search(model, start, goal, seconds, max_cells, alternatives,
                             no_route_seconds, out_of_time, t0, stages)  # fmt: skip
        except MarkingStopped:
            result = CorridorResult(None, reason="out of time marking the lattice's cells")
    return dataclasses.replace(result, time=time.perf_counter() - t0, stages=stages)


def _marking_stops(model, stop):
    """``model.marking_stops(stop)`` where the model has it (the World, the space information's
    adapter), else nothing."""
    marking_stops = getattr(model, "marking_stops", None)
    return contextlib.nullcontext() if marking_stops is None else marking_stops(stop)


def _search(model, start, goal, seconds, max_cells, alternatives, no_route_seconds, out_of_time,
            t0, stages) -> CorridorResult:  # fmt: skip
    """:func:`search`'s steps (a marking cut short raises :class:`MarkingStopped`)."""
    end = out_of_time.end
    terminate = out_of_time.terminate
    left = out_of_time.left
    on_map = getattr(model, "raster", None) is not None
    # Among shapes the wholly free cells may miss gaps narrower than a cell (a dense field of
    # circles): time is kept for the route through free cell centres.
    first = (out_of_time if on_map or end is None
             else _Deadline(t0 + SHAPE_BAND_SHARE * seconds, terminate))  # fmt: skip
    # Among shapes the cost of marking a cell grows with the obstacles' detail (a polygon of
    # 10,000 vertices marks 100,000 cells a second, a few circles millions): measured first.
    rate = CELLS_PER_SECOND
    if not on_map and end is not None:
        rate = _marking_rate(model, seconds)
        if rate is None:
            return CorridorResult(None, reason="marking cells is too slow for the time (the "
                                  "obstacles are too detailed)")  # fmt: skip
    result, fine_cells, route_cells = _coarse_tries(
        model, start, goal, max_cells, alternatives, out_of_time, first, t0, stages, rate
    )
    if result.path is None and end is not None and no_route_seconds is not None:
        out_of_time.end = max(end, t0 + no_route_seconds)
        if on_map and not out_of_time():  # the whole fine lattice, if it now fits
            result = _map_corridors(model, fine_cells, route_cells, start, goal, 0, out_of_time,
                                    t0, stages, left)  # fmt: skip
    if result.path is None and not out_of_time():
        per_second = min(CENTRE_CELLS_PER_SECOND, 0.5 * rate)
        cells = min(max_cells, int(per_second * left())) if end else 1 << 18
        thin = centre_route(model, start, goal, max(cells, 4096), out_of_time)
        if thin.path is not None:
            result = thin
    return result


def _marking_rate(model, seconds: float) -> float | None:
    """Lattice cells per second ``model`` marks (its free cell centres), measured on a small
    lattice; at most :data:`CELLS_PER_SECOND`. None when the probe takes more than
    :data:`MARKING_PROBE_SHARE` of ``seconds`` (it is stopped there)."""
    probe = model.lattice(MARKING_PROBE_CELLS)
    t = time.perf_counter()
    end = t + MARKING_PROBE_SHARE * seconds
    outer = getattr(model, "mark_stop", None)

    def stop() -> bool:
        return time.perf_counter() >= end or bool(outer is not None and outer())

    try:
        with _marking_stops(model, stop):
            model.centres_free(probe)
    except MarkingStopped:
        return None
    return min(CELLS_PER_SECOND, probe.n_cells / max(time.perf_counter() - t, 1e-6))


def _coarse_tries(model, start, goal, max_cells, alternatives, out_of_time, first, t0, stages,
                  rate=CELLS_PER_SECOND):  # fmt: skip
    """:func:`search`'s tries until a path, ``first()`` or too little time: when no corridor
    held a route at the fine level (the coarse lattice joined cells that do not join), twice the
    coarse cells, while a try as long again fits twice over. The last result, the fine and the
    coarse lattice's cells."""
    left = out_of_time.left
    on_map = getattr(model, "raster", None) is not None
    route_cells = int(min(max_cells, max(min(CELLS_PER_SECOND, rate) * left() / 3.0, 1024)))
    fine_cells = 0
    while True:  # at most log2(max_cells) rounds: the coarse cells double each time
        t1 = time.perf_counter()
        if on_map:
            fine_cells = int(min(max_cells, max(0.4 * MARK_CELLS_PER_SECOND * left(), 4096)))
            result = _map_corridors(model, fine_cells, route_cells, start, goal, alternatives,
                                    out_of_time, t0, stages, left)  # fmt: skip
        else:
            result = _shape_corridors(model, route_cells, max_cells, start, goal, alternatives,
                                      first, t0, stages, rate)  # fmt: skip
        took = time.perf_counter() - t1
        if result.path is not None or route_cells >= max_cells or first() or left() < 4.0 * took:
            return result, fine_cells, route_cells
        route_cells = min(2 * route_cells, max_cells)


def _map_corridors(model, fine_cells, route_cells, start, goal, alternatives, terminate, t0,
                   stages, left) -> CorridorResult:  # fmt: skip
    """:func:`search` on a map: the fine cells marked once, searched whole when the time
    ``left()`` affords it (:data:`DIRECT_CELLS_PER_SECOND`), else pooled into a coarse lattice;
    when no coarse corridor holds a fine route, the whole fine lattice without alternatives if
    it still fits."""
    fine = model.lattice(fine_cells)
    if fine.nx < 2 or fine.ny < 2:
        return CorridorResult(None, reason="the lattice is too small")
    free = model.free_cells(fine)
    stages["cells"] = time.perf_counter() - t0
    k = max(1, math.ceil(math.sqrt(fine.n_cells / route_cells)))
    nx, ny = fine.nx // k, fine.ny // k
    if k == 1 or nx < 2 or ny < 2 or fine.n_cells <= DIRECT_CELLS_PER_SECOND * left():
        return _route_and_funnel(model, fine, free, start, goal, alternatives, terminate, t0,
                                 stages)  # fmt: skip
    result = _pooled_corridors(model, fine, free, k, start, goal, alternatives, terminate, t0,
                               stages)  # fmt: skip
    if result.path is None and fine.n_cells <= DIRECT_CELLS_PER_SECOND * left():
        return _route_and_funnel(model, fine, free, start, goal, 0, terminate, t0, stages)
    return result


def _pooled_corridors(model, fine, free, k, start, goal, alternatives, terminate, t0,
                      stages) -> CorridorResult:  # fmt: skip
    """Corridors on the coarse lattice pooling ``k`` x ``k`` fine cells (open when any is wholly
    free: no passage of the fine lattice is closed), each searched again on the fine cells."""
    nx, ny = fine.nx // k, fine.ny // k
    pooled = free[: nx * k, : ny * k].reshape(nx, k, ny, k).any(axis=(1, 3))
    coarse = Lattice(fine.origin, fine.h * k, nx, ny)

    def fine_band(r0, r1, c0, c1, mask):
        i0, i1, j0, j1 = r0 * k, r1 * k, c0 * k, c1 * k
        box = Lattice((fine.origin[0] + i0 * fine.h, fine.origin[1] + j0 * fine.h), fine.h,
                      i1 - i0, j1 - j0)  # fmt: skip
        return box, free[i0:i1, j0:j1], k

    return _corridors(model, coarse, pooled, fine_band, start, goal, alternatives, terminate,
                      t0, stages)  # fmt: skip


def _shape_corridors(model, route_cells, max_cells, start, goal, alternatives, terminate, t0,
                     stages, rate=CELLS_PER_SECOND) -> CorridorResult:  # fmt: skip
    """:func:`search` among shapes: coarse cells open when their centre is free, fine cells
    (:data:`SHAPE_SPLIT` per coarse side) marked in each band's box only."""
    coarse = model.lattice(route_cells)
    if coarse.nx < 2 or coarse.ny < 2:
        return CorridorResult(None, reason="the lattice is too small")
    opened = model.centres_free(coarse)
    stages["cells"] = time.perf_counter() - t0

    def fine_band(r0, r1, c0, c1, mask):
        cells = int(mask.sum())
        # As fine as the time left affords: the band's cells are routed and funnelled too.
        afford = max_cells
        if terminate.end is not None:
            afford = min(afford, rate * max(terminate.end - time.perf_counter(), 0.0))
        k = SHAPE_SPLIT
        while k > 1 and cells * k * k > afford:
            k -= 1
        box = Lattice((coarse.origin[0] + r0 * coarse.h, coarse.origin[1] + c0 * coarse.h),
                      coarse.h / k, (r1 - r0) * k, (c1 - c0) * k)  # fmt: skip
        near = np.repeat(np.repeat(mask, k, axis=0), k, axis=1)
        return box, model.free_cells(box, near), k

    return _corridors(model, coarse, opened, fine_band, start, goal, alternatives, terminate,
                      t0, stages)  # fmt: skip


def _corridors(model, coarse: Lattice, opened, fine_band, start, goal, alternatives, terminate,
               t0, stages) -> CorridorResult:  # fmt: skip
    """Coarse routes over ``opened``, then the funnel path of the fine route in each one's band
    (``fine_band(r0, r1, c0, c1)`` gives, for a box of coarse cells, its fine lattice, which of
    its cells are wholly free and the fine cells per coarse side); the shortest valid one."""
    nx, ny = coarse.nx, coarse.ny
    ends = []
    for point in (start, goal):
        cell = _nearest_open(opened, coarse.cell_of(point))
        if cell is None:
            return CorridorResult(None, lattice=coarse, reason="start or goal is not next to "
                                  "a free lattice cell")  # fmt: skip
        ends.append(cell)
    t1 = time.perf_counter()
    apart = max(3.0, ALTERNATIVE_APART * math.hypot(nx, ny))
    routes = alternative_routes(opened, ends[0], ends[1], alternatives, ALTERNATIVE_SLACK, apart)
    stages["coarse_route"] = time.perf_counter() - t1
    best = None
    grow = math.ceil(BAND_CELLS)
    for route in routes:
        if terminate():
            break
        mask = np.zeros((nx, ny), dtype=bool)
        mask[tuple(np.array(route).T)] = True
        mask = ndimage.binary_dilation(mask, iterations=grow)
        rows, cols = np.nonzero(mask)
        r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
        try:
            box, free, k = fine_band(r0, r1, c0, c1, mask[r0:r1, c0:c1])
            near = np.repeat(np.repeat(mask[r0:r1, c0:c1], k, axis=0), k, axis=1)
            result = _route_and_funnel(model, box, free & near, start, goal, 0, terminate, t0,
                                       stages)  # fmt: skip
            if result.path is None and not terminate():
                # The corridor's gaps are narrower than wholly free fine cells: through the
                # centres of the fine cells that are free, every segment checked.
                result = centre_route(model, start, goal, 0, terminate, box, near)
        except MarkingStopped:
            break  # out of time in this corridor: the best of those before it
        if result.path is not None and (best is None or result.length < best.length):
            best = result
    if best is None:
        return CorridorResult(None, lattice=coarse, reason="no route through the lattice")
    return dataclasses.replace(best, routes=len(routes))


class _Deadline:
    """A termination test: ``terminate()``, or the clock past ``end``; :meth:`grace` the same
    with ``grace_end`` (later) for a step that improves a path already found."""

    def __init__(self, end: float | None, terminate=None) -> None:
        self.end, self.terminate = end, terminate
        self.grace_end = end

    def left(self) -> float:
        """Seconds until ``end`` (infinite without one)."""
        return math.inf if self.end is None else max(self.end - time.perf_counter(), 0.0)

    def grace(self) -> bool:
        return bool(self.terminate is not None and self.terminate()) or (
            self.grace_end is not None and time.perf_counter() >= self.grace_end
        )

    def __call__(self) -> bool:
        return bool(self.terminate is not None and self.terminate()) or (
            self.end is not None and time.perf_counter() >= self.end
        )


def _nearest_open(opened: np.ndarray, cell, reach: int = 2):
    """``cell`` when open, else the nearest open cell within ``reach`` (Manhattan), or None."""
    if opened[cell]:
        return cell
    i0, j0 = max(cell[0] - reach, 0), max(cell[1] - reach, 0)
    near = np.argwhere(opened[i0 : cell[0] + reach + 1, j0 : cell[1] + reach + 1])
    if not len(near):
        return None
    near += (i0, j0)
    return tuple(int(c) for c in near[np.argmin(np.abs(near - cell).sum(axis=1))])
