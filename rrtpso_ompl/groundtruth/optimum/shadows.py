"""The shadow filter of the tangent search: tangents that the discs near a circle block.

A tangent leaving circle ``i`` (centre ``c``, radius ``rho``) in direction ``phi``, in the sense
``s``, runs on the line ``cross(x - c, u(phi)) = s rho``. A disc of radius ``r`` at distance
``D`` and bearing ``theta`` from ``c`` (an obstacle circle, or the disc inscribed in a box, grown
by the clearance threshold) blocks every such tangent with ``|D sin(phi - theta) - s rho| < r``
once it is ``D`` long: an interval of directions per disc and sense. Binned over the directions
(:data:`_SHADOW_BINS` a turn), the least such length bounds how far a free tangent can go; a
range-maximum table over the bins answers for a whole cone of directions at once. Angles are in
radians, lengths in the problem's unit.
"""

from __future__ import annotations

import numpy as np

from ...model.obstacle_index import BOX, CIRCLE
from ...model.world import World
from .tangents import TWO_PI

__all__ = ["shadowed"]

#: Bins of directions of a circle's shadow profile, and how far (index cells) its discs are.
_SHADOW_BINS = 1024
_SHADOW_BIN = TWO_PI / _SHADOW_BINS
_SHADOW_CELLS = 8.0
#: A circle's shadow profile is built when it has at least this many candidate pairs.
_SHADOW_WORTH = 100


def shadowed(world: World, c: np.ndarray, batch: np.ndarray, row: np.ndarray, j: np.ndarray):
    """The pairs ``(batch[row], j)`` of the circles ``c`` (``(k, 3)``: centre, radius) not wholly
    in the shadow of the obstacles of ``world`` near the first circle.

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
    i = batch[row]
    d = c[j, :2] - c[i, :2]
    dist = np.hypot(d[:, 0], d[:, 1])
    gap = dist - c[i, 2] - c[j, 2]
    beta = np.arcsin(np.clip((c[i, 2] + c[j, 2]) / np.maximum(dist, 1e-300), 0.0, 1.0))
    phi = np.mod(np.arctan2(d[:, 1], d[:, 0]), TWO_PI)
    # Profiles only for the circles with many pairs (else the tangent-level filters are
    # cheaper than the table).
    count = np.bincount(row, minlength=len(batch))
    busy = np.flatnonzero(count >= _SHADOW_WORTH)
    if not len(busy):
        return row, j
    tables = _shadow_tables(world, c, batch[busy])  # (senses, busy, levels, bins)
    slot = np.full(len(batch), -1, dtype=np.intp)
    slot[busy] = np.arange(len(busy))
    mine = np.flatnonzero(slot[row] >= 0)
    lo = np.floor((phi[mine] - beta[mine] - 1e-9) / _SHADOW_BIN).astype(np.intp)
    hi = np.floor((phi[mine] + beta[mine] + 1e-9) / _SHADOW_BIN).astype(np.intp)
    reach = np.max([_range_max(t, slot[row[mine]], lo, hi) for t in tables], axis=0)
    keep = np.ones(len(row), dtype=bool)
    keep[mine] = gap[mine] < reach
    return row[keep], j[keep]


def _shadow_tables(world: World, circles: np.ndarray, which: np.ndarray) -> list[np.ndarray]:
    """Range-maximum tables of the bound per bin of directions of each circle ``which`` of
    ``circles``, one per sense: arrays ``(which, levels, bins)`` (:func:`shadowed`)."""
    w = world
    c, rho = circles[which, :2], circles[which, 2]
    bins = np.full((2, len(which), _SHADOW_BINS), np.inf)
    if w.n_obstacles:
        reach = (rho + _SHADOW_CELLS * w.index.grid.h)[:, None]
        query, ids = w.index.grid.pairs_in_boxes(c - reach, c + reach)
        kind = w.index.kind_of(ids)
        disc = np.empty((len(ids), 3))
        x = kind == CIRCLE
        disc[x] = w.circles[ids[x]]
        disc[x, 2] += w.threshold
        x = kind == BOX
        box = w.boxes[ids[x] - w.index.n_circles]
        disc[x, :2] = 0.5 * (box[:, :2] + box[:, 2:])
        disc[x, 2] = 0.5 * np.minimum(box[:, 2] - box[:, 0], box[:, 3] - box[:, 1])
        disc[x, 2] += w.threshold
        # Polygons (their edges and interiors, whose rows above stay unset) cast no shadow
        # here.
        use = kind <= BOX
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
