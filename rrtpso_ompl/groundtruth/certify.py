"""A certificate of solvability: a collision-checked path through a grid of the free space.

:func:`grid_path` searches a fine grid of the free configuration space: grid points are free by
the world's exact point clearance (:meth:`~rrtpso_ompl.model.World.point_clearance`),
neighbouring free points are joined when the segment between them is free, and a shortest route
is found with Dijkstra's algorithm. A segment is accepted either by the exact test
:meth:`~rrtpso_ompl.model.World.segments_free` or, when both ends are far enough from every
obstacle, by the Lipschitz bound (clearance changes by at most the distance moved, so a segment of
length ``L`` whose ends both have clearance ``c`` keeps at least ``c - L/2`` everywhere). Every
edge of the returned polyline is therefore a genuine collision-free motion: a path found is a
proof that the problem is solvable, with no OMPL and no randomness. (The converse does not hold:
a passage narrower than the grid spacing may be missed.)
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse.csgraph import dijkstra

from ..errors import GenerationError
from ..model.geometry import shortcut as shortcut_path
from ..model.grid_graph import grid_graph, move_pairs, walk
from ..model.problem_types import Problem
from ..model.world import World
from ..validation import check_number

__all__ = ["GRID_POINTS", "grid_path", "is_solvable"]

#: Grid points per side of the solvability check unless ``resolution`` says otherwise: fine enough
#: for corridors a few percent of the workspace wide, coarse enough to take a fraction of a second.
GRID_POINTS = 200
#: Largest grid of the solvability check (memory: a few hundred bytes per point).
_MAX_GRID_POINTS = 4_000_000


def grid_path(
    problem: Problem, resolution: float | None = None, *, shortcut: bool = True
) -> np.ndarray | None:
    """A certified collision-free path from start to goal through a grid, or None.

    The grid covers the bounds with spacing at most ``resolution`` (edges included). A grid point
    is a node when the robot disc there is free (exact point clearance); nodes are joined to their
    8 neighbours when the segment between them is free (exact segment test, or the Lipschitz bound
    when both ends are far from every obstacle); start and goal are joined to the grid points of
    the cells around them by exact segment tests. Dijkstra's algorithm then finds the shortest
    grid route, which ``shortcut`` straightens by skipping waypoints while the straight segment
    stays free (exact test again).

    Parameters
    ----------
    problem : Problem
        A validated problem (moving obstacles are ignored, as by ``rrtpso solve``).
    resolution : float, optional
        Largest grid spacing; default 1/200 of the larger side of the bounds.
    shortcut : bool
        Straighten the grid route (default True): a shorter, still certified path.

    Returns
    -------
    (m, 2) ndarray or None
        The polyline, from ``start`` to ``goal`` (or to a grid point within ``goal_tolerance`` of
        it); every waypoint in bounds and every segment free, so
        ``World.from_problem(problem).path_valid(path)`` holds. None when the grid has no route,
        which does *not* prove the problem unsolvable (a passage narrower than the spacing may be
        missed).
    """
    world = World.from_problem(problem)
    grid = _Grid.over(world, resolution)
    a, b, length = _grid_edges(grid, world)
    ends = np.array([problem.start, problem.goal], dtype=float)
    extra = _end_edges(grid, world, ends)
    n_grid = len(grid.points)
    rows = np.concatenate([a, *(e[0] for e in extra)])
    cols = np.concatenate([b, *(e[1] for e in extra)])
    # csgraph drops explicit zero weights (no edge): a start on a grid point needs a tiny weight.
    weight = np.maximum(np.concatenate([length, *(e[2] for e in extra)]), 1e-12 * grid.spacing)
    graph = grid_graph(n_grid + 2, rows, cols, weight)
    dist, pred = dijkstra(graph, directed=False, indices=n_grid, return_predecessors=True)

    # The goal, or with a goal tolerance the nearest-by-route grid point within it.
    targets = [n_grid + 1]
    if problem.goal_tolerance > 0:
        near_goal = np.hypot(*(grid.points - ends[1]).T) <= problem.goal_tolerance
        targets += np.flatnonzero(grid.free & near_goal).tolist()
    best = min(targets, key=lambda t: dist[t])
    if not math.isfinite(dist[best]):
        return None
    path = np.vstack([grid.points, ends])[walk(pred, best)]  # from the start, the tree's root
    return shortcut_path(path, world.segments_free) if shortcut else path


class _Grid:
    """The grid points over the bounds, their clipped clearances and which are free.

    Node ``j * nx + i`` is the point ``(xs[i], ys[j])``.
    """

    def __init__(self, world: World, xs: np.ndarray, ys: np.ndarray) -> None:
        self.xs, self.ys = xs, ys
        self.nx, self.ny = len(xs), len(ys)
        self.hx, self.hy = xs[1] - xs[0], ys[1] - ys[0]
        self.spacing = max(self.hx, self.hy)
        gx, gy = np.meshgrid(xs, ys)
        self.points = np.column_stack([gx.ravel(), gy.ravel()])
        self.index = np.arange(self.nx * self.ny).reshape(self.ny, self.nx)
        # Clearance matters only up to what the edge test can use; beyond `cap` it is clipped.
        self.step = math.hypot(self.hx, self.hy)  # the longest grid edge
        cap = world.threshold + 0.5 * self.step + 2.0 * world.tol
        # Clearances up to `cap` through the world's index (exact; larger ones are clipped).
        self.clearance = np.minimum(world.point_clearance(self.points, cap=cap), cap)
        self.free = self.clearance >= world.threshold

    @classmethod
    def over(cls, world: World, resolution: float | None) -> _Grid:
        """The grid of spacing at most ``resolution`` (default 1/200 of the larger side)."""
        (xmin, ymin), (xmax, ymax) = world.bounds
        if resolution is None:
            resolution = max(xmax - xmin, ymax - ymin) / GRID_POINTS
        try:
            resolution = check_number(resolution, low=0.0, strict_low=True)
        except ValueError as exc:
            raise GenerationError(f"resolution {exc}") from None
        nx = math.ceil((xmax - xmin) / resolution) + 1
        ny = math.ceil((ymax - ymin) / resolution) + 1
        if nx * ny > _MAX_GRID_POINTS:
            raise GenerationError(
                f"resolution {resolution:g} is too fine for these bounds: {nx} x {ny} grid "
                f"points (at most {_MAX_GRID_POINTS:,})"
            )
        return cls(world, np.linspace(xmin, xmax, nx), np.linspace(ymin, ymax, ny))


def _grid_edges(grid: _Grid, world: World) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Free edges between free neighbours (right, up, up-right, up-left: each edge once):
    ``(a, b, length)``."""
    # Nodes are the free grid points; node j * nx + i sits at row j, column i of the index, so
    # right, up, up-right and up-left are the steps (0, 1), (1, 0), (1, 1), (1, -1) there.
    index = np.where(grid.free.reshape(grid.ny, grid.nx), grid.index, -1)
    pairs = [move_pairs(index, step) for step in ((0, 1), (1, 0), (1, 1), (1, -1))]
    a = np.concatenate([p[0] for p in pairs])
    b = np.concatenate([p[1] for p in pairs])
    length = np.hypot(*(grid.points[b] - grid.points[a]).T)
    # Lipschitz bound: clearance drops by at most the distance moved, and every point of a
    # segment is within L/2 of an end. The margin `tol` keeps the bound safe from round-off.
    lowest = np.minimum(grid.clearance[a], grid.clearance[b])
    sure = lowest - 0.5 * length >= world.threshold + world.tol
    unsure = np.flatnonzero(~sure)
    ok = sure.copy()
    if len(unsure):
        ok[unsure] = world.segments_free(grid.points[a[unsure]], grid.points[b[unsure]])
    return a[ok], b[ok], length[ok]


def _end_edges(grid: _Grid, world: World, ends: np.ndarray) -> list[tuple[np.ndarray, ...]]:
    """Start (node ``n``) and goal (node ``n + 1``) joined to the free grid points of the cells
    around them (within 1.5 cells), and to each other when the straight segment is free."""
    n_grid = len(grid.points)
    (xmin, ymin), _ = world.bounds
    reach = 1.5 * grid.spacing
    out = []
    for node, p in ((n_grid, ends[0]), (n_grid + 1, ends[1])):
        i_lo = max(0, math.floor((p[0] - xmin - reach) / grid.hx))
        i_hi = min(grid.nx - 1, math.ceil((p[0] - xmin + reach) / grid.hx))
        j_lo = max(0, math.floor((p[1] - ymin - reach) / grid.hy))
        j_hi = min(grid.ny - 1, math.ceil((p[1] - ymin + reach) / grid.hy))
        near = grid.index[j_lo : j_hi + 1, i_lo : i_hi + 1].ravel()
        near = near[grid.free[near]]
        near = near[np.hypot(*(grid.points[near] - p).T) <= reach]
        if len(near):
            near = near[world.segments_free(np.broadcast_to(p, (len(near), 2)), grid.points[near])]
        out.append((np.full(len(near), node), near, np.hypot(*(grid.points[near] - p).T)))
    # The straight segment itself, when free (then no grid is needed at all).
    if world.segments_free(ends[:1], ends[1:])[0]:
        length = float(np.hypot(*(ends[1] - ends[0])))
        out.append((np.array([n_grid]), np.array([n_grid + 1]), np.array([length])))
    return out


def is_solvable(problem: Problem, resolution: float | None = None) -> bool:
    """Whether :func:`grid_path` certifies the problem solvable (see there; False is not a proof
    of unsolvability)."""
    return grid_path(problem, resolution, shortcut=False) is not None
