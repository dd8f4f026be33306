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
from dataclasses import dataclass

import numpy as np

__all__ = ["DEFAULT_COST_SCALING_FACTOR", "DEFAULT_COST_WEIGHT", "MAX_SAMPLES", "InflationCost"]

#: Nav2's default ``cost_scaling_factor`` (1/m), used when only ``inflation_radius`` is given.
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
        """The cost of a :class:`~rrtpso_ompl.model.Robot` (its inflation keys)."""
        return cls(
            radius=robot.radius,
            inflation_radius=robot.inflation_radius or 0.0,
            cost_scaling_factor=robot.cost_scaling_factor or DEFAULT_COST_SCALING_FACTOR,
            weight=robot.cost_travel_multiplier or DEFAULT_COST_WEIGHT,
        )

    def cost(self, d: np.ndarray) -> np.ndarray:
        """``c(d)`` of distances ``d`` to the nearest obstacle (module docstring), in [0, 1]."""
        d = np.asarray(d, dtype=float)
        c = np.exp(-self.cost_scaling_factor * np.maximum(d - self.radius, 0.0))
        return np.where(d > self.inflation_radius, 0.0, c)

    def segment_integrals(self, world, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``integral c(d(s)) ds`` along each segment ``a[i]-b[i]`` (length units).

        Parameters
        ----------
        world : World
            Gives the exact distance to the nearest obstacle (``point_clearance``, through its
            index up to ``R_i``).
        a, b : (..., 2) array_like
            End points, broadcast together.

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
        c = self.cost(world.point_clearance(pts, cap=self.inflation_radius))
        out = np.bincount(seg, weights=c, minlength=len(a)) * (length / steps)
        return out.reshape(shape)

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
