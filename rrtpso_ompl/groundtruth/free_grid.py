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
grid of more than :data:`NUMPY_SEARCH_CELLS` cells (scipy's breadth-first search). A smaller one,
every raster of a few dozen obstacles without a map, is searched level by level in numpy: the
same step counts (a breadth-first search's are unique), without the 0.2-0.4 s importing scipy
costs, several times what ``rrtpso optimum`` of such a problem computes (docs/startup.md).
"""

from __future__ import annotations

import itertools
import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..model.geometry import segment_box_distance
from ..model.world import World

if TYPE_CHECKING:
    from scipy.sparse import csr_matrix

__all__ = ["FreeGrid", "Stopped", "box_lattice"]

_SQRT2 = math.sqrt(2.0)
#: Most cells of the raster over a world without a map, along the longer side of the bounds (16
#: times the square root of the number of obstacles, at least 32).
GENERIC_CELLS = 192
#: Most cells of the breadth-first search: finer rasters are searched in blocks of k x k cells.
MAX_SEARCH_CELLS = 300_000
#: Most cells of a search grid searched in numpy, level by level (:func:`_numpy_steps`), rather
#: than with scipy: a level costs a few numpy calls, and a search has at most one level per cell,
#: so even a winding one stays below the cost of importing scipy (a 100 x 100 serpentine, 5,000
#: levels, takes 0.03 s per search on the machine of docs/startup.md; importing scipy 0.35 s).
NUMPY_SEARCH_CELLS = 10_000
#: Most cells of a raster on the lattice of a world's boxes (else the generic raster is used).
MAX_LATTICE_CELLS = 30_000_000
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
                 goal_tolerance: float = 0.0, terminate=None) -> None:  # fmt: skip
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
        k = max(1, math.ceil(math.sqrt(self.nx * self.ny / MAX_SEARCH_CELLS)))
        self.k = k
        self.H = k * self.h
        coarse = _block_any(self.free, k)
        self.cny, self.cnx = coarse.shape
        self._dist = _bfs_distances(coarse, [self._cell(self.start), self._cell(self.goal)],
                                    terminate)  # fmt: skip

    # ------------------------------------------------------------------------------------------
    @classmethod
    def for_world(cls, world: World, start, goal, goal_tolerance: float = 0.0,
                  terminate=None) -> FreeGrid:  # fmt: skip
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
            grid = cls(origin, h, free, start, goal, goal_tolerance, terminate)
            grid.blocked = blocked
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
        return cls((xmin, ymin), h, free, start, goal, goal_tolerance, terminate)

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
            grid = self._geodesic(which, np.arange(self.cnx * self.cny)).reshape(self.cny, self.cnx)
            if w > 0:
                grid = _window_extreme(grid, w, np.minimum)
            out[small] = np.maximum(euclid[small], grid.ravel()[self._cells(c[small, :2])])
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
        cells = self._cells(c[small, :2])
        for k, grid in enumerate((self._dist[0][0], self._dist[0][1], self._dist[1][0],
                                  self._dist[1][1])):  # fmt: skip
            g = grid.reshape(self.cny, self.cnx)
            lo = np.where(np.isfinite(g), g, np.inf)
            hi = np.where(np.isfinite(g), g, -np.inf)
            if w > 0:
                lo = _window_extreme(lo, w, np.minimum)
                hi = _window_extreme(hi, w, np.maximum)
            out[small, k, 0] = lo.ravel()[cells]
            out[small, k, 1] = hi.ravel()[cells]
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

    def segments_near_blocked(self, a: np.ndarray, b: np.ndarray, threshold: float) -> np.ndarray:
        """Which segments come closer than ``threshold`` to a blocked cell (booleans): the exact
        test of a world made only of the lattice's boxes, straight from the cells.

        Samples at most a cell apart leave every point of a segment within half a cell of one,
        so a cell closer than ``threshold`` to the segment lies within
        ``ceil(threshold / h + 1/2)`` cells of a sample's; the distance to each blocked cell
        found there is the world's own segment-box formula, so the answer is the world's
        (``World.segments_free`` is its negation, bounds apart). Only for thresholds of up to
        :data:`MAX_BAND` cells minus a half (:attr:`band_ok`).
        """
        a = np.asarray(a, dtype=float).reshape(-1, 2)
        b = np.asarray(b, dtype=float).reshape(-1, 2)
        out = np.zeros(len(a), dtype=bool)
        if not len(a) or self.blocked is None:
            return out
        k = math.ceil(threshold / self.h + 0.5)
        off = np.arange(-k, k + 1)
        di, dj = (v.ravel() for v in np.meshgrid(off, off))
        d = b - a
        n = np.ceil(np.hypot(d[:, 0], d[:, 1]) / self.h).astype(np.intp) + 1
        starts = np.concatenate([[0], np.cumsum(n)])
        cut = np.searchsorted(starts, np.arange(0, starts[-1], _BAND_CHUNK))
        bounds = np.unique(np.concatenate([cut, [len(a)]]))
        rim, inner = self._rim()  # only rim cells need the distance formula (_rim)
        for s0, s1 in itertools.pairwise(bounds.tolist()):
            nn = n[s0:s1]
            seg = np.repeat(np.arange(s0, s1), nn)
            t = (np.arange(nn.sum()) - np.repeat(np.cumsum(nn) - nn, nn)) / np.maximum(
                nn[seg - s0] - 1, 1)  # fmt: skip
            i = np.floor((a[seg, 0] + t * d[seg, 0] - self.x0) / self.h).astype(np.intp)
            j = np.floor((a[seg, 1] + t * d[seg, 1] - self.y0) / self.h).astype(np.intp)
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


def _window_extreme(grid: np.ndarray, w: int, extreme: np.ufunc) -> np.ndarray:
    """The least (``extreme=np.minimum``) or greatest (``np.maximum``) value of each cell's
    ``(2w + 1) x (2w + 1)`` window, the border cells repeated beyond the edges: what
    ``scipy.ndimage.minimum_filter(grid, size=2 * w + 1, mode="nearest")`` (or
    ``maximum_filter``) returns, one axis after the other (a square window's extreme is the
    extreme of its rows' extremes)."""
    out = grid
    for axis in (0, 1):
        pad = [(0, 0), (0, 0)]
        pad[axis] = (w, w)
        rows = sliding_window_view(np.pad(out, pad, mode="edge"), 2 * w + 1, axis=axis)
        out = extreme.reduce(rows, axis=-1)
    return out


def _bfs_distances(free: np.ndarray, sources: list[int],
                   terminate=None) -> list[tuple[np.ndarray, np.ndarray]]:  # fmt: skip
    """Breadth-first step counts over the possibly-free cells, 8- and 4-connected, from each
    source cell: ``[(m8, m4), ...]`` as flat arrays (``inf`` where unreachable).

    Searched in numpy up to :data:`NUMPY_SEARCH_CELLS` cells, else with scipy's
    ``breadth_first_order``: the step counts are the same (a cell's is its distance in steps)."""
    ny, nx = free.shape
    n = nx * ny
    flat = free.ravel()
    out = [[None, None] for _ in sources]
    for k, moves in enumerate((((0, 1), (1, 0), (1, 1), (1, -1)), ((0, 1), (1, 0)))):
        nbr, ok = _neighbours(free, moves)
        graph = _grid_graph(nbr, ok) if n > NUMPY_SEARCH_CELLS else None
        for s, src in enumerate(sources):
            _poll(terminate)
            if not flat[src]:  # a source outside the possibly-free cells: no grid bound
                out[s][k] = np.zeros(n)
            elif graph is None:
                out[s][k] = _numpy_steps(np.where(ok, nbr, n), src)
            else:
                out[s][k] = _scipy_steps(graph, src)
    return [(m8, m4) for m8, m4 in out]


def _neighbours(free: np.ndarray, moves) -> tuple[np.ndarray, np.ndarray]:
    """Each cell's neighbours along ``moves`` and their opposites: ``(nbr, ok)``, both ``(n,
    2 len(moves))``, ``nbr`` the neighbours' flat indices and ``ok`` where both cells are
    possibly free (and the neighbour inside the grid). A cell's neighbours come in the order of
    their index."""
    ny, nx = free.shape
    n = nx * ny
    offsets = sorted((m for dj, di in moves for m in ((dj, di), (-dj, -di))),
                     key=lambda m: m[0] * nx + m[1])  # fmt: skip
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


def _scipy_steps(graph: csr_matrix, src: int) -> np.ndarray:
    """:func:`_numpy_steps` with scipy's breadth-first search (for large grids)."""
    from scipy.sparse.csgraph import breadth_first_order

    steps = np.full(graph.shape[0], np.inf)
    order, pred = breadth_first_order(graph, src, directed=True, return_predecessors=True)
    steps[order] = _depths(pred)[order]
    return steps


def _grid_graph(nbr: np.ndarray, ok: np.ndarray) -> csr_matrix:
    """The graph of the possibly-free cells (:func:`_neighbours`), built straight as CSR arrays
    (a cell's neighbours come in the order of their index, so no sorting)."""
    from scipy.sparse import csr_matrix

    n = len(nbr)
    indices = nbr[ok]
    indptr = np.concatenate([[0], np.cumsum(ok.sum(axis=1))])
    graph = csr_matrix((np.ones(len(indices)), indices, indptr), shape=(n, n))
    graph.has_sorted_indices = True
    return graph


def _depths(pred: np.ndarray) -> np.ndarray:
    """Depth of every node in a breadth-first tree given by its predecessors (negative at the
    root and at unreached nodes), by pointer doubling: log2(depth) vectorised steps."""
    n = len(pred)
    jump = np.where(pred >= 0, pred, np.arange(n))
    depth = (pred >= 0).astype(float)
    for _ in range(64):
        nxt = jump[jump]
        depth = depth + depth[jump]
        if np.array_equal(nxt, jump):
            break
        jump = nxt
    return depth
