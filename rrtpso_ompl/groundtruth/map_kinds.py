"""Generated occupancy-grid maps that look like real ones (``rrtpso generate rooms_map``, ...).

Six kinds, each a ROS map_server map (:mod:`rrtpso_ompl.model.occupancy`: a YAML file and an 8-bit
PGM, free 254, occupied 0) with a problem on it:

* ``rooms_map``: an office or home floor plan: rooms of random sizes joined by doors over a
  spanning tree plus extra doors, walls a few cells thick, furniture against the walls
  (:class:`RoomsMapOptions`);
* ``maze_map``: a maze carved on corridors ``corridor`` cells wide between walls ``wall_cells``
  thick, perfect or braided (:class:`MazeMapOptions`);
* ``city_map``: blocks between streets of several widths, built up with buildings, alleys,
  courtyards and setbacks, open squares, sometimes a diagonal avenue (:class:`CityMapOptions`);
* ``warehouse_map``: rows of racks between aisles, cross aisles lined up across the rows, a
  loading area with pallets (:class:`WarehouseMapOptions`);
* ``caves_map``: cellular-automaton caves, the largest open region kept (:class:`CavesMapOptions`);
* ``random_map``: random blocked cells at a density (:class:`RandomMapOptions`).

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

**Python API.** :func:`~rrtpso_ompl.groundtruth.generate.generate` returns the problem dictionary
(its ``map`` the relative name ``<name>_map.yaml``); :func:`generate_map` returns a
:class:`GeneratedMap`: that dictionary, the image and the map YAML dictionary, which
:meth:`GeneratedMap.write` writes (the problem file, ``<stem>_map.yaml`` and ``<stem>_map.pgm``
beside it). :func:`~rrtpso_ompl.groundtruth.generate.generate_to_file` does both. All three
files are written to temporary names in a temporary folder beside them, the problem read back
from there (map included), then renamed into place: when anything fails nothing is left behind.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import shutil
import stat
import tempfile
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order
from scipy.spatial import ConvexHull, QhullError

from ..errors import GenerationError, ProblemError
from ..model.geometry import path_length
from ..model.occupancy import OccupancyMap
from ..model.problem import problem_from_dict
from ..model.problem_file import round_floats, write_problem
from ..model.raster import Lattice
from ..model.world import World
from ..outputs import make_folders, publish, remove_folders
from ..params import Rule, declared, param
from .generate import GeneratorOptions, _round_up, generate_command, register_kind

__all__ = [
    "MAX_MAP_CELLS",
    "CavesMapOptions",
    "CityMapOptions",
    "GeneratedMap",
    "MapKindOptions",
    "MazeMapOptions",
    "RandomMapOptions",
    "RoomsMapOptions",
    "WarehouseMapOptions",
    "generate_map",
]

#: Most cells per side of a generated map (16 million cells).
MAX_MAP_CELLS = 4096
#: Grey values of the image (ROS map_saver's).
FREE_GREY, OCCUPIED_GREY = 254, 0


# ----------------------------------------------------------------------------------------------
# What a map kind generates
# ----------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True, eq=False)
class GeneratedMap:
    """A generated map and the problem on it.

    Attributes
    ----------
    problem : dict
        The problem dictionary (file format); its ``map`` is ``map_file`` (relative).
    blocked : ndarray of bool, shape (cells, cells)
        Blocked cells in image order (row 0 on top).
    map_yaml : dict
        The map_server YAML keys (``image`` is ``image_file``).
    map_file, image_file : str
        The names the problem and the map YAML give them.
    header : str
        Comment lines for the top of the problem and map files (the command that regenerates
        them).
    decimals : int
        Decimal places of the problem's coordinates.
    """

    problem: dict[str, Any]
    blocked: np.ndarray
    map_yaml: dict[str, Any]
    map_file: str
    image_file: str
    header: str = ""
    decimals: int = 3

    @property
    def image(self) -> np.ndarray:
        """(cells, cells) uint8 grey image: free 254, occupied 0."""
        return np.where(self.blocked, OCCUPIED_GREY, FREE_GREY).astype(np.uint8)

    def pgm_bytes(self) -> bytes:
        """The image as an 8-bit binary PGM (P5)."""
        h, w = self.blocked.shape
        return f"P5\n{w} {h}\n255\n".encode("ascii") + self.image.tobytes()

    def yaml_text(self) -> str:
        """The map YAML file's text."""
        m = self.map_yaml
        lines = [f"# {line}".rstrip() for line in self.header.splitlines()]
        lines += [
            f"image: {m['image']}",
            f"resolution: {m['resolution']!r}",
            f"origin: [{m['origin'][0]!r}, {m['origin'][1]!r}, {m['origin'][2]!r}]",
            f"negate: {m['negate']}",
            f"occupied_thresh: {m['occupied_thresh']}",
            f"free_thresh: {m['free_thresh']}",
            f"mode: {m['mode']}",
        ]
        return "\n".join(lines) + "\n"

    def renamed(self, stem: str) -> GeneratedMap:
        """The same, the map files named ``<stem>_map.yaml`` and ``<stem>_map.pgm``."""
        map_file, image_file = f"{stem}_map.yaml", f"{stem}_map.pgm"
        return dataclasses.replace(
            self,
            problem={**self.problem, "map": map_file},
            map_yaml={**self.map_yaml, "image": image_file},
            map_file=map_file,
            image_file=image_file,
        )

    def write(self, out: str | Path) -> Path:
        """Write the problem to ``out`` and the map beside it (``<out stem>_map.yaml`` and
        ``.pgm``), all or nothing.

        Existing regular files are replaced; a path that is ``-``, a symbolic link, a fifo or
        anything but a regular file is refused before anything is written
        (:class:`GenerationError`). The three files are written in a temporary folder beside
        ``out``, the problem validated by reading it back (the map with it), then renamed into
        place; when a step fails the files already moved are removed, and so is the folder.

        Returns
        -------
        Path
            ``out``.
        """
        out = Path(out)
        named = self.renamed(out.stem if out.suffix else out.name)
        paths = map_output_paths(out)
        for p in paths:
            _check_writable_place(p)
        folder = out.parent
        made = make_folders(folder) if str(folder) else []
        moved: list[Path] = []
        tmp = None
        try:
            tmp = Path(tempfile.mkdtemp(prefix=f".{out.name[:40]}.", dir=folder))
            (tmp / named.image_file).write_bytes(named.pgm_bytes())
            (tmp / named.map_file).write_text(named.yaml_text(), encoding="utf-8")
            # write_problem reads the problem back, the map from beside it: the files are valid.
            write_problem(named.problem, tmp / out.name, header=named.header,
                          decimals=named.decimals)  # fmt: skip
            for name, target in zip((named.image_file, named.map_file, out.name), paths[::-1],
                                    strict=True):  # fmt: skip
                _publish(tmp / name, target)
                moved.append(target)
        except BaseException as exc:
            for p in moved:
                with contextlib.suppress(OSError):
                    p.unlink()
            if tmp is not None:
                shutil.rmtree(tmp, ignore_errors=True)
            remove_folders(made)
            if isinstance(exc, OSError):
                raise GenerationError(f"cannot write '{out}' and its map: {exc.strerror or exc}"
                                      ) from None  # fmt: skip
            raise
        shutil.rmtree(tmp, ignore_errors=True)
        return out


def map_output_paths(out: str | Path) -> list[Path]:
    """``[out, <stem>_map.yaml, <stem>_map.pgm]`` beside ``out``."""
    out = Path(out)
    stem = out.stem if out.suffix else out.name
    return [out, out.with_name(f"{stem}_map.yaml"), out.with_name(f"{stem}_map.pgm")]


def _check_writable_place(path: Path) -> None:
    """Refuse ``-`` and an existing path that is not a regular file (a link is not followed: the
    map must lie beside the problem)."""
    if str(path) == "-":
        raise GenerationError("a map kind writes three files; give --out a file name, not '-'")
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise GenerationError(f"cannot write '{path}': {exc.strerror}") from None
    if stat.S_ISLNK(mode):
        raise GenerationError(f"'{path}' is a symbolic link; a map kind writes regular files only")
    if not stat.S_ISREG(mode):
        what = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
        raise GenerationError(f"'{path}' is {what}; it is left as it is")


def _publish(tmp: Path, target: Path) -> None:
    """Rename a finished file into place with the permissions a new file gets (or the old
    file's), never over a results file or a file being written
    (:func:`~rrtpso_ompl.outputs.publish`)."""
    publish(tmp, target)


# ----------------------------------------------------------------------------------------------
# The options every map kind takes
# ----------------------------------------------------------------------------------------------
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
            _check_writable_place(Path(p))

    def write(self, seed: int, out: str | Path) -> Path:
        self.check_places(out)  # before the map is drawn
        return generate_map_from(self.resolved(), seed, generate_command(self, seed)).write(out)


def generate_map(kind: str, seed: int, **options: Any) -> GeneratedMap:
    """The map and problem of a map kind (see the module docstring).

    Parameters are those of :func:`~rrtpso_ompl.groundtruth.generate.generate`; ``kind`` must be
    a map kind (its name ends in ``_map``).
    """
    from .generate import _options_of, _seed

    options_ = _options_of(kind, options)
    if not isinstance(options_, MapKindOptions):
        raise GenerationError(f"generate_map: {kind!r} is not a map kind")
    seed = _seed(seed)
    return generate_map_from(options_.resolved(), seed, generate_command(options_, seed))


def generate_map_from(options: MapKindOptions, seed: int, command: str = "") -> GeneratedMap:
    """Draw maps from ``default_rng(seed)`` until one has a place for the query, then the query
    from ``default_rng([seed, query])``, certified (module docstring)."""
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
        length = _round_up(path_length(path), 4)
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
        data["description"] = (
            f"{options.what()} A {options.cells} x {options.cells} occupancy grid of "
            f"{options.size:g} m x {options.size:g} m (cells of {lat.h:.4g} m, "
            f"{100 * n_blocked / blocked.size:.0f}% blocked). Robot radius "
            f"{options.robot_radius:g} m; start and goal are free cell centres in the largest "
            f"region the robot can move in, {math.dist(data['start'], data['goal']):.4g} m "
            f"apart (query {options.query}). Generated by rrtpso generate (kind {kind}, seed "
            f"{seed}, attempt {attempt}); {how}."
        )
        map_yaml = {
            "image": f"{name}_map.pgm",
            "resolution": float(lat.h),
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
    raise GenerationError(
        f"generate {kind}: no map with room for the query in {options.max_attempts} attempts "
        f"(last: {last}); use a smaller robot_radius, other options or more max_attempts"
    )


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


# ----------------------------------------------------------------------------------------------
# The kinds
# ----------------------------------------------------------------------------------------------
def _range_rule(name: str, low: int) -> Rule:
    return Rule((name,), lambda v: low <= v[0] <= v[1], f"{low} <= {name} min <= max")


@register_kind
@declared(rules=(_range_rule("room", 4), _range_rule("door", 1)))
class RoomsMapOptions(MapKindOptions):
    """Rooms joined by doors: an office or home floor plan (``rrtpso generate rooms_map``)."""

    KIND: ClassVar[str] = "rooms_map"

    room: tuple[int, int] = param((14, 26), "Least and largest room side, cells.", low=4,
                                  high=MAX_MAP_CELLS)  # fmt: skip
    door: tuple[int, int] = param((2, 5), "Least and largest door width, cells.", low=1,
                                  high=MAX_MAP_CELLS)  # fmt: skip
    wall_cells: int = param(2, "Wall thickness, cells.", low=1, high=64)
    extra_doors: float = param(
        0.3,
        "Share of the walls between two rooms that get a door beyond those of a spanning tree "
        "(0: one route between any two rooms).",
        low=0.0,
        high=1.0,
    )
    clutter: float = param(
        2.0, "Furniture against the walls: pieces per room (never in front of a door).",
        low=0.0, high=10.0,
    )  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _rooms(rng, self.cells, self.room, self.door, self.wall_cells, self.extra_doors,
                      self.clutter)  # fmt: skip

    def what(self) -> str:
        return (
            f"A floor plan: rooms {self.room[0]}-{self.room[1]} cells a side, walls "
            f"{self.wall_cells} cells thick, doors {self.door[0]}-{self.door[1]} cells wide over a "
            f"spanning tree plus {self.extra_doors:.0%} extra doors, {self.clutter:g} pieces of "
            "furniture per room against the walls."
        )


@register_kind
@declared
class MazeMapOptions(MapKindOptions):
    """A maze of corridors ``corridor`` cells wide (``rrtpso generate maze_map``)."""

    KIND: ClassVar[str] = "maze_map"

    corridor: int = param(2, "Corridor width, cells.", low=1, high=256)
    wall_cells: int = param(1, "Wall thickness, cells.", low=1, high=64)
    loops: float = param(
        0.0,
        "Share of the walls left after carving that are opened too (0: a perfect maze, one "
        "route between any two places; more: a braid maze with several routes).",
        low=0.0,
        high=1.0,
    )

    def resolved(self) -> MazeMapOptions:
        if self.corridor + 2 * self.wall_cells > self.cells:
            raise GenerationError(
                f"corridor + 2 wall_cells ({self.corridor + 2 * self.wall_cells}) must be at most "
                f"cells ({self.cells})"
            )
        return super().resolved()

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _maze(rng, self.cells, self.corridor, self.wall_cells, self.loops)

    def what(self) -> str:
        kind = (
            "A perfect maze"
            if self.loops == 0
            else f"A braid maze ({self.loops:.0%} extra openings)"
        )
        return (
            f"{kind} carved by randomised depth-first search: corridors {self.corridor} cells "
            f"wide, walls {self.wall_cells} cells thick."
        )


@register_kind
@declared(rules=(_range_rule("street", 1), _range_rule("block", 6)))
class CityMapOptions(MapKindOptions):
    """City blocks between streets (``rrtpso generate city_map``; like MovingAI's city maps)."""

    KIND: ClassVar[str] = "city_map"

    street: tuple[int, int] = param((2, 6), "Least and largest street width, cells.", low=1,
                                    high=MAX_MAP_CELLS)  # fmt: skip
    block: tuple[int, int] = param((12, 30), "Least and largest block side, cells.", low=6,
                                   high=MAX_MAP_CELLS)  # fmt: skip
    plazas: float = param(0.08, "Chance that a block is an open square.", low=0.0, high=1.0)
    avenue: float = param(0.6, "Chance of a diagonal avenue across the city.", low=0.0, high=1.0)

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _city(rng, self.cells, self.street, self.block, self.avenue, self.plazas)

    def what(self) -> str:
        return (
            f"A city: blocks {self.block[0]}-{self.block[1]} cells a side between streets "
            f"{self.street[0]}-{self.street[1]} cells wide (recursive splits), buildings with "
            f"alleys, courtyards and setbacks, {self.plazas:.0%} of the blocks open squares, a "
            f"diagonal avenue with chance {self.avenue:g}."
        )


@register_kind
@declared(rules=(_range_rule("aisle", 1), _range_rule("run", 2), _range_rule("cross", 1)))
class WarehouseMapOptions(MapKindOptions):
    """Racks between aisles (``rrtpso generate warehouse_map``)."""

    KIND: ClassVar[str] = "warehouse_map"

    rack: int = param(2, "Rack depth, cells.", low=1, high=64)
    aisle: tuple[int, int] = param((3, 5), "Least and largest aisle width, cells.", low=1,
                                   high=MAX_MAP_CELLS)  # fmt: skip
    run: tuple[int, int] = param((16, 30), "Least and longest rack run between cross aisles, "
                                 "cells.", low=2, high=MAX_MAP_CELLS)  # fmt: skip
    cross: tuple[int, int] = param((3, 5), "Least and largest cross-aisle width, cells.", low=1,
                                   high=MAX_MAP_CELLS)  # fmt: skip
    pallets: float = param(0.003, "Pallets (2 x 2 cells) in the loading area per map cell.",
                           low=0.0, high=0.05)  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _warehouse(rng, self.cells, self.rack, self.aisle, self.run, self.cross,
                          self.pallets)  # fmt: skip

    def what(self) -> str:
        return (
            f"A warehouse: racks {self.rack} cells deep in runs of {self.run[0]}-{self.run[1]} "
            f"cells between aisles {self.aisle[0]}-{self.aisle[1]} cells wide, cross aisles "
            f"{self.cross[0]}-{self.cross[1]} cells wide lined up across the rows, a loading "
            "area with pallets along the top."
        )


@register_kind
@declared
class CavesMapOptions(MapKindOptions):
    """Cellular-automaton caves (``rrtpso generate caves_map``; game levels)."""

    KIND: ClassVar[str] = "caves_map"

    fill: float = param(0.45, "Share of cells blocked before smoothing.", low=0.0, high=0.9)
    steps: int = param(5, "Smoothing steps (a cell is blocked when 5 of its 3 x 3 are).", low=0,
                       high=50)  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return _caves(rng, self.cells, self.fill, self.steps)

    def what(self) -> str:
        return (
            f"Caves: cells blocked with chance {self.fill:g}, smoothed {self.steps} times by the "
            "5-of-9 rule, only the largest open region kept."
        )


@register_kind
@declared
class RandomMapOptions(MapKindOptions):
    """Random blocked cells (``rrtpso generate random_map``; MovingAI's random maps)."""

    KIND: ClassVar[str] = "random_map"

    density: float = param(0.2, "Share of cells blocked, each independently.", low=0.0,
                           high=0.9)  # fmt: skip

    def draw_cells(self, rng: np.random.Generator) -> np.ndarray:
        return rng.random((self.cells, self.cells)) < self.density

    def what(self) -> str:
        return f"Random cells, each blocked with chance {self.density:g}."


# ----------------------------------------------------------------------------------------------
# Drawing (True blocked, image order); every loop bounded by the map's size
# ----------------------------------------------------------------------------------------------
def _border(g: np.ndarray, t: int = 1) -> np.ndarray:
    g[:t, :] = g[-t:, :] = g[:, :t] = g[:, -t:] = True
    return g


def _spans(rng: np.random.Generator, total: int, lo: int, hi: int) -> list[int]:
    """Sizes drawn from ``[lo, hi]`` that sum to ``total`` (the last absorbs the rest, merged
    into its neighbour when below ``lo``)."""
    sizes: list[int] = []
    left = total
    while left > 0 and len(sizes) < total:
        s = int(rng.integers(lo, hi + 1))
        if left - s < lo:
            s = left
        sizes.append(s)
        left -= s
    return sizes


def _union_find(n: int):
    parent = list(range(n))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    return parent, find


def _maze(rng: np.random.Generator, size: int, corridor: int, wall: int, loops: float):
    step = corridor + wall
    n = max((size - wall) // step, 1)
    g = np.ones((size, size), dtype=bool)
    for i in range(n):
        for j in range(n):
            r, c = wall + i * step, wall + j * step
            g[r : r + corridor, c : c + corridor] = False

    def link(i: int, j: int, a: int, b: int) -> None:
        r, c = wall + min(i, a) * step, wall + min(j, b) * step
        if a != i:
            g[r + corridor : r + step, c : c + corridor] = False
        else:
            g[r : r + corridor, c + corridor : c + step] = False

    seen = np.zeros((n, n), dtype=bool)
    linked: set[tuple[int, int, int, int]] = set()
    i0, j0 = int(rng.integers(n)), int(rng.integers(n))
    seen[i0, j0] = True
    stack = [(i0, j0)]
    for _ in range(2 * n * n):  # each cell is pushed once and popped once
        if not stack:
            break
        i, j = stack[-1]
        nb = [(i + di, j + dj) for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0))
              if 0 <= i + di < n and 0 <= j + dj < n and not seen[i + di, j + dj]]  # fmt: skip
        if not nb:
            stack.pop()
            continue
        a, b = nb[int(rng.integers(len(nb)))]
        seen[a, b] = True
        link(i, j, a, b)
        linked.add((min(i, a), min(j, b), max(i, a), max(j, b)))
        stack.append((a, b))
    if loops > 0:  # open walls the tree left: a braid maze with several routes
        walls = [(i, j, i + 1, j) for i in range(n - 1) for j in range(n)]
        walls += [(i, j, i, j + 1) for i in range(n) for j in range(n - 1)]
        rest = [w for w in walls if w not in linked]
        opened = rng.random(len(rest)) < loops
        for w, o in zip(rest, opened.tolist(), strict=True):
            if o:
                link(*w)
    return g


def _rooms(rng, size: int, room, door, wall: int, extra: float, clutter: float):
    g = np.zeros((size, size), dtype=bool)
    inner = size - wall
    heights = _spans(rng, inner, room[0] + wall, room[1] + wall)
    widths = _spans(rng, inner, room[0] + wall, room[1] + wall)
    rows = np.concatenate([[0], np.cumsum(heights)])  # wall k starts at rows[k]
    cols = np.concatenate([[0], np.cumsum(widths)])
    for r in rows:
        g[r : r + wall, :] = True
    for c in cols:
        g[:, c : c + wall] = True
    _border(g, wall)
    nr, nc = len(heights), len(widths)
    keep = np.zeros_like(g)  # in front of doors: no furniture
    walls = [(i, j, i + 1, j) for i in range(nr - 1) for j in range(nc)]
    walls += [(i, j, i, j + 1) for i in range(nr) for j in range(nc - 1)]
    parent, find = _union_find(nr * nc)
    for k in rng.permutation(len(walls)).tolist():
        i, j, a, b = walls[k]
        ra, rb = find(i * nc + j), find(a * nc + b)
        if ra == rb and rng.random() >= extra:
            continue
        parent[ra] = rb
        if a != i:  # a door in the horizontal wall below room (i, j)
            lo, hi = cols[j] + wall, cols[j + 1]
        else:  # in the vertical wall right of it
            lo, hi = rows[i] + wall, rows[i + 1]
        w = min(int(rng.integers(door[0], door[1] + 1)), hi - lo)
        off = lo + int(rng.integers(0, hi - lo - w + 1))
        reach = w + 2
        if a != i:
            r = rows[i + 1]
            g[r : r + wall, off : off + w] = False
            keep[max(r - reach, 0) : r + wall + reach, max(off - 1, 0) : off + w + 1] = True
        else:
            c = cols[j + 1]
            g[off : off + w, c : c + wall] = False
            keep[max(off - 1, 0) : off + w + 1, max(c - reach, 0) : c + wall + reach] = True
    _furnish(rng, g, keep, rows, cols, wall, clutter)
    return g


def _furnish(rng, g: np.ndarray, keep: np.ndarray, rows, cols, wall: int, clutter: float):
    """Pieces of furniture (``clutter`` per room on average) against a wall of a random room,
    each kept out of the ``keep`` cells in front of the doors."""
    nr, nc = len(rows) - 1, len(cols) - 1
    pieces = int(rng.poisson(clutter * nr * nc)) if clutter > 0 else 0
    for _ in range(min(pieces, 10 * nr * nc)):  # furniture against a wall of a random room
        i, j = int(rng.integers(nr)), int(rng.integers(nc))
        r0, r1 = rows[i] + wall, rows[i + 1]
        c0, c1 = cols[j] + wall, cols[j + 1]
        h_room, w_room = r1 - r0, c1 - c0
        depth = int(rng.integers(1, max(2, min(h_room, w_room) // 4) + 1))
        side = int(rng.integers(4))
        along = h_room if side >= 2 else w_room
        length = int(rng.integers(2, max(3, along // 2) + 1))
        off = int(rng.integers(0, max(1, along - length + 1)))
        if side == 0:  # against the top wall
            box = (r0, r0 + depth, c0 + off, c0 + off + length)
        elif side == 1:  # bottom
            box = (r1 - depth, r1, c0 + off, c0 + off + length)
        elif side == 2:  # left
            box = (r0 + off, r0 + off + length, c0, c0 + depth)
        else:  # right
            box = (r0 + off, r0 + off + length, c1 - depth, c1)
        a0, a1, b0, b1 = box
        if not keep[a0:a1, b0:b1].any():
            g[a0:a1, b0:b1] = True


def _city(rng, size: int, street, block, avenue: float, plazas: float):
    g = np.zeros((size, size), dtype=bool)

    def built(h: int, w: int) -> np.ndarray:
        b = np.ones((h, w), dtype=bool)
        along = w >= h  # lots along the longer side, an alley (1 cell) between some
        length = w if along else h
        x = 0
        for _ in range(length):
            if x >= length:
                break
            lot = int(rng.integers(4, 11))
            if rng.random() < 0.3 and x + lot < length:
                if along:
                    b[:, x + lot : x + lot + 1] = False
                else:
                    b[x + lot : x + lot + 1, :] = False
                x += 1
            x += lot
        if min(h, w) > 8 and rng.random() < 0.5:  # a courtyard
            ch, cw = int(rng.integers(2, h // 2)), int(rng.integers(2, w // 2))
            r, c = int(rng.integers(2, h - ch - 1)), int(rng.integers(2, w - cw - 1))
            b[r : r + ch, c : c + cw] = False
        for _ in range(int(rng.integers(0, 4))):  # setbacks and notches on the edges
            side = int(rng.integers(4))
            span = w if side < 2 else h
            d = int(rng.integers(1, 3))
            n = int(rng.integers(2, max(3, span // 2)))
            o = int(rng.integers(0, max(1, span - n)))
            if side == 0:
                b[:d, o : o + n] = False
            elif side == 1:
                b[h - d :, o : o + n] = False
            elif side == 2:
                b[o : o + n, :d] = False
            else:
                b[o : o + n, w - d :] = False
        return b

    lo, hi = block
    m = int(rng.integers(1, 4))
    todo = [(m, m, size - m, size - m, 0)]  # rectangles still to split (an explicit stack)
    for _ in range(4 * size):  # each split makes two smaller rectangles
        if not todo:
            break
        r0, c0, r1, c1, depth = todo.pop()
        h, w = r1 - r0, c1 - c0
        s = int(rng.integers(street[0], street[1] + 1))
        if (h <= hi and w <= hi) or depth > 12 or max(h, w) < 2 * lo + s:
            if h > 2 and w > 2 and rng.random() >= plazas:
                g[r0:r1, c0:c1] = built(h, w)
            continue
        if h >= w:
            cut = int(rng.integers(r0 + lo, r1 - lo - s + 1))
            todo += [(cut + s, c0, r1, c1, depth + 1), (r0, c0, cut, c1, depth + 1)]
        else:
            cut = int(rng.integers(c0 + lo, c1 - lo - s + 1))
            todo += [(r0, cut + s, r1, c1, depth + 1), (r0, c0, r1, cut, depth + 1)]
    if rng.random() < avenue:
        yy, xx = np.mgrid[0:size, 0:size]
        a, c = rng.uniform(0.25, 1.5), rng.uniform(-0.3, 0.3) * size
        if rng.random() < 0.5:
            a, c = -a, c + size
        g[np.abs(yy - a * xx - c) / np.hypot(1.0, a) < rng.uniform(1.5, 3.0)] = False
    return g


def _warehouse(rng, size: int, rack: int, aisle, run, cross, pallets: float):
    g = _border(np.zeros((size, size), dtype=bool))
    margin = min(int(rng.integers(8, 14)), size // 3)  # the loading area along the top
    rows = []
    r = margin
    for _ in range(size):  # rack runs down the map, cross aisles between them
        if r >= size - 4:
            break
        n = int(rng.integers(run[0], run[1] + 1))
        rows.append((r, min(r + n, size - 3)))
        r += n + int(rng.integers(cross[0], cross[1] + 1))
    c = int(rng.integers(3, 6))
    for _ in range(size):  # rack columns across the map, aisles between them
        if c + rack >= size - 3:
            break
        for r0, r1 in rows:
            g[r0:r1, c : c + rack] = True
        c += rack + int(rng.integers(aisle[0], aisle[1] + 1))
    if margin > 5:
        n = min(int(rng.poisson(pallets * size * size)), size * size // 8)
        pr = rng.integers(2, margin - 3, size=n)
        pc = rng.integers(2, size - 4, size=n)
        for r, c in zip(pr.tolist(), pc.tolist(), strict=True):
            g[r : r + 2, c : c + 2] = True
    return g


def _caves(rng, size: int, fill: float, steps: int):
    g = rng.random((size, size)) < fill
    kernel = np.ones((3, 3), dtype=int)
    for _ in range(steps):
        g = ndimage.convolve(g.astype(int), kernel, mode="constant", cval=1) >= 5
    _border(g)
    labels, n = ndimage.label(~g)  # keep the largest open region (game levels are connected)
    if n > 1:
        sizes = np.bincount(labels.ravel())[1:]
        g |= labels != int(np.argmax(sizes)) + 1
    return g
