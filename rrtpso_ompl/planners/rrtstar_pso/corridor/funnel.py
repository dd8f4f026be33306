"""The taut path in a channel of cells: the channel as free rectangles and the portals between
them, the funnel algorithm (Lee and Preparata 1984; Mononen's "simple stupid funnel"), and a
point robot's path pushed off the blocked corners it would touch."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ....model.raster import Lattice


@dataclass(frozen=True)
class FunnelEnds:
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


def rectangle_channel(cells, label: np.ndarray) -> list[int]:
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


def channel_portals(seq: list[int], rects: np.ndarray, lat: Lattice, shrink: float):
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


def push_off_corners(path: np.ndarray, lat: Lattice, free: np.ndarray, step: float) -> np.ndarray:
    """Move each interior vertex ``step`` away from the blocked cells at its lattice corner.

    For a point robot the funnel's corners lie on the corners of blocked cells, and a segment
    between two corners of one wall runs along it: zero clearance, which counts as entering.
    Pushed diagonally off the corner, the path keeps a clearance of about ``step``. A wall
    corner a segment passes through between two of its corners (three on one line, the walls
    on alternate sides: the funnel does not bend there) becomes a vertex first and is pushed
    off too: pushed apart, the two ends alone would leave the line through it.
    """
    path = _with_passed_corners(path, lat, free)
    out = path.copy()
    for k in range(1, len(path) - 1):
        away = away_from_walls(path[k], lat, free)
        norm = math.hypot(*away)
        if norm > 0.0:
            out[k] += step * away / norm
    return out


def _corner_of(point, lat: Lattice) -> tuple[int, int]:
    """The lattice corner nearest ``point`` (``(i, j)``: the lower-left corner of cell
    ``(i, j)``)."""
    (ox, oy), h = lat.origin, lat.h
    return round((point[0] - ox) / h), round((point[1] - oy) / h)


def away_from_walls(point, lat: Lattice, free: np.ndarray) -> np.ndarray:
    """The sum of the directions from the blocked cells (or the lattice's outside) at the corner
    nearest ``point`` towards it (zero where none or all four are blocked)."""
    ci, cj = _corner_of(point, lat)
    away = np.zeros(2)
    for di in (-1, 0):
        for dj in (-1, 0):
            i, j = ci + di, cj + dj
            if not (0 <= i < lat.nx and 0 <= j < lat.ny) or not free[i, j]:
                away -= (di + 0.5, dj + 0.5)
    return away


def _with_passed_corners(path: np.ndarray, lat: Lattice, free: np.ndarray) -> np.ndarray:
    """``path`` with the wall corners its interior segments pass through inserted: between two
    vertices at lattice corners ``(di, dj)`` apart, the ``gcd(di, dj) - 1`` corners on the line
    (at most the segment's length in cells, each checked in O(1))."""
    (ox, oy), h = lat.origin, lat.h
    out = [path[0]]
    for k in range(len(path) - 1):
        a, b = path[k], path[k + 1]
        if 0 < k < len(path) - 2:
            ca, cb = np.array(_corner_of(a, lat)), np.array(_corner_of(b, lat))
            d = cb - ca
            g = math.gcd(int(d[0]), int(d[1]))
            on_corners = (np.abs(a - (ox, oy) - h * ca).max() < 1e-2 * h
                          and np.abs(b - (ox, oy) - h * cb).max() < 1e-2 * h)  # fmt: skip
            for m in range(1, g if on_corners else 1):
                c = ca + (d // g) * m
                point = np.array([ox + h * c[0], oy + h * c[1]])
                if away_from_walls(point, lat, free).any():
                    out.append(point)
        out.append(b)
    return np.array(out)


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
