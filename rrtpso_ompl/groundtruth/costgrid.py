r"""The reference for the inflation objective: a fine-grid search, as NavFn and Smac 2D plan on a
costmap.

With inflation (:mod:`rrtpso_ompl.model.objective`: ``J = length + w * integral of c(d)``, the
formula is declared there once) the exact shortest path (:mod:`.optimum`) is no longer the
reference: the best path keeps away from walls where there is room. Nav2's grid planners search
their costmap's cells; this module does the same on a lattice of the bounds, with the exact
geometry and the planners' own cost:

1. **Nodes**: the centres of a lattice of square cells (:class:`~rrtpso_ompl.model.raster.Lattice`)
   of side ``h`` (the *resolution*): by default the map's own cells for a map problem (the
   costmap Nav2 would plan on), else about :data:`TARGET_NODES` cells over the bounds. A node is
   free when its exact clearance (:meth:`~rrtpso_ompl.model.World.point_clearance`) is at least
   the robot radius.
2. **Edges**: 16-connected: the 8 neighbours and the 8 knight moves (``(2, 1)`` and its
   rotations). The knight moves cut the metrication error: the grid route of a straight line
   is at worst ``1 / cos(22.5 deg)``, 8.2 %, longer on 8 directions, ``1 / cos(13.3 deg)``,
   2.7 %, on 16.
   An edge is kept when its whole segment is free: by the Lipschitz bound (clearance changes by
   at most the distance moved, so a segment of length ``L`` between end clearances ``d_a, d_b``
   keeps at least ``(d_a + d_b - L) / 2``) or else the exact test
   (:meth:`~rrtpso_ompl.model.World.segments_free`).
3. **Costs**: an edge costs its ``J`` (:meth:`InflationCost.segment_integrals
   <rrtpso_ompl.model.objective.InflationCost.segment_integrals>`, all edges at once in chunks);
   an edge whose Lipschitz bound exceeds the inflation radius costs its length exactly (every
   quadrature point has ``c = 0`` there), without sampling.
4. **Search**: Dijkstra (``scipy.sparse.csgraph``) from the start, joined by exact free segments
   to the free nodes around it (5 x 5 cells, wider when none is in free sight), to the goal,
   joined alike, or to any free node within the goal tolerance; and the straight segment from
   start to goal when it is free.
5. **Smoothing** (optional, on by default): shortcuts over 64, 32, ..., 2 vertices, each kept
   only when its segment is free and its ``J`` is lower than that of the vertices it skips. ``J``
   is a sum over segments, so every kept shortcut lowers the path's ``J``: the smoothed path never
   costs more than the grid path, and both costs are reported.

The ``cost`` reported is :meth:`InflationCost.path_cost
<rrtpso_ompl.model.objective.InflationCost.path_cost>` of the returned polyline: the evaluator
every planner's result goes through, so the numbers compare directly. The path is valid, so its
``J`` is an upper bound on the best ``J``, not a proof of optimality: a finer ``resolution``
usually lowers it.

Bounds (measured by ``benchmarks/cost_reference.py``, docs/cost-reference.md, CPU seconds on a
shared 2-core machine, 1 m inflation): 4-8 s and 150-260 MB for the office and lab maps
(192,000-240,000 nodes, about a million edges), 23 s and 630 MB for the warehouse map (1.7
million nodes, 7.6 million edges), 4 s for a 256 x 256-cell floor plan, 6 s and 360 MB for a
world of shapes at the default :data:`TARGET_NODES`. Most of it is the exact clearance of the
quadrature points of the edges near obstacles. Time and memory grow with the nodes (and the
share of them near obstacles): under 1 GB at :data:`MAX_NODES`. Above :data:`MAX_NODES`
lattice nodes the default resolution is coarsened (the map's cells merged 2 x 2, 3 x 3, ...: the
result's ``coarsened`` says so) and an explicit ``resolution`` is refused (:class:`CostGridError`).

Nothing here imports OMPL.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.sparse.csgraph import dijkstra

from ..errors import RrtpsoError
from ..model.grid_graph import MOVES_16, grid_graph, move_pairs, walk
from ..model.objective import InflationCost
from ..model.problem_types import Problem
from ..model.raster import Lattice
from ..model.world import World
from ..validation import check_number

__all__ = [
    "MAX_NODES",
    "TARGET_NODES",
    "CostGridError",
    "CostGridResult",
    "cost_reference",
    "cost_reference_in_world",
    "smooth_path",
]

#: Lattice nodes of the default resolution of a problem without a map (a cell of side
#: ``sqrt(area / TARGET_NODES)``).
TARGET_NODES = 500_000
#: Most lattice nodes of one search (memory: the warehouse map's 1.7 million took 630 MB at the
#: peak, mostly the edges' arrays and the graph).
MAX_NODES = 2_000_000
#: The 8 undirected moves of the 16-connected lattice (each edge once): right, up, the two
#: diagonals and the four knight moves; their opposites are the same edges. Each edge is
#: checked exactly, so the cells a move passes need not be nodes.
MOVES = tuple(step for step, _, _ in MOVES_16)
#: Most quadrature samples one call of the cost integral takes (memory: about 100 bytes each).
_SAMPLE_CHUNK = 2_000_000
#: Shortcut spans of the smoothing, in vertices (each round tries them all, longest first).
_SPANS = (64, 32, 16, 8, 4, 2)
#: Most rounds of the smoothing (each stops early when no shortcut lowers the cost).
_SMOOTH_ROUNDS = 30


class CostGridError(RrtpsoError, ValueError):
    """A resolution that is not a positive number, or that would give the lattice more than
    :data:`MAX_NODES` nodes."""


@dataclass(frozen=True)
class CostGridResult:
    """The grid reference of a problem's objective, or the report that the grid has no path.

    Attributes
    ----------
    problem : str
        Problem name.
    path : (m, 2) ndarray
        Start to goal (or to a node within the goal tolerance); empty when not found. Every
        segment is free (exact).
    cost : float or None
        ``J`` of :attr:`path` (:meth:`InflationCost.path_cost`), length units.
    length : float or None
        Its length.
    grid_cost, grid_length : float or None
        The same of the grid path before smoothing (``cost <= grid_cost``).
    resolution : float
        Side ``h`` of the lattice's cells (its node spacing), length units.
    coarsened : bool
        The default resolution was coarsened to stay within :data:`MAX_NODES`.
    nodes, free_nodes, edges : int
        Lattice nodes, free ones, and free edges (each once).
    time : float
        Seconds spent (smoothing included).
    smoothed : bool
        Whether the smoothing ran.
    inflation : dict
        The objective's parameters (``radius``, ``inflation_radius``, ``cost_scaling_factor``,
        ``weight``).
    """

    problem: str
    path: np.ndarray = field(repr=False)
    cost: float | None
    length: float | None
    grid_cost: float | None
    grid_length: float | None
    resolution: float
    coarsened: bool
    nodes: int
    free_nodes: int
    edges: int
    time: float
    smoothed: bool
    inflation: dict[str, float]

    @property
    def found(self) -> bool:
        """Whether the grid joins start and goal (False proves nothing: a passage narrower than
        the lattice may be missed)."""
        return self.cost is not None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary: the contract's ``length`` and ``path`` first, then ``cost``."""
        return {
            "length": self.length,
            "path": self.path.tolist(),
            "cost": self.cost,
            "problem": self.problem,
            "reference": "grid",
            "grid": {
                "resolution": self.resolution,
                "coarsened": self.coarsened,
                "connectivity": 16,
                "nodes": self.nodes,
                "free_nodes": self.free_nodes,
                "edges": self.edges,
                "cost": self.grid_cost,
                "length": self.grid_length,
            },
            "smoothed": self.smoothed,
            "inflation": dict(self.inflation),
            "time": self.time,
        }


# ----------------------------------------------------------------------------------------------
def cost_reference(
    problem: Problem,
    world: World | None = None,
    *,
    resolution: float | None = None,
    smooth: bool = True,
) -> CostGridResult:
    """The grid reference of ``problem``'s objective (:class:`InflationCost.of` its robot).

    Parameters
    ----------
    problem : Problem
        A validated problem (moving obstacles ignored).
    world : World, optional
        Its static world, when already built.
    resolution : float, optional
        Node spacing, length units; default the map's resolution (aligned with its cells), else
        the spacing of about :data:`TARGET_NODES` nodes.
    smooth : bool
        Shortcut the grid path where that lowers ``J`` (module docstring).

    Raises
    ------
    CostGridError
        When ``resolution`` is not a positive number or, given explicitly, gives more than
        :data:`MAX_NODES` nodes.
    """
    world = world or World.from_problem(problem)
    anchor = problem.map.origin if problem.map is not None else None
    if resolution is None and problem.map is not None:
        resolution = problem.map.resolution
        explicit = False
    else:
        explicit = resolution is not None
    return cost_reference_in_world(
        world, problem.objective, problem.start[:2], problem.goal[:2],
        float(problem.goal_tolerance), resolution=resolution, explicit=explicit, anchor=anchor,
        smooth=smooth, name=problem.name,
    )  # fmt: skip


def cost_reference_in_world(
    world: World,
    cost: InflationCost,
    start,
    goal,
    goal_tolerance: float = 0.0,
    *,
    resolution: float | None = None,
    explicit: bool = True,
    anchor=None,
    smooth: bool = True,
    name: str = "",
) -> CostGridResult:
    """:func:`cost_reference` for a world, a cost and a query.

    Parameters
    ----------
    world : World
        Obstacles, bounds and the robot radius (the hard constraint).
    cost : InflationCost
        The objective.
    start, goal : (float, float)
        The query, length units.
    goal_tolerance : float
        Radius of the goal disc: free nodes within it are goals too.
    resolution : float, optional
        Node spacing; default about :data:`TARGET_NODES` nodes over the bounds.
    explicit : bool
        Whether ``resolution`` was asked for (refused above :data:`MAX_NODES` nodes) or is a
        default (coarsened instead).
    anchor : (float, float), optional
        A point on the lattice's cell corners (a map's origin: nodes at its cell centres).
    smooth, name
        As for :func:`cost_reference`.
    """
    t0 = time.perf_counter()
    start = np.asarray(start, dtype=float)[:2]
    goal = np.asarray(goal, dtype=float)[:2]
    lat, coarsened = _lattice(world.bounds, resolution, explicit, anchor)
    grid = _Nodes(world, cost, lat)
    ends = np.array([start, goal])
    if math.dist(start, goal) <= goal_tolerance or np.array_equal(start, goal):
        a = b = weight = np.empty(0)  # already there: the path is the start alone
        grid_path = path = start[None]
    else:
        a, b, weight = grid.edges()
        grid_path = path = _search(grid, ends, a, b, weight, goal_tolerance)
        if smooth and len(path) > 2:
            path = smooth_path(world, cost, path)
    return _result(world, cost, name, (path, grid_path), lat, coarsened, grid, len(a), t0,
                   bool(smooth and len(grid_path) > 2))  # fmt: skip


def _result(world, cost, name, paths, lat, coarsened, grid, n_edges, t0, smoothed):
    """The :class:`CostGridResult` of a search: ``paths = (path, grid_path)``, both empty when
    none was found."""
    path, grid_path = paths
    found = len(path) > 0
    return CostGridResult(
        problem=name,
        path=path,
        cost=cost.path_cost(world, path) if found else None,
        length=_length(path) if found else None,
        grid_cost=cost.path_cost(world, grid_path) if found else None,
        grid_length=_length(grid_path) if found else None,
        resolution=lat.h,
        coarsened=coarsened,
        nodes=lat.n_cells,
        free_nodes=grid.n_free,
        edges=n_edges,
        time=time.perf_counter() - t0,
        smoothed=smoothed,
        inflation={
            "radius": cost.radius,
            "inflation_radius": cost.inflation_radius,
            "cost_scaling_factor": cost.cost_scaling_factor,
            "weight": cost.weight,
        },
    )


def _search(grid: _Nodes, ends: np.ndarray, a, b, weight, goal_tolerance: float) -> np.ndarray:
    """Dijkstra from the start (node ``n``) to the goal (node ``n + 1``) or the cheapest free
    node within the goal tolerance: the path as an ``(m, 2)`` polyline, empty when none."""
    n = grid.n_free
    extra = _end_edges(grid, ends)
    rows = np.concatenate([a, *(e[0] for e in extra)])
    cols = np.concatenate([b, *(e[1] for e in extra)])
    weights = np.concatenate([weight, *(e[2] for e in extra)])
    graph = grid_graph(n + 2, rows, cols, weights)
    del rows, cols, weights
    dist, pred = dijkstra(graph, directed=False, indices=n, return_predecessors=True)
    del graph
    targets = np.concatenate([[n + 1], grid.within(ends[1], goal_tolerance)]).astype(np.int64)
    best = int(targets[np.argmin(dist[targets])])
    if not math.isfinite(dist[best]):
        return np.empty((0, 2))
    route = walk(pred, best)  # from the start: the tree's root
    return np.vstack([grid.points, ends])[route]


def _length(path: np.ndarray) -> float:
    return float(np.hypot(*np.diff(path, axis=0).T).sum())


def _lattice(bounds, resolution: float | None, explicit: bool, anchor) -> tuple[Lattice, bool]:
    """The lattice of the search, and whether its resolution was coarsened."""
    (xmin, ymin), (xmax, ymax) = bounds
    if resolution is None:
        resolution = math.sqrt((xmax - xmin) * (ymax - ymin) / TARGET_NODES)
    try:
        resolution = check_number(resolution, low=0.0, strict_low=True)
    except ValueError as exc:
        raise CostGridError(f"resolution {exc}") from None
    lat = Lattice.over(bounds, resolution, anchor)
    if lat.n_cells <= MAX_NODES:
        return lat, False
    if explicit:
        raise CostGridError(
            f"resolution {resolution:g} gives {lat.nx} x {lat.ny} = {lat.n_cells:,} grid nodes "
            f"(at most {MAX_NODES:,}): use a coarser resolution"
        )
    k = 2  # cells merged k x k, so a map's lattice stays aligned with its cells
    while (lat := Lattice.over(bounds, resolution * k, anchor)).n_cells > MAX_NODES:
        k += 1
    return lat, True


class _Nodes:
    """The free lattice nodes, numbered ``0 .. n_free - 1``, and their clearances.

    Parameters
    ----------
    world : World
    cost : InflationCost
    lat : Lattice
    """

    def __init__(self, world: World, cost: InflationCost, lat: Lattice) -> None:
        self.world, self.cost, self.lat = world, cost, lat
        longest = lat.h * math.hypot(*max(MOVES, key=lambda m: math.hypot(*m)))
        # Clearance matters up to where an edge's bound certifies it free and costless.
        reach = max(cost.inflation_radius if cost.active else 0.0, world.threshold)
        self.cap = reach + 0.5 * longest + 4.0 * world.tol
        centres = lat.centres()
        d = world.point_clearance(centres, cap=self.cap)
        d = np.where(np.isinf(d), self.cap, d)  # beyond the cap: at least the cap
        free = d >= world.threshold
        self.index = np.full(lat.n_cells, -1, dtype=np.int64)
        self.index[free] = np.arange(int(free.sum()))
        self.index = self.index.reshape(lat.nx, lat.ny)
        self.points = centres[free]
        self.clearance = d[free]
        self.n_free = len(self.points)

    def edges(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Free edges between free nodes, each once: ``(a, b, J)``."""
        parts = [self._move(di, dj) for di, dj in MOVES]
        return tuple(np.concatenate([p[k] for p in parts]) for k in range(3))  # type: ignore

    def _move(self, di: int, dj: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The free edges of one move ``(di, dj)``: node ``(i, j)`` to ``(i + di, j + dj)``."""
        a, b = move_pairs(self.index, (di, dj))
        world, cost = self.world, self.cost
        length = self.lat.h * math.hypot(di, dj)
        # Lipschitz: a point of the segment at t from a has clearance >= max(d_a - t, d_b - L + t).
        low = 0.5 * (self.clearance[a] + self.clearance[b] - length)
        ok = low >= world.threshold + world.tol
        unsure = np.flatnonzero(~ok)
        if len(unsure):
            ok[unsure] = world.segments_free(self.points[a[unsure]], self.points[b[unsure]])
        a, b, low = a[ok], b[ok], low[ok]
        weight = np.full(len(a), length)
        if cost.active:
            # Beyond the inflation radius c = 0 at every quadrature point: J is the length.
            near = np.flatnonzero(low <= cost.inflation_radius)
            per_edge = max(1, math.ceil(length / cost.step))
            chunk = max(1, _SAMPLE_CHUNK // per_edge)
            for k in range(0, len(near), chunk):
                e = near[k : k + chunk]
                integral = cost.segment_integrals(world, self.points[a[e]], self.points[b[e]])
                weight[e] += cost.weight * integral
        return a.astype(np.int32), b.astype(np.int32), weight

    def around(self, p: np.ndarray, m: int) -> np.ndarray:
        """The free nodes in the ``(2m + 1)^2`` cells around the cell of ``p``."""
        i, j = self.lat.cell_of(p)
        block = self.index[max(0, i - m) : i + m + 1, max(0, j - m) : j + m + 1].ravel()
        return block[block >= 0]

    def within(self, p: np.ndarray, radius: float) -> np.ndarray:
        """The free nodes within ``radius`` of ``p``."""
        if radius <= 0.0:
            return np.empty(0, dtype=np.int64)
        near = self.around(p, math.ceil(radius / self.lat.h) + 1)
        return near[np.hypot(*(self.points[near] - p).T) <= radius]


def _end_edges(grid: _Nodes, ends: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Start (node ``n``) and goal (node ``n + 1``) joined by exact free segments to the free
    nodes of the 5 x 5 cells around them (9 x 9, 17 x 17, 33 x 33 while none is in free sight),
    and to each other when the straight segment is free."""
    world, cost, n = grid.world, grid.cost, grid.n_free
    out = []
    for node, p in ((n, ends[0]), (n + 1, ends[1])):
        for m in (2, 4, 8, 16):
            near = grid.around(p, m)
            q = np.broadcast_to(p, (len(near), 2))
            near = near[world.segments_free(q, grid.points[near])] if len(near) else near
            if len(near):
                break
        j = cost.path_costs(world, np.stack([np.broadcast_to(p, (len(near), 2)),
                                             grid.points[near]], axis=1))  # fmt: skip
        out.append((np.full(len(near), node), near, np.maximum(j, 1e-300)))
    if world.segments_free(ends[:1], ends[1:])[0] and not np.array_equal(ends[0], ends[1]):
        j = cost.path_costs(world, ends[None])
        out.append((np.array([n]), np.array([n + 1]), j))
    return out


# ----------------------------------------------------------------------------------------------
def smooth_path(world: World, cost: InflationCost, path: np.ndarray) -> np.ndarray:
    """Shortcuts that lower ``J``: never a higher cost, always a valid path for a valid input.

    Each round tries, for spans of 64, 32, ..., 2 vertices, the segment from every vertex ``i``
    to ``i + span``; a shortcut is kept when the segment is free and its ``J`` is lower than the
    sum of the ``J`` of the segments it replaces (``J`` is additive over segments), the kept ones
    not overlapping (greedily, from the start). Rounds repeat while any shortcut is kept (at
    most :data:`_SMOOTH_ROUNDS`).

    Parameters
    ----------
    world : World
    cost : InflationCost
    path : (n, 2) array_like
        A valid polyline.

    Returns
    -------
    (k, 2) ndarray
        A subset of the vertices, end points kept.
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    for _ in range(_SMOOTH_ROUNDS):
        changed = False
        for span in _SPANS:
            if len(p) <= span:
                continue
            seg = cost.path_costs(world, np.stack([p[:-1], p[1:]], axis=1))
            prefix = np.concatenate([[0.0], np.cumsum(seg)])
            i = np.arange(len(p) - span)
            old = prefix[i + span] - prefix[i]
            new = cost.path_costs(world, np.stack([p[i], p[i + span]], axis=1))
            gain = np.flatnonzero(new < old)
            if len(gain):
                gain = gain[world.segments_free(p[gain], p[gain + span])]
            if not len(gain):
                continue
            drop = np.zeros(len(p), dtype=bool)
            last = -1
            for k in gain.tolist():  # non-overlapping, from the start
                if k >= last:
                    drop[k + 1 : k + span] = True
                    last = k + span
            p = p[~drop]
            changed = True
        if not changed:
            break
    return p
