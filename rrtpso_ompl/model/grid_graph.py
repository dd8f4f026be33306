"""Graphs over the cells of a grid: the one builder every grid search of the package uses.

Four searches walk a grid of cells or points: the corridor stage of RRTstarPSO (a
16-connected lattice of wholly free cells), the inflation objective's cost route and its grid
reference (16-connected, every edge certified free and weighted by its cost), the solvability
certificate (8-connected grid points) and the DWA's navigation grid (8-connected cells). They
differ in which nodes exist and what an edge weighs; the moves, which cells a move passes, the
node pairs of a move over a whole grid, the sparse graph and the walk back along a shortest-path
tree are the same, and live here.

A grid is a 2-D array ``index`` of node numbers, ``-1`` where there is no node (a blocked cell).
A move ``(d0, d1)`` joins ``index[i, j]`` to ``index[i + d0, j + d1]``; moves are listed once
each (the graphs are undirected), with the cells a move passes, which must be nodes too so that
a route never slips between two blocked corners.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix

__all__ = [
    "MOVES_8",
    "MOVES_16",
    "Move",
    "entry_cell",
    "grid_graph",
    "move_pairs",
    "node_dtype",
    "walk",
]

#: A move: its step ``(d0, d1)``, the cells beside the way that must be nodes too, and the cells
#: a channel through it goes through (each sharing an edge with the one before).
Move = tuple[tuple[int, int], tuple[tuple[int, int], ...], tuple[tuple[int, int], ...]]

#: The 8-connected moves, each undirected edge once: right, up and the two diagonals (a diagonal
#: needs both cells beside it).
MOVES_8: tuple[Move, ...] = (
    ((1, 0), (), ()),
    ((0, 1), (), ()),
    ((1, 1), ((1, 0), (0, 1)), ((1, 0),)),
    ((1, -1), ((1, 0), (0, -1)), ((1, 0),)),
)
#: The 16-connected moves: the 8 and the four knight's moves, so that a route deviates from a
#: straight line by at most 2.7 % in length.
MOVES_16: tuple[Move, ...] = (
    *MOVES_8,
    ((2, 1), ((1, 0), (1, 1)), ((1, 0), (1, 1))),
    ((1, 2), ((0, 1), (1, 1)), ((0, 1), (1, 1))),
    ((2, -1), ((1, 0), (1, -1)), ((1, 0), (1, -1))),
    ((1, -2), ((0, -1), (1, -1)), ((0, -1), (1, -1))),
)


def move_pairs(
    index: np.ndarray, step: tuple[int, int], passed: Sequence[tuple[int, int]] = ()
) -> tuple[np.ndarray, np.ndarray]:
    """Every node pair ``(a, b)`` joined by one move over the whole grid, in row-major order.

    Parameters
    ----------
    index : (n0, n1) ndarray of int
        Node numbers, ``-1`` where there is no node.
    step : (int, int)
        The move ``(d0, d1)``: node ``index[i, j]`` to ``index[i + d0, j + d1]``.
    passed : sequence of (int, int)
        Offsets from ``(i, j)`` of the cells the move passes, which must be nodes too.

    Returns
    -------
    a, b : ndarray of int
        The pairs' two ends (empty when the move leaves the grid from every cell).
    """
    d0, d1 = step
    n0, n1 = index.shape
    i0, i1 = max(0, -d0), n0 - max(0, d0)
    j0, j1 = max(0, -d1), n1 - max(0, d1)
    if i0 >= i1 or j0 >= j1:
        empty = np.empty(0, dtype=index.dtype)
        return empty, empty
    a = index[i0:i1, j0:j1]
    b = index[i0 + d0 : i1 + d0, j0 + d1 : j1 + d1]
    ok = (a >= 0) & (b >= 0)
    for p0, p1 in passed:
        ok &= index[i0 + p0 : i1 + p0, j0 + p1 : j1 + p1] >= 0
    return a[ok], b[ok]


def node_dtype(n_nodes: int) -> type:
    """The integer type for node numbers of a graph of ``n_nodes``: 32 bits while they fit.

    SciPy stores such a graph with 32-bit indices; handed 64-bit ones it scans and narrows them,
    and the arrays twice the size cost page faults: building the 16-connected graph of a million
    cells took 0.23-0.5 s with 64-bit numbers, 0.07-0.1 s with 32-bit ones.
    """
    return np.int32 if n_nodes < np.iinfo(np.int32).max else np.int64


def grid_graph(
    n_nodes: int,
    a: np.ndarray,
    b: np.ndarray,
    weights: np.ndarray,
    *,
    symmetric: bool = False,
) -> csr_matrix:
    """The sparse graph of the edges ``a[k] - b[k]`` weighing ``weights[k]`` (each listed once).

    With ``symmetric`` both directions are stored (a directed search, such as a wavefront from
    many sources, needs them); otherwise search it with ``directed=False``. Zero weights are no
    edges to ``scipy.sparse.csgraph``: give a coincident pair a tiny weight instead.
    """
    dtype = node_dtype(n_nodes)
    a, b = np.asarray(a).astype(dtype, copy=False), np.asarray(b).astype(dtype, copy=False)
    graph = coo_matrix((weights, (a, b)), shape=(n_nodes, n_nodes)).tocsr()
    return (graph + graph.T).tocsr() if symmetric else graph


def walk(pred: np.ndarray, node: int) -> list[int]:
    """Nodes from the root of a shortest-path tree (``pred`` as ``scipy.sparse.csgraph``
    returns it: ``-9999`` at the root and at nodes not reached) to ``node``; a tree has no cycle,
    so at most as many steps as nodes."""
    out = [node]
    while pred[out[-1]] >= 0:
        out.append(int(pred[out[-1]]))
    return out[::-1]


def entry_cell(
    lat: Any,
    free: np.ndarray,
    point,
    reach: int,
    segments_free: Callable[[np.ndarray, np.ndarray], np.ndarray],
) -> tuple[tuple[int, int] | None, bool]:
    """The free cell to enter a lattice from ``point``, and whether it is not ``point``'s own.

    Its own cell when free, else the nearest free cell within ``reach`` cells whose centre it
    sees (``segments_free``, an exact segment test), nearest first; ``(None, False)`` when none.

    Parameters
    ----------
    lat : Lattice
        The lattice (:class:`~rrtpso_ompl.model.raster.Lattice`).
    free : (nx, ny) ndarray of bool
        Which cells are free.
    point : (2,) array_like
        A point in the lattice's bounds.
    reach : int
        The most cells away the entry may be.
    segments_free : callable
        ``segments_free(a, b)`` for ``(n, 2)`` arrays: which segments are free.
    """
    cell = lat.cell_of(point)
    if free[cell]:
        return cell, False
    ci, cj = cell
    cand = [(i, j) for i in range(ci - reach, ci + reach + 1)
            for j in range(cj - reach, cj + reach + 1)
            if 0 <= i < lat.nx and 0 <= j < lat.ny and free[i, j]]  # fmt: skip
    if not cand:
        return None, False
    centres = np.array([lat.centre(c) for c in cand])
    p = np.asarray(point, dtype=float)
    order = np.argsort(np.hypot(*(centres - p).T))
    for chunk in np.array_split(order, max(1, math.ceil(len(order) / 16))):
        sees = segments_free(np.broadcast_to(p, (len(chunk), 2)), centres[chunk])
        if sees.any():
            return cand[int(chunk[np.flatnonzero(sees)[0]])], True
    return None, False
