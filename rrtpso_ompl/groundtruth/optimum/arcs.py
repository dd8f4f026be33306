"""Exact tests of arcs: a path wrapping a circle between two tangents, against the bounds and
the obstacles.

An arc runs counter-clockwise from angle ``a0`` through ``sweep`` (radians) on a circle of centre
``c`` and radius ``rho``. Its distance to a point is the radial gap where the point's bearing
lies on the arc, else the distance to the nearer end; to a segment, the least of the end cases,
the crossings (0) and the foot of the common normal. Lengths are in the problem's unit.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...model.geometry import point_segment_distance
from ...model.world import World
from .tangents import TWO_PI

__all__ = ["arcs_free"]


def arcs_free(world: World, center, rho, a0, sweep) -> np.ndarray:
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


def _in_sweep(phi: Any, a0: np.ndarray, sweep: np.ndarray) -> np.ndarray:
    """Whether angle ``phi`` lies on the counter-clockwise arc from ``a0`` through ``sweep``."""
    return np.mod(phi - a0, TWO_PI) <= sweep


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
