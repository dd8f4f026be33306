"""The path cost every planner optimises: length plus a costmap's inflation cost.

Nav2's costmap inflation layer gives a cell at distance ``d`` from the nearest obstacle, for a
robot of inscribed radius ``r``, the cost

.. math::

    \\mathrm{cost}(d) = 252 \\, e^{-k (d - r)} \\quad (r < d \\le R_i), \\qquad 0 \\quad (d > R_i),

with ``k`` = ``cost_scaling_factor`` (1/length) and ``R_i`` = ``inflation_radius`` (length). Its
planners (Smac 2D, NavFn) then charge a step of length ``ds`` through that cell
``ds * (1 + w * cost / 252)``; Smac 2D calls ``w`` its ``cost_travel_multiplier``. The same
objective here, on the exact distance instead of a cell's:

.. math::

    J(\\gamma) = \\int_\\gamma \\bigl(1 + w \\, c(d(s))\\bigr) \\, ds
              = L(\\gamma) + w \\int_\\gamma c(d(s)) \\, ds,
    \\qquad c(d) = \\begin{cases} 1 & d \\le r \\\\ e^{-k (d - r)} & r < d \\le R_i \\\\
                                   0 & d > R_i \\end{cases}

``d(s)`` is the distance from the robot's centre at arc length ``s`` to the nearest static
obstacle, so ``c`` is Nav2's cost divided by 252 (1 where the robot touches an obstacle). ``J``
is in length units: a stretch driven at the robot's radius from a wall costs ``1 + w`` times its
length, one farther than ``R_i`` from every obstacle costs its length. With no inflation
(``R_i <= r``, the default) ``J`` is the length: the paper's shortest path.

Because the integrand is at least 1, ``J`` of any path is at least its length, hence at least the
straight-line distance between its ends: the cost-to-go heuristic that keeps informed planners
(BIT*, Informed RRT*) admissible.

The integral is evaluated by the composite midpoint rule with steps no longer than
:attr:`InflationCost.step` (exact for stretches at constant distance, and within
``O(step^2)`` elsewhere).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

__all__ = [
    "DEFAULT_COST_SCALING_FACTOR",
    "DEFAULT_COST_WEIGHT",
    "MAX_SAMPLES",
    "ClearanceField",
    "InflationCost",
    "default_scaling",
]

#: Nav2's default ``cost_scaling_factor``, 1/m: a problem in other units gets it converted
#: (:func:`default_scaling`).
DEFAULT_COST_SCALING_FACTOR = 3.0
#: ``w``: Smac 2D's default ``cost_travel_multiplier``.
DEFAULT_COST_WEIGHT = 2.0
#: Bound on the points one evaluation samples (an input-driven allocation).
MAX_SAMPLES = 20_000_000


@dataclass(frozen=True)
class InflationCost:
    """The inflation cost of a robot (module docstring), and the objective ``J`` it gives.

    Attributes
    ----------
    radius : float
        ``r``: the robot's radius, the hard constraint (length).
    inflation_radius : float
        ``R_i``: how far from obstacles the cost reaches (length); ``<= radius`` means none.
    cost_scaling_factor : float
        ``k`` (1/length): how fast the cost falls beyond the radius.
    weight : float
        ``w``: the cost of driving at the radius from a wall, in extra lengths per length.
    """

    radius: float
    inflation_radius: float = 0.0
    cost_scaling_factor: float = DEFAULT_COST_SCALING_FACTOR
    weight: float = DEFAULT_COST_WEIGHT

    @property
    def active(self) -> bool:
        """Whether the objective differs from the length."""
        return self.inflation_radius > self.radius and self.weight > 0

    @property
    def step(self) -> float:
        """Largest quadrature step along a path (length): an eighth of the inflated band, and
        no longer than a fifth of ``1 / k``, the length over which the cost falls by ``e``."""
        if not self.active:
            return math.inf
        k = self.cost_scaling_factor
        return min((self.inflation_radius - self.radius) / 8.0, 0.2 / k if k > 0 else math.inf)

    @classmethod
    def of(cls, robot) -> InflationCost:
        """The cost of a :class:`~rrtpso_ompl.model.Robot` (its inflation keys; a problem file's
        robot has its scaling factor in the problem's units, :func:`default_scaling`)."""
        return cls(
            radius=robot.radius,
            inflation_radius=robot.inflation_radius or 0.0,
            cost_scaling_factor=robot.cost_scaling_factor or DEFAULT_COST_SCALING_FACTOR,
            weight=robot.cost_travel_multiplier or DEFAULT_COST_WEIGHT,
        )

    def cost(self, d: np.ndarray) -> np.ndarray:
        """``c(d)`` of distances ``d`` to the nearest obstacle (module docstring), in [0, 1]."""
        d = np.asarray(d, dtype=float)
        # Clipped to the band, so that far (infinite) distances give no 0 * inf.
        band = np.clip(d - self.radius, 0.0, max(self.inflation_radius - self.radius, 0.0))
        c = np.exp(-self.cost_scaling_factor * band)
        return np.where(d > self.inflation_radius, 0.0, c)

    def segment_integrals(
        self, world, a: np.ndarray, b: np.ndarray, distance: ClearanceField | None = None
    ) -> np.ndarray:
        """``integral c(d(s)) ds`` along each segment ``a[i]-b[i]`` (length units).

        Parameters
        ----------
        world : World
            Gives the exact distance to the nearest obstacle (``point_clearance``, through its
            index up to ``R_i``).
        a, b : (..., 2) array_like
            End points, broadcast together.
        distance : ClearanceField, optional
            Interpolated distances instead of exact ones (the swarm's many evaluations).

        Returns
        -------
        ndarray of shape ``(...)``
        """
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        shape = a.shape[:-1]
        if not self.active:
            return np.zeros(shape)
        a, b = a.reshape(-1, 2), b.reshape(-1, 2)
        d = b - a
        length = np.hypot(d[:, 0], d[:, 1])
        steps = np.maximum(1, np.ceil(length / self.step)).astype(np.int64)
        total = int(steps.sum())
        if total > MAX_SAMPLES:
            raise ValueError(f"{total} cost samples exceed the bound of {MAX_SAMPLES}")
        seg = np.repeat(np.arange(len(a)), steps)
        first = np.cumsum(steps) - steps
        t = (np.arange(total) - first[seg] + 0.5) / steps[seg]  # mid-points of equal steps
        pts = a[seg] + t[:, None] * d[seg]
        d = (distance(pts) if distance is not None
             else world.point_clearance(pts, cap=self.inflation_radius))  # fmt: skip
        c = self.cost(d)
        out = np.bincount(seg, weights=c, minlength=len(a)) * (length / steps)
        return out.reshape(shape)

    def segment_integral(self, field: ClearanceField, ax: float, ay: float, bx: float,
                         by: float) -> float:  # fmt: skip
        """``integral c(d(s)) ds`` along one segment on a :class:`ClearanceField`: the cost of
        one motion as an OMPL planner asks for it thousands of times a second, with as few
        numpy calls as the midpoint rule allows (their per-call overhead is most of it)."""
        if (bx, by) < (ax, ay):  # one order, so that a motion costs the same both ways
            ax, ay, bx, by = bx, by, ax, ay
        length = math.hypot(bx - ax, by - ay)
        if not self.active or length == 0.0:
            return 0.0
        # The distance is 1-Lipschitz: no point of the segment is nearer an obstacle than an end
        # point's distance less half the length (the field's values are at most the true ones,
        # and its interpolation errs by less than its spacing).
        near = min(field.at(ax, ay), field.at(bx, by)) - 0.5 * length - field.spacing
        if near > self.inflation_radius:
            return 0.0
        n = max(1, math.ceil(length / self.step))
        d = field.along(ax, ay, bx, by, n)
        band = np.clip(d - self.radius, 0.0, self.inflation_radius - self.radius)
        c = np.exp(-self.cost_scaling_factor * band)
        return float(c[d <= self.inflation_radius].sum()) * length / n

    def path_costs(self, world, paths: np.ndarray) -> np.ndarray:
        """``J`` of each polyline of ``paths`` (``(..., n, 2)``), length units."""
        p = np.asarray(paths, dtype=float)
        seg = np.diff(p, axis=-2)
        length = np.sqrt(np.einsum("...i,...i->...", seg, seg)).sum(axis=-1)
        if not self.active:
            return length
        extra = self.segment_integrals(world, p[..., :-1, :], p[..., 1:, :]).sum(axis=-1)
        return length + self.weight * extra

    def path_cost(self, world, path: np.ndarray) -> float:
        """``J`` of one polyline (length units)."""
        return float(self.path_costs(world, np.asarray(path, dtype=float).reshape(-1, 2)))

    def near_share(self, world, path: np.ndarray) -> float:
        """The share of the path's length closer than ``R_i`` to an obstacle (0 without
        inflation): the issue's measure of a path that hugs walls."""
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        seg = np.hypot(*np.diff(p, axis=0).T)
        total = float(seg.sum())
        if not self.active or total == 0.0:
            return 0.0
        near = InflationCost(self.radius, self.inflation_radius, 0.0, 1.0)  # c = 1 inside R_i
        return float(near.segment_integrals(world, p[:-1], p[1:]).sum()) / total


def default_scaling(units: str) -> float:
    """Nav2's default ``cost_scaling_factor`` (3.0 per metre) per unit of ``units`` (per metre
    when the unit is not one :mod:`~rrtpso_ompl.model.units` knows)."""
    from .units import metres_per_unit

    try:
        return DEFAULT_COST_SCALING_FACTOR * metres_per_unit(units)
    except ValueError:
        return DEFAULT_COST_SCALING_FACTOR


class ClearanceField:
    """Distances to the nearest obstacle, sampled on a lattice and interpolated bilinearly.

    The swarm evaluates the inflation cost of thousands of candidate paths, each at hundreds of
    points; the exact distance through the world's index costs about 2 us a point, a lookup
    here a few tens of nanoseconds. The lattice covers the bounds; its tiles are measured
    exactly (``World.point_clearance``, capped at ``cap``) the first time a point falls in
    them, so only the neighbourhood of the paths is ever measured. The distance is 1-Lipschitz,
    so the interpolation errs by less than ``spacing / sqrt(2)`` anywhere and not at all along a
    straight wall (0.01-0.05 % of the cost's integral at the default spacing, measured on a
    rooms map); decisions that must hold exactly (that a path is no costlier than another) use
    the exact distance.

    Parameters
    ----------
    world : World
    spacing : float
        Lattice spacing (length); made coarser when the bounds would need more than
        :attr:`MAX_NODES` nodes.
    cap : float
        Distances beyond ``cap`` are returned as ``cap``: give a little more than the
        inflation radius, so that a capped distance costs nothing.
    tile : int
        Lattice cells per tile side.
    """

    #: Most lattice nodes (8 bytes each: 64 MB).
    MAX_NODES = 8_000_000

    def __init__(self, world, spacing: float, cap: float, tile: int = 16) -> None:
        if not (spacing > 0 and math.isfinite(spacing)):
            raise ValueError(f"spacing must be positive and finite, got {spacing!r}")
        (x0, y0), (x1, y1) = world.bounds
        area_nodes = ((x1 - x0) / spacing + 2) * ((y1 - y0) / spacing + 2)
        if area_nodes > self.MAX_NODES:
            spacing *= math.sqrt(area_nodes / self.MAX_NODES)
        self.world = world
        self.spacing = float(spacing)
        self.cap = float(cap)
        self.tile = int(tile)
        self.origin = np.array([x0, y0], dtype=float)
        tiles = np.ceil(np.array([x1 - x0, y1 - y0]) / (spacing * tile)).astype(np.int64) + 1
        self._done = np.zeros(tiles, dtype=bool)
        self._d = np.full(tiles * tile + 1, np.nan)
        # Flat views for :meth:`along` (one gather per corner).
        self._d_flat = self._d.reshape(-1)
        self._done_flat = self._done.reshape(-1)
        self._strides = np.array([self._d.shape[1], 1])
        self._tile_strides = np.array([self._done.shape[1], 1])
        self._uv_max = np.array([self._d.shape[0] - 1.0, self._d.shape[1] - 1.0])
        self._ij_max = np.array([self._d.shape[0] - 2, self._d.shape[1] - 2])
        self._midpoints: dict[int, np.ndarray] = {}
        # What :meth:`at` reads, as Python numbers (numpy scalars are slow one at a time).
        self._scalars = (float(x0), float(y0), self.spacing, int(self._d.shape[0] - 2),
                         int(self._d.shape[1] - 2), self.tile)  # fmt: skip

    def _fill(self, tiles: np.ndarray) -> None:
        """Measure the tiles ``tiles`` (``(k, 2)`` tile indices, not measured yet), in one
        call to the world."""
        n = self.tile + 1  # a tile's nodes include its far edge, shared with the next tile
        ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
        nodes = (tiles[:, None, :] * self.tile + ij[None]).reshape(-1, 2)
        pts = self.origin + nodes * self.spacing
        d = np.minimum(self.world.point_clearance(pts, cap=self.cap), self.cap)
        self._d[nodes[:, 0], nodes[:, 1]] = d
        self._done[tiles[:, 0], tiles[:, 1]] = True

    def prefill(self, path: np.ndarray, margin: float, deadline: float | None = None) -> bool:
        """Measure, a chunk of tiles at a time, the tiles within ``margin`` of the polyline
        ``path`` (where a swarm round's candidates lie); False when ``deadline``
        (``time.perf_counter()`` seconds) came first. A measurement cannot be interrupted, so
        work that must end in time measures its neighbourhood here first."""
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        side = self.tile * self.spacing
        seg = np.diff(p, axis=0)
        n = np.maximum(np.ceil(np.hypot(*seg.T) / (0.5 * side)).astype(np.int64), 1)
        k = np.repeat(np.arange(len(seg)), n)
        t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / n[k]
        pts = np.vstack([p[:-1][k] + t[:, None] * seg[k], p[-1:]])
        reach = math.ceil(margin / side) + 1
        base = np.floor((pts - self.origin) / side).astype(np.int64)
        offs = np.arange(-reach, reach + 1)
        di, dj = np.meshgrid(offs, offs, indexing="ij")
        tiles = (base[:, None, :] + np.stack([di.ravel(), dj.ravel()], 1)[None]).reshape(-1, 2)
        tiles = np.clip(tiles, 0, np.array(self._done.shape) - 1)
        flat = np.unique(tiles[:, 0] * self._done.shape[1] + tiles[:, 1])
        todo = flat[~self._done_flat[flat]]
        took = 0.0  # the last chunk's time: the next one would take about as long
        for chunk in np.array_split(todo, max(1, math.ceil(len(todo) / 8))):
            t0 = time.perf_counter()
            if deadline is not None and t0 + took >= deadline:
                return False
            if len(chunk):
                self._fill(np.stack(np.divmod(chunk, self._done.shape[1]), axis=1))
            took = time.perf_counter() - t0
        return True

    def at(self, x: float, y: float) -> float:
        """The interpolated distance at one point, in plain Python (see :meth:`__call__`)."""
        x0, y0, h, imax, jmax, tile = self._scalars
        u = min(max((x - x0) / h, 0.0), imax + 1.0)
        v = min(max((y - y0) / h, 0.0), jmax + 1.0)
        i = min(int(u), imax)
        j = min(int(v), jmax)
        if not self._done.item(i // tile, j // tile):
            self._fill(np.array([[i // tile, j // tile]]))
        fx, fy = u - i, v - j
        item = self._d.item
        return ((item(i, j) * (1 - fx) + item(i + 1, j) * fx) * (1 - fy)
                + (item(i, j + 1) * (1 - fx) + item(i + 1, j + 1) * fx) * fy)  # fmt: skip

    def along(self, ax: float, ay: float, bx: float, by: float, n: int) -> np.ndarray:
        """Interpolated distances at the midpoints of ``n`` equal steps from ``a`` to ``b``
        (:meth:`__call__` for one segment, with as few numpy calls as it takes)."""
        x0, y0, h, _, _, tile = self._scalars
        t = self._midpoints.get(n)
        if t is None:
            t = ((np.arange(n) + 0.5) / n)[:, None]
            if n <= 256:  # the usual motions' step counts (a bounded cache)
                self._midpoints[n] = t
        uv = np.array([(ax - x0) / h, (ay - y0) / h]) + t * [(bx - ax) / h, (by - ay) / h]
        np.clip(uv, 0.0, self._uv_max, out=uv)
        ij = np.minimum(uv.astype(np.int64), self._ij_max)
        f = uv - ij
        flat = ij @ self._strides
        if not self._done_flat[(ij // tile) @ self._tile_strides].all():
            self._fill_around(ij)
        d = self._d_flat
        ny = self._strides[0]
        d0 = d[flat] + f[:, 0] * (d[flat + ny] - d[flat])
        d1 = d[flat + 1] + f[:, 0] * (d[flat + ny + 1] - d[flat + 1])
        return d0 + f[:, 1] * (d1 - d0)

    def _fill_around(self, ij: np.ndarray) -> None:
        """Measure the tiles of lattice cells ``ij`` not measured yet."""
        keys = np.unique((ij // self.tile) @ self._tile_strides)
        todo = keys[~self._done_flat[keys]]
        self._fill(np.stack(np.divmod(todo, self._tile_strides[0]), axis=1))

    def __call__(self, points: np.ndarray) -> np.ndarray:
        """Interpolated distances of ``points`` (``(n, 2)``, inside the bounds), at most
        ``cap``."""
        p = np.asarray(points, dtype=float).reshape(-1, 2)
        u = (p - self.origin) / self.spacing
        hi = np.array(self._d.shape) - 2
        cell = np.clip(np.floor(u).astype(np.int64), 0, hi)
        frac = np.clip(u - cell, 0.0, 1.0)
        tiles = cell // self.tile
        todo = ~self._done[tiles[:, 0], tiles[:, 1]]
        if todo.any():
            flat = np.unique(tiles[todo, 0] * self._done.shape[1] + tiles[todo, 1])
            self._fill(np.stack(np.divmod(flat, self._done.shape[1]), axis=1))
        i, j = cell[:, 0], cell[:, 1]
        d = self._d
        fx, fy = frac[:, 0], frac[:, 1]
        return ((d[i, j] * (1 - fx) + d[i + 1, j] * fx) * (1 - fy)
                + (d[i, j + 1] * (1 - fx) + d[i + 1, j + 1] * fx) * fy)  # fmt: skip
