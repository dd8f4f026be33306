"""The tangent graph of one round of the exact optimum: its circles and their free tangents.

Whether a tangent is free does not depend on the node that leaves along it, so each circle's
free tangents are found once, for a batch of circles at a time (those the search will likely
expand next), through filters that each drop only what no path within the bound can use,
cheapest first: on a map's cells alone, circles out of reach of straight runs from the first
one's centre (:mod:`.sight`); circle pairs beyond the bound or whose step counts to the goal
differ by more than a free segment between them allows; directions outside the cones; pairs in
the shadow of the discs near the first circle (:mod:`.shadows`); tangents beyond the bound; the
raster's sound rejection; then the exact tests (obstacles near the circle first, then the
world's). Lengths are in the problem's unit.
"""

from __future__ import annotations

import math

import numpy as np

from ...model.spatial import Grid
from ...model.world import World
from ..free_grid import FreeGrid
from .circles import NodeCircles
from .shadows import shadowed
from .sight import Reach
from .tangents import ANGLE_TOL, TWO_PI, Tangents, cone_pos, tangents_from

__all__ = ["TangentGraph"]

#: Worlds with at most this many obstacles skip the near-obstacle pass (the world's own test,
#: without an index, is as cheap).
_NEAR_ALL = 24
#: Most (tangent, obstacle) pairs of the near-obstacle pass.
_NEAR_PAIRS = 2_000_000
#: Circles whose tangents one vectorised pass finds: at first, and at least, :data:`_BATCH`;
#: then as many as make about :data:`_BATCH_PAIRS` candidate pairs at the rate seen so far, up
#: to :data:`_MAX_BATCH`. A pass has a fixed cost (a few milliseconds of numpy calls): a maze's
#: corners have 15 candidates each, where rooms, cities and warehouses have 40 to 700, and
#: passes of 32 made two thirds of a 1024 x 1024 maze's search (docs/optimum-scaling.md).
_BATCH = 32
_BATCH_PAIRS = 8192
_MAX_BATCH = 512
#: The raster's rejection is run when at least this share of its cells is core.
_RASTER_WORTH = 0.02


class TangentGraph:
    """The circles a path within one bound can pass, and their free tangents, found as the
    search asks for them (package docstring, steps 2 and 4).

    Parameters
    ----------
    world : World
        The obstacles (robot radius at least twice the touch tolerance).
    grid : FreeGrid
        The conservative raster: lower bounds, step counts, sound rejections.
    nodes : NodeCircles
        Every circle a shortest path can wrap, start and goal first.
    goal_tol : float
        Radius of the goal disc (0: the goal point).
    bound : float
        No path longer than this is looked for (``inf``: none).
    """

    def __init__(self, world: World, grid: FreeGrid, nodes: NodeCircles, goal_tol: float,
                 bound: float) -> None:  # fmt: skip
        self.world = world
        self.grid = grid
        self.goal_tol = goal_tol
        self.bound = _loosen(bound, world.tol)
        #: Costs closer than this are equal (round-off), problem units.
        self.eps = 1e-12 * max(1.0, bound if math.isfinite(bound) else 1.0)
        c = nodes.circles
        self.start, self.goal = c[0, :2], c[1, :2]
        # Only circles on which a path within the bound can pass: the geodesic ellipse.
        lb_s = grid.circle_lower_bound(0, c)
        lb_g = grid.circle_lower_bound(1, c)
        through = lb_s + lb_g  # inf: the circle cannot be reached at all
        keep = np.flatnonzero(((through <= self.bound) & np.isfinite(through))
                              | (np.arange(len(c)) < 2))  # fmt: skip
        self.circles = c[keep]
        self.lo, self.width, self.sure = nodes.lo[keep], nodes.width[keep], nodes.sure[keep]
        self.lb_s, self.lb_g = lb_s[keep], lb_g[keep]
        self.steps = grid.step_ranges(self.circles)
        self._sieve = _Sieve(self.circles, self.lb_g, self.steps, grid.H)
        self._cache: dict[int, Tangents] = {}
        self._batch = _BATCH
        self._seen = np.zeros(2, dtype=np.int64)  # circles prepared, their candidate pairs
        self._cached = np.zeros(len(self.circles), dtype=bool)
        self._cached[1] = True  # the goal: never expanded
        self._cells_only = (grid.band_ok(world.threshold) and not len(world.circles)
                            and not world.polygons)  # fmt: skip
        # On a map's cells alone, how far straight runs go from each circle's centre, and the
        # centres by place (made on the first batch: _local_rows).
        self._reach: Reach | None = None
        self._runs: np.ndarray | None = None
        self._centres: Grid | None = None

    def free_tangents(self, i: int, g: float, f: float) -> Tangents:
        """The tangents from circle ``i`` that some path within the bound could use and that are
        free (segment and end points in bounds), computed once per circle.

        Whether a tangent segment is free does not depend on the node it leaves from, so each
        circle's are found once, and together with those of the circles the search will likely
        expand next (a batch of :data:`_BATCH` or more in one vectorised pass, which costs
        little more than a pass over one): those whose lower bound from the start is nearest to
        ``g`` and whose lower bound through them is below or near ``f``.
        """
        cached = self._cache.get(i)
        if cached is not None:
            return cached
        todo = np.flatnonzero(~self._cached)
        todo = todo[todo != i]
        if len(todo) >= self._batch:
            key = np.abs(self.lb_s[todo] - g) + np.maximum(
                self.lb_s[todo] + self.lb_g[todo] - f, 0.0)  # fmt: skip
            todo = todo[np.argpartition(key, self._batch - 2)[: self._batch - 1]]
        self._prepare(np.concatenate([[i], todo]).astype(np.intp))
        return self._cache[i]

    def _prepare(self, batch: np.ndarray) -> None:
        """Fill the cache of each circle of ``batch`` with its usable free tangents.

        The filters, cheapest first, each exact or dropping only what no path within the bound
        can use: circle pairs too far apart for the bound; tangents leaving or reaching a vertex
        outside its cone of free directions; tangents no path within the bound can use (lower
        bounds from the start to the tangent and from its end to the goal); tangents with a
        sample in a core cell of the raster; then the exact test, first against the obstacles
        near the circle they leave (where most blocked tangents are blocked), then the world's
        test of the whole segment.
        """
        row, j = self._candidate_pairs(batch)
        self._seen += (len(batch), len(row))
        rate = self._seen[1] / self._seen[0]  # candidate pairs per circle
        self._batch = int(np.clip(_BATCH_PAIRS / max(rate, 1.0), _BATCH, _MAX_BATCH))
        row, j = self._directions_ok(batch, row, j)
        row, j = shadowed(self.world, self.circles, batch, row, j)
        cand = self._usable(tangents_from(self.circles, batch[row], j))
        cand = self._free(cand)
        cand.node = np.full(len(cand.j), -1, dtype=np.intp)
        order = np.argsort(cand.i, kind="stable")
        cand = cand.take(order)
        cuts = np.searchsorted(cand.i, batch, side="left"), np.searchsorted(cand.i, batch, "right")
        for k, circle in enumerate(batch.tolist()):
            self._cache[circle] = cand.take(slice(int(cuts[0][k]), int(cuts[1][k])))
        self._cached[batch] = True

    def _candidate_pairs(self, batch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The pairs ``(batch[row], j)`` whose tangents a path within the bound may use, by the
        distances between the circles and their step counts to the goal; on a map's cells
        alone, first by where straight runs from the circle's centre can go (:mod:`.sight`:
        the centres within reach, not the whole ellipse)."""
        c = self.circles
        local = self._local_rows(batch)
        row, j = np.empty(0, dtype=np.intp), np.empty(0, dtype=np.intp)
        wide = batch[~local]
        if len(wide):
            row, j = self._sieve.pairs(c[wide], self.bound - self.lb_s[wide], self.steps[wide, 2])
            row = np.flatnonzero(~local)[row]
        if local.any():
            near_row, near_j = self._within_reach(batch, np.flatnonzero(local))
            row, j = np.concatenate([row, near_row]), np.concatenate([j, near_j])
        keep = (j != 0) & (j != batch[row])
        row, j = row[keep], j[keep]
        # Then the exact distances, and of the pairs within the bound every step count.
        i = batch[row]
        d = c[j, :2] - c[i, :2]
        spread = c[i, 2] + c[j, 2]
        gap = np.hypot(d[:, 0], d[:, 1]) - spread
        near = np.flatnonzero(self.lb_s[i] + np.maximum(gap, 0.0) + self.lb_g[j] <= self.bound)
        i, j, d, spread = i[near], j[near], d[near], spread[near]
        ok = self.grid.visible_pairs(self.steps[i], self.steps[j], np.abs(d[:, 0]) + spread,
                                     np.abs(d[:, 1]) + spread)  # fmt: skip
        return row[near[ok]], j[ok]

    def _local_rows(self, batch: np.ndarray) -> np.ndarray:
        """Which circles of ``batch`` have a bounded reach (:mod:`.sight`): on a map's cells
        alone, those whose straight runs end within :data:`.sight.MAX_SWEEP` cells every way."""
        if not self._cells_only:
            return np.zeros(len(batch), dtype=bool)
        if self._runs is None:
            g = self.grid
            self._reach = Reach(~g.blocked, self.world.tol / g.h)
            c = self.circles
            self._runs = self._reach.runs((c[:, 0] - g.x0) / g.h, (c[:, 1] - g.y0) / g.h)
            self._centres = Grid(c[:, :2].min(axis=0), c[:, :2].max(axis=0),
                                 np.hstack([c[:, :2], c[:, :2]]), cell=8.0 * g.h)  # fmt: skip
        return np.isfinite(self._runs[batch]).all(axis=1)

    def _within_reach(self, batch: np.ndarray, rows: np.ndarray):
        """``(row, j)``: the circles ``j`` whose centres the segments from the centres of
        ``batch[rows]`` may reach (:meth:`.sight.Reach.may_see`), and the goal for each (a
        tangent into a goal disc is cut short: the segment to its centre need not be free)."""
        g, c = self.grid, self.circles
        i = batch[rows]
        runs = self._runs[i]
        # How far a segment can go each way: a mostly horizontal one rises no more than it runs,
        # so leftwards (say) the longest of the left run and the up and down runs.
        far = np.column_stack([np.maximum(runs[:, 1], runs[:, 2:].max(axis=1)),
                               np.maximum(runs[:, 3], runs[:, :2].max(axis=1)),
                               np.maximum(runs[:, 0], runs[:, 2:].max(axis=1)),
                               np.maximum(runs[:, 2], runs[:, :2].max(axis=1))]) * g.h  # fmt: skip
        q, j = self._centres.pairs_in_boxes(c[i, :2] - far[:, :2], c[i, :2] + far[:, 2:])
        d = (c[j, :2] - c[i[q], :2]) / g.h
        seen = self._reach.may_see(runs[q], d[:, 0], d[:, 1]) & (j != 1)
        q, j = q[seen], j[seen]
        return (np.concatenate([rows[q], rows]),
                np.concatenate([j, np.ones(len(rows), dtype=j.dtype)]))  # fmt: skip

    def _usable(self, cand: Tangents) -> Tangents:
        """The tangents within the cones of free directions at both ends, in the bounds, that
        a path within the bound may use; with their ends, lengths and bounds to the goal."""
        i = cand.i
        cand.pos_i = cone_pos(cand.angle_i, self.lo[i])
        wi, wj = self.width[i], self.width[cand.j]
        pos_j = cone_pos(cand.angle_j, self.lo[cand.j])
        cone = ((wi >= TWO_PI) | (cand.pos_i <= wi + ANGLE_TOL)) & (
            (wj >= TWO_PI) | (pos_j <= wj + ANGLE_TOL))  # fmt: skip
        cand = cand.take(np.flatnonzero(cone))
        cand.q = self._ends(cand, cand.j == 1)
        cand.seg = np.hypot(*(cand.q - cand.p).T)
        cand.h = self.grid.lower_bound(1, cand.q)
        lower = self.grid.lower_bound(0, cand.p) + cand.seg + cand.h
        w = self.world
        ok = lower <= self.bound
        ok &= w.points_in_bounds(cand.p) & w.points_in_bounds(cand.q)
        return cand.take(np.flatnonzero(ok))

    def _free(self, cand: Tangents) -> Tangents:
        """The free tangents among ``cand``: in a world of the lattice's cells alone, the exact
        test straight from the cells (its sure "near" pass, then its windows, each piece by
        piece: :func:`_in_stages`); elsewhere the raster's sound rejection, then the exact tests
        against the obstacles near the circle and the world's."""
        w = self.world
        g = self.grid
        if len(cand.j) and self._cells_only:
            # A world of the lattice's cells alone: the exact test straight from the cells, its
            # cheap first pass piece by piece (sharper than the raster's rejection), then the
            # windows round the samples of those it left.
            near = _in_stages(lambda a, b: g.segments_near_blocked(a, b, w.threshold, False),
                              cand.p, cand.q, g.h)  # fmt: skip
            cand = cand.take(np.flatnonzero(~near))
            near = _in_stages(lambda a, b: g.segments_near_blocked(a, b, w.threshold,
                                                                   sure_pass=False),
                              cand.p, cand.q, g.h)  # fmt: skip
            return cand.take(np.flatnonzero(~near))
        if len(cand.j) and g.core_share >= _RASTER_WORTH:
            cand = cand.take(np.flatnonzero(~_in_stages(g.blocked_segments, cand.p, cand.q, g.h)))
        if len(cand.j):
            cand = cand.take(np.flatnonzero(~self.blocked_near(cand)))
        if len(cand.j):
            cand = cand.take(np.flatnonzero(w.segments_free(cand.p, cand.q)))
        return cand

    def _directions_ok(self, batch: np.ndarray, row: np.ndarray, j: np.ndarray):
        """The pairs ``(batch[row], j)`` that can have a tangent leaving the first circle and
        reaching the second within their cones of free directions.

        A path wrapping a circle at the outward normal ``n`` travels along ``n +- pi / 2``, so a
        tangent leaving a vertex whose cone is ``[lo, lo + w]`` heads into one of the two arcs of
        directions ``[lo + pi / 2, lo + w + pi / 2]`` and ``[lo - pi / 2, lo + w - pi / 2]``,
        and it arrives at the other circle in the same way. The tangent's direction differs from
        that of the line of centres by at most ``asin((rho_i + rho_j) / d)``.
        """
        i = batch[row]
        c = self.circles
        d = c[j, :2] - c[i, :2]
        dist = np.hypot(d[:, 0], d[:, 1])
        slack = np.arcsin(np.clip((c[i, 2] + c[j, 2]) / np.maximum(dist, 1e-300), 0.0, 1.0))
        slack += 1e-7
        phi = np.arctan2(d[:, 1], d[:, 0])
        ok = np.ones(len(i), dtype=bool)
        for k in (i, j):
            w = self.width[k]
            cone = w < TWO_PI
            if not cone.any():
                continue
            inside = np.zeros(len(i), dtype=bool)
            for turn in (0.5 * math.pi, -0.5 * math.pi):
                off = np.mod(phi - (self.lo[k] + turn) + slack, TWO_PI)
                inside |= off <= w + 2.0 * slack
            ok &= ~cone | inside
        return row[ok], j[ok]

    def blocked_near(self, cand: Tangents) -> np.ndarray:
        """Tangents that come too close to an obstacle near the circle they leave (booleans; the
        world's exact distance formulas, against the obstacles the index holds within a few
        index cells of that circle)."""
        w = self.world
        blocked = np.zeros(len(cand.j), dtype=bool)
        if w.n_obstacles <= _NEAR_ALL:
            return blocked  # few obstacles: the world's own test is as cheap
        circles, inverse = np.unique(cand.i, return_inverse=True)
        c, rho = self.circles[circles, :2], self.circles[circles, 2]
        reach = (rho + 2.0 * w.index.grid.h)[:, None]
        query, ids = w.index.grid.pairs_in_boxes(c - reach, c + reach)
        count = np.bincount(query, minlength=len(circles))
        first = np.concatenate([[0], np.cumsum(count)])[:-1]
        n = count[inverse]
        if not n.sum() or n.sum() > _NEAR_PAIRS:
            return blocked
        seg = np.repeat(np.arange(len(cand.j)), n)
        k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
        obs = ids[np.repeat(first[inverse], n) + k]
        d = w.index.pair_distance(seg, obs, cand.p, cand.q)
        blocked[seg[d < w.threshold]] = True
        return blocked

    def _ends(self, cand, to_goal: np.ndarray) -> np.ndarray:
        """Where each tangent ends: its tangent point, or inside a goal tolerance, the point where
        it enters the goal disc."""
        end = cand.q.copy()
        if self.goal_tol > 0 and to_goal.any():
            d = cand.q[to_goal] - cand.p[to_goal]
            n = np.hypot(*d.T)
            frac = np.clip(1.0 - self.goal_tol / np.where(n > 0, n, 1.0), 0.0, 1.0)
            end[to_goal] = cand.p[to_goal] + frac[:, None] * d
        return end


class _Sieve:
    """The first sieve of :meth:`TangentGraph._candidate_pairs`, over a batch of circles and
    every other, with cheap over-estimates of distances (``|dx| + |dy|``) and under-estimates
    (``max(|dx|, |dy|)``): the bound through the pair, and the 8-connected step counts to the
    goal (:meth:`~..free_grid.FreeGrid.step_ranges`). The circles are held in the order of
    their bound to the goal, with the terms of each test that depend on one circle alone
    folded in advance, so a batch meets only a prefix of them (those whose bound leaves room
    for a path through a circle of the batch), read in place: it runs once for every 32
    circles expanded, over every circle of the round's ellipse."""

    def __init__(self, circles: np.ndarray, lb_g: np.ndarray, steps: np.ndarray,
                 H: float) -> None:  # fmt: skip
        self.order = np.argsort(lb_g, kind="stable")
        c = circles[self.order]
        self.lb_g = lb_g[self.order]
        self.x, self.y, rho = (np.ascontiguousarray(c[:, k]) for k in range(3))
        self.rho_max = float(rho.max()) if len(rho) else 0.0
        self.inv_h = 1.0 / H
        #: ``max(|dx|, |dy|) + lb_g - rho <= bound - lb_s(i) + rho_i``: the bound through.
        self.reach = self.lb_g - rho
        # |steps_j - steps_i| <= (|dx| + |dy| + 2 (rho_i + rho_j)) / H + 2, one side each.
        s = steps[self.order, 2]
        self.above = s[:, 0] - 2.0 * rho * self.inv_h
        self.below = -s[:, 1] - 2.0 * rho * self.inv_h

    def pairs(self, ci: np.ndarray, room: np.ndarray, steps: np.ndarray):
        """``(row, j)``: the pairs of the batch's circle ``ci[row]`` (``(x, y, rho)`` rows) and
        circle ``j`` (the graph's numbering) that pass; ``room`` is each batch circle's bound
        less its bound from the start, ``steps`` its 8-connected step range to the goal, ``(len(ci),
        2)``."""
        rho_i = ci[:, 2:3]
        top = float((room + ci[:, 2]).max()) + self.rho_max
        m = int(np.searchsorted(self.lb_g, top, side="right"))
        dx = np.subtract.outer(ci[:, 0], self.x[:m])
        np.abs(dx, out=dx)
        dy = np.subtract.outer(ci[:, 1], self.y[:m])
        np.abs(dy, out=dy)
        t = np.maximum(dx, dy)
        t += self.reach[:m]
        ok = t <= room[:, None] + rho_i
        dx += dy
        dx *= self.inv_h  # now (|dx| + |dy|) / H
        slack = 2.0 * rho_i * self.inv_h + 2.0
        with np.errstate(invalid="ignore"):  # inf - inf: a circle no free path reaches: drop
            np.subtract(self.above[:m], dx, out=t)
            ok &= t <= steps[:, 1:2] + slack
            np.subtract(self.below[:m], dx, out=t)
            ok &= t <= slack - steps[:, 0:1]
        row, k = np.nonzero(ok)
        return row, self.order[k]


#: Where the segment tests of :func:`_in_stages` cut the tangents, in cells from their start.
_STAGES = (16.0, 64.0, 256.0)


def _in_stages(test, p: np.ndarray, q: np.ndarray, h: float) -> np.ndarray:
    """Which segments ``p``-``q`` ``test`` finds blocked, tested piece by piece from ``p``: the
    first 16 cells of every segment, then the next pieces (to 64, 256 cells, the rest) of those
    not yet blocked. A segment is blocked where one of its pieces is, so the answer is the
    test's (a piece's ends are off the segment by round-off, far below the touch tolerance);
    a tangent leaves its circle at ``p``, and of those a city's search rejected, two thirds
    came too near within 16 cells of it, where testing whole tangents of 200 cells on average
    cost most of the search."""
    d = q - p
    length = np.hypot(d[:, 0], d[:, 1]) / h
    out = np.zeros(len(p), dtype=bool)
    t0 = np.zeros(len(p))
    for end in (*_STAGES, math.inf):
        t1 = np.minimum(end / np.maximum(length, 1e-300), 1.0)
        live = np.flatnonzero(~out & (t0 < 1.0))
        if not len(live):
            break
        a = p[live] + t0[live, None] * d[live]
        b = np.where((t1[live] >= 1.0)[:, None], q[live], p[live] + t1[live, None] * d[live])
        out[live] = test(np.where((t0[live] <= 0.0)[:, None], p[live], a), b)
        t0 = t1
    return out


def _loosen(bound: float, tol: float) -> float:
    """A bound with room for round-off (lengths add up over many pieces)."""
    return bound * (1.0 + 1e-9) + 10.0 * tol if math.isfinite(bound) else math.inf
