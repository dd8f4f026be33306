"""Routes between cell corners with long moves: a lattice whose lengths are close to the taut
length, so that it tells apart corridors the cell lattice rates alike.

The cell lattice of :mod:`.routes` walks from cell centre to cell centre in 16 directions, and a
diagonal needs both cells beside it free. Where corridors are one cell wide that makes every
route a staircase of axis moves: a corridor running at 45 degrees costs 41 % more on the lattice
than its taut path, and of many aisles of equal lattice length (a warehouse of racks crossed
diagonally) the lattice cannot tell which one the taut string shortens most.

Here the nodes are the cells' *corners* and a move joins two corners up to :data:`CORNER_REACH`
cells apart in any primitive direction (``(a, b)`` with ``gcd(a, b) = 1``: 48 directions for a
reach of 4), allowed when no blocked cell's interior meets it (along a cell edge: when a cell
beside it is free). A taut path bends only at corners of blocked cells, and between two bends it
is a straight segment, which the moves approximate within the angle between neighbouring
directions: at most 0.8 % longer for a reach of 4 (the largest gap, next to the axes, is
``atan(1/4)``), however narrow the corridor. The shortest route and its via-node alternatives
(:func:`.routes.via_routes`) are then turned into channels of cells for the funnel, which makes
each one taut exactly; the shortest funnel path wins.

Its cost is a few shifted-array operations per move and one sparse-graph search over
``(nx + 1) (ny + 1)`` corners and about ``24 (nx + 1) (ny + 1)`` edges: about three times the
cell lattice's, so the corridor stage adds it where the time affords
(:data:`CORNER_CELLS_PER_SECOND`).
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ....model.grid_graph import grid_graph, node_dtype
from ....model.raster import Lattice
from .routes import via_routes

#: The longest move of the corner lattice, in cells along each axis (a move ``(a, b)`` has
#: ``max(|a|, |b|) <= CORNER_REACH``). 4 gives 48 directions, within 0.8 % of any straight line.
CORNER_REACH = 4

#: Lattice cells per second the corner lattice is built over and searched (both ends, with
#: alternatives), on the safe side (measured 0.30-0.49 million on random maps of 128 x 128 to
#: 1024 x 1024 cells).
CORNER_CELLS_PER_SECOND = 300_000

#: The corner lattice searches the cells some route through which on the cell lattice is at most
#: this much (relative) longer than the shortest: the corridors worth telling apart. The cell
#: lattice's error is up to 2.7 % in the open and more along staircases of one-cell corridors
#: (41 % at 45 degrees), which a slack this wide keeps for the common ones.
CORNER_BAND_SLACK = 0.15

__all__ = [
    "CORNER_BAND_SLACK",
    "CORNER_CELLS_PER_SECOND",
    "CORNER_REACH",
    "corner_edges",
    "corner_moves",
    "corner_routes",
]


@functools.lru_cache(maxsize=8)
def corner_moves(reach: int = CORNER_REACH) -> tuple[tuple[tuple[int, int], tuple, tuple], ...]:
    """The corner lattice's moves, each undirected move once: ``(step, crossed, beside)``.

    ``crossed`` lists, in order along the move, the offsets (from the cell whose lower-left
    corner the move starts at) of the cells whose interior the move passes; ``beside`` is empty
    except for a move along a cell edge, which passes no interior: the two cells it runs
    between, of which one must be free.
    """
    moves = []
    for a in range(0, reach + 1):
        for b in range(-reach, reach + 1):
            if (a == 0 and b <= 0) or math.gcd(a, b) != 1:
                continue  # each direction once: a > 0, or straight up
            if a == 0:
                moves.append(((0, 1), (), ((-1, 0), (0, 0))))
            elif b == 0:
                moves.append(((1, 0), (), ((0, -1), (0, 0))))
            else:
                moves.append(((a, b), _crossed(a, b), ()))
    return tuple(moves)


def _crossed(a: int, b: int) -> tuple[tuple[int, int], ...]:
    """Cells whose interior the segment from ``(0, 0)`` to ``(a, b)`` passes (``gcd = 1``, so it
    meets no other lattice point), in order: the cell round each midpoint between consecutive
    crossings of grid lines."""
    ts = sorted({k / abs(a) for k in range(abs(a) + 1)} | {k / abs(b) for k in range(abs(b) + 1)})
    mids = [0.5 * (t0 + t1) for t0, t1 in itertools.pairwise(ts)]
    return tuple((math.floor(a * t), math.floor(b * t)) for t in mids)


def _corner_nodes(free: np.ndarray) -> np.ndarray:
    """(nx + 1, ny + 1) booleans: corners the route may pass, those with a free cell beside
    them, but not a pinch (exactly two free cells, diagonally across: the funnel's channel could
    not pass between the two blocked ones)."""
    nx, ny = free.shape
    pad = np.zeros((nx + 2, ny + 2), dtype=bool)
    pad[1:-1, 1:-1] = free
    sw, se, nw, ne = pad[:-1, :-1], pad[1:, :-1], pad[:-1, 1:], pad[1:, 1:]
    pinch = (sw & ne & ~se & ~nw) | (se & nw & ~sw & ~ne)
    return (sw | se | nw | ne) & ~pinch


def _shifted(arr: np.ndarray, di: int, dj: int, shape: tuple[int, int]) -> np.ndarray:
    """``shape`` booleans: ``out[i, j] = arr[i + di, j + dj]``, False where that is off
    ``arr``."""
    n0, n1 = arr.shape
    out = np.zeros(shape, dtype=bool)
    i0, i1 = max(0, -di), min(shape[0], n0 - di)
    j0, j1 = max(0, -dj), min(shape[1], n1 - dj)
    if i0 < i1 and j0 < j1:
        out[i0:i1, j0:j1] = arr[i0 + di : i1 + di, j0 + dj : j1 + dj]
    return out


def corner_edges(free: np.ndarray, reach: int = CORNER_REACH):
    """The corner lattice of ``free`` ((nx, ny) booleans): ``(tails, heads, weights)``, each
    edge once (corner ``(i, j)``, the lower-left corner of cell ``(i, j)``, is node
    ``i * (ny + 1) + j``; move lengths in cells)."""
    nx, ny = free.shape
    shape = (nx + 1, ny + 1)
    nodes = _corner_nodes(free)
    index = np.arange(shape[0] * shape[1], dtype=node_dtype(shape[0] * shape[1] + 2)).reshape(shape)
    tails, heads, weights = [], [], []
    for (a, b), crossed, beside in corner_moves(reach):
        ok = nodes & _shifted(nodes, a, b, shape)
        for ci, cj in crossed:
            ok &= _shifted(free, ci, cj, shape)
        if beside:
            ok &= _shifted(free, *beside[0], shape) | _shifted(free, *beside[1], shape)
        t = index[ok]
        tails.append(t)
        heads.append(t + a * shape[1] + b)
        weights.append(np.full(len(t), math.hypot(a, b)))
    return np.concatenate(tails), np.concatenate(heads), np.concatenate(weights)


def corner_routes(lat: Lattice, free: np.ndarray, ends, count: int, slack: float, apart: float,
                  reach: int = CORNER_REACH) -> list[list[tuple[int, int]]]:  # fmt: skip
    """The shortest route over the corner lattice and up to ``count`` alternatives
    (:func:`.routes.via_routes`), each as the channel of cells it passes (consecutive cells
    share an edge), from the first end's cell to the second's.

    Parameters
    ----------
    lat : Lattice
        The lattice of ``free``.
    free : (nx, ny) ndarray of bool
        Which cells are free.
    ends : ((cell, point), (cell, point))
        Where the routes start and end: a free cell and the point in it (or its centre) the
        route leaves from, joined to the cell's corners.
    count, slack, apart
        As for :func:`.routes.via_routes` (``apart`` in corners).
    reach : int
        The longest move (:data:`CORNER_REACH`).
    """
    nx, ny = free.shape
    n = (nx + 1) * (ny + 1)
    tails, heads, weights = corner_edges(free, reach)
    extra_t, extra_h, extra_w = [], [], []
    for node, ((ci, cj), point) in zip((n, n + 1), ends, strict=True):
        for di in (0, 1):
            for dj in (0, 1):
                corner = np.array([lat.origin[0] + (ci + di) * lat.h,
                                   lat.origin[1] + (cj + dj) * lat.h])  # fmt: skip
                d = float(np.hypot(*(corner - np.asarray(point, dtype=float)))) / lat.h
                extra_t.append(node)
                extra_h.append((ci + di) * (ny + 1) + cj + dj)
                extra_w.append(max(d, 1e-9))  # zero weights are no edges to csgraph
    graph = grid_graph(n + 2, np.concatenate([tails, extra_t]), np.concatenate([heads, extra_h]),
                       np.concatenate([weights, extra_w]))  # fmt: skip
    routes = via_routes(graph, (nx + 1, ny + 1), n, n + 1, count, slack, apart)
    out = []
    for route in routes:
        cells = _channel(route[1:-1], ends[0][0], ends[1][0], free, ny + 1, reach)
        if cells is not None:
            out.append(cells)
    return out


def _channel(corners, first, last, free: np.ndarray, stride: int, reach: int):
    """The cells a route through ``corners`` (node numbers) passes, from cell ``first`` to
    cell ``last``, each sharing an edge with the one before (a cell across a corner the route
    turns at is joined through a free cell beside both); None if the route cannot be made a
    channel."""
    table = {step: (crossed, beside) for step, crossed, beside in corner_moves(reach)}
    cells = [tuple(first)]
    for u, v in itertools.pairwise(corners):
        (i0, j0), (i1, j1) = divmod(u, stride), divmod(v, stride)
        step = (i1 - i0, j1 - j0)
        if step in table:
            crossed, beside = table[step]
            origin = (i0, j0)
        else:  # the move listed the other way round: walked back from the far corner
            crossed, beside = table[(-step[0], -step[1])]
            crossed = crossed[::-1]
            origin = (i1, j1)
        if beside:
            crossed = [c for c in beside if _free(free, origin[0] + c[0], origin[1] + c[1])][:1]
        for ci, cj in crossed:
            if not _append(cells, (origin[0] + ci, origin[1] + cj), free):
                return None
    if not _append(cells, tuple(last), free):
        return None
    return cells


def _free(free: np.ndarray, i: int, j: int) -> bool:
    return 0 <= i < free.shape[0] and 0 <= j < free.shape[1] and bool(free[i, j])


def _append(cells: list, cell: tuple[int, int], free: np.ndarray) -> bool:
    """Append ``cell`` to the channel ``cells``, through a free cell beside both when the two
    meet only at a corner; False when they do not meet, or meet at a corner with no such cell."""
    i0, j0 = cells[-1]
    di, dj = cell[0] - i0, cell[1] - j0
    if (di, dj) == (0, 0):
        return True
    if abs(di) + abs(dj) == 1:
        cells.append(cell)
        return True
    if abs(di) == 1 and abs(dj) == 1:
        for via in ((i0 + di, j0), (i0, j0 + dj)):
            if _free(free, *via):
                cells.extend([via, cell])
                return True
    return False
