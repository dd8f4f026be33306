"""The exact optimum's entry points: a problem, or a world and a query, in; an
:class:`~.result.OptimumResult` out.

:func:`shortest_path_in_world` turns a turned map into its grid coordinates (or its boxes into
polygons), rounds a point robot's corners (radius ``2 tol``), settles the trivial and the
unsolvable cases with the conservative raster (:mod:`..free_grid`), and runs the tangent search
(:mod:`.search`) in rounds of growing bounds until one finds a path within its bound: the
package docstring tells why the answer is exact. A point robot on a map alone goes through the
interval search instead (:mod:`.intervals`, :func:`_on_map`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ...model.problem_types import Problem
from ...model.world import World
from ..free_grid import FreeGrid, Stopped, box_lattice
from .circles import NodeCircles
from .intervals import corner_sides, interval_path, rounded
from .mesh import RectMesh
from .result import OptimumResult, OptimumTooLarge, Piece
from .search import TangentSearch

__all__ = ["shortest_path", "shortest_path_in_world"]


def shortest_path(
    problem: Problem,
    world: World | None = None,
    upper_bound: float | None = None,
    *,
    terminate: Callable[[], bool] | None = None,
) -> OptimumResult:
    """The shortest collision-free path of ``problem`` for its disc robot (moving obstacles
    ignored).

    Parameters
    ----------
    problem : Problem
        A validated problem.
    world : World, optional
        Its static world, when already built.
    upper_bound : float, optional
        The length of any valid path, or ``inf``: the search never looks beyond it. By default
        none is needed: the search runs in rounds of growing bounds (package docstring).
    terminate : callable, optional
        Polled between expansions; when it returns True the search stops and the result has
        ``stopped`` set and no path.

    Returns
    -------
    OptimumResult
        ``length`` None when no path exists (or when stopped).

    Raises
    ------
    OptimumTooLarge
        When the search would create more than :data:`MAX_NODES` tangent nodes.
    """
    world = world or World.from_problem(problem)
    return shortest_path_in_world(
        world, problem.start[:2], problem.goal[:2], float(problem.goal_tolerance),
        upper_bound=upper_bound, terminate=terminate, name=problem.name, source=problem.source,
    )  # fmt: skip


def shortest_path_in_world(
    world: World,
    start,
    goal,
    goal_tolerance: float = 0.0,
    *,
    upper_bound: float | None = None,
    terminate: Callable[[], bool] | None = None,
    name: str = "",
    source: str = "<world>",
) -> OptimumResult:
    """:func:`shortest_path` for a :class:`~rrtpso_ompl.model.World` and a query (what the
    ``Exact`` planner has: no problem file).

    Parameters
    ----------
    world : World
        Obstacles, bounds and robot radius.
    start, goal : (float, float)
        The query, problem units.
    goal_tolerance : float
        Radius of the goal disc (0: the goal point).
    upper_bound, terminate
        As for :func:`shortest_path`.
    name, source : str
        The problem's name (for the result) and where it came from (for messages).
    """
    frame = world.box_frame
    if frame is not None and frame.confined is not None:
        local = shortest_path_in_world(
            _grid_frame_world(world), frame.to_grid(np.asarray(start, dtype=float)[:2]),
            frame.to_grid(np.asarray(goal, dtype=float)[:2]), goal_tolerance,
            upper_bound=upper_bound, terminate=terminate, name=name, source=source,
        )  # fmt: skip
        return replace(local, pieces=[_turned(p, frame) for p in local.pieces])
    if frame is not None:
        world = _boxes_as_polygons(world)
    t0 = time.perf_counter()
    start = np.asarray(start, dtype=float)[:2]
    goal = np.asarray(goal, dtype=float)[:2]
    goal_tol = float(goal_tolerance)
    if math.dist(start, goal) <= goal_tol or np.array_equal(start, goal):
        still = Piece("line", tuple(map(float, start)), tuple(map(float, start)))
        return OptimumResult(name, 0.0, [still], True, 1, 0, time.perf_counter() - t0)
    cap = math.inf if upper_bound is None else float(upper_bound)
    lattice = _point_on_map(world, goal_tol)
    if lattice is not None:
        return _on_map(lattice, 2.0 * world.tol, start, goal, cap, terminate, source,
                       _Report(name, True, t0))  # fmt: skip
    radius = max(world.robot_radius, 2.0 * world.tol)  # see the package docstring for R = 0
    if radius != world.robot_radius:
        world = world.with_robot_radius(radius)
    exact = goal_tol == 0.0 or bool(
        world.point_clearance(goal[None])[0] >= goal_tol + world.threshold
    )
    report = _Report(name, exact, t0)
    return _search(world, start, goal, goal_tol, cap, terminate, source, report)


@dataclass(frozen=True)
class _Report:
    """Makes the :class:`OptimumResult` of one query: its name, whether it is exact, and when it
    started (``time.perf_counter()`` seconds)."""

    name: str
    exact: bool
    t0: float

    def __call__(self, found, search=None, stopped=False, rounds=0) -> OptimumResult:
        """The result of ``found`` (``(length, pieces)`` or None) after ``search``."""
        nodes, edges = (search.n_nodes, search.n_edges) if search is not None else (0, 0)
        seconds = time.perf_counter() - self.t0
        if found is None:
            return OptimumResult(self.name, None, [], self.exact, nodes, edges, seconds, stopped,
                                 rounds)  # fmt: skip
        length, pieces = found
        pieces = _merge_arcs([p for p in pieces if p.length > 0.0] or pieces[:1])
        return OptimumResult(self.name, length, pieces, self.exact, nodes, edges, seconds, False,
                             rounds)  # fmt: skip


def _search(world: World, start: np.ndarray, goal: np.ndarray, goal_tol: float, cap: float,
            terminate: Callable[[], bool] | None, source: str,
            report: _Report) -> OptimumResult:  # fmt: skip
    """The raster's proof or bounds, then the tangent search in rounds of growing bounds up to
    ``cap`` (package docstring); start and goal apart, the robot radius at least twice the
    tolerance."""
    stop = terminate if terminate is not None else (lambda: False)
    if stop():
        return report(None, stopped=True)
    try:
        grid = FreeGrid.for_world(world, start, goal, goal_tol, terminate)
    except Stopped:
        return report(None, stopped=True)
    if not grid.connected:  # a proof: no chain of possibly-free cells joins them
        return report(None)
    if stop():
        return report(None, stopped=True)
    sharp = guess = 0.0
    if grid.gates is None:  # else the gates' bound is closer than the point's guess
        try:
            sharp, guess = _point_path(world, start, goal, goal_tol, terminate, source)
        except Stopped:
            return report(None, stopped=True)
    if grid.refinable and sharp > _REFINE * float(grid.lower_bound(1, start[None])[0]):
        grid = None  # blocks of cells lost the map's walls (rooms', a maze's): cell by cell
        try:
            grid = FreeGrid.for_world(world, start, goal, goal_tol, terminate, cell_by_cell=True)
        except Stopped:
            return report(None, stopped=True)
    lower = max(float(grid.lower_bound(1, start[None])[0]), sharp)
    if lower == math.inf:  # a proof: no point (no chain of gates) passes between them
        return report(None)
    nodes = NodeCircles.build(world, grid, start, goal, world.robot_radius)
    search = None
    kind = "lattice" if grid.blocked is not None else "generic"
    if guess > lower:
        lower, kind = guess, "guess"
    for k, bound in enumerate(_bounds(lower, cap, world.tol, kind)):
        search = TangentSearch(world, grid, nodes, goal_tol, bound, source, terminate)
        found = search.run()
        if search.stopped:
            return report(None, search, stopped=True, rounds=k + 1)
        if found is not None or bound >= cap:
            return report(found, search, rounds=k + 1)
    return report(None, search)  # pragma: no cover - the last bound is the cap


def _point_path(world: World, start: np.ndarray, goal: np.ndarray, goal_tol: float,
                terminate: Callable[[], bool] | None,
                source: str) -> tuple[float, float]:  # fmt: skip
    """On a map alone, a lower bound on the length of a disc's path and a guess at it: the
    length ``L`` of the point's shortest path through the closure of the free cells (sharp
    corners, :func:`.intervals.interval_path`), and ``L + R * turn``, ``turn`` its total turning
    (radians), both less the goal tolerance; ``(inf, inf)`` when no such path exists, ``(0, 0)``
    for any other world.

    The disc's centre keeps a positive clearance from every blocked cell, so its path is one of
    the point's: ``L`` bounds it from below. Among a map's many corners the raster's bound is
    short by up to a fifth (it counts cells); ``L`` is within a percent of a disc's length on
    rooms and cities and within 5 % in mazes of 4-cell corridors. A disc that follows the
    point's path round its corners is ``R`` times the turning longer (the offset of a convex
    chain): the guess, within 4 % of the optimum in mazes of 1-cell corridors, where ``L`` is 19
    % short. It only places the first round's bound (a round that finds nothing within its bound
    hands over to the next), so it need not be a bound itself."""
    if len(world.circles) or world.polygons:
        return 0.0, 0.0
    lattice = box_lattice(world)
    if lattice is None:
        return 0.0, 0.0
    (x0, y0), h, blocked = lattice
    mesh = RectMesh.build(~blocked)
    a, b = ((start[0] - x0) / h, (start[1] - y0) / h), ((goal[0] - x0) / h, (goal[1] - y0) / h)
    try:
        found = interval_path(mesh, a, b, terminate, source, _point_budget(mesh))
    except OptimumTooLarge:
        return 0.0, 0.0
    if found is None:
        return math.inf, math.inf
    d = np.diff(np.asarray(found.vertices, dtype=float), axis=0) * h
    heading = np.arctan2(d[:, 1], d[:, 0])
    turn = float(np.abs(np.mod(np.diff(heading) + math.pi, 2.0 * math.pi) - math.pi).sum())
    sharp = max(float(np.hypot(d[:, 0], d[:, 1]).sum()) - goal_tol, 0.0)
    return sharp, sharp + world.robot_radius * turn


def _point_budget(mesh: RectMesh) -> int:
    """The expansions :func:`_point_path` allows the interval search: 8 per wall corner. A maze
    needs about one per corner (and there the bound saves the tangent search the most), a
    city's streets 4 to 20; a warehouse's open aisles 40 (1.7 million cells: 100,000
    expansions, 0.5 s), where the tangent search has few corners and its raster's bound, already
    close, needs no help."""
    return 8 * int(np.count_nonzero(mesh.corner)) + 4096


def _point_on_map(world: World, goal_tol: float):
    """:func:`~..free_grid.box_lattice` of a point robot's world of a map alone (no circles or
    polygons) and a goal point, else None."""
    if world.robot_radius > 0.0 or goal_tol > 0.0 or len(world.circles) or world.polygons:
        return None
    return box_lattice(world)


def _on_map(lattice, rho: float, start: np.ndarray, goal: np.ndarray, cap: float,
            terminate: Callable[[], bool] | None, source: str,
            report: _Report) -> OptimumResult:  # fmt: skip
    """A point robot on a map alone (``lattice``: :func:`~..free_grid.box_lattice`'s origin,
    cell side and blocked cells): the interval search over the rectangles of its free cells
    (:mod:`.intervals`), whose work follows the region it explores rather than the number of
    wall corners (a 1024 x 1024 maze of one-cell corridors: 2-3 s, where the tangent search did
    not finish in 300 s). Its path bends at the corners themselves; the package rounds a point
    robot's corners (radius ``rho``, twice the tolerance: package docstring), so the path is
    drawn round them, with the corners it touches between its bends
    (:func:`.intervals.corner_sides`, :func:`.intervals.rounded`): the tangent search's answer
    for the same query, the same to 4e-15 on the benchmarks' 104 point-robot map queries (the
    sharp path is shorter by up to 3e-7 relative on a maze). No path beyond ``cap``, as the
    tangent search. No raster, no copy of the world: on 4 million cells those took 3.4 s."""
    if terminate is not None and terminate():
        return report(None, stopped=True)
    (x0, y0), h, blocked = lattice
    mesh = RectMesh.build(~blocked)
    a, b = ((start[0] - x0) / h, (start[1] - y0) / h), ((goal[0] - x0) / h, (goal[1] - y0) / h)
    try:
        found = interval_path(mesh, a, b, terminate, source)
    except Stopped:
        return report(None, stopped=True)
    if found is None:
        return report(None, found, rounds=1)
    points, sides = corner_sides(mesh, found.vertices)
    corners = [(x0 + x * h, y0 + y * h) for x, y in points]
    corners[0], corners[-1] = tuple(map(float, start)), tuple(map(float, goal))
    length, pieces = rounded(corners, sides, rho)
    if length > cap:
        return report(None, found, rounds=1)
    return report((length, pieces), found, rounds=1)


def _grid_frame_world(world: World) -> World:
    """The world of a turned map in its grid coordinates, where its free configurations are
    the same (the frame's ``confined`` holds them all, package docstring): the map's rectangle as
    the bounds, the boxes as they are, the circles and polygons turned into grid coordinates."""
    f = world.box_frame
    x0, y0, x1, y1 = f.confined
    circles = np.column_stack([f.to_grid(world.circles[:, :2]), world.circles[:, 2]])
    polygons = [f.to_grid(p) for p in world.polygons]
    return World(((x0, y0), (x1, y1)), circles, polygons, world.robot_radius, world.boxes)


def _boxes_as_polygons(world: World) -> World:
    """The world of a turned map with its boxes as polygons (their turned squares) in the world's
    coordinates: the search below treats boxes as axis-aligned."""
    squares = list(world.box_frame.box_corners(world.boxes))
    return World(world.bounds, world.circles, [*world.polygons, *squares], world.robot_radius)


def _turned(piece: Piece, frame) -> Piece:
    """A piece found in grid coordinates, in the world's."""

    def back(p):
        return tuple(frame.to_world(np.asarray(p, dtype=float)).tolist())

    if piece.kind != "arc":
        return replace(piece, start=back(piece.start), end=back(piece.end))
    return replace(piece, start=back(piece.start), end=back(piece.end),
                   center=back(piece.center), angle=piece.angle + frame.yaw)  # fmt: skip


#: When the point's path is this many times the raster's bound at the start and the raster went
#: into blocks for its size alone (:attr:`.FreeGrid.refinable`), the blocks lost the map's walls
#: (rooms of 2048 x 2048 cells with one-cell walls: 1.25; a maze of four-cell corridors: 75),
#: and it is searched again cell by cell: those rooms 29-50 s -> 17 s, the maze over 300 s ->
#: 17 s. Below a million free cells the raster's shape chose already (rooms of 1024 x 1024 cells
#: at 1.21 keep their blocks, which cost less than the search they would save).
_REFINE = 1.15
#: The rounds' bounds, as multiples of the lower bound on the optimum: a round that finds no
#: path within its bound proves the optimum longer, and the next one looks further. On a map's
#: lattice the geodesic bound is a few percent short (it counts cells) and a loose bound costs
#: little (the step counts and the raster bound the candidates); among circles and polygons it
#: is often within a fraction of a percent, and the width of the ellipse drives the cost. From
#: the guess of :func:`_point_path` (a disc on a map), within 4 % of the optimum on the mazes
#: measured, one round of 1.05 found the path on every one.
_ROUND_FACTORS = {
    "lattice": (1.08, 1.3, 2.0, 4.0, 8.0),
    "guess": (1.05, 1.3, 2.0, 4.0, 8.0),
    "generic": (1.005, 1.02, 1.08, 1.3, 2.0, 4.0, 8.0),
}


def _bounds(lower: float, cap: float, tol: float, kind: str):
    """The bound of each round, ending with ``cap``."""
    for factor in _ROUND_FACTORS[kind]:
        b = lower * factor + 10.0 * tol
        if b >= cap:
            break
        yield b
    yield cap


def _merge_arcs(pieces: list[Piece]) -> list[Piece]:
    """Join consecutive arcs on the same circle (the path passed a tangent point it did not use)."""
    out: list[Piece] = []
    for p in pieces:
        last = out[-1] if out else None
        if (p.kind == "arc" and last is not None and last.kind == "arc"
                and last.center == p.center and last.radius == p.radius
                and math.copysign(1.0, last.sweep) == math.copysign(1.0, p.sweep)):  # fmt: skip
            out[-1] = Piece("arc", last.start, p.end, last.center, last.radius, last.angle,
                            last.sweep + p.sweep)  # fmt: skip
        else:
            out.append(p)
    return out
