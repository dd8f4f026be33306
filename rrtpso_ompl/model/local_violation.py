"""A culled violation model: the safety-zone intrusion of swarms of paths confined to boxes.

The PSO confines each waypoint of a path to a box per round, so segment ``s`` of every particle
lies in a box ``seg_lo[s]..seg_hi[s]``; only obstacles within the robot radius of that box can
touch it. :class:`LocalViolation` asks the world's index once for those candidates (padded to a
dense ``(segments, candidates)`` table with an obstacle that is never near) and then evaluates
``sum_k max(0, R - d_k)`` (the world's
:meth:`~rrtpso_ompl.model.world.World.segment_violation`) for whole swarms by one broadcast per
call. :func:`local_model` builds it only when the build ends before a deadline, at the rate
measured on this machine's earlier builds (:class:`BuildRate`). Lengths are in the problem's
unit, times in seconds.
"""

from __future__ import annotations

import time

import numpy as np

from .geometry import point_segment_distance, segment_box_distance, segment_segment_distance
from .obstacle_index import BOX, CIRCLE, EDGE, INTERIOR, ObstacleIndex

__all__ = ["BuildRate", "LocalViolation", "gather", "local_model"]


class BuildRate:
    """Seconds a :class:`LocalViolation` takes per registration of the index in its boxes: a
    prior on the slow side (1-1.6 µs measured on the reference machine for large builds), then
    what this process measures on builds large enough to time."""

    def __init__(self, prior: float = 2e-6, timed: int = 20_000) -> None:
        self.seconds_per_pair = prior
        self.timed = timed

    def measured(self, pairs: int, seconds: float) -> None:
        """Learn from a build of ``pairs`` registrations that took ``seconds`` (builds under
        ``timed`` pairs are too short to time)."""
        if pairs >= self.timed:
            self.seconds_per_pair = 0.5 * (self.seconds_per_pair + seconds / pairs)


_LOCAL_BUILD = BuildRate()


class LocalViolation:
    """:meth:`World.segment_violation <rrtpso_ompl.model.world.World.segment_violation>` for a
    fixed number of segments confined to boxes.

    Candidate obstacles per segment come from the index once (padded with an obstacle that is never
    near, so the per-call work is one dense broadcast over ``(paths, segments, candidates)``).
    """

    def __init__(self, index: ObstacleIndex, seg_lo: np.ndarray, seg_hi: np.ndarray) -> None:
        self.index = index
        n_seg = len(seg_lo)
        far = 1e6 * max(1.0, *(abs(v) for b in index.bounds for v in b))
        if index.n_obstacles:
            seg, ids = index.grid.pairs_in_boxes(seg_lo, seg_hi)
        else:
            seg, ids = np.empty(0, dtype=np.intp), np.empty(0, dtype=np.intp)
        kind = index.kind_of(ids)
        c = kind == CIRCLE
        self.circles = gather(seg[c], index.circles[ids[c]], n_seg, np.array([far, far, 0.0]))
        x = kind == BOX
        self.boxes = gather(seg[x], index.boxes[ids[x] - index.n_circles], n_seg,
                             np.array([far, far, far, far]))  # fmt: skip
        # Polygons: the edges near each segment's box, and the interiors that could hold its
        # first point (per segment: a segment near a large polygon has many edges, the rest few).
        p = kind >= EDGE
        self.polygon_segments = np.unique(seg[p]).tolist()
        order = np.argsort(seg[p], kind="stable")
        p_seg, p_ids, p_kind = seg[p][order], ids[p][order], kind[p][order]
        cut = np.searchsorted(p_seg, np.arange(n_seg + 1))
        self._edges: list[np.ndarray] = []
        self._edge_lo: list[np.ndarray] = []  # their bounding boxes
        self._edge_hi: list[np.ndarray] = []
        self._edge_mid: list[np.ndarray] = []  # their mid-points and half lengths
        self._edge_half: list[np.ndarray] = []
        self._interiors: list[np.ndarray] = []
        for s in range(n_seg):
            mine, kinds = p_ids[cut[s] : cut[s + 1]], p_kind[cut[s] : cut[s + 1]]
            edges = index.edges[mine[kinds == EDGE] - index.first_edge]
            self._edges.append(edges)
            self._edge_lo.append(np.minimum(edges[:, :2], edges[:, 2:]))
            self._edge_hi.append(np.maximum(edges[:, :2], edges[:, 2:]))
            self._edge_mid.append(0.5 * (edges[:, :2] + edges[:, 2:]))
            self._edge_half.append(0.5 * np.hypot(*(edges[:, 2:] - edges[:, :2]).T))
            self._interiors.append(mine[kinds == INTERIOR] - index.first_interior)

    def violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Same as :meth:`World.segment_violation` for ``a, b`` of shape ``(P, S, 2)``."""
        index = self.index
        r_need = index.threshold
        v = np.zeros(a.shape[:2])
        A = a[:, :, None, :]
        B = b[:, :, None, :]
        if self.circles.shape[1]:
            c = self.circles[None, :, :, :2]
            d = point_segment_distance(c, A, B) - self.circles[None, :, :, 2]
            v += np.maximum(0.0, r_need - np.maximum(d, 0.0)).sum(axis=2)
        if self.boxes.shape[1]:
            shape = (a.shape[0], a.shape[1], self.boxes.shape[1])
            # Once per (path, segment):
            GA, GB = index.in_box_frame(A), index.in_box_frame(B)
            d = segment_box_distance(
                np.broadcast_to(GA, (*shape, 2)).reshape(-1, 2),
                np.broadcast_to(GB, (*shape, 2)).reshape(-1, 2),
                np.broadcast_to(self.boxes[None], (*shape, 4)).reshape(-1, 4),
            ).reshape(shape)
            v += np.maximum(0.0, r_need - d).sum(axis=2)
        n = a.shape[0]
        for s in self.polygon_segments:
            best = np.full(n, np.inf)
            edges = self._edges[s]
            if len(edges):
                # Only an edge whose box comes within the threshold of a particle's segment's box
                # can be nearer than the threshold: a cheap test before the exact distances (a
                # segment's box may hold thousands of edges of a detailed polygon).
                lo = np.minimum(a[:, s], b[:, s]) - r_need
                hi = np.maximum(a[:, s], b[:, s]) + r_need
                e_lo, e_hi = self._edge_lo[s], self._edge_hi[s]
                near = (e_lo[None, :, 0] <= hi[:, None, 0]) & (e_hi[None, :, 0] >= lo[:, None, 0])
                near &= (e_lo[None, :, 1] <= hi[:, None, 1]) & (e_hi[None, :, 1] >= lo[:, None, 1])
                p_idx, e_idx = np.nonzero(near)
                # Then an edge whose mid-point lies farther than the threshold plus half the
                # edge from the segment cannot come within the threshold either.
                d_mid = point_segment_distance(self._edge_mid[s][e_idx], a[p_idx, s], b[p_idx, s])
                keep = d_mid <= r_need + self._edge_half[s][e_idx]
                p_idx, e_idx = p_idx[keep], e_idx[keep]
                d = segment_segment_distance(a[p_idx, s], b[p_idx, s], edges[e_idx])
                np.minimum.at(best, p_idx, d)
            for poly in self._interiors[s].tolist():
                inside = index.interior_distance(a[:, s], np.full(n, poly))
                best = np.minimum(best, inside)
            v[:, s] += np.maximum(0.0, r_need - best)
        return v


def gather(seg: np.ndarray, rows: np.ndarray, n_seg: int, pad: np.ndarray) -> np.ndarray:
    """(S, K, m) array of the rows of each segment (``seg[k]`` owns ``rows[k]``), padded."""
    counts = np.bincount(seg, minlength=n_seg) if len(seg) else np.zeros(n_seg, dtype=np.intp)
    k = max(1, int(counts.max()) if n_seg else 1)
    out = np.broadcast_to(pad, (n_seg, k, len(pad))).copy()
    if len(seg):
        order = np.argsort(seg, kind="stable")
        s = seg[order]
        slot = np.arange(len(s)) - np.repeat(np.cumsum(counts) - counts, counts)
        out[s, slot] = rows[order]
    return out


def local_model(index: ObstacleIndex, seg_lo: np.ndarray, seg_hi: np.ndarray,
                deadline: float | None = None) -> LocalViolation | None:  # fmt: skip
    """:meth:`World.local_model <rrtpso_ompl.model.world.World.local_model>` over the world's
    ``index``: the model, or None
    when its build (the index's registrations in the boxes, at :data:`_LOCAL_BUILD`'s rate) would
    end after ``deadline`` (``time.perf_counter()`` seconds)."""
    seg_lo, seg_hi = np.asarray(seg_lo, float), np.asarray(seg_hi, float)
    grid = index.grid
    pairs = int(grid.registrations_in_boxes(seg_lo, seg_hi).sum()) if len(seg_lo) else 0
    t = time.perf_counter()
    if deadline is not None and t + pairs * _LOCAL_BUILD.seconds_per_pair > deadline:
        return None
    model = LocalViolation(index, seg_lo, seg_hi)
    _LOCAL_BUILD.measured(pairs, time.perf_counter() - t)
    return model
