"""A seed for the swarm under an inflation cost: the cheapest route in a band round a path.

The corridor stage (:mod:`.corridor`) finds the corridor and the taut path through it, which
touches every wall and door frame at the robot's radius: the shortest path, the worst seed for a
clearance cost. A swarm moving its waypoints a box at a time takes many iterations to carry a
long path to the middle of its corridors. Here the corridor's path is re-routed the way NavFn
and Smac 2D plan on a costmap: a lattice of cells of a quarter of the inflation band within
:data:`BAND_RADII` inflation radii of the path (the whole bounds when they take few cells), each
free cell costing the inflation cost at its centre, a 16-connected route minimising
``sum(length * (1 + w * mean cost))`` over its moves;
then waypoints are dropped wherever the straight segment costs no more (``J``, exactly). The
swarm then polishes the result, which it never makes costlier.

Everything goes through the world's vectorised queries (``free_cells``, ``point_clearance``,
``segments_free``): the cost is only defined with our world's distances.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
from scipy.sparse.csgraph import dijkstra

from ...model.grid_graph import entry_cell, walk
from ...model.objective import InflationCost
from ...model.raster import Lattice
from .corridor import band, lattice_graph

__all__ = [
    "BAND_RADII",
    "CELL_SECONDS",
    "MAX_BAND_CELLS",
    "WHOLE_CELLS",
    "cost_route",
    "drop_waypoints",
]

#: Half-width of the band round the corridor's path, in inflation radii: room to leave the
#: inflated zone on either side of it.
BAND_RADII = 3.0
#: Most lattice cells over the bounds (the band is a small part of them): the cells are made
#: larger to fit.
MAX_BAND_CELLS = 4_000_000
#: A lattice of the whole bounds of at most this many cells is searched whole, not only the band.
WHOLE_CELLS = 250_000
#: Seconds per cell searched (marking it free, its clearance, its moves, the search): 2.3 us
#: measured on the 1.7-million-cell warehouse map with a 0.2 m inflated band, doubled for a
#: busy machine; sizes the cells to the time left.
CELL_SECONDS = 5e-6


def cost_route(
    world: Any,
    inflation: InflationCost,
    path: np.ndarray,
    deadline: float | None = None,
) -> np.ndarray | None:
    """The cheapest 16-connected route of lattice cells within a band round ``path``, from its
    start to its goal, with waypoints dropped where that lowers ``J``; None when there is none
    (or ``deadline``, a ``time.perf_counter()`` time, passed).

    The cells are a quarter of the inflated band (``R_i - r``); where the wholly free cells do
    not join (a passage a few cells wide), cells half and a quarter as large are tried.

    Parameters
    ----------
    world : World
    inflation : InflationCost
        Active (``inflation.active``).
    path : (n, 2) ndarray
        A valid path: its ends are the route's, its neighbourhood the band.
    """
    path = np.asarray(path, dtype=float)
    band_width = inflation.inflation_radius - inflation.radius
    h = 0.25 * band_width
    for k, size in enumerate((h, 0.5 * h, 0.25 * h)):
        if deadline is not None:
            # The work grows with the cells searched: coarser cells when the time is short
            # (first try only, and never coarser than the band), else no route.
            need = CELL_SECONDS * _cells(world, path, size, inflation.inflation_radius)
            left = deadline - time.perf_counter()
            if need > left:
                size *= math.sqrt(need / max(left, 1e-9))
                if k > 0 or size > band_width:
                    return None
        route = _route_on_lattice(world, inflation, path, size, deadline)
        if route is not None:
            return drop_waypoints(world, inflation, route, deadline)
    return None


def _cells(world, path: np.ndarray, h: float, radius: float) -> float:
    """About how many cells :func:`_route_on_lattice` searches on cells of side ``h``."""
    (xmin, ymin), (xmax, ymax) = world.bounds
    whole = (xmax - xmin) * (ymax - ymin) / (h * h)
    if whole <= WHOLE_CELLS:
        return whole
    width = BAND_RADII * radius
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    band_cells = (length + 2 * width) * 2 * width / (h * h)
    # ... and the box round the path, whose cells the band is measured on (about 20 times
    # cheaper each).
    box = np.ptp(path, axis=0) + 2 * width
    return band_cells + float(box[0] * box[1]) / (h * h) / 20.0


def _route_on_lattice(world, inflation: InflationCost, path, h: float, deadline):
    """:func:`cost_route`'s route on cells of side ``h`` (made larger to keep the lattice within
    :data:`MAX_BAND_CELLS`), before waypoints are dropped; None when the cells do not join.

    The lattice covers the path's box grown by the band (on a large map a small part of it);
    when the whole bounds take at most :data:`WHOLE_CELLS` cells, all of them are searched (the
    cheapest corridor may be another than the path's).
    """
    radius = inflation.inflation_radius
    width = BAND_RADII * radius
    (xmin, ymin), (xmax, ymax) = world.bounds
    h = max(h, 1e-9, math.sqrt((xmax - xmin) * (ymax - ymin) / MAX_BAND_CELLS))
    raster = getattr(world, "raster", None)
    if raster is not None:  # cells aligned with the map's (its cells split or merged)
        res = raster.resolution
        h = res / max(1, round(res / h)) if h < res else res * round(h / res)
    whole = (xmax - xmin) * (ymax - ymin) / (h * h) <= WHOLE_CELLS
    if whole:
        region = world.bounds
    else:
        lo = np.maximum(path.min(axis=0) - width - 2 * h, [xmin, ymin])
        hi = np.minimum(path.max(axis=0) + width + 2 * h, [xmax, ymax])
        region = (tuple(lo), tuple(hi))
    anchor = raster.origin if raster is not None else (xmin, ymin)
    lat = Lattice.over(region, h, anchor)
    if lat.nx < 2 or lat.ny < 2:
        return None
    free = world.free_cells(lat, None if whole else band(lat, path, width))
    # The end points may lie near a wall, where the conservative cells leave a gap: look a few
    # cells (the inflated band's width) round them.
    reach = math.ceil(radius / h) + 2
    s_cell, _ = entry_cell(lat, free, path[0], reach, world.segments_free)
    g_cell, _ = entry_cell(lat, free, path[-1], reach, world.segments_free)
    if s_cell is None or g_cell is None:
        return None
    if deadline is not None and time.perf_counter() >= deadline:
        return None
    cells = np.flatnonzero(free.ravel())
    cost = np.zeros(lat.n_cells)
    cost[cells] = inflation.cost(world.point_clearance(lat.centres()[cells], cap=radius))
    graph = lattice_graph(free).tocoo()  # move lengths in cells
    mean = 0.5 * (cost[graph.row] + cost[graph.col])
    graph.data = graph.data * lat.h * (1.0 + inflation.weight * mean)
    ny = lat.ny
    s, g = s_cell[0] * ny + s_cell[1], g_cell[0] * ny + g_cell[1]
    if deadline is not None and time.perf_counter() >= deadline:
        return None
    dist, pred = dijkstra(graph.tocsr(), directed=False, indices=s, return_predecessors=True)
    if not np.isfinite(dist[g]):
        return None
    # Into the first cell and out of the last: the end points lie in them or see their centres.
    centres = np.array([lat.centre((v // ny, v % ny)) for v in walk(pred, g)])
    route = np.vstack([path[:1], centres, path[-1:]])
    return route if world.path_valid(route) else None


def drop_waypoints(
    world: Any, inflation: InflationCost, path: np.ndarray, deadline: float | None = None
) -> np.ndarray:
    """Drop every other waypoint whose neighbours see each other and whose straight segment costs
    no more ``J`` than the two it replaces (exact distances), in sweeps over the odd and even
    waypoints until neither drops one (each sweep that does anything drops a waypoint: at most
    ``n + 2`` sweeps); the path stays valid and never costs more."""
    p = np.asarray(path, dtype=float)
    still = 0
    parity = 1
    while len(p) > 2 and still < 2:
        if deadline is not None and time.perf_counter() >= deadline:
            break
        idx = np.arange(parity, len(p) - 1, 2)
        parity = 2 - parity  # 1, 2, 1, ...: odd and even interior waypoints in turn
        if not len(idx):
            still += 1
            continue
        a, m, b = p[idx - 1], p[idx], p[idx + 1]
        short = np.hypot(*(b - a).T) + inflation.weight * inflation.segment_integrals(world, a, b)
        long = (np.hypot(*(m - a).T) + np.hypot(*(b - m).T)
                + inflation.weight * (inflation.segment_integrals(world, a, m)
                                      + inflation.segment_integrals(world, m, b)))  # fmt: skip
        drop = short <= long
        if drop.any():
            drop[drop] = world.segments_free(a[drop], b[drop])
        if drop.any():
            keep = np.ones(len(p), dtype=bool)
            keep[idx[drop]] = False
            p = p[keep]
            still = 0
        else:
            still += 1
    return p
