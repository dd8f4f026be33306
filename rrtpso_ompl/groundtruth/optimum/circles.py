"""The circles a shortest path can wrap: the start and the goal (radius 0), the obstacle circles
grown by the robot radius ``R``, and the convex corners of polygons, boxes and map cells (radius
``R``), each with its cone of free directions.

A path wraps a polygon's convex vertex only between the outward normals of its two edges (a
quarter circle at a box's or map cell's corner); elsewhere it would enter an edge's offset. Where
nothing but the circle's own obstacle is within reach, the whole arc is free and needs no exact
test (``sure``). Angles are in radians, lengths in the problem's unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...model.world import World
from ..free_grid import FreeGrid
from .tangents import TWO_PI

__all__ = ["NodeCircles"]


@dataclass
class NodeCircles:
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
    def build(cls, world: World, grid: FreeGrid, start, goal, radius: float) -> NodeCircles:
        rows = [np.array([[*start, 0.0], [*goal, 0.0]])]
        lo, width = [np.zeros(2)], [np.full(2, TWO_PI)]
        c = world.circles
        rows.append(np.column_stack([c[:, :2], c[:, 2] + radius]))
        lo.append(np.zeros(len(c)))
        width.append(np.full(len(c), TWO_PI))
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
            lo.append(np.mod(a0, TWO_PI))
            width.append(np.mod(a1 - a0, TWO_PI))
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
