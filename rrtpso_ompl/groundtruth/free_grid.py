r"""A conservative raster of the configuration space: the exact optimum's lower bounds and its
cheap, sound rejection of segments.

The plane is cut into square cells of side ``h``. A cell is *possibly free* when some point of the
closed cell may be a free configuration, and *core* otherwise: every point of a core cell is
closer than the clearance threshold to an obstacle. The test only ever errs towards "possibly
free", which is what makes both uses below exact:

* **Rejection.** A segment with a point in a core cell is not free, so a segment whose samples
  meet a core cell is rejected without the exact test (:meth:`FreeGrid.blocked_segments`); the
  survivors still get the exact one.
* **Geodesic lower bounds.** A free path of length ``L`` from a point ``x`` to the goal passes
  through closed cells that each hold one of its (free) points, so through possibly-free cells.
  Points taken along it every ``H`` (the side of a cell of the search grid) lie in cells that are
  equal or 8-neighbours, so an 8-connected breadth-first search over the possibly-free cells
  from the goal's cell reaches ``x``'s cell in ``m8 <= ceil(L / H)`` steps: ``L > (m8 - 1) H``.
  A path crosses at most ``Vx / H + 1`` vertical and ``Vy / H + 1`` horizontal grid lines, where
  ``Vx + Vy <= sqrt(2) L`` are its total variations in x and y; each crossing is one step of a
  4-connected chain (a crossing through a corner point passes through one of the two other cells,
  which holds that free point too), so ``L >= (m4 - 2) H / sqrt(2)``. The bound is the largest of
  these and of the straight distance (:meth:`FreeGrid.lower_bound`). It is not consistent (it can
  drop by up to a cell over a short step), so the search that uses it as its heuristic re-opens
  nodes (:mod:`.optimum`).

Which cells are core: for a map (its cells are the raster's), a blocked cell and every free cell
whose centre is so far inside the grown obstacles that no point of it can be free, from the
Euclidean distance transform of the blocked cells (``scipy.ndimage``); for circles, polygons and
boxes, from the world's exact point clearance at the cell centres (clearance is 1-Lipschitz, so
a cell whose centre has clearance ``c`` has none above ``c + h / sqrt(2)``).

scipy is imported only where it is needed: for a map (the distance transform) and for a search
grid of more than :data:`NUMPY_SEARCH_CELLS` cells (scipy's unweighted shortest paths). A
smaller one, every raster of a few dozen obstacles without a map, is searched level by level in
numpy: the same step counts (a breadth-first search's are unique), without the 0.2-0.4 s
importing scipy costs, several times what ``rrtpso optimum`` of such a problem computes
(docs/startup.md).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ..model.geometry import segment_box_distance
from ..model.world import World
from .gates import Gates

__all__ = ["FreeGrid", "Stopped", "box_lattice"]

_SQRT2 = math.sqrt(2.0)
#: Most cells of the raster over a world without a map, along the longer side of the bounds (16
#: times the square root of the number of obstacles, at least 32).
GENERIC_CELLS = 192
#: Cells of a search grid that keeps the raster's set-up cheap (0.3 s on the machine of
#: docs/optimum-scaling.md): a finer raster is searched in blocks of k x k cells, a block possibly
#: free when any of its cells is, where the blocks keep the map's shape, their area at most
#: :data:`BLOCK_GROWTH` times the possibly-free cells' (the warehouse of problems/maps: 1.04 with
#: blocks of 3 x 3; rooms 1.06 with 2 x 2).
FAST_SEARCH_CELLS = 300_000
#: Where blocks would not keep the shape (a maze's one-cell corridors merged with their walls,
#: 2.0; a city's streets for a wide robot, 1.4), the raster is searched cell by cell, up to
#: :data:`MAX_SEARCH_FREE` possibly-free cells and :data:`MAX_SEARCH_CELLS` cells (then in the
#: smallest blocks within those): on a 1024 x 1024 maze, blocks of 2 x 2 made the bound the
#: straight line, and a disc's search 36 s rather than 16.
BLOCK_GROWTH = 1.1
MAX_SEARCH_FREE = 1_200_000
MAX_SEARCH_CELLS = 4_200_000
#: Most possibly-free cells of a raster searched cell by cell on request (the optimum's search,
#: when the point's path shows that blocks lost the map's walls: docs/benchmarking.md): a map of
#: 2048 x 2048 cells, whatever its share of free ones (0.45 GB for the search at its peak).
MAX_REFINED_FREE = 4_200_000
#: Most cells of a search grid searched in numpy, level by level (:func:`_numpy_steps`), rather
#: than with scipy: a level costs a few numpy calls, and a search has at most one level per cell,
#: so even a winding one stays below the cost of importing scipy (a 100 x 100 serpentine, 5,000
#: levels, takes 0.03 s per search on the machine of docs/startup.md; importing scipy 0.35 s).
NUMPY_SEARCH_CELLS = 10_000
#: Most cells of a raster on the lattice of a world's boxes (else the generic raster is used).
MAX_LATTICE_CELLS = 30_000_000
#: The gates' bounds are scaled by this, below 1 by far more than their round-off (a bound a
#: hair too high could cost the optimum that hair).
_ROUND = 1.0 - 1e-12
#: Most samples one call of :meth:`FreeGrid.blocked_segments` takes at once (memory bound).
_SAMPLE_CHUNK = 2_000_000


class Stopped(Exception):
    """Raised between the stages of building a :class:`FreeGrid` when its ``terminate`` callback
    returns True."""


def _poll(terminate) -> None:
    if terminate is not None and terminate():
        raise Stopped


class FreeGrid:
    """Possibly-free cells over the bounds, and the geodesic lower bounds to the start and goal.

    Parameters
    ----------
    origin : (float, float)
        Lower-left corner of cell ``[0, 0]``, problem units.
    h : float
        Side of a cell, problem units.
    free : (ny, nx) ndarray of bool
        Possibly-free cells, row ``j`` at ``y = origin[1] + j h`` (rows from the bottom).
    start, goal : (2,) array_like
        The query (the bounds are measured from them).
    goal_tolerance : float
        Radius of the goal disc; the bound to the goal is to that disc.
    terminate : callable, optional
        Polled between the stages of the breadth-first searches (raises :class:`Stopped`).
    """

    def __init__(self, origin, h: float, free: np.ndarray, start, goal,
                 goal_tolerance: float = 0.0, terminate=None,
                 cell_by_cell: bool = False) -> None:  # fmt: skip
        self.x0, self.y0 = float(origin[0]), float(origin[1])
        self.h = float(h)
        self.free = np.asarray(free, dtype=bool)
        self._core = ~self.free
        #: Share of core cells (the raster's rejection is worth running only with some).
        self.core_share = float(self._core.mean()) if self._core.size else 0.0
        self.ny, self.nx = self.free.shape
        self.start = np.asarray(start, dtype=float)
        self.goal = np.asarray(goal, dtype=float)
        self.goal_tolerance = float(goal_tolerance)
        #: The cells the world's boxes cover, when they lie on this raster's lattice (a map's
        #: blocked cells), else None (set by :meth:`for_world`).
        self.blocked: np.ndarray | None = None
        # The search grid: blocks of k x k cells, a block possibly free when any of its cells is.
        k, coarse, narrow = _search_blocks(self.free, cell_by_cell)
        n_free = int(np.count_nonzero(self.free))
        #: Whether the raster went into blocks for its size alone (more possibly-free cells
        #: than :data:`MAX_SEARCH_FREE`) and could be searched cell by cell on request.
        self.refinable = k > 1 and MAX_SEARCH_FREE < n_free <= MAX_REFINED_FREE
        #: Whether blocks of cells would not keep the raster's shape (corridors a cell or two
        #: wide): then, on a map, the gates between its cells bound a disc's paths too.
        self.narrow = narrow
        #: The gates' bounds to the start and the goal (:mod:`.gates`), or None (set by
        #: :meth:`for_world`).
        self.gates: Gates | None = None
        self.k = k
        self.H = k * self.h
        self.cny, self.cnx = coarse.shape
        self._dist = _bfs_distances(coarse, [self._cell(self.start), self._cell(self.goal)],
                                    terminate)  # fmt: skip

    # ------------------------------------------------------------------------------------------
    @classmethod
    def for_world(cls, world: World, start, goal, goal_tolerance: float = 0.0,
                  terminate=None, cell_by_cell: bool = False) -> FreeGrid:  # fmt: skip
        """The raster of a world: the lattice of its boxes when they have one (a map's cells;
        then :attr:`blocked` holds the cells the boxes cover), else 32 to :data:`GENERIC_CELLS`
        cells per side (more with more obstacles) through the world's exact clearance.

        Circles and polygons on top of a lattice of boxes are left out of the raster: that only
        makes more cells possibly free, which keeps both uses exact. ``terminate`` is polled
        between stages (:class:`Stopped`).
        """
        thr = world.threshold
        lattice = box_lattice(world)
        _poll(terminate)
        if lattice is not None:
            origin, h, blocked = lattice
            free = ~blocked
            if blocked.any():
                from scipy import ndimage

                # Distance (cells) from each free cell's centre to the nearest blocked centre;
                # the blocked square holds the disc of radius h/2 around its centre, and no point
                # of the cell is more than h/sqrt(2) from the centre.
                d = ndimage.distance_transform_edt(free)
                free &= (d - 0.5 + 0.5 * _SQRT2) * h >= thr - 4.0 * world.tol
            _poll(terminate)
            grid = cls(origin, h, free, start, goal, goal_tolerance, terminate, cell_by_cell)
            grid.blocked = blocked
            if grid.narrow and _covers(origin, h, blocked.shape, world.bounds):
                _poll(terminate)
                targets = [
                    ((np.asarray(start, dtype=float) - origin) / h, 0.0),
                    ((np.asarray(goal, dtype=float) - origin) / h, goal_tolerance / h),
                ]
                grid.gates = Gates.where_pinched(blocked, thr / h, targets)  # start, goal
            return grid
        (xmin, ymin), (xmax, ymax) = world.bounds
        # A few cells per obstacle: a handful of obstacles needs no fine raster (its set-up,
        # the exact clearance at every centre, would cost more than the search).
        side = int(np.clip(round(16.0 * math.sqrt(world.n_obstacles + 1)), 32, GENERIC_CELLS))
        h = max(xmax - xmin, ymax - ymin) / side
        nx = max(1, math.ceil((xmax - xmin) / h))
        ny = max(1, math.ceil((ymax - ymin) / h))
        gx, gy = np.meshgrid(xmin + (np.arange(nx) + 0.5) * h, ymin + (np.arange(ny) + 0.5) * h)
        half_diag = 0.5 * _SQRT2 * h
        cap = thr + half_diag + 4.0 * world.tol
        centres = np.column_stack([gx.ravel(), gy.ravel()])
        clear = world.point_clearance(centres, cap=cap).reshape(ny, nx)
        free = clear + half_diag >= thr - 4.0 * world.tol
        _poll(terminate)
        return cls((xmin, ymin), h, free, start, goal, goal_tolerance, terminate, cell_by_cell)

    # ------------------------------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        """False when the goal's cell cannot be reached from the start's through possibly-free
        cells: then no path exists (a proof, since the possibly-free cells hold every free
        configuration)."""
        return bool(np.isfinite(self._dist[0][0][self._cell(self.goal)]))

    def _cell(self, p) -> int:
        """Search-grid cell of one point (clamped: a point on the far border is in the last)."""
        i = min(max(math.floor((p[0] - self.x0) / self.H), 0), self.cnx - 1)
        j = min(max(math.floor((p[1] - self.y0) / self.H), 0), self.cny - 1)
        return j * self.cnx + i

    def _cells(self, p: np.ndarray) -> np.ndarray:
        i = np.clip(np.floor((p[..., 0] - self.x0) / self.H), 0, self.cnx - 1).astype(np.intp)
        j = np.clip(np.floor((p[..., 1] - self.y0) / self.H), 0, self.cny - 1).astype(np.intp)
        return j * self.cnx + i

    def _geodesic(self, which: int, cells: np.ndarray) -> np.ndarray:
        """The grid part of the bound for search-grid cells (``inf`` where unreachable)."""
        m8, m4 = self._dist[which][0][cells], self._dist[which][1][cells]
        return np.maximum(np.maximum((m8 - 1.0) * self.H, (m4 - 2.0) * self.H / _SQRT2), 0.0)

    def lower_bound(self, which: int, points: np.ndarray) -> np.ndarray:
        """Lower bound on the length of every free path from each point to the start
        (``which = 0``) or to the goal disc (``which = 1``); ``inf`` where none can exist.

        Valid for free points; a point that is not free may get any value (a path through it is
        invalid anyway).
        """
        p = np.asarray(points, dtype=float)
        target = self.start if which == 0 else self.goal
        euclid = np.hypot(p[..., 0] - target[0], p[..., 1] - target[1])
        lb = np.maximum(euclid, self._geodesic(which, self._cells(p)))
        if which == 1 and self.goal_tolerance > 0:
            lb = np.maximum(lb - self.goal_tolerance, 0.0)
        if self.gates is not None:
            rel = (p.reshape(-1, 2) - (self.x0, self.y0)) / self.h
            gated = self.gates.bound(which, rel) * self.h * _ROUND
            lb = np.maximum(lb, gated.reshape(lb.shape))
        return lb

    def circle_lower_bound(self, which: int, circles: np.ndarray) -> np.ndarray:
        """Lower bound of :meth:`lower_bound` over every point of each circle ``(cx, cy, rho)``
        (the least over the search-grid cells its bounding box meets; circles wider than four
        cells get the straight distance only)."""
        c = np.asarray(circles, dtype=float).reshape(-1, 3)
        target = self.start if which == 0 else self.goal
        euclid = np.maximum(np.hypot(c[:, 0] - target[0], c[:, 1] - target[1]) - c[:, 2], 0.0)
        small = c[:, 2] <= 4.0 * self.H
        out = euclid.copy()
        if small.any():
            w = math.ceil(float(c[small, 2].max()) / self.H)
            cells = self._cells(c[small, :2])
            near = _window_cells(cells, w, self.cny, self.cnx)
            least = self._geodesic(which, near).min(axis=0)
            if self.gates is not None:
                g = self.gates
                w = math.ceil(float(c[small, 2].max()) / self.h)
                i = np.clip((c[small, 0] - self.x0) // self.h, 0, g.nx - 1).astype(np.intp)
                j = np.clip((c[small, 1] - self.y0) // self.h, 0, g.ny - 1).astype(np.intp)
                near = _window_cells(j * g.nx + i, w, g.ny, g.nx)
                gated = g.cell_bound[which][near].min(axis=0) * self.h * _ROUND
                least = np.maximum(least, gated)
            out[small] = np.maximum(euclid[small], least)
        if which == 1 and self.goal_tolerance > 0:
            out = np.maximum(out - self.goal_tolerance, 0.0)
        return out

    def step_ranges(self, circles: np.ndarray) -> np.ndarray:
        """For each circle, the least and greatest step counts of the reachable search-grid cells
        its bounding box meets: ``(n, 4, 2)``, for the 8- and 4-connected counts from the start
        and from the goal (``[0, inf]``, no information, for circles wider than four cells).

        The points of a free segment lie in possibly-free cells, and points ``H`` apart in equal
        or 8-neighbouring ones, so the 8-connected count changes by at most ``ceil(L / H)`` along
        a free segment of length ``L``, and the 4-connected one by at most the grid lines it
        crosses, ``(|dx| + |dy|) / H + 2``. :meth:`visible_pairs` tests that.
        """
        c = np.asarray(circles, dtype=float).reshape(-1, 3)
        out = np.empty((len(c), 4, 2))
        out[:, :, 0], out[:, :, 1] = 0.0, np.inf
        small = c[:, 2] <= 4.0 * self.H
        if not small.any():
            return out
        w = math.ceil(float(c[small, 2].max()) / self.H)
        near = _window_cells(self._cells(c[small, :2]), w, self.cny, self.cnx)
        for k, grid in enumerate((self._dist[0][0], self._dist[0][1], self._dist[1][0],
                                  self._dist[1][1])):  # fmt: skip
            steps = grid[near]
            out[small, k, 0] = steps.min(axis=0)
            out[small, k, 1] = np.where(np.isfinite(steps), steps, -np.inf).max(axis=0)
        return out

    def visible_pairs(self, ranges_a: np.ndarray, ranges_b: np.ndarray, dx: np.ndarray,
                      dy: np.ndarray) -> np.ndarray:  # fmt: skip
        """Whether a free segment can join a point with step ranges ``ranges_a`` to one with
        ``ranges_b`` (:meth:`step_ranges`, shapes ``(..., 4, 2)``, broadcast) when its extent is
        at most ``|dx|, |dy|`` (booleans; False is a proof that it cannot)."""
        n8 = np.ceil(np.hypot(dx, dy) / self.H) + 1.0
        n4 = (np.abs(dx) + np.abs(dy)) / self.H + 3.0
        ok = np.ones(n8.shape, dtype=bool)
        # inf - inf (NaN, compared False) only where a point's cells are all unreachable: no
        # free segment touches it.
        with np.errstate(invalid="ignore"):
            for k, n in ((0, n8), (1, n4), (2, n8), (3, n4)):
                a, b = ranges_a[..., k, :], ranges_b[..., k, :]
                ok &= b[..., 0] - a[..., 1] <= n
                ok &= a[..., 0] - b[..., 1] <= n
        return ok

    # ------------------------------------------------------------------------------------------
    def blocked_segments(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Segments surely not free: a sample strictly between the end points lies in a core cell
        (booleans; False does not mean free).

        A first pass samples every four cells and drops the segments it catches (thick walls,
        where most blocked segments end); the rest are sampled at most half a cell apart, so a
        segment that crosses a core cell by more than half a cell is caught. Grazing ones are
        left to the exact test.
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        out = np.zeros(len(a), dtype=bool)
        for spacing in (4.0 * self.h, 0.5 * self.h):
            alive = np.flatnonzero(~out)
            if not len(alive):
                break
            out[alive[self._hits(a[alive], b[alive], spacing)]] = True
        return out

    def segments_near_blocked(self, a: np.ndarray, b: np.ndarray, threshold: float,
                              exact: bool = True,
                              sure_pass: bool = True) -> np.ndarray:  # fmt: skip
        """Which segments come closer than ``threshold`` to a blocked cell (booleans): the exact
        test of a world made only of the lattice's boxes, straight from the cells.

        Samples at most a cell apart leave every point of a segment within half a cell of one,
        so a cell closer than ``threshold`` to the segment lies within
        ``ceil(threshold / h + 1/2)`` cells of a sample's; the distance to each blocked cell
        found there is the world's own segment-box formula, so the answer is the world's
        (``World.segments_free`` is its negation, bounds apart). Only for thresholds of up to
        :data:`MAX_BAND` cells minus a half (:attr:`band_ok`). A first pass (:meth:`_deep`)
        settles, without the windows, most segments that come well inside the threshold; with
        ``exact`` False only that pass runs (a "near" is sure, a "free" is not), with
        ``sure_pass`` False only the windows (for segments that pass has seen).
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        out = np.zeros(len(a), dtype=bool)
        if not len(a) or self.blocked is None:
            return out
        if sure_pass:
            out = self._deep(a, b, threshold)  # most that are near, cheaply
        if exact:
            keep = np.flatnonzero(~out)
            out[keep] = self._near_by_window(a[keep], b[keep], threshold)
        return out

    def _deep(self, a: np.ndarray, b: np.ndarray, threshold: float) -> np.ndarray:
        """Segments with a sample (a cell apart) closer than ``threshold`` to the blocked cell
        nearest its cell's centre (a sure "near": that cell is near the segment). Of the
        tangents a wide robot's search tests along a city's streets, most are near, and this
        finds nine in ten of them for a tenth of the window's work."""
        out = np.zeros(len(a), dtype=bool)
        if self.blocked is None or not self.blocked.any() or not len(a):
            return out
        margin = threshold - 1e-9 * self.h  # round-off of the samples: never a false "near"
        if margin <= 0.0:
            return out
        fi, fj = self._nearest_blocked()
        for seg, px, py in _samples(a, b, self.h):
            i = np.floor((px - self.x0) / self.h).astype(np.intp)
            j = np.floor((py - self.y0) / self.h).astype(np.intp)
            inside = (i >= 0) & (i < self.nx) & (j >= 0) & (j < self.ny)
            seg, px, py, i, j = seg[inside], px[inside], py[inside], i[inside], j[inside]
            bx = self.x0 + fi[j, i] * self.h
            by = self.y0 + fj[j, i] * self.h
            ex = np.maximum(np.maximum(bx - px, px - bx - self.h), 0.0)
            ey = np.maximum(np.maximum(by - py, py - by - self.h), 0.0)
            out[seg[ex * ex + ey * ey < margin * margin]] = True
        return out

    def _nearest_blocked(self) -> tuple[np.ndarray, np.ndarray]:
        """Column and row of the blocked cell nearest each cell's centre (cached)."""
        cached = self.__dict__.get("_feature_cache")
        if cached is None:
            from scipy import ndimage  # a map's raster: scipy is loaded for it already

            idx = ndimage.distance_transform_edt(~self.blocked, return_distances=False,
                                                 return_indices=True)  # fmt: skip
            cached = self.__dict__["_feature_cache"] = (idx[1].astype(np.int32),
                                                        idx[0].astype(np.int32))  # fmt: skip
        return cached

    def _near_by_window(self, a: np.ndarray, b: np.ndarray, threshold: float) -> np.ndarray:
        """:meth:`segments_near_blocked` through the windows of cells around the samples."""
        out = np.zeros(len(a), dtype=bool)
        if not len(a):
            return out
        k = math.ceil(threshold / self.h + 0.5)
        off = np.arange(-k, k + 1)
        di, dj = (v.ravel() for v in np.meshgrid(off, off))
        rim, inner = self._rim()  # only rim cells need the distance formula (_rim)
        for seg, px, py in _samples(a, b, self.h, _BAND_CHUNK):
            i = np.floor((px - self.x0) / self.h).astype(np.intp)
            j = np.floor((py - self.y0) / self.h).astype(np.intp)
            # Only samples with a rim cell in their window need the window.
            near = self._near_blocked(k)
            inside = (i >= 0) & (i < self.nx) & (j >= 0) & (j < self.ny)
            out[seg[inside][inner[j[inside], i[inside]]]] = True
            look = np.zeros(len(i), dtype=bool)
            look[inside] = near[j[inside], i[inside]]
            look |= ~inside  # a sample just outside the raster: look anyway
            i, j, seg = i[look], j[look], seg[look]
            ii = (i[:, None] + di[None, :]).ravel()
            jj = (j[:, None] + dj[None, :]).ravel()
            ss = np.repeat(seg, len(di))
            inside = (ii >= 0) & (ii < self.nx) & (jj >= 0) & (jj < self.ny)
            ii, jj, ss = ii[inside], jj[inside], ss[inside]
            hit = rim[jj, ii]
            ii, jj, ss = ii[hit], jj[hit], ss[hit]
            if not len(ss):
                continue
            # Each (segment, cell) pair once: neighbouring samples see the same cells.
            key = _sorted_unique((ss.astype(np.int64) * self.ny + jj) * self.nx + ii)
            ss, rest = np.divmod(key, self.ny * self.nx)
            jj, ii = np.divmod(rest, self.nx)
            x0 = self.x0 + ii * self.h
            y0 = self.y0 + jj * self.h
            box = np.column_stack([x0, y0, x0 + self.h, y0 + self.h])
            dist = segment_box_distance(a[ss], b[ss], box)
            out[ss[dist < threshold]] = True
        return out

    def _near_blocked(self, k: int) -> np.ndarray:
        """Cells with a rim cell (:meth:`_rim`) within ``k`` cells each way (cached per ``k``)."""
        cache = self.__dict__.setdefault("_near_cache", {})
        if k not in cache:
            from scipy import ndimage  # a map's raster: scipy is loaded for it already

            cache[k] = ndimage.maximum_filter(self._rim()[0], size=2 * k + 1, mode="constant")
        return cache[k]

    def _rim(self) -> tuple[np.ndarray, np.ndarray]:
        """The blocked cells with a free cell (or the outside) among their eight neighbours, and
        the other blocked cells, the inner ones (cached; on a city's solid blocks most are inner).

        The nearest blocked point to a point outside the cells lies on a rim cell's edge, and a
        segment that reaches an inner cell has a sample in it or crossed a rim cell first: only
        rim cells need the distance formula of :meth:`segments_near_blocked`."""
        cached = self.__dict__.get("_rim_cache")
        if cached is None:
            free = np.pad(~self.blocked, 1, constant_values=True)
            open_by = np.zeros(self.blocked.shape, dtype=bool)
            ny, nx = self.blocked.shape
            for dj in (0, 1, 2):
                for di in (0, 1, 2):
                    open_by |= free[dj : dj + ny, di : di + nx]
            cached = self.__dict__["_rim_cache"] = (self.blocked & open_by,
                                                    self.blocked & ~open_by)  # fmt: skip
        return cached

    def band_ok(self, threshold: float) -> bool:
        """Whether :meth:`segments_near_blocked` serves this threshold."""
        return self.blocked is not None and threshold / self.h + 0.5 <= MAX_BAND

    def _hits(self, a: np.ndarray, b: np.ndarray, spacing: float) -> np.ndarray:
        """Which segments have a sample (``spacing`` apart, ends excluded) in a core cell."""
        out = np.zeros(len(a), dtype=bool)
        d = b - a
        n = np.ceil(np.hypot(d[:, 0], d[:, 1]) / spacing).astype(np.intp) + 1
        starts = np.concatenate([[0], np.cumsum(n)])
        cut = np.searchsorted(starts, np.arange(0, starts[-1], _SAMPLE_CHUNK))
        bounds = np.unique(np.concatenate([cut, [len(a)]]))
        for s0, s1 in itertools.pairwise(bounds.tolist()):
            nn = n[s0:s1]
            seg = np.repeat(np.arange(s0, s1), nn)
            k = np.arange(nn.sum()) - np.repeat(np.cumsum(nn) - nn, nn)
            t = (k + 0.5) / nn[seg - s0]  # strictly inside (0, 1)
            i = np.floor((a[seg, 0] + t * d[seg, 0] - self.x0) / self.h).astype(np.intp)
            j = np.floor((a[seg, 1] + t * d[seg, 1] - self.y0) / self.h).astype(np.intp)
            inside = (i >= 0) & (i < self.nx) & (j >= 0) & (j < self.ny)
            hit = np.zeros(len(seg), dtype=bool)
            hit[inside] = self._core[j[inside], i[inside]]
            out[seg[hit]] = True
        return out


#: Most cells each way around a sample that :meth:`FreeGrid.segments_near_blocked` looks at.
MAX_BAND = 2
#: Samples per vectorised step of :meth:`FreeGrid.segments_near_blocked`.
_BAND_CHUNK = 100_000


def _sorted_unique(key: np.ndarray) -> np.ndarray:
    """``np.unique`` by sorting (numpy 2's hash-based one is much slower on large arrays)."""
    if len(key) < 2:
        return key
    key = np.sort(key)
    keep = np.empty(len(key), dtype=bool)
    keep[0] = True
    np.not_equal(key[1:], key[:-1], out=keep[1:])
    return key[keep]


def box_lattice(world: World) -> tuple[tuple[float, float], float, np.ndarray] | None:
    """``(origin, h, blocked)`` when every box edge and the bounds lie on one square lattice of
    at most :data:`MAX_LATTICE_CELLS` cells (a map's merged cells), else None. ``blocked`` has
    rows from the bottom; a cell is blocked when a box covers it."""
    b = world.boxes
    if not len(b):
        return None
    (xmin, ymin), (xmax, ymax) = world.bounds
    xs = np.unique(np.concatenate([b[:, 0], b[:, 2], [xmin, xmax]]))
    ys = np.unique(np.concatenate([b[:, 1], b[:, 3], [ymin, ymax]]))
    steps = np.concatenate([np.diff(xs), np.diff(ys)])
    steps = steps[steps > 0]
    if not len(steps):
        return None
    h = float(steps.min())
    nx, ny = round((xmax - xmin) / h), round((ymax - ymin) / h)
    if nx * ny > MAX_LATTICE_CELLS or nx < 1 or ny < 1:
        return None

    def index(v: np.ndarray, v0: float) -> np.ndarray | None:
        k = (v - v0) / h
        r = np.round(k)
        return r.astype(np.intp) if np.all(np.abs(k - r) <= 1e-6) else None

    i0, i1 = index(b[:, 0], xmin), index(b[:, 2], xmin)
    j0, j1 = index(b[:, 1], ymin), index(b[:, 3], ymin)
    ends = index(np.array([xmax]), xmin), index(np.array([ymax]), ymin)
    if any(v is None for v in (i0, i1, j0, j1, *ends)):
        return None
    # Paint the boxes (clipped to the bounds) with a 2-D difference array.
    i0, i1 = np.clip(i0, 0, nx), np.clip(i1, 0, nx)
    j0, j1 = np.clip(j0, 0, ny), np.clip(j1, 0, ny)
    diff = np.zeros((ny + 1, nx + 1), dtype=np.int32)
    np.add.at(diff, (j0, i0), 1)
    np.add.at(diff, (j0, i1), -1)
    np.add.at(diff, (j1, i0), -1)
    np.add.at(diff, (j1, i1), 1)
    blocked = np.cumsum(np.cumsum(diff, axis=0), axis=1)[:ny, :nx] > 0
    return (xmin, ymin), h, blocked


def _block_any(free: np.ndarray, k: int) -> np.ndarray:
    """Blocks of k x k cells, True when any cell is (the grid padded with False)."""
    if k == 1:
        return free
    ny, nx = free.shape
    py, px = -ny % k, -nx % k
    f = np.pad(free, ((0, py), (0, px)), constant_values=False)
    return f.reshape(f.shape[0] // k, k, f.shape[1] // k, k).any(axis=(1, 3))


def _samples(a: np.ndarray, b: np.ndarray, spacing: float, chunk: int = 0):
    """Points along each segment at most ``spacing`` apart, ends included, in chunks of
    about ``chunk`` (:data:`_SAMPLE_CHUNK`) points: ``(segment, x, y)`` arrays."""
    d = b - a
    n = np.ceil(np.hypot(d[:, 0], d[:, 1]) / spacing).astype(np.intp) + 1
    starts = np.concatenate([[0], np.cumsum(n)])
    cut = np.searchsorted(starts, np.arange(0, starts[-1], chunk or _SAMPLE_CHUNK))
    bounds = np.unique(np.concatenate([cut, [len(a)]]))
    for s0, s1 in itertools.pairwise(bounds.tolist()):
        nn = n[s0:s1]
        seg = np.repeat(np.arange(s0, s1), nn)
        t = (np.arange(nn.sum()) - np.repeat(np.cumsum(nn) - nn, nn)) / np.maximum(
            nn[seg - s0] - 1, 1)  # fmt: skip
        yield seg, a[seg, 0] + t * d[seg, 0], a[seg, 1] + t * d[seg, 1]


def _covers(origin, h: float, shape, bounds) -> bool:
    """Whether the lattice's cells cover the bounds (no path can go round them)."""
    (xmin, ymin), (xmax, ymax) = bounds
    ny, nx = shape
    slack = 1e-9 * h
    across = origin[0] <= xmin + slack and origin[0] + nx * h >= xmax - slack
    up = origin[1] <= ymin + slack and origin[1] + ny * h >= ymax - slack
    return across and up


def _search_blocks(free: np.ndarray, cell_by_cell: bool = False) -> tuple[int, np.ndarray, bool]:
    """The block side ``k`` of the search grid, that grid (:func:`_block_any`) and whether the
    raster is narrow (blocks of the fast side, at least 2, would not keep its shape): the side of
    :data:`FAST_SEARCH_CELLS` where its blocks keep the map's shape (:data:`BLOCK_GROWTH`), else
    the smallest within :data:`MAX_SEARCH_CELLS` and :data:`MAX_SEARCH_FREE` possibly-free cells
    (:data:`MAX_REFINED_FREE` when asked for ``cell_by_cell``; at most ``sqrt(cells / limit) + 1``
    sides tried)."""
    fast = math.ceil(math.sqrt(free.size / FAST_SEARCH_CELLS))
    k = max(2, fast)
    coarse = _block_any(free, k)
    narrow = np.count_nonzero(coarse) * k * k > BLOCK_GROWTH * np.count_nonzero(free)
    if fast > 1 and not narrow and not cell_by_cell:
        return k, coarse, narrow
    limit = MAX_REFINED_FREE if cell_by_cell else MAX_SEARCH_FREE
    k = max(1, math.ceil(math.sqrt(free.size / MAX_SEARCH_CELLS)))
    while True:
        coarse = _block_any(free, k)
        if coarse.size <= MAX_SEARCH_CELLS and np.count_nonzero(coarse) <= limit:
            return k, coarse, narrow
        k += 1


def _window_cells(cells: np.ndarray, w: int, ny: int, nx: int) -> np.ndarray:
    """The cells of each cell's ``(2w + 1) x (2w + 1)`` window, ``((2w + 1)^2, n)`` flat indices,
    the border cells repeated beyond the edges (as ``scipy.ndimage``'s filters with ``mode=
    "nearest"``): gathered for the cells asked about, not filtered over the whole grid, which on
    a map of a million cells cost more than the rest of setting up a round."""
    j, i = np.divmod(np.asarray(cells, dtype=np.intp), nx)
    d = np.arange(-w, w + 1)
    rows = np.clip(j[None, :] + d[:, None], 0, ny - 1)
    cols = np.clip(i[None, :] + d[:, None], 0, nx - 1)
    return (rows[:, None, :] * nx + cols[None, :, :]).reshape(len(d) ** 2, -1)


def _bfs_distances(free: np.ndarray, sources: list[int],
                   terminate=None) -> list[tuple[np.ndarray, np.ndarray]]:  # fmt: skip
    """Breadth-first step counts over the possibly-free cells, 8- and 4-connected, from each
    source cell: ``[(m8, m4), ...]`` as flat arrays (``inf`` where unreachable).

    Searched in numpy up to :data:`NUMPY_SEARCH_CELLS` cells, else with scipy (a graph of the
    possibly-free cells alone): the step counts are the same (a cell's is its distance in
    steps). A source outside the possibly-free cells gets no grid bound (zeros)."""
    n = free.size
    flat = free.ravel()
    out = [[np.zeros(n), np.zeros(n)] for _ in sources]
    inside = [s for s, src in enumerate(sources) if flat[src]]
    for k, moves in enumerate((((0, 1), (1, 0), (1, 1), (1, -1)), ((0, 1), (1, 0)))):
        _poll(terminate)
        if not inside:
            break
        if n <= NUMPY_SEARCH_CELLS:
            nbr, ok = _neighbours(free, moves)
            steps = [_numpy_steps(np.where(ok, nbr, n), sources[s]) for s in inside]
        else:
            steps = _scipy_steps(free, moves, [sources[s] for s in inside])
        for s, row in zip(inside, steps, strict=True):
            out[s][k] = row
    return [(m8, m4) for m8, m4 in out]


def _neighbours(free: np.ndarray, moves) -> tuple[np.ndarray, np.ndarray]:
    """Each cell's neighbours along ``moves`` and their opposites: ``(nbr, ok)``, both ``(n,
    2 len(moves))``, ``nbr`` the neighbours' flat indices and ``ok`` where both cells are
    possibly free (and the neighbour inside the grid)."""
    ny, nx = free.shape
    n = nx * ny
    offsets = [m for dj, di in moves for m in ((dj, di), (-dj, -di))]
    nbr = np.empty((n, len(offsets)), dtype=np.int64)
    ok = np.zeros((n, len(offsets)), dtype=bool)
    idx = np.arange(n).reshape(ny, nx)
    for k, (dj, di) in enumerate(offsets):
        both = np.zeros((ny, nx), dtype=bool)
        js = slice(max(0, -dj), ny - max(0, dj))
        is_ = slice(max(0, -di), nx - max(0, di))
        jt = slice(max(0, dj), ny - max(0, -dj))
        it = slice(max(0, di), nx - max(0, -di))
        both[js, is_] = free[js, is_] & free[jt, it]
        ok[:, k] = both.ravel()
        nbr[:, k] = (idx + dj * nx + di).ravel()
    return nbr, ok


def _numpy_steps(nbr: np.ndarray, src: int) -> np.ndarray:
    """Breadth-first step counts from ``src`` (``inf`` where unreachable), level by level:
    ``nbr`` is ``(n, m)``, each cell's neighbours, ``n`` where there is none."""
    n = len(nbr)
    steps = np.full(n + 1, np.inf)
    steps[n] = -1.0  # "no neighbour" is never reached
    steps[src] = 0.0
    frontier = np.array([src])
    level = 0.0
    while len(frontier):
        level += 1.0
        reached = nbr[frontier].ravel()
        frontier = np.unique(reached[steps[reached] == np.inf])
        steps[frontier] = level
    return steps[:n]


def _scipy_steps(free: np.ndarray, moves, sources: list[int]) -> list[np.ndarray]:
    """:func:`_numpy_steps` from each (possibly-free) source, by scipy's unweighted shortest
    paths over a graph of the possibly-free cells alone: half a maze's cells, a tenth of a
    city's for a wide robot, with 32-bit indices, which scipy uses without a copy."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    ny, nx = free.shape
    cells = np.flatnonzero(free)
    ids = np.full((ny + 2, nx + 2), -1, dtype=np.int32)  # a border of "no cell"
    ids[1:-1, 1:-1][free] = np.arange(len(cells), dtype=np.int32)
    j, i = np.divmod(cells, nx)
    # A row's neighbours in the order of their index (the ids keep it): no sorting.
    offsets = sorted((m for dj, di in moves for m in ((dj, di), (-dj, -di))),
                     key=lambda m: m[0] * nx + m[1])  # fmt: skip
    nbr = np.stack([ids[j + 1 + dj, i + 1 + di] for dj, di in offsets], axis=1)
    ok = nbr >= 0
    indptr = np.zeros(len(cells) + 1, dtype=np.int32)
    np.cumsum(ok.sum(axis=1), out=indptr[1:])
    indices = nbr[ok]
    del nbr, ok
    graph = csr_matrix((np.ones(len(indices)), indices, indptr), shape=(len(cells), len(cells)))
    graph.has_sorted_indices = True
    src = ids[1:-1, 1:-1].ravel()[sources]
    out = []
    for row in np.atleast_2d(dijkstra(graph, directed=True, indices=src, unweighted=True)):
        steps = np.full(free.size, np.inf)
        steps[cells] = row
        out.append(steps)
    return out
