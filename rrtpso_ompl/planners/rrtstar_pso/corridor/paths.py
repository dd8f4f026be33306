"""One corridor search on one lattice: routes through the corridors, each funnelled taut (or
wrapped round corners for a disc), the shortest valid path kept; among shapes, the route of cell
centres re-routed round segments that fail the exact check."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.sparse.csgraph import dijkstra

from ....model.geometry import path_length, shortcut
from ....model.grid_graph import entry_cell, walk
from ....model.raster import Lattice
from .corner_routes import CORNER_BAND_SLACK, CORNER_CELLS_PER_SECOND, corner_routes
from .corners import circumscribe_corners, wrapped_funnel
from .funnel import (
    FunnelEnds,
    channel_portals,
    free_rectangles,
    funnel,
    push_off_corners,
    rectangle_channel,
)
from .routes import (
    ALTERNATIVE_APART,
    ALTERNATIVE_SLACK,
    CUT,
    alternative_routes,
    band,
    channel,
    cut_edges,
    lattice_graph,
)

#: Most re-routings of :func:`centre_route` around segments that failed the check.
CENTRE_ROUTE_ROUNDS = 32


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
    return route_and_funnel(model, lat, free, start, goal, alternatives, terminate, t0, stages)


def route_and_funnel(model, lat, free, start, goal, alternatives, terminate, t0, stages,
                      routes=None, corner_reach=0) -> CorridorResult:  # fmt: skip
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
        routes = _routes(lat, free, n_free, (s_cell, s_hop), (g_cell, g_hop), start, goal,
                         alternatives, terminate, corner_reach)  # fmt: skip
    stages["route"] = stages.get("route", 0.0) + time.perf_counter() - t1
    if not routes:
        return done("no route through the lattice", lattice=lat, cells=n_free)
    t2 = time.perf_counter()
    # Through a cell the end point lies in, the funnel starts at the point itself; entered from
    # outside, at the cell's centre (the segment there was checked).
    ends = FunnelEnds(lat.centre(s_cell) if s_hop else start, lat.centre(g_cell) if g_hop else goal,
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


def _routes(lat, free, n_free: int, s_end, g_end, start, goal, alternatives: int, terminate,
            corner_reach: int):  # fmt: skip
    """The cell lattice's routes and, where its band fits the time, the corner lattice's
    (:mod:`.corner_routes`), between the entry cells ``s_end`` and ``g_end`` (``(cell, hop)``)."""
    (s_cell, s_hop), (g_cell, g_hop) = s_end, g_end
    apart = max(3.0, ALTERNATIVE_APART * math.hypot(lat.nx, lat.ny))
    # The band comes with the alternatives' search from both ends; alone, it doubles the
    # search, worth it only where the whole lattice would fit the corner lattice's time.
    if not corner_reach or (not alternatives and not _corner_fits(n_free, corner_reach,
                                                                      terminate)):  # fmt: skip
        return alternative_routes(free, s_cell, g_cell, alternatives, ALTERNATIVE_SLACK, apart)
    routes, near = alternative_routes(free, s_cell, g_cell, alternatives, ALTERNATIVE_SLACK, apart,
                                      CORNER_BAND_SLACK)  # fmt: skip
    if not routes or not _corner_fits(int(near.sum()), corner_reach, terminate):
        return routes
    a = start if not s_hop else np.asarray(lat.centre(s_cell))
    b = goal if not g_hop else np.asarray(lat.centre(g_cell))
    # Over the cells of the routes within the slack: the corner lattice's work follows the
    # corridors worth telling apart, not the whole map.
    return routes + corner_routes(lat, free & near, ((s_cell, a), (g_cell, b)), alternatives,
                                  ALTERNATIVE_SLACK, apart, corner_reach)  # fmt: skip


def _corner_fits(cells: int, reach: int, terminate) -> bool:
    """Whether the corner lattice over ``cells`` cells fits the time ``terminate`` leaves
    (:data:`.corner_routes.CORNER_CELLS_PER_SECOND`); always without a time limit."""
    left = getattr(terminate, "left", None)
    return reach > 0 and (left is None or cells <= CORNER_CELLS_PER_SECOND * left())


def _funnel_routes(model, lat: Lattice, free, routes, ends: FunnelEnds, terminate):
    """``(path, length, route cells, route index)`` of the shortest checked funnel path over
    ``routes`` (portals shrunk by the touch tolerance, then by a thousandth of a cell), or
    None."""
    rects, label = free_rectangles(free)
    best = None
    for k, route in enumerate(routes):
        if k and terminate is not None and terminate():
            break
        seq = rectangle_channel(channel(route), label)
        for shrink in (max(1e-6 * lat.h, 16.0 * model.tol), 1e-3 * lat.h, None):
            if shrink is None:
                # A point robot's path along a wall between two of its corners, lifted off the
                # corners diagonally, may cut the wall's cells: the taut string round the
                # corners at the touch tolerance instead (maps; None elsewhere).
                if model.robot_radius > 0.0 or (terminate is not None and terminate()):
                    break
                candidate = wrapped_funnel(model, lat, free, route, ends, terminate)
                if candidate is None:
                    break
            else:
                inner = funnel(ends.a, ends.b, channel_portals(seq, rects, lat, shrink))
                if model.robot_radius <= 0.0:
                    inner = push_off_corners(inner, lat, free, 2.0 * shrink)
                candidate = ends.path(inner)
            if model.path_valid(candidate):
                length = path_length(candidate)
                if best is None or length < best[1]:
                    best = (candidate, length, len(route), k)
                break
    return best


def _pulled_taut(model, lat: Lattice, free, routes, ends: FunnelEnds, terminate, best):
    """``best`` (see :func:`_funnel_routes`) improved or, when None, replaced: a disc robot's
    path pulled to the walls (:func:`wrapped_funnel`); with no checked funnel path (a point
    robot's grazing a corner it was not lifted off), the taut string round the corners at the
    touch tolerance; else the centres of the first channel's cells (segments inside free cells)
    greedily shortcut.

    A route found is worth its taut path: the string round its corners (at most
    :data:`~.corners.WRAP_REPAIRS` checks) may run up to the outer deadline
    (``terminate.terminate`` where there is one), past the stage's own. A route found late on a
    map of a million cells was otherwise left as the staircase of its cells (+2 to +25 %), a
    disc's path on a warehouse of 2 million cells unwrapped (+1.0 %, wrapped +0.24 %).
    """
    finish = getattr(terminate, "terminate", terminate)
    if best is not None and model.robot_radius > 0.0 and not (finish and finish()):
        wrapped = wrapped_funnel(model, lat, free, routes[best[3]], ends, finish)
        if wrapped is not None and path_length(wrapped) < best[1]:
            best = (wrapped, path_length(wrapped), *best[2:])
    if best is None and not (finish and finish()):
        wrapped = wrapped_funnel(model, lat, free, routes[0], ends, finish)
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
        if not dist[t] < CUT:
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
                thin_funnel(model, lat, free, route, path, s_hop, g_hop))  # fmt: skip
            if taut is not None and path_length(taut) < path_length(path):
                path = taut
            return CorridorResult(path, path_length(path), lat, int(free.sum()), len(nodes),
                                  time.perf_counter() - t0, "", {}, 1, 0)  # fmt: skip
        cut_edges(graph, nodes[:-1][~ok], nodes[1:][~ok])
    return CorridorResult(None, lattice=lat, cells=int(free.sum()), time=time.perf_counter() - t0,
                          reason="no checked route through free cell centres")  # fmt: skip


def thin_funnel(model, lat: Lattice, free: np.ndarray, route, path, s_hop: bool, g_hop: bool):
    """The funnel through a route of cells whose centres are free but whose sides are not, each
    corner it bends round wrapped at the robot's radius (:func:`.circumscribe_corners`).
    Checked; None when the check fails."""
    rects = np.array([(i, i + 1, j, j + 1) for i, j in channel(route)])
    seq = list(range(len(rects)))
    start, goal = path[0], path[-1]
    a = path[1] if s_hop else start
    b = path[-2] if g_hop else goal
    inner = funnel(a, b, channel_portals(seq, rects, lat, 16.0 * model.tol))
    inner = circumscribe_corners(inner, lat, free, float(model.robot_radius) + 16.0 * model.tol)
    candidate = np.vstack([start[None]] * s_hop + [inner] + [goal[None]] * g_hop)
    return candidate if model.path_valid(candidate) else None
