"""Random problem generators with a certificate of solvability.

``generate("circles", seed=7, n=40)`` returns a problem *dictionary* in the file format of
``docs/problem-format.md``: plain ``dict``/``list``/``float``/``str`` values, in the format's key
order, so it round-trips through :func:`~rrtpso_ompl.problem.problem_from_dict` and
``yaml.safe_dump``. :func:`write_problem` writes such a dictionary as a problem file and
:func:`generate_to_file` does both (the ``rrtpso generate`` command is a thin wrapper around it).

Three kinds:

* ``"circles"``: random non-overlapping circles;
* ``"polygons"``: random non-overlapping convex polygons;
* ``"maze"``: a perfect maze (exactly one route between any two cells) on a grid of cells, its walls
  as rectangles, start and goal in opposite corner cells.

Every random choice comes from one ``numpy.random.default_rng(seed)`` stream, and nothing else
(no clock, no hash order) enters the output, so the same kind, seed and options give a
byte-identical file.

**Solvability is certified, not hoped for.** :func:`grid_path` searches a fine grid of the free
configuration space: grid points are free by the world's exact point clearance
(:meth:`~rrtpso_ompl.world.World.point_clearance`), neighbouring free points are joined when the
segment between them is free, and a shortest route is found with Dijkstra's algorithm. A segment
is accepted either by the exact test :meth:`~rrtpso_ompl.world.World.segments_free` or, when both
ends are far enough from every obstacle, by the Lipschitz bound (clearance changes by at most the
distance moved, so a segment of length ``L`` whose ends both have clearance ``c`` keeps at least
``c - L/2`` everywhere). Every edge of the returned polyline is therefore a genuine collision-free
motion: a path found is a proof that the problem is solvable, with no OMPL and no randomness.
(The converse does not hold: a passage narrower than the grid spacing may be missed, in which case
the generator draws again.)
"""

from __future__ import annotations

import math
import numbers
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from ..model.problem import (
    _MOVING_KEYS,
    _OBSTACLE_KEYS,
    _PLANNER_KEYS,
    _ROBOT_KEYS,
    _TOP_KEYS,
    Problem,
    ProblemError,
    problem_from_dict,
)
from ..model.world import World
from ..outputs import write_text_atomic

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

#: Grid points per side of the solvability check unless ``resolution`` says otherwise: fine enough
#: for corridors a few percent of the workspace wide, coarse enough to take a fraction of a second.
_GRID_POINTS = 200
#: Largest grid of the solvability check (memory: a few hundred bytes per point).
_MAX_GRID_POINTS = 4_000_000
#: Segments per vectorised distance call: bounds the (chunk x obstacle edges) arrays.
_CHUNK = 4096
#: Grid points per side of a tile of the solvability grid (see _Tiles).
_TILE = 16


class GenerationError(ValueError):
    """No problem satisfying the options was found within the allowed attempts.

    A ``ValueError``: the options ask for something too dense (too many or too large obstacles,
    too large a robot) for the workspace.
    """


# ----------------------------------------------------------------------------------------------
# Public API
# ----------------------------------------------------------------------------------------------
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
    the result validated with :func:`~rrtpso_ompl.problem.problem_from_dict` and certified with
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
    given = {
        "n": n,
        "cells": cells,
        "robot_radius": robot_radius,
        "radius_range": radius_range,
        "vertices": vertices,
        "gap": gap,
        "wall": wall,
        "algorithm": algorithm,
    }
    kind = _check_kind(kind)
    for key, value in given.items():
        if value is not None and key not in _KIND_OPTIONS[kind] and key not in _COMMON_OPTIONS:
            applies = [k for k, opts in _KIND_OPTIONS.items() if key in opts]
            raise ValueError(
                f"option '{key}' does not apply to kind '{kind}' "
                f"(it applies to: {', '.join(applies)}); options for {kind}: "
                f"{', '.join(_KIND_OPTIONS[kind] + _COMMON_OPTIONS)}"
            )
    seed = _check_int("seed", seed, low=0)
    size = _check_number("size", size, low=0.0, strict=True)
    max_attempts = _check_int("max_attempts", max_attempts, low=1)
    decimals = (
        default_decimals(size) if decimals is None else _check_int("decimals", decimals, 0, 12)
    )
    if name is not None and (not isinstance(name, str) or not name.strip()):
        raise ValueError(f"name must be a non-empty string, got {name!r}")
    name = name or f"{kind}_{seed}"
    if resolution is not None:
        resolution = _check_number("resolution", resolution, low=0.0, strict=True)

    if kind == "maze":
        spec = _MazeSpec.build(size, cells, robot_radius, wall, algorithm, resolution)
    else:
        spec = _FieldSpec.build(kind, size, n, robot_radius, radius_range, vertices, gap)
    resolution = resolution or spec.resolution
    if resolution > size / 2:
        raise ValueError(f"resolution must be at most size / 2 = {size / 2:g}, got {resolution:g}")

    rng = np.random.default_rng(seed)
    last_failure = ""
    for attempt in range(1, max_attempts + 1):
        obstacles = spec.draw(rng)
        data = _round_floats(spec.document(name, obstacles), decimals)
        try:
            problem = problem_from_dict(data, source=f"<generate {kind}>")
        except ProblemError as exc:
            # Rounding can, rarely, make a polygon degenerate or nudge an obstacle onto the start.
            last_failure = f"the drawn problem was invalid after rounding ({exc.message})"
            continue
        path = grid_path(problem, resolution)
        if path is None:
            last_failure = f"no collision-free grid path at resolution {resolution:g}"
            continue
        length = _round_up(float(np.hypot(*np.diff(path, axis=0).T).sum()), 4)
        data["description"] = (
            f"{spec.describe()} Generated by rrtpso_ompl.generate (kind {kind}, seed {seed}, "
            f"attempt {attempt}). A collision-free path of length {length:g} exists "
            f"(certified on a grid of spacing {resolution:.3g}), so the "
            "shortest path is at most that long."
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
        "(rrtpso_ompl.generate.grid_path), see the description."
    )
    return write_problem(data, out, header=header, decimals=options.get("decimals"))


def write_problem(
    data: Mapping[str, Any],
    path: str | Path,
    *,
    header: str | None = None,
    decimals: int | None = None,
) -> Path:
    """Write a problem dictionary as a problem file.

    Keys are written in the format's documented order (top level, ``robot``, ``planner``, each
    obstacle, each moving obstacle), points and obstacles on one line each in YAML flow style,
    like the hand-written files in ``problems/``. Every float is rounded to ``decimals`` places
    first, and the rounded problem is validated again: rounding may move an obstacle onto the
    start or make a thin polygon degenerate, and such a file is refused rather than written.

    Parameters
    ----------
    data : mapping
        A problem in the file format (as from :func:`generate` or ``yaml.safe_load``).
    path : str or Path
        Where to write; the folder is created if needed, the file replaced atomically.
    header : str, optional
        Comment lines written first (each line gets a ``# `` prefix).
    decimals : int, optional
        Decimal places for floats, 0..12; default :func:`default_decimals` of the bounds.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ProblemError
        When ``data`` is not a valid problem.
    ValueError
        When it is no longer valid after rounding (the message says which key and suggests more
        decimals), or ``decimals`` is out of range.
    """
    path = Path(path)
    problem = problem_from_dict(data, source=str(path))
    if decimals is None:
        (xmin, ymin), (xmax, ymax) = problem.bounds
        decimals = default_decimals(max(xmax - xmin, ymax - ymin))
    else:
        decimals = _check_int("decimals", decimals, 0, 12)
    rounded = _round_floats(data, decimals)
    try:
        problem_from_dict(rounded, source=str(path))
    except ProblemError as exc:
        raise ValueError(
            f"{path}: after rounding to {decimals} decimals the problem is no longer valid: "
            f"{exc.key + ': ' if exc.key else ''}{exc.message}; write more decimals"
        ) from None

    text = _format_problem(rounded, header)
    # The text must read back as exactly the validated dictionary: a formatting slip (a string
    # that YAML would read as a number, say) must not reach the file.
    if yaml.safe_load(text) != _plain(rounded):
        raise AssertionError("internal error: the formatted YAML does not read back as written")

    return write_text_atomic(text, path)


def default_decimals(size: float) -> int:
    """Decimal places that keep coordinates to about ``1e-5`` of a workspace of side ``size``.

    3 for a side of 100 to 999, 2 for 1000 to 9999, 4 for 10 to 99, and so on (between 0 and 12).
    """
    if not (size > 0 and math.isfinite(size)):
        raise ValueError(f"size must be a positive finite number, got {size!r}")
    return int(min(12, max(0, 5 - math.floor(math.log10(size)))))


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
    (xmin, ymin), (xmax, ymax) = world.bounds
    if resolution is None:
        resolution = max(xmax - xmin, ymax - ymin) / _GRID_POINTS
    resolution = _check_number("resolution", resolution, low=0.0, strict=True)
    nx = math.ceil((xmax - xmin) / resolution) + 1
    ny = math.ceil((ymax - ymin) / resolution) + 1
    if nx * ny > _MAX_GRID_POINTS:
        raise ValueError(
            f"resolution {resolution:g} is too fine for these bounds: {nx} x {ny} grid points "
            f"(at most {_MAX_GRID_POINTS:,})"
        )
    xs = np.linspace(xmin, xmax, nx)
    ys = np.linspace(ymin, ymax, ny)
    hx, hy = xs[1] - xs[0], ys[1] - ys[0]
    gx, gy = np.meshgrid(xs, ys)  # node (j, i) is point (xs[i], ys[j]), index j * nx + i
    points = np.column_stack([gx.ravel(), gy.ravel()])
    # Clearance matters only up to what the edge test below can use; beyond `cap` it is clipped.
    step = math.hypot(hx, hy)  # the longest grid edge
    cap = world.threshold + 0.5 * step + 2.0 * world.tol
    tiles = _Tiles(world, xs, ys, reach=cap + step)
    clearance = tiles.clearance(points, cap)
    free = clearance >= world.threshold

    # Grid edges to the right, up, up-right and up-left neighbours: each undirected edge once.
    index = np.arange(nx * ny).reshape(ny, nx)
    a_parts, b_parts = [], []
    for dj, di in ((0, 1), (1, 0), (1, 1), (1, -1)):
        i0, i1 = max(0, -di), nx - max(0, di)
        a_parts.append(index[: ny - dj, i0:i1].ravel())
        b_parts.append(index[dj:, i0 + di : i1 + di].ravel())
    a = np.concatenate(a_parts)
    b = np.concatenate(b_parts)
    keep = free[a] & free[b]
    a, b = a[keep], b[keep]
    length = np.hypot(*(points[b] - points[a]).T)
    # Lipschitz bound: clearance drops by at most the distance moved, and every point of a
    # segment is within L/2 of an end. The margin `tol` keeps the bound safe from round-off.
    sure = np.minimum(clearance[a], clearance[b]) - 0.5 * length >= world.threshold + world.tol
    unsure = np.flatnonzero(~sure)
    ok = sure.copy()
    if len(unsure):
        ok[unsure] = tiles.segments_free(points, a[unsure], b[unsure])
    a, b, length = a[ok], b[ok], length[ok]

    # Start and goal join the grid points of the cells around them (within 1.5 cells).
    n_grid = nx * ny
    s_idx, g_idx = n_grid, n_grid + 1
    extra_a, extra_b, extra_len = [], [], []
    ends = np.array([problem.start, problem.goal], dtype=float)
    reach = 1.5 * max(hx, hy)
    for node, p in ((s_idx, ends[0]), (g_idx, ends[1])):
        i_lo = max(0, math.floor((p[0] - xmin - reach) / hx))
        i_hi = min(nx - 1, math.ceil((p[0] - xmin + reach) / hx))
        j_lo = max(0, math.floor((p[1] - ymin - reach) / hy))
        j_hi = min(ny - 1, math.ceil((p[1] - ymin + reach) / hy))
        near = index[j_lo : j_hi + 1, i_lo : i_hi + 1].ravel()
        near = near[free[near]]
        near = near[np.hypot(*(points[near] - p).T) <= reach]
        if len(near):
            near = near[world.segments_free(np.broadcast_to(p, (len(near), 2)), points[near])]
        extra_a.append(np.full(len(near), node))
        extra_b.append(near)
        extra_len.append(np.hypot(*(points[near] - p).T))
    # The straight segment itself, when free (then no grid is needed at all).
    if world.segments_free(ends[:1], ends[1:])[0]:
        extra_a.append(np.array([s_idx]))
        extra_b.append(np.array([g_idx]))
        extra_len.append(np.array([float(np.hypot(*(ends[1] - ends[0])))]))

    all_points = np.vstack([points, ends])
    rows = np.concatenate([a, *extra_a])
    cols = np.concatenate([b, *extra_b])
    # csgraph drops explicit zero weights (no edge): a start on a grid point needs a tiny weight.
    weight = np.maximum(np.concatenate([length, *extra_len]), 1e-12 * max(hx, hy))
    graph = coo_matrix((weight, (rows, cols)), shape=(n_grid + 2, n_grid + 2)).tocsr()
    dist, pred = dijkstra(graph, directed=False, indices=s_idx, return_predecessors=True)

    # The goal, or with a goal tolerance the nearest-by-route grid point within it.
    targets = [g_idx]
    if problem.goal_tolerance > 0:
        within = np.flatnonzero(
            free & (np.hypot(*(points - ends[1]).T) <= problem.goal_tolerance)
        ).tolist()
        targets += within
    best = min(targets, key=lambda t: dist[t])
    if not math.isfinite(dist[best]):
        return None
    route = [best]
    while route[-1] != s_idx:
        route.append(int(pred[route[-1]]))
    path = all_points[route[::-1]]
    return _shortcut(world, path) if shortcut else path


def is_solvable(problem: Problem, resolution: float | None = None) -> bool:
    """Whether :func:`grid_path` certifies the problem solvable (see there; False is not a proof
    of unsolvability)."""
    return grid_path(problem, resolution, shortcut=False) is not None


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
        self.resolution = size / _GRID_POINTS

    @classmethod
    def build(cls, kind, size, n, robot_radius, radius_range, vertices, gap) -> _FieldSpec:
        default_n = 30 if kind == "circles" else 20
        n = _check_int("n", default_n if n is None else n, low=1)
        default_range = (0.02, 0.06) if kind == "circles" else (0.03, 0.08)
        if radius_range is None:
            radius_range = (default_range[0] * size, default_range[1] * size)
        lo, hi = _check_range("radius_range", radius_range, number=True)
        if lo <= 0:
            raise ValueError(f"radius_range must be positive, got ({lo:g}, {hi:g})")
        if hi >= size / 2:
            raise ValueError(
                f"radius_range: the largest radius {hi:g} must be less than size / 2 = {size / 2:g}"
            )
        if kind == "polygons":
            v = _check_range("vertices", (3, 8) if vertices is None else vertices, number=False)
            if v[0] < 3:
                raise ValueError(f"vertices: a polygon needs at least 3, got ({v[0]}, {v[1]})")
        else:
            v = None
        if robot_radius is None:
            robot_radius = 0.01 * size
        robot_radius = _check_number("robot_radius", robot_radius, low=0.0)
        if robot_radius >= 0.05 * size:
            raise ValueError(
                f"robot_radius {robot_radius:g} must be less than the start's inset from the "
                f"corner, 0.05 size = {0.05 * size:g}"
            )
        gap = _check_number("gap", 0.0 if gap is None else gap, low=0.0)
        return cls(kind, size, n, robot_radius, (lo, hi), v, gap)

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        """n obstacles by rejection sampling.

        Candidates come in batches of 256 (one vectorised test against everything placed so far),
        then the survivors are accepted in order, each tested against those accepted before it in
        the same batch. The stream is consumed batch by batch, so the result depends on the seed
        only.
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
                d = np.hypot(
                    c[:, None, 0] - centres[None, :placed, 0],
                    c[:, None, 1] - centres[None, :placed, 1],
                )
                ok &= np.all(d >= radii[None, :placed] + r[:, None] + self.gap, axis=1)
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
        cells = _check_int("cells", 8 if cells is None else cells, low=2)
        cell = size / cells
        wall = _check_number("wall", 0.1 * cell if wall is None else wall, low=0.0, strict=True)
        if wall >= cell:
            raise ValueError(f"wall thickness {wall:g} must be less than the cell size {cell:g}")
        if robot_radius is None:
            robot_radius = 0.2 * cell
        robot_radius = _check_number("robot_radius", robot_radius, low=0.0)
        corridor = cell - wall - 2.0 * robot_radius  # free width for the robot's centre
        if corridor <= 0:
            raise ValueError(
                f"the robot (diameter {2 * robot_radius:g}) does not fit the maze corridors "
                f"(cell {cell:g} minus wall {wall:g} = {cell - wall:g}); use a smaller "
                "robot_radius or wall, or fewer cells"
            )
        algorithm = "dfs" if algorithm is None else algorithm
        if algorithm not in _MAZE_ALGORITHMS:
            raise ValueError(
                f"algorithm must be one of {', '.join(_MAZE_ALGORITHMS)}, got {algorithm!r}"
            )
        # At least four grid points across every corridor, so the certificate cannot miss one.
        resolution = resolution or min(size / _GRID_POINTS, corridor / 4.0)
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


# ----------------------------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------------------------
def _format_problem(data: Mapping[str, Any], header: str | None) -> str:
    lines = [f"# {line}".rstrip() for line in header.splitlines()] if header else []
    nested = {"robot": _ROBOT_KEYS, "planner": _PLANNER_KEYS}
    for key in _ordered(data, _TOP_KEYS):
        value = data[key]
        if value is None:
            continue
        if key in nested and isinstance(value, Mapping):
            lines.append(f"{key}:")
            lines += [f"  {k}: {_flow(value[k])}" for k in _ordered(value, nested[key])]
        elif key in ("obstacles", "moving_obstacles") and isinstance(value, list | tuple):
            if not value:
                lines.append(f"{key}: []")
                continue
            lines.append(f"{key}:")
            for item in value:
                order = (
                    _OBSTACLE_KEYS.get(item.get("type"), ()) if key == "obstacles" else _MOVING_KEYS
                )
                lines.append(f"  - {_flow({k: item[k] for k in _ordered(item, order)})}")
        elif key == "description" and isinstance(value, str):
            lines.append(_folded(key, value))
        else:
            lines.append(f"{key}: {_flow(value)}")
    return "\n".join(lines) + "\n"


def _folded(key: str, text: str) -> str:
    """``key: >-`` and the text folded at 100 columns, like the hand-written files.

    Folding is exact only for plain one-line prose (no line breaks, no runs of spaces, no
    leading or trailing space); anything else is left to PyYAML's own quoting.
    """
    if text and text == " ".join(text.split()) and text.isprintable():
        body = textwrap.wrap(text, width=98, break_long_words=False, break_on_hyphens=False)
        block = f"{key}: >-\n" + "\n".join(f"  {line}" for line in body)
        if yaml.safe_load(block) == {key: text}:
            return block
    return yaml.safe_dump({key: text}, width=80, sort_keys=False, allow_unicode=True).rstrip("\n")


def _ordered(mapping: Mapping[str, Any], order: Sequence[str]) -> list[str]:
    """Keys of ``mapping`` in the documented ``order`` (any others, which validation has already
    refused at the top levels, after them in their own order)."""
    return [k for k in order if k in mapping] + [k for k in mapping if k not in order]


def _flow(value: Any) -> str:
    """One value as single-line YAML flow text (``[1.5, 2.0]``, ``{type: circle, ...}``)."""
    text = yaml.safe_dump(
        _plain(value),
        default_flow_style=True,
        width=math.inf,
        sort_keys=False,
        allow_unicode=True,
    ).strip()
    # A lone scalar is dumped as a document with an explicit end marker.
    if text.endswith("\n..."):
        text = text[: -len("\n...")].rstrip()
    return text


def _plain(value: Any) -> Any:
    """Mappings as dicts, sequences as lists, numpy scalars as Python numbers (for PyYAML)."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _round_floats(value: Any, decimals: int) -> Any:
    """A deep copy with every float rounded (ints, bools and strings untouched, -0.0 made 0.0)."""
    if isinstance(value, Mapping):
        return {k: _round_floats(v, decimals) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_round_floats(v, decimals) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and math.isfinite(value):
        return round(value, decimals) + 0.0
    return value


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


# ----------------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------------
def _shortcut(world: World, path: np.ndarray) -> np.ndarray:
    """Greedy straightening: from each kept waypoint jump to the farthest one in free sight.

    The look-ahead window starts at 64 waypoints and doubles while its far end is in sight (a
    long winding route need not be tested against every later waypoint). Every new segment passes
    the exact test, so the result is as certified as the input.
    """
    out = [0]
    i = 0
    last = len(path) - 1
    while i < last:
        window = 64
        while True:
            j = np.arange(i + 1, min(last, i + window) + 1)
            sight = _chunked2(world.segments_free, np.broadcast_to(path[i], (len(j), 2)), path[j])
            # The next waypoint is always in sight (a certified edge), so there is a last True.
            best = int(j[np.flatnonzero(sight)[-1]])
            if best < i + window or best == last:
                break
            window *= 2
        i = best
        out.append(i)
    return path[out]


class _Tiles:
    """The grid cut into square tiles, each with a local world of the obstacles near it.

    A tile's local world holds the obstacles whose bounding box comes within ``reach`` of the
    tile's box. Every point of the tile, and every point of a segment of length at most
    ``reach - cap`` starting in the tile, is farther than ``cap`` from all other obstacles (it is
    at least as far from an obstacle as the two boxes are apart). So clearances clipped at ``cap``,
    and free tests of such segments against a threshold below ``cap``, are the same in the local
    world as in the whole one: exact, and a maze of 100 walls costs a few walls per point.
    """

    def __init__(self, world: World, xs: np.ndarray, ys: np.ndarray, reach: float) -> None:
        self.nx, self.ntx = len(xs), -(-len(xs) // _TILE)
        poly_box = np.array(
            [[p[:, 0].min(), p[:, 1].min(), p[:, 0].max(), p[:, 1].max()] for p in world.polygons]
        ).reshape(-1, 4)
        circles = world.circles
        self.worlds: list[World | None] = []
        for j0 in range(0, len(ys), _TILE):
            for i0 in range(0, len(xs), _TILE):
                lo = np.array([xs[i0], ys[j0]])
                hi = np.array([xs[min(i0 + _TILE, len(xs)) - 1], ys[min(j0 + _TILE, len(ys)) - 1]])
                # Box-to-box (and box-to-centre) gaps: lower bounds on every point's distance.
                gap = np.maximum(0.0, np.maximum(poly_box[:, :2] - hi, lo - poly_box[:, 2:]))
                near_poly = np.flatnonzero(np.hypot(gap[:, 0], gap[:, 1]) < reach)
                gap = np.maximum(0.0, np.maximum(circles[:, :2] - hi, lo - circles[:, :2]))
                near_circ = np.flatnonzero(np.hypot(gap[:, 0], gap[:, 1]) - circles[:, 2] < reach)
                if not len(near_poly) and not len(near_circ):
                    self.worlds.append(None)
                    continue
                self.worlds.append(
                    World(
                        world.bounds,
                        circles[near_circ],
                        [world.polygons[k] for k in near_poly],
                        world.robot_radius,
                    )
                )

    def tile_of(self, nodes: np.ndarray) -> np.ndarray:
        """The tile of each grid node (index ``j * nx + i``)."""
        j, i = np.divmod(nodes, self.nx)
        return (j // _TILE) * self.ntx + i // _TILE

    def clearance(self, points: np.ndarray, cap: float) -> np.ndarray:
        """``min(world.point_clearance(p), cap)`` for every grid point (in node order)."""
        out = np.full(len(points), cap)
        for t, sel in self._groups(np.arange(len(points))):
            out[sel] = np.minimum(self.worlds[t].point_clearance(points[sel]), cap)
        return out

    def segments_free(self, points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``world.segments_free`` for the grid edges ``a[k] -> b[k]`` (node indices)."""
        out = np.ones(len(a), dtype=bool)
        for t, sel in self._groups(a):
            out[sel] = _chunked2(self.worlds[t].segments_free, points[a[sel]], points[b[sel]])
        return out

    def _groups(self, nodes: np.ndarray):
        """(tile, positions in ``nodes``) for every tile that has obstacles near it."""
        tiles = self.tile_of(nodes)
        order = np.argsort(tiles, kind="stable")
        bounds = np.searchsorted(tiles[order], np.arange(len(self.worlds) + 1))
        for t, local in enumerate(self.worlds):
            if local is not None and bounds[t] < bounds[t + 1]:
                yield t, order[bounds[t] : bounds[t + 1]]


def _chunked2(fn, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if len(a) <= _CHUNK:
        return fn(a, b)
    return np.concatenate(
        [fn(a[i : i + _CHUNK], b[i : i + _CHUNK]) for i in range(0, len(a), _CHUNK)]
    )


def _check_kind(kind: Any) -> str:
    if kind not in KINDS:
        raise ValueError(f"unknown kind {kind!r}; known kinds: {', '.join(KINDS)}")
    return kind


def _check_int(name: str, value: Any, low: int | None = None, high: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    value = int(value)
    if low is not None and value < low:
        raise ValueError(f"{name} must be >= {low}, got {value}")
    if high is not None and value > high:
        raise ValueError(f"{name} must be <= {high}, got {value}")
    return value


def _check_number(name: str, value: Any, low: float | None = None, strict: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a number, got {type(value).__name__} {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    if low is not None and (x <= low if strict else x < low):
        raise ValueError(f"{name} must be {'>' if strict else '>='} {low:g}, got {x:g}")
    return x


def _check_range(name: str, value: Any, number: bool) -> tuple[Any, Any]:
    if isinstance(value, str) or not isinstance(value, Sequence) or len(value) != 2:
        raise ValueError(f"{name} must be a pair (min, max), got {value!r}")
    check = _check_number if number else _check_int
    lo, hi = check(f"{name}[0]", value[0]), check(f"{name}[1]", value[1])
    if lo > hi:
        raise ValueError(f"{name} needs min <= max, got ({lo}, {hi})")
    return lo, hi
