"""Random problem generators with a certificate of solvability.

``generate("circles", seed=7, n=40)`` returns a problem *dictionary* in the file format of
``docs/problem-format.md``: plain ``dict``/``list``/``float``/``str`` values, in the format's key
order, so it round-trips through :func:`~rrtpso_ompl.model.problem_from_dict` and
``yaml.safe_dump``. :func:`~rrtpso_ompl.model.problem_file.write_problem` writes such a
dictionary as a problem file and :func:`generate_to_file` does both (the ``rrtpso generate``
command is a thin wrapper around it).

Three kinds:

* ``"circles"``: random non-overlapping circles;
* ``"polygons"``: random non-overlapping convex polygons;
* ``"maze"``: a perfect maze (exactly one route between any two cells) on a grid of cells, its walls
  as rectangles, start and goal in opposite corner cells.

Every random choice comes from one ``numpy.random.default_rng(seed)`` stream, and nothing else
(no clock, no hash order) enters the output, so the same kind, seed and options give a
byte-identical file.

**Solvability is certified, not hoped for**: every problem comes with a collision-checked grid
path (:mod:`rrtpso_ompl.groundtruth.certify`); when the certificate fails the obstacles are drawn
again from the same generator stream.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import GenerationError, ProblemError, RrtpsoError
from ..model.geometry import path_length
from ..model.problem import problem_from_dict
from ..model.problem_file import default_decimals, round_floats, write_problem
from ..validation import check_integer, check_number
from .certify import GRID_POINTS, grid_path, is_solvable

__all__ = [
    "KINDS",
    "GenerationError",
    "default_decimals",
    "generate",
    "generate_to_file",
    "grid_path",
    "is_solvable",
    "write_problem",
]

#: Most obstacles of a circle or polygon field, and most cells per side of a maze: the bounds of
#: every loop and allocation the generator makes (a maze of 200 x 200 cells has about 80,000
#: walls).
MAX_OBSTACLES = 100_000
MAX_CELLS = 200

#: The kinds of problem :func:`generate` can make.
KINDS = ("circles", "polygons", "maze")

#: Options every kind accepts, then the kind-specific ones (in signature order: it is also the
#: order in which :func:`generate_to_file` writes them into the header's command line).
_COMMON_OPTIONS = ("size", "robot_radius", "resolution", "max_attempts", "decimals", "name")
_KIND_OPTIONS = {
    "circles": ("n", "radius_range", "gap"),
    "polygons": ("n", "radius_range", "vertices", "gap"),
    "maze": ("cells", "wall", "algorithm"),
}
_OPTION_ORDER = (
    "size",
    "n",
    "cells",
    "robot_radius",
    "radius_range",
    "vertices",
    "gap",
    "wall",
    "algorithm",
    "resolution",
    "max_attempts",
    "decimals",
    "name",
)
_MAZE_ALGORITHMS = ("dfs", "kruskal")


def generate(
    kind: str,
    seed: int,
    *,
    size: float = 100.0,
    n: int | None = None,
    cells: int | None = None,
    robot_radius: float | None = None,
    radius_range: Sequence[float] | None = None,
    vertices: Sequence[int] | None = None,
    gap: float | None = None,
    wall: float | None = None,
    algorithm: str | None = None,
    resolution: float | None = None,
    max_attempts: int = 50,
    decimals: int | None = None,
    name: str | None = None,
) -> dict[str, Any]:
    """A random, valid and certified-solvable problem as a dictionary in the file format.

    The workspace is the square ``[0, size]^2``. For ``"circles"`` and ``"polygons"`` the start is
    at ``(0.05 size, 0.05 size)`` and the goal in the opposite corner, and obstacles keep at least
    ``max(2 robot_radius, 0.03 size)`` away from both. For ``"maze"`` they are the centres of the
    bottom-left and top-right cells. Obstacles are drawn, coordinates rounded to ``decimals``,
    the result validated with :func:`~rrtpso_ompl.model.problem_from_dict` and certified with
    :func:`grid_path`; when the certificate fails the obstacles are drawn again from the same
    generator stream (so the outcome still depends on the seed only).

    Parameters
    ----------
    kind : {"circles", "polygons", "maze"}
        What to generate.
    seed : int
        Seed of ``numpy.random.default_rng``, >= 0. The same seed and options give the same
        problem, byte for byte once written.
    size : float
        Side of the square workspace, > 0 (default 100).
    n : int, optional
        ``circles``/``polygons``: number of obstacles, >= 1 (defaults 30 and 20).
    cells : int, optional
        ``maze``: cells per side, >= 2 (default 8).
    robot_radius : float, optional
        Robot radius, >= 0 (0 is a point robot). Defaults: ``0.01 size`` for circles and polygons,
        a fifth of a cell for the maze.
    radius_range : (float, float), optional
        ``circles``: range of the radii; ``polygons``: range of the circumradii; ``0 < lo <= hi``.
        Defaults ``(0.02 size, 0.06 size)`` and ``(0.03 size, 0.08 size)``.
    vertices : (int, int), optional
        ``polygons``: range of the number of vertices, ``3 <= lo <= hi`` (default ``(3, 8)``).
    gap : float, optional
        ``circles``/``polygons``: least free distance between two obstacles (between their
        circumscribed circles for polygons), >= 0 (default 0: obstacles may touch but not overlap).
    wall : float, optional
        ``maze``: wall thickness, ``0 < wall < cell`` (default a tenth of a cell).
    algorithm : {"dfs", "kruskal"}, optional
        ``maze``: randomised depth-first search (long winding corridors, the default) or
        randomised Kruskal (many short dead ends). Both give a perfect maze.
    resolution : float, optional
        Grid spacing of the solvability certificate, > 0. Default ``size / 200``, and for the maze
        at most a quarter of the corridor's free width.
    max_attempts : int
        How many times to draw the obstacles before giving up, >= 1 (default 50).
    decimals : int, optional
        Decimal places of every coordinate, 0..12 (default :func:`default_decimals`: about
        ``1e-5`` of the workspace).
    name : str, optional
        The problem's ``name`` (default ``"<kind>_<seed>"``).

    Returns
    -------
    dict
        Keys ``name``, ``description``, ``bounds``, ``start``, ``goal``, ``robot``, ``obstacles``
        in the format's order; every number a Python ``float``.

    Raises
    ------
    ValueError
        For an unknown kind, an option that does not apply to the kind, or an option out of range.
    GenerationError
        (a ``ValueError``) When obstacles cannot be placed or no certified-solvable problem is
        found within ``max_attempts``.
    """
    given = {"n": n, "cells": cells, "robot_radius": robot_radius, "radius_range": radius_range,
             "vertices": vertices, "gap": gap, "wall": wall, "algorithm": algorithm}  # fmt: skip
    kind = _check_kind(kind, given)
    seed = _option("seed", check_integer, seed, low=0)
    size = _option("size", check_number, size, low=0.0, strict_low=True)
    max_attempts = _option("max_attempts", check_integer, max_attempts, low=1)
    if decimals is None:
        decimals = default_decimals(size)
    decimals = _option("decimals", check_integer, decimals, low=0, high=12)
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise GenerationError(f"name must be a non-empty string, got {name!r}")
    if resolution is not None:
        resolution = _option("resolution", check_number, resolution, low=0.0, strict_low=True)
    if kind == "maze":
        spec = _MazeSpec.build(size, cells, robot_radius, wall, algorithm, resolution)
    else:
        spec = _FieldSpec.build(kind, size, n, robot_radius, radius_range, vertices, gap)
    resolution = resolution or spec.resolution
    if resolution > size / 2:
        raise GenerationError(
            f"resolution must be at most size / 2 = {size / 2:g}, got {resolution:g}"
        )
    return _draw_until_certified(
        spec, kind, seed, name or f"{kind}_{seed}", decimals, resolution, max_attempts
    )


def _draw_until_certified(spec, kind, seed, name, decimals, resolution, max_attempts):
    """Draw obstacles from one seeded stream until the rounded problem is valid and certified."""
    rng = np.random.default_rng(seed)
    last_failure = ""
    for attempt in range(1, max_attempts + 1):
        obstacles = spec.draw(rng)
        data = round_floats(spec.document(name, obstacles), decimals)
        try:
            problem = problem_from_dict(data, source=f"<generate {kind}>")
        except ProblemError as exc:
            # Rounding can, rarely, make a polygon degenerate or nudge an obstacle onto the start.
            last_failure = f"the drawn problem was invalid after rounding ({exc.message})"
            continue
        try:
            path = grid_path(problem, resolution)
        except RrtpsoError:  # a grid that fine would be too large
            path = None
        if path is not None:
            length = _round_up(path_length(path), 4)
            how = f"certified on a grid of spacing {resolution:.3g}"
        else:
            # Gaps narrower than the grid (many small obstacles): the exact optimum decides.
            from .optimum import shortest_path

            best = shortest_path(problem, upper_bound=math.inf)
            if not best.found:
                last_failure = "start and goal are not connected (exact tangent graph)"
                continue
            length = _round_up(best.length, 4)
            how = "the exact shortest path, by rrtpso optimum's tangent graph"
        data["description"] = (
            f"{spec.describe()} Generated by rrtpso generate (kind {kind}, seed {seed}, "
            f"attempt {attempt}). A collision-free path of length {length:g} exists "
            f"({how}), so the shortest path is at most that long."
        )
        return data
    raise GenerationError(
        f"generate {kind}: no certified-solvable problem in {max_attempts} attempts "
        f"(last: {last_failure}); use fewer or smaller obstacles, a smaller robot_radius, "
        "a finer resolution or more max_attempts"
    )


def generate_to_file(kind: str, seed: int, out: str | Path, **options: Any) -> Path:
    """Generate a problem and write it as a problem file.

    Parameters
    ----------
    kind : {"circles", "polygons", "maze"}
        What to generate (see :func:`generate`).
    seed : int
        Seed of the generator, >= 0.
    out : str or Path
        The YAML file to write (its folder is created if needed; an existing file is replaced
        atomically).
    **options
        Any keyword of :func:`generate`:

        * every kind: ``size`` (side of the square workspace, default 100), ``robot_radius``,
          ``resolution`` (grid spacing of the solvability certificate), ``max_attempts``
          (default 50), ``decimals`` (decimal places of coordinates), ``name``;
        * ``circles``: ``n`` (default 30), ``radius_range`` (min and max radius), ``gap`` (least
          distance between circles);
        * ``polygons``: ``n`` (default 20), ``radius_range`` (circumradii), ``vertices`` (min and
          max vertex count, default 3 to 8), ``gap``;
        * ``maze``: ``cells`` (per side, default 8), ``wall`` (thickness), ``algorithm``
          (``"dfs"`` or ``"kruskal"``).

    Returns
    -------
    Path
        ``out``. The file starts with a comment holding the command that regenerates it,
        ``rrtpso generate KIND --seed N [--option value ...]``, and is byte-identical for the same
        kind, seed and options (the output path is not part of it).

    Raises
    ------
    ValueError
        Bad options, or :class:`GenerationError` (see :func:`generate`).
    TypeError
        An unknown option name.
    """
    unknown = sorted(set(options) - set(_OPTION_ORDER))
    if unknown:
        raise TypeError(
            f"generate_to_file() got unknown option(s) {', '.join(unknown)}; "
            f"known: {', '.join(_OPTION_ORDER)}"
        )
    data = generate(kind, seed, **options)
    command = " ".join(
        [f"rrtpso generate {kind} --seed {seed}"]
        + [
            f"--{key.replace('_', '-')} {_cli_value(options[key])}"
            for key in _OPTION_ORDER
            if options.get(key) is not None
        ]
    )
    header = (
        f"Generated by: {command} --out FILE\n"
        "Every obstacle below was drawn from numpy.random.default_rng(seed); the same command\n"
        "writes the same bytes. Solvability is certified by a collision-free grid path\n"
        "(rrtpso generate's certificate), see the description."
    )
    return write_problem(data, out, header=header, decimals=options.get("decimals"))


# ----------------------------------------------------------------------------------------------
# The kinds
# ----------------------------------------------------------------------------------------------
class _FieldSpec:
    """Random non-overlapping circles or convex polygons, start and goal in opposite corners."""

    def __init__(self, kind, size, n, robot_radius, radius_range, vertices, gap) -> None:
        self.kind = kind
        self.size = size
        self.n = n
        self.robot_radius = robot_radius
        self.radius_range = radius_range
        self.vertices = vertices
        self.gap = gap
        inset = 0.05 * size
        self.start = np.array([inset, inset])
        self.goal = np.array([size - inset, size - inset])
        # Obstacles keep off start and goal: the robot must be able to turn away from them.
        self.keep_out = max(2.0 * robot_radius, 0.03 * size)
        self.resolution = size / GRID_POINTS

    @classmethod
    def build(cls, kind, size, n, robot_radius, radius_range, vertices, gap) -> _FieldSpec:
        default_n = 30 if kind == "circles" else 20
        n = _option("n", check_integer, default_n if n is None else n, low=1, high=MAX_OBSTACLES)
        default_range = (0.02, 0.06) if kind == "circles" else (0.03, 0.08)
        if radius_range is None:
            shrink = _shrink(n, default_n)
            radius_range = (default_range[0] * size * shrink, default_range[1] * size * shrink)
        lo, hi = _check_range("radius_range", radius_range, number=True)
        if lo <= 0:
            raise GenerationError(f"radius_range must be positive, got ({lo:g}, {hi:g})")
        if hi >= size / 2:
            raise GenerationError(
                f"radius_range: the largest radius {hi:g} must be less than size / 2 = {size / 2:g}"
            )
        if kind == "polygons":
            v = _check_range("vertices", (3, 8) if vertices is None else vertices, number=False)
            if v[0] < 3:
                raise GenerationError(f"vertices: a polygon needs at least 3, got ({v[0]}, {v[1]})")
        else:
            v = None
        if robot_radius is None:
            robot_radius = 0.01 * size * _shrink(n, default_n)  # as the radii
        robot_radius = _option("robot_radius", check_number, robot_radius, low=0.0)
        if robot_radius >= 0.05 * size:
            raise GenerationError(
                f"robot_radius {robot_radius:g} must be less than the start's inset from the "
                f"corner, 0.05 size = {0.05 * size:g}"
            )
        gap = _option("gap", check_number, 0.0 if gap is None else gap, low=0.0)
        return cls(kind, size, n, robot_radius, (lo, hi), v, gap)

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        """n obstacles by rejection sampling.

        Candidates come in batches of 256, each tested against the obstacles placed so far that
        a k-d tree of their centres names within reach (``r + hi + gap``), then accepted in
        order, each also tested against those accepted before it in the same batch. The cost
        per batch grows as ``log n``, not ``n``: 10,000 obstacles take a second or two. The
        stream is consumed batch by batch, so the result depends on the seed only.
        """
        lo, hi = self.radius_range
        centres = np.empty((self.n, 2))
        radii = np.empty(self.n)
        ends = np.array([self.start, self.goal])
        placed = 0
        budget = max(200 * self.n, 10_000)
        batch = 256
        for _ in range(0, budget, batch):
            r = rng.uniform(lo, hi, size=batch)
            c = rng.uniform(r[:, None], self.size - r[:, None], size=(batch, 2))
            clear_ends = (
                np.hypot(c[:, None, 0] - ends[None, :, 0], c[:, None, 1] - ends[None, :, 1])
                - r[:, None]
            )
            ok = np.all(clear_ends >= self.keep_out, axis=1)
            if placed:
                ok &= _clear_of(c, r, centres[:placed], radii[:placed], hi, self.gap)
            first_new = placed
            for k in np.flatnonzero(ok).tolist():
                new = slice(first_new, placed)  # accepted earlier in this batch
                if placed > first_new and np.any(
                    np.hypot(*(centres[new] - c[k]).T) < radii[new] + r[k] + self.gap
                ):
                    continue
                centres[placed], radii[placed] = c[k], r[k]
                placed += 1
                if placed == self.n:
                    break
            if placed == self.n:
                break
        else:
            raise GenerationError(
                f"generate {self.kind}: placed only {placed} of {self.n} non-overlapping "
                f"obstacles (radius {lo:g}-{hi:g}, gap {self.gap:g}) in {budget} tries; "
                "use fewer or smaller obstacles or a larger size"
            )
        if self.kind == "circles":
            return [
                {"type": "circle", "center": c.tolist(), "radius": float(r)}
                for c, r in zip(centres, radii, strict=True)
            ]
        return [
            {"type": "polygon", "points": _convex_polygon(rng, c, r, self.vertices).tolist()}
            for c, r in zip(centres, radii, strict=True)
        ]

    def document(self, name: str, obstacles: list[dict[str, Any]]) -> dict[str, Any]:
        return _document(name, self.size, self.start, self.goal, self.robot_radius, obstacles)

    def describe(self) -> str:
        lo, hi = self.radius_range
        what = (
            f"{self.n} random non-overlapping circles of radius {lo:.3g}-{hi:.3g}"
            if self.kind == "circles"
            else f"{self.n} random non-overlapping convex polygons with {self.vertices[0]}-"
            f"{self.vertices[1]} vertices and circumradius {lo:.3g}-{hi:.3g}"
        )
        return (
            f"{what} in a {self.size:g} x {self.size:g} workspace, robot radius "
            f"{self.robot_radius:g}, start and goal in opposite corners."
        )


#: Up to this many obstacles the default radii are fixed fractions of the size (the files of
#: problems/ were made so); beyond it they shrink.
_SHRINK_FROM = 100


def _shrink(n: int, default_n: int) -> float:
    """Factor of the default radii (and robot radius) for ``n`` obstacles: 1 up to
    :data:`_SHRINK_FROM`, then ``sqrt(default_n / n)``, so that the obstacles cover the share of
    the workspace the default count covers (about 15 % for circles) and the world stays
    feasible: 10,000 circles in a 100 x 100 world have radii 0.11-0.33 and a robot of radius
    0.055."""
    return 1.0 if n <= _SHRINK_FROM else math.sqrt(default_n / n)


def _clear_of(c, r, centres, radii, hi: float, gap: float) -> np.ndarray:
    """Whether each candidate disc ``(c[k], r[k])`` keeps ``gap`` from every placed disc: only the
    placed discs a k-d tree finds within ``r[k] + hi + gap`` can be too close."""
    from scipy.spatial import cKDTree

    ok = np.ones(len(c), dtype=bool)
    near = cKDTree(centres).query_ball_point(c, r + hi + gap)
    for k, idx in enumerate(near):
        if idx:
            d = np.hypot(*(centres[idx] - c[k]).T)
            ok[k] = bool(np.all(d >= radii[idx] + r[k] + gap))
    return ok


class _MazeSpec:
    """A perfect maze on a cells x cells grid; one rectangle per wall between two cells."""

    def __init__(self, size, cells, robot_radius, wall, algorithm, resolution) -> None:
        self.size = size
        self.cells = cells
        self.robot_radius = robot_radius
        self.wall = wall
        self.algorithm = algorithm
        self.resolution = resolution
        cell = size / cells
        self.start = np.array([0.5 * cell, 0.5 * cell])
        self.goal = np.array([size - 0.5 * cell, size - 0.5 * cell])

    @classmethod
    def build(cls, size, cells, robot_radius, wall, algorithm, resolution) -> _MazeSpec:
        cells = _option(
            "cells", check_integer, 8 if cells is None else cells, low=2, high=MAX_CELLS
        )
        cell = size / cells
        wall = _option(
            "wall", check_number, 0.1 * cell if wall is None else wall, low=0.0, strict_low=True
        )
        if wall >= cell:
            raise GenerationError(
                f"wall thickness {wall:g} must be less than the cell size {cell:g}"
            )
        if robot_radius is None:
            robot_radius = 0.2 * cell
        robot_radius = _option("robot_radius", check_number, robot_radius, low=0.0)
        corridor = cell - wall - 2.0 * robot_radius  # free width for the robot's centre
        if corridor <= 0:
            raise GenerationError(
                f"the robot (diameter {2 * robot_radius:g}) does not fit the maze corridors "
                f"(cell {cell:g} minus wall {wall:g} = {cell - wall:g}); use a smaller "
                "robot_radius or wall, or fewer cells"
            )
        algorithm = "dfs" if algorithm is None else algorithm
        if algorithm not in _MAZE_ALGORITHMS:
            raise GenerationError(
                f"algorithm must be one of {', '.join(_MAZE_ALGORITHMS)}, got {algorithm!r}"
            )
        # At least four grid points across every corridor, so the certificate cannot miss one.
        resolution = resolution or min(size / GRID_POINTS, corridor / 4.0)
        return cls(size, cells, robot_radius, wall, algorithm, resolution)

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        c = self.cells
        # Interior walls: vertical ones between (r, k) and (r, k + 1), then horizontal ones
        # between (r, k) and (r + 1, k); a cell (r, k) is the integer r * c + k.
        vertical = [(r * c + k, r * c + k + 1) for r in range(c) for k in range(c - 1)]
        horizontal = [(r * c + k, (r + 1) * c + k) for r in range(c - 1) for k in range(c)]
        walls = vertical + horizontal
        carve = _dfs_tree if self.algorithm == "dfs" else _kruskal_tree
        opened = carve(rng, c, walls)
        cell = self.size / c
        h = 0.5 * self.wall
        obstacles = []
        # Each wall runs along its cell edge and half a thickness beyond both ends, so walls
        # meeting at a corner overlap (no leak) and walls reaching the border pass it (no gap).
        for w, (p, q) in enumerate(walls):
            if w in opened:
                continue
            r, k = divmod(p, c)
            if q == p + 1:  # vertical wall at x = (k + 1) cell
                lo = [(k + 1) * cell - h, r * cell - h]
                hi = [(k + 1) * cell + h, (r + 1) * cell + h]
            else:  # horizontal wall at y = (r + 1) cell
                lo = [k * cell - h, (r + 1) * cell - h]
                hi = [(k + 1) * cell + h, (r + 1) * cell + h]
            obstacles.append({"type": "rectangle", "min": lo, "max": hi})
        return obstacles

    def document(self, name: str, obstacles: list[dict[str, Any]]) -> dict[str, Any]:
        return _document(name, self.size, self.start, self.goal, self.robot_radius, obstacles)

    def describe(self) -> str:
        how = "randomised depth-first search" if self.algorithm == "dfs" else "randomised Kruskal"
        n_walls = (self.cells - 1) ** 2
        return (
            f"A perfect maze ({how}) of {self.cells} x {self.cells} cells in a {self.size:g} x "
            f"{self.size:g} workspace: its {n_walls} interior walls of thickness {self.wall:g} are "
            "rectangles (the bounds are the outer wall), so exactly one corridor route joins any "
            f"two cells. Robot radius {self.robot_radius:g}; start and goal at the centres of "
            "opposite corner cells."
        )


def _dfs_tree(rng: np.random.Generator, c: int, walls: list[tuple[int, int]]) -> set[int]:
    """Walls opened by a randomised depth-first search (recursive backtracker) from cell 0."""
    wall_of: dict[tuple[int, int], int] = {}
    for w, (p, q) in enumerate(walls):
        wall_of[(p, q)] = wall_of[(q, p)] = w
    visited = np.zeros(c * c, dtype=bool)
    visited[0] = True
    stack = [0]
    opened: set[int] = set()
    while stack:
        p = stack[-1]
        r, k = divmod(p, c)
        options = [
            q
            for q, inside in (
                (p - c, r > 0),
                (p + c, r < c - 1),
                (p - 1, k > 0),
                (p + 1, k < c - 1),
            )
            if inside and not visited[q]
        ]
        if not options:
            stack.pop()
            continue
        q = options[int(rng.integers(len(options)))]
        opened.add(wall_of[(p, q)])
        visited[q] = True
        stack.append(q)
    return opened


def _kruskal_tree(rng: np.random.Generator, c: int, walls: list[tuple[int, int]]) -> set[int]:
    """Walls opened by randomised Kruskal: walls in random order, opened when they join two
    separate regions (union-find with path halving)."""
    parent = list(range(c * c))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    opened: set[int] = set()
    for w in rng.permutation(len(walls)).tolist():
        p, q = walls[w]
        rp, rq = find(p), find(q)
        if rp != rq:
            parent[rp] = rq
            opened.add(w)
    return opened


def _convex_polygon(
    rng: np.random.Generator, centre: np.ndarray, radius: float, vertices: tuple[int, int]
) -> np.ndarray:
    """A random convex polygon inscribed in the circle (centre, radius).

    Vertices at jittered, increasing angles on an ellipse (a random squash and rotation of the
    circle): points on an ellipse in angular order are always a strictly convex polygon, and the
    jitter keeps every angular step at least 40% of the even one, so there are no slivers.
    """
    k = int(rng.integers(vertices[0], vertices[1] + 1))
    theta0 = rng.uniform(0.0, 2.0 * math.pi)
    jitter = rng.uniform(-0.3, 0.3, size=k)
    angles = theta0 + 2.0 * math.pi * (np.arange(k) + jitter) / k
    aspect = rng.uniform(0.5, 1.0)
    phi = rng.uniform(0.0, math.pi)
    unit = np.column_stack([np.cos(angles), aspect * np.sin(angles)])
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    return centre + radius * unit @ rot.T


def _document(
    name: str,
    size: float,
    start: np.ndarray,
    goal: np.ndarray,
    robot_radius: float,
    obstacles: list[dict[str, Any]],
) -> dict[str, Any]:
    return {
        "name": name,
        "description": "",  # filled in once the problem is certified
        "bounds": [[0.0, 0.0], [float(size), float(size)]],
        "start": [float(v) for v in start],
        "goal": [float(v) for v in goal],
        "robot": {"radius": float(robot_radius)},
        "obstacles": obstacles,
    }


def _round_up(x: float, digits: int) -> float:
    """``x`` rounded *up* to ``digits`` significant digits (an upper bound stays an upper bound)."""
    if x <= 0 or not math.isfinite(x):
        return x
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(x)))
    return math.ceil(x * scale) / scale


def _cli_value(value: Any) -> str:
    if isinstance(value, list | tuple):
        return " ".join(_cli_value(v) for v in value)
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _check_kind(kind: Any, given: dict[str, Any]) -> str:
    """The kind, with every option given checked to apply to it."""
    if kind not in KINDS:
        raise GenerationError(f"unknown kind {kind!r}; known kinds: {', '.join(KINDS)}")
    for key, value in given.items():
        if value is not None and key not in _KIND_OPTIONS[kind] and key not in _COMMON_OPTIONS:
            applies = [k for k, opts in _KIND_OPTIONS.items() if key in opts]
            raise GenerationError(
                f"option '{key}' does not apply to kind '{kind}' "
                f"(it applies to: {', '.join(applies)}); options for {kind}: "
                f"{', '.join(_KIND_OPTIONS[kind] + _COMMON_OPTIONS)}"
            )
    return kind


def _option(name: str, check: Callable[..., Any], value: Any, **limits: Any) -> Any:
    """``check(value, **limits)`` with the option's name in a :class:`GenerationError`."""
    try:
        return check(value, **limits)
    except ValueError as exc:
        raise GenerationError(f"{name} {exc}") from None


def _check_range(name: str, value: Any, number: bool) -> tuple[Any, Any]:
    if isinstance(value, str) or not isinstance(value, Sequence) or len(value) != 2:
        raise GenerationError(f"{name} must be a pair (min, max), got {value!r}")
    check = check_number if number else check_integer
    lo, hi = _option(f"{name}[0]", check, value[0]), _option(f"{name}[1]", check, value[1])
    if lo > hi:
        raise GenerationError(f"{name} needs min <= max, got ({lo}, {hi})")
    return lo, hi
