"""Lattices over the workspace and which of their cells are wholly free.

A *lattice* is a grid of square cells of side ``h`` laid over the bounds. The corridor search of
:mod:`rrtpso_ompl.planners.rrtstar_pso.corridor` walks from cell to cell, so it needs to know
which cells the robot's centre may occupy *everywhere*: a path that stays inside such cells is
valid without a single further check. Two ways to answer, both conservative (a cell reported
free is free):

* an occupancy-grid map (:class:`MapRaster`) answers exactly, with array operations on its
  blocked cells: the distance from a lattice cell to the nearest blocked square is a Euclidean
  distance transform of the blocked cells grown by one cell (``scipy.ndimage``), so a map of a
  million cells takes milliseconds;
* circles and polygons answer through the exact point clearance at the cell's centre: the whole
  square keeps at least ``clearance - h / sqrt(2)`` (clearance is 1-Lipschitz).

For a point robot (``R = 0``) a cell counts as free when no obstacle enters its interior; its
border may touch one (a corridor one cell wide is still a corridor). The corridor search keeps
its path a little inside such cells.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Lattice", "MapRaster"]


@dataclass(frozen=True)
class Lattice:
    """Square cells ``[ox + i h, ox + (i + 1) h] x [oy + j h, oy + (j + 1) h]``, ``0 <= i < nx``,
    ``0 <= j < ny`` (cell ``(i, j)``: ``i`` along x, ``j`` along y).

    Attributes
    ----------
    origin : (float, float)
        Lower-left corner of cell ``(0, 0)``, problem units.
    h : float
        Side of a cell, problem units.
    nx, ny : int
        Cells along x and y.
    """

    origin: tuple[float, float]
    h: float
    nx: int
    ny: int

    def __post_init__(self) -> None:
        # Plain Python numbers (index arithmetic with numpy integers overflows or casts).
        object.__setattr__(self, "origin", (float(self.origin[0]), float(self.origin[1])))
        object.__setattr__(self, "h", float(self.h))
        object.__setattr__(self, "nx", int(self.nx))
        object.__setattr__(self, "ny", int(self.ny))

    @property
    def n_cells(self) -> int:
        return self.nx * self.ny

    def centres(self) -> np.ndarray:
        """(nx * ny, 2) cell centres, cell ``(i, j)`` at row ``i * ny + j``."""
        i, j = np.meshgrid(np.arange(self.nx), np.arange(self.ny), indexing="ij")
        ox, oy = self.origin
        return np.column_stack([ox + self.h * (i.ravel() + 0.5), oy + self.h * (j.ravel() + 0.5)])

    def centre(self, cell: tuple[int, int]) -> tuple[float, float]:
        return (
            self.origin[0] + self.h * (cell[0] + 0.5),
            self.origin[1] + self.h * (cell[1] + 0.5),
        )

    def cell_of(self, point) -> tuple[int, int]:
        """The cell holding ``point`` (clamped into the lattice)."""
        i = math.floor((point[0] - self.origin[0]) / self.h)
        j = math.floor((point[1] - self.origin[1]) / self.h)
        return min(max(i, 0), self.nx - 1), min(max(j, 0), self.ny - 1)

    @classmethod
    def over(cls, bounds, h: float, anchor=None) -> Lattice:
        """The lattice of cells of side ``h`` that lie wholly inside ``bounds``.

        With ``anchor`` (a point), cell corners fall on ``anchor + h * k`` (so that a map's cell
        edges are lattice lines); otherwise the cells are centred in the bounds.
        """
        (xmin, ymin), (xmax, ymax) = bounds
        if anchor is None:
            nx = max(int((xmax - xmin) // h), 0)
            ny = max(int((ymax - ymin) // h), 0)
            ox = xmin + 0.5 * ((xmax - xmin) - nx * h)
            oy = ymin + 0.5 * ((ymax - ymin) - ny * h)
            return cls((ox, oy), h, nx, ny)
        ax, ay = anchor
        # Smallest lattice line at or above the lower bound (with round-off slack).
        ox = ax + h * math.ceil((xmin - ax) / h - 1e-9)
        oy = ay + h * math.ceil((ymin - ay) / h - 1e-9)
        nx = max(math.floor((xmax - ox) / h + 1e-9), 0)
        ny = max(math.floor((ymax - oy) / h + 1e-9), 0)
        return cls((ox, oy), h, nx, ny)


@dataclass(frozen=True, eq=False)
class MapRaster:
    """An occupancy grid's blocked cells in the map frame, for lattice queries (a map that is not
    turned: a turned map's cells are no lattice of the world's axes, and its world has no raster,
    so the corridor stage uses generic cells there).

    Attributes
    ----------
    blocked : (W, H) ndarray of bool
        Cell ``(i, j)``: column ``i`` from the left, row ``j`` from the bottom (x right, y up).
    origin : (float, float)
        Lower-left corner of cell ``(0, 0)``.
    resolution : float
        Side of a map cell.
    outside_blocked : bool
        Whether space outside the map counts as blocked (``unknown: obstacle``).
    """

    blocked: np.ndarray
    origin: tuple[float, float]
    resolution: float
    outside_blocked: bool = True

    @classmethod
    def from_image(cls, blocked_image: np.ndarray, origin, resolution, outside_blocked=True):
        """From blocked cells in image order (row 0 on top)."""
        grid = np.ascontiguousarray(np.asarray(blocked_image, dtype=bool)[::-1].T)
        return cls(grid, (float(origin[0]), float(origin[1])), float(resolution), outside_blocked)

    def lattice(self, bounds, max_cells: int, split: int = 4) -> Lattice:
        """The finest lattice aligned with the map's cells (the map's own cells, split in two or
        four, at most ``split``, when the map is small, merged 2 x 2, 3 x 3, ... when it is
        large) of at most ``max_cells`` cells inside ``bounds``."""
        res = self.resolution
        for sub in (s for s in (4, 2, 1) if s <= split):
            lat = Lattice.over(bounds, res / sub, self.origin)
            if lat.n_cells <= max_cells:
                return lat
        k = 2
        while True:
            lat = Lattice.over(bounds, res * k, self.origin)
            if lat.n_cells <= max_cells:
                return lat
            k += 1

    def blocked_on(self, lat: Lattice) -> np.ndarray:
        """(nx, ny) booleans: lattice cells that overlap a blocked map cell (or, when outside
        space blocks, that reach beyond the map). ``lat`` must be aligned with the map."""
        res = self.resolution
        ratio = lat.h / res
        # Map-cell index of the lattice's lower-left corner.
        i0 = round((lat.origin[0] - self.origin[0]) / res)
        j0 = round((lat.origin[1] - self.origin[1]) / res)
        w, hgt = self.blocked.shape
        if ratio >= 1.0 - 1e-9:
            k = round(ratio)
            span_x, span_y = lat.nx * k, lat.ny * k
            window = self._window(i0, j0, span_x, span_y)
            return window.reshape(lat.nx, k, lat.ny, k).any(axis=(1, 3))
        sub = round(1.0 / ratio)
        # Lattice cells are sub-cells of map cells: map cell of lattice cell (i, j) is
        # (i0' + i // sub) with the lattice origin on a sub-cell line.
        fx = (lat.origin[0] - self.origin[0]) / lat.h
        fy = (lat.origin[1] - self.origin[1]) / lat.h
        ix = (round(fx) + np.arange(lat.nx)) // sub
        iy = (round(fy) + np.arange(lat.ny)) // sub
        inside_x = (ix >= 0) & (ix < w)
        inside_y = (iy >= 0) & (iy < hgt)
        out = np.full((lat.nx, lat.ny), self.outside_blocked)
        sel = np.ix_(np.flatnonzero(inside_x), np.flatnonzero(inside_y))
        out[sel] = self.blocked[np.ix_(ix[inside_x], iy[inside_y])]
        return out

    def _window(self, i0: int, j0: int, nx: int, ny: int) -> np.ndarray:
        """Map cells ``[i0, i0 + nx) x [j0, j0 + ny)``, outside padded by ``outside_blocked``."""
        w, h = self.blocked.shape
        out = np.full((nx, ny), self.outside_blocked)
        a0, a1 = max(i0, 0), min(i0 + nx, w)
        b0, b1 = max(j0, 0), min(j0 + ny, h)
        if a0 < a1 and b0 < b1:
            out[a0 - i0 : a1 - i0, b0 - j0 : b1 - j0] = self.blocked[a0:a1, b0:b1]
        return out

    def free_cells(self, lat: Lattice, clearance: float, bounds=None) -> np.ndarray:
        """(nx, ny) booleans: lattice cells every point of which keeps ``clearance`` from every
        blocked map cell (``clearance <= 0``: cells no blocked cell enters; they may touch one).

        Exact for a lattice aligned with the map: the distance between the squares of cells
        ``(i, j)`` and ``(k, l)`` is ``h * hypot(max(|i - k| - 1, 0), max(|j - l| - 1, 0))``,
        the centre distance to the nearest cell of the blocked set grown by one cell in each
        direction, which is one Euclidean distance transform. Conservative on a coarser lattice
        (a lattice cell counts as blocked when any map cell in it is). Blocked cells just
        outside the lattice count too; beyond ``bounds`` (where the robot's centre never goes,
        but its disc may reach) only the map's own cells do.
        """
        if clearance <= 0.0:
            return ~self.blocked_on(lat)
        ext = math.ceil(clearance / lat.h) + 2
        ox, oy = lat.origin
        wide = Lattice((ox - ext * lat.h, oy - ext * lat.h), lat.h, lat.nx + 2 * ext,
                       lat.ny + 2 * ext)  # fmt: skip
        blocked = self.blocked_on(wide)
        if bounds is not None and self.outside_blocked:
            # Unknown space outside the map blocks only inside the bounds (as the world's boxes).
            (xmin, ymin), (xmax, ymax) = bounds
            (mx0, my0), (mx1, my1) = self.extent
            cx = wide.origin[0] + lat.h * (np.arange(wide.nx) + 0.5)
            cy = wide.origin[1] + lat.h * (np.arange(wide.ny) + 0.5)
            half = 0.5 * lat.h
            beyond_x = (cx + half <= xmin) | (cx - half >= xmax)
            beyond_y = (cy + half <= ymin) | (cy - half >= ymax)
            off_map_x = (cx + half <= mx0) | (cx - half >= mx1)
            off_map_y = (cy + half <= my0) | (cy - half >= my1)
            clear = (beyond_x[:, None] | beyond_y[None, :]) & (
                off_map_x[:, None] | off_map_y[None, :]
            )
            blocked = blocked & ~clear
        from scipy import ndimage  # here: the model stage loads without SciPy

        grown = ndimage.binary_dilation(blocked, structure=np.ones((3, 3), dtype=bool))
        if not grown.any():
            return np.ones((lat.nx, lat.ny), dtype=bool)
        dist = ndimage.distance_transform_edt(~grown) * lat.h
        return dist[ext : ext + lat.nx, ext : ext + lat.ny] >= clearance

    def thin_free_cells(self, i0: int, j0: int, near: np.ndarray, k: int,
                        clearance: float) -> np.ndarray:  # fmt: skip
        """Booleans of the cells of map cells ``[i0, i0 + n0) x [j0, j0 + n1)`` split ``k`` x ``k``
        (``n0 k`` x ``n1 k``, a lattice aligned with the map), true where every point keeps
        ``clearance`` from every blocked map cell; only map cells where ``near`` ((n0, n1)
        booleans) is true are asked about, the others come back False.

        Exact for ``clearance`` up to a map cell, where only the 8 neighbours of a cell can come
        that close: per neighbour, the sub-cells within ``clearance`` of it are a fixed ``k`` x
        ``k`` pattern, so the work is ``9 k^2`` per cell asked about, however large the box
        (:meth:`free_cells` transforms the whole box).
        """
        if not 0.0 <= clearance <= self.resolution:
            raise ValueError("thin_free_cells needs a clearance of at most one map cell")
        n0, n1 = near.shape
        window = self._window(i0 - 1, j0 - 1, n0 + 2, n1 + 2)
        c = clearance / self.resolution
        lo, hi = np.arange(k) / k, np.arange(1, k + 1) / k
        # Gap along one axis between sub-cell a and the neighbour at offset d (map-cell units).
        gap = {d: np.maximum(np.maximum(d - hi, lo - (d + 1)), 0.0) for d in (-1, 0, 1)}
        asked = near & ~window[1:-1, 1:-1]
        out = np.repeat(np.repeat(asked, k, axis=0), k, axis=1)
        view = out.reshape(n0, k, n1, k)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                close = np.hypot(gap[di][:, None], gap[dj][None, :]) < c
                if (di, dj) == (0, 0) or not close.any():
                    continue
                blocked = window[1 + di : 1 + di + n0, 1 + dj : 1 + dj + n1] & asked
                view &= ~(blocked[:, None, :, None] & close[None, :, None, :])
        return out

    @property
    def extent(self):
        """``((xmin, ymin), (xmax, ymax))`` of the map."""
        w, h = self.blocked.shape
        ox, oy = self.origin
        return (ox, oy), (ox + w * self.resolution, oy + h * self.resolution)
