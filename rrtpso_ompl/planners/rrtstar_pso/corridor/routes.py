"""Routes on the lattice of free cells: the 16-connected graph, the shortest route, routes through
other corridors (via nodes), the channel of cells a route passes, and the band round a path."""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy import ndimage
from scipy.sparse.csgraph import dijkstra

from ....model.grid_graph import MOVES_16, grid_graph, move_pairs, node_dtype, walk
from ....model.raster import Lattice

#: Alternative routes are tried when their lattice length is within this share of the best's
#: (the lattice's error in length: up to 2.7 % for the moves, plus the cells' conservatism).
ALTERNATIVE_SLACK = 0.06


#: ... and when they pass this share of the lattice's diagonal away from the routes before.
ALTERNATIVE_APART = 0.03


#: The weight of a move found blocked: no route uses it while another exists.
CUT = 1e12


def lattice_graph(free: np.ndarray):
    """The 16-connected graph of the free cells (CSR, undirected; cell ``(i, j)`` is node
    ``i * ny + j``; move lengths in cells)."""
    nx, ny = free.shape
    index = np.where(free, np.arange(nx * ny, dtype=node_dtype(nx * ny)).reshape(nx, ny), -1)
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
    free: np.ndarray, source, target, count: int, slack: float, apart: float, within=None
):
    """The shortest route of cells and up to ``count`` others through different corridors
    (:func:`via_routes` over :func:`lattice_graph`).

    With ``within`` (a relative slack), also the (nx, ny) booleans of the cells some route
    through which is at most ``1 + within`` times the shortest: ``(routes, cells)``.
    """
    ny = free.shape[1]
    s = source[0] * ny + source[1]
    t = target[0] * ny + target[1]
    found = via_routes(lattice_graph(free), free.shape, s, t, count, slack, apart, within)
    routes, cells = found if within is not None else (found, None)
    routes = [[(v // ny, v % ny) for v in r] for r in routes]
    return routes if within is None else (routes, cells)


def via_routes(graph, shape: tuple[int, int], s: int, t: int, count: int, slack: float,
               apart: float, within: float | None = None):  # fmt: skip
    """The shortest route from node ``s`` to node ``t`` of an undirected ``graph`` over a grid of
    ``shape`` nodes (node ``i * shape[1] + j``; nodes past the grid's, such as end points joined
    to it, are never via nodes), and up to ``count`` others through different corridors.

    With Dijkstra distances from both ends, the best route through a node ``v`` has length
    ``d_s(v) + d_t(v)``. An alternative goes through the node of least such length that lies
    more than ``apart`` nodes from every route taken so far, if that length is within ``slack``
    (relative) of the best: a different door, aisle or side of an obstacle (the *via-node* method
    of alternative route planning on road networks). Node lists, the shortest first; with
    ``within``, also the grid's booleans of the nodes some route through which is at most
    ``1 + within`` times the shortest.
    """
    n = shape[0] * shape[1]
    if count <= 0 and within is None:  # the shortest alone: one search, from one end
        dist, pred = dijkstra(graph, directed=False, indices=s, return_predecessors=True)
        return [walk(pred, t)] if np.isfinite(dist[t]) else []
    dist, pred = dijkstra(graph, directed=False, indices=[s, t], return_predecessors=True)
    best = dist[0, t]
    through = (dist[0] + dist[1])[:n]
    if not np.isfinite(best):
        return [] if within is None else ([], np.zeros(shape, dtype=bool))
    routes = [walk(pred[0], t)]
    near = np.zeros(n, dtype=bool)
    for _ in range(count):
        last = np.asarray(routes[-1])
        near[last[last < n]] = True
        far = ndimage.distance_transform_edt(~near.reshape(shape)) > apart
        ok = far.ravel() & (through <= best * (1.0 + slack))
        if not ok.any():
            break
        v = int(np.flatnonzero(ok)[np.argmin(through[ok])])
        routes.append(walk(pred[0], v) + walk(pred[1], v)[::-1][1:])
    if within is None:
        return routes
    return routes, (through <= best * (1.0 + within)).reshape(shape)


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


def cut_edges(graph, tails, heads) -> None:
    """Give the edges ``tails[i] - heads[i]`` of the sorted CSR ``graph`` the weight
    :data:`CUT`: no route uses them while another exists."""
    for a, b in zip(tails, heads, strict=True):
        for u, v in ((a, b), (b, a)):  # the edge is stored once, in either direction
            lo, hi = graph.indptr[u], graph.indptr[u + 1]
            at = lo + np.searchsorted(graph.indices[lo:hi], v)
            if at < hi and graph.indices[at] == v:
                graph.data[at] = CUT  # as good as gone


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
