"""The problem on a generated occupancy-grid map: :class:`MapKindOptions`, the options every map
kind takes, and :func:`generate_map_from`, which draws a map kind's cells, a query on them and its
certificate.

The map is ``cells x cells`` cells over the workspace ``[0, size]^2`` (cell side ``size /
cells``, units m); it depends on the seed only. Start and goal are centres of cells where the
robot disc fits (the project's :class:`~rrtpso_ompl.model.World` decides: its exact point test on
the map's cells), in the largest region the robot can move in, at least ``size / 2`` apart, drawn
from a second stream seeded with ``(seed, query)``: ``query`` poses another start and goal on the
same map. The robot radius defaults to a quarter of a cell, so corridors one cell wide stay
passable.

**Certificate.** A route through the centres of free cells (4-neighbours; between two
neighbouring free centres the straight segment is free, since the nearest blocked square of any
point of it is at least as near one end), straightened by the world's exact segment test and
checked again by :meth:`~rrtpso_ompl.model.World.path_valid`: a certified path in milliseconds,
also through one-cell corridors where a general grid would need a spacing of an eighth of a cell.
With ``exact`` the exact optimum (:func:`~rrtpso_ompl.groundtruth.optimum.shortest_path`) is
computed too and its length stated.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order
from scipy.spatial import ConvexHull, QhullError

from ..errors import GenerationError, ProblemError
from ..model.geometry import path_length
from ..model.occupancy import OccupancyMap
from ..model.problem import problem_from_dict
from ..model.problem_file import round_floats
from ..model.raster import Lattice
from ..model.world import World
from ..params import Rule, declared, param
from .kinds import GeneratorOptions, generate_command, round_up
from .map_files import GeneratedMap, check_map_place, map_output_paths

__all__ = ["MAX_MAP_CELLS", "MapKindOptions", "generate_map_from"]

#: Most cells per side of a generated map (16 million cells).
MAX_MAP_CELLS = 4096


@declared(
    rules=(
        Rule(("resolution",), lambda r: r is None,
             "resolution is not used by map kinds (the map's cell side is size / cells)"),
    )
)  # fmt: skip
class MapKindOptions(GeneratorOptions):
    """An occupancy-grid map and a query on it (each map kind draws its cells)."""

    robot_radius: float | None = param(
        None,
        "Robot radius (0: a point robot). Default: a quarter of a cell (size / cells / 4), so "
        "corridors one cell wide stay passable.",
        unit="length",
        low=0.0,
    )
    resolution: float | None = param(
        None,
        "Not used by map kinds (leave it unset): the map's cell side is size / cells.",
        unit="length",
        low=0.0,
    )
    cells: int = param(128, "Cells per side of the map (the cell side is size / cells).",
                       low=8, high=MAX_MAP_CELLS)  # fmt: skip
    query: int = param(
        0,
        "Which start and goal on the map (the map depends on the seed only; start and goal on "
        "seed and query).",
        low=0,
    )
    exact: bool = param(
        False, "Also compute the exact shortest path (slower) and state its length."
    )

    def resolved(self) -> MapKindOptions:
        # The radius as the file will hold it (rounded to the decimals; the default rounded
        # down), so that the certificate is checked with the radius that is written.
        options = self._resolve(None)
        scale = 10.0**options.decimals
        if self.robot_radius is None:
            robot = math.floor(0.25 * self.cell * scale) / scale
        else:
            robot = float(round_floats(self.robot_radius, options.decimals))
        return dataclasses.replace(options, robot_radius=robot)

    @property
    def cell(self) -> float:
        """Side of a map cell, m."""
        return self.size / self.cells

    # -- what each map kind provides ------------------------------------------------------------
    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        """(cells, cells) booleans, True blocked, image order (row 0 on top)."""
        raise NotImplementedError

    def what(self) -> str:
        """What the map holds, in words (the description's first sentence)."""
        raise NotImplementedError

    # -- the generator's hooks --------------------------------------------------------------------
    def problem_dict(self, seed: int) -> dict[str, Any]:
        return generate_map_from(self, seed).problem

    @classmethod
    def output_paths(cls, out: str | Path) -> list[Path]:
        return map_output_paths(out)

    @classmethod
    def check_places(cls, out: str | Path) -> None:
        """Refuse ``-`` and a link, fifo or folder at any of the three places."""
        for p in map_output_paths(out) if str(out) != "-" else ["-"]:
            check_map_place(Path(p))

    def write(self, seed: int, out: str | Path) -> Path:
        self.check_places(out)  # before the map is drawn
        return generate_map_from(self.resolved(), seed, generate_command(self, seed)).write(out)


def generate_map_from(options: MapKindOptions, seed: int, command: str = "") -> GeneratedMap:
    """Draw maps from ``default_rng(seed)`` until one has a place for the query, then the query
    from ``default_rng([seed, query])``, certified (module docstring).

    Parameters
    ----------
    options : MapKindOptions
        The resolved options of a map kind.
    seed : int
        The map's seed, >= 0.
    command : str
        The command line that regenerates the files (their header's first line), if any.
    """
    kind = options.KIND
    name = options.name or f"{kind}_{seed}"
    rng = np.random.default_rng(seed)
    last = ""
    for attempt in range(1, options.max_attempts + 1):
        blocked = np.ascontiguousarray(options.draw_cells(rng), dtype=bool)
        world, lat = _map_world(options, blocked)
        region, reason = _largest_region(world, lat, 0.5 * options.size)
        if region is None:
            last = reason
            continue
        query_rng = np.random.default_rng([seed, options.query])
        start_cell, goal_cell = _draw_query(query_rng, region, lat.h, 0.5 * options.size)
        data = {
            "name": name,
            "description": "",
            "units": "m",
            "map": f"{name}_map.yaml",
            "start": list(lat.centre(start_cell)),
            "goal": list(lat.centre(goal_cell)),
            "robot": {"radius": float(options.robot_radius)},
        }
        data = round_floats(data, options.decimals)
        path = _certify(world, lat, region, data["start"], data["goal"])
        if path is None:  # rounding moved an end off its cell centre into a wall's reach
            last = "the start or goal was not free after rounding (use more decimals)"
            continue
        data["description"] = _description(options, seed, attempt, data, world, lat, blocked,
                                           path)  # fmt: skip
        return _generated(options, data, blocked, lat.h, command)
    raise GenerationError(
        f"generate {kind}: no map with room for the query in {options.max_attempts} attempts "
        f"(last: {last}); use a smaller robot_radius, other options or more max_attempts"
    )


def _description(options: MapKindOptions, seed: int, attempt: int, data: dict[str, Any],
                 world: World, lat: Lattice, blocked: np.ndarray, path: np.ndarray
                 ) -> str:  # fmt: skip
    """The problem's description: what the map holds, its grid, the query and its certificate
    (``path``; with ``exact`` the exact optimum's length)."""
    length = round_up(path_length(path), 4)
    how = (
        f"a collision-free path of length {length:g} exists (through free cell centres, "
        "checked exactly), so the shortest path is at most that long"
    )
    if options.exact:
        from .optimum import shortest_path

        best = shortest_path(_problem(world, data), world, upper_bound=float(length) * 1.001)
        if best.found:
            how = f"the shortest path is {best.length:.6g} long (exact, rrtpso optimum)"
    n_blocked = int(blocked.sum())
    return (
        f"{options.what()} A {options.cells} x {options.cells} occupancy grid of "
        f"{options.size:g} m x {options.size:g} m (cells of {lat.h:.4g} m, "
        f"{100 * n_blocked / blocked.size:.0f}% blocked). Robot radius "
        f"{options.robot_radius:g} m; start and goal are free cell centres in the largest "
        f"region the robot can move in, {math.dist(data['start'], data['goal']):.4g} m "
        f"apart (query {options.query}). Generated by rrtpso generate (kind {options.KIND}, "
        f"seed {seed}, attempt {attempt}); {how}."
    )


def _generated(options: MapKindOptions, data: dict[str, Any], blocked: np.ndarray, cell: float,
               command: str) -> GeneratedMap:  # fmt: skip
    """The :class:`GeneratedMap` of the certified problem ``data`` on ``blocked`` (cells of side
    ``cell``, m), its header naming ``command``."""
    name = data["name"]
    map_yaml = {
        "image": f"{name}_map.pgm",
        "resolution": float(cell),
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
        "mode": "trinary",
    }
    header = (f"Generated by: {command} --out FILE\n" if command else "") + (
        "The map was drawn from numpy.random.default_rng(seed), start and goal from\n"
        "default_rng([seed, query]); the same command writes the same bytes. Solvability\n"
        "is certified by a collision-free path, see the description."
    )
    return GeneratedMap(data, blocked, map_yaml, data["map"], map_yaml["image"], header,
                        options.decimals)  # fmt: skip


def _map_world(options: MapKindOptions, blocked: np.ndarray) -> tuple[World, Lattice]:
    """The world of the map (built as ``rrtpso solve`` builds it) and the map's own lattice."""
    res = options.size / options.cells
    occupancy = OccupancyMap(f"<generate {options.KIND}>", "<image>", res, (0.0, 0.0),
                             blocked.astype(np.int8))  # fmt: skip
    n = options.cells
    problem = _problem(None, {"start": [0.0, 0.0], "goal": [0.0, 0.0],
                              "robot": {"radius": float(options.robot_radius)}},
                       bounds=occupancy.extent)  # fmt: skip
    problem = dataclasses.replace(problem, map=occupancy)
    return World.from_problem(problem), Lattice((0.0, 0.0), res, n, n)


def _problem(world: World | None, data: dict[str, Any], bounds=None):
    """A problem of ``data``'s start, goal and robot over ``bounds`` (default the world's), no
    obstacles of its own (the map is the world's)."""
    bounds = bounds if bounds is not None else world.bounds
    doc = {"bounds": [list(bounds[0]), list(bounds[1])], "start": data["start"],
           "goal": data["goal"], "robot": data["robot"]}  # fmt: skip
    try:
        return problem_from_dict(doc, source="<generate>")
    except ProblemError as exc:  # pragma: no cover - start and goal lie in the bounds
        raise GenerationError(str(exc)) from None


def _largest_region(world: World, lat: Lattice, apart: float):
    """The cells ``(i, j)`` (i along x) of the largest 4-connected region of free cell centres,
    as an (m, 2) array, when two of them are at least ``apart`` apart; else None and why."""
    free = world.centres_free(lat)
    if not free.any():
        return None, "the robot fits nowhere on the map"
    labels, _ = ndimage.label(free)
    sizes = np.bincount(labels.ravel())[1:]
    cells = np.argwhere(labels == int(np.argmax(sizes)) + 1)
    if _diameter(cells) * lat.h < apart:
        return None, f"the largest free region has no two cells {apart:g} m apart"
    return cells, ""


def _hull(cells: np.ndarray) -> np.ndarray:
    """The cells on the convex hull of ``cells`` (all of them when degenerate)."""
    if len(cells) < 3:
        return cells
    try:
        return cells[ConvexHull(cells).vertices]
    except QhullError:  # collinear
        return cells


def _diameter(cells: np.ndarray) -> float:
    """Largest distance between two cells, in cells."""
    hull = _hull(cells).astype(float)
    d = np.hypot(hull[:, None, 0] - hull[None, :, 0], hull[:, None, 1] - hull[None, :, 1])
    return float(d.max())


def _draw_query(rng: np.random.Generator, cells: np.ndarray, h: float, apart: float):
    """Start and goal cells of ``cells``, at least ``apart`` apart: the start uniform among the
    cells that have such a partner (the farthest cell from any point is a hull vertex), the goal
    uniform among its partners."""
    hull = _hull(cells).astype(float)
    far = np.zeros(len(cells), dtype=bool)
    for lo in range(0, len(cells), 4096):  # memory: 4096 x hull vertices at a time
        c = cells[lo : lo + 4096].astype(float)
        d = np.hypot(c[:, None, 0] - hull[None, :, 0], c[:, None, 1] - hull[None, :, 1])
        far[lo : lo + 4096] = d.max(axis=1) * h >= apart
    starts = np.flatnonzero(far)
    s = cells[starts[int(rng.integers(len(starts)))]]
    goals = np.flatnonzero(np.hypot(*(cells - s).T) * h >= apart)
    g = cells[goals[int(rng.integers(len(goals)))]]
    return (int(s[0]), int(s[1])), (int(g[0]), int(g[1]))


def _certify(world: World, lat: Lattice, cells: np.ndarray, start, goal) -> np.ndarray | None:
    """A valid path from ``start`` to ``goal`` through the centres of ``cells`` (4-neighbours,
    breadth first), shortcut with the exact segment test and checked with
    :meth:`World.path_valid`; None when an end is not free."""
    a, b = np.asarray(start, float), np.asarray(goal, float)
    if not (world.point_free(*a) and world.point_free(*b)):
        return None
    index = np.full((lat.nx, lat.ny), -1, dtype=np.int64)
    index[cells[:, 0], cells[:, 1]] = np.arange(len(cells))
    rows, cols = [], []
    for di, dj in ((1, 0), (0, 1)):
        src = index[: lat.nx - di, : lat.ny - dj]
        dst = index[di:, dj:]
        ok = (src >= 0) & (dst >= 0)
        rows.append(src[ok])
        cols.append(dst[ok])
    r, c = np.concatenate(rows), np.concatenate(cols)
    graph = coo_matrix((np.ones(len(r)), (r, c)), shape=(len(cells), len(cells))).tocsr()
    s = int(index[lat.cell_of(a)])
    g = int(index[lat.cell_of(b)])
    _, pred = breadth_first_order(graph, s, directed=False, return_predecessors=True)
    route = [g]
    for _ in range(len(cells)):  # bounded walk back along the predecessors
        if route[-1] == s:
            break
        route.append(int(pred[route[-1]]))
    if route[-1] != s:
        return None
    centres = lat.centres().reshape(lat.nx, lat.ny, 2)
    picked = cells[route[::-1]]
    path = centres[picked[:, 0], picked[:, 1]]
    path[0], path[-1] = a, b
    # Straight runs of centres are one free segment (the union of free unit steps): keep their
    # ends only, so the shortcut's exact tests see the turns, not every cell.
    step = np.diff(path, axis=0)
    turn = np.any(step[1:] != step[:-1], axis=1)
    path = path[np.concatenate([[True], turn, [True]])] if len(path) > 2 else path
    path = _straighten(path, world)
    return path if world.path_valid(path) else None


def _straighten(path: np.ndarray, world: World, passes: int = 24) -> np.ndarray:
    """Drop waypoints whose neighbours see each other, in vectorised passes: each pass tests
    every ``(p[i], p[i + 2])`` at once (exact segment test) and drops ``p[i + 1]`` where it is
    free, for ``i`` of one parity only (two dropped waypoints are never neighbours, so every
    new segment was tested). A long maze route of thousands of turns takes a few calls, where
    the greedy shortcut would take one per kept waypoint."""
    for k in range(passes):
        if len(path) < 3:
            break
        free = world.segments_free(path[:-2], path[2:])
        i = np.arange(len(free))
        drop = free & (i % 2 == k % 2)
        if not drop.any() and not (free & (i % 2 != k % 2)).any():
            break
        keep = np.ones(len(path), dtype=bool)
        keep[1:-1][drop] = False
        path = path[keep]
    return path
