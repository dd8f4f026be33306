"""Random problem generators with a certificate of solvability.

``generate("circles", seed=7, n=40)`` returns a problem *dictionary* in the file format of
``docs/problem-format.md``: plain ``dict``/``list``/``float``/``str`` values, in the format's key
order, so it round-trips through :func:`~rrtpso_ompl.model.problem_from_dict` and
``yaml.safe_dump``. :func:`~rrtpso_ompl.model.problem_file.write_problem` writes such a
dictionary as a problem file and :func:`generate_to_file` does both (the ``rrtpso generate``
command is a thin wrapper around it).

The first three kinds (:data:`GENERATORS`, by name):

* ``"circles"``: random non-overlapping circles (:class:`CirclesOptions`);
* ``"polygons"``: random non-overlapping convex polygons (:class:`PolygonsOptions`);
* ``"maze"``: a perfect maze (exactly one route between any two cells) on a grid of cells, its walls
  as rectangles, start and goal in opposite corner cells (:class:`MazeOptions`).

More kinds register from their own modules, imported at the end of this one:
:mod:`.shape_kinds` (``slabs``, ``combs``, ``spiral``, ``rooms``: shapes, certified as these) and
:mod:`.map_kinds` (``rooms_map``, ``maze_map``, ``city_map``, ``warehouse_map``, ``caves_map``,
``random_map``: occupancy-grid maps written beside the problem; :func:`generate` returns the
problem dictionary, whose ``map`` names the map relatively, and
:func:`~.map_kinds.generate_map` the map too). A kind may override how it is generated and
written (:meth:`GeneratorOptions.problem_dict`, :meth:`~GeneratorOptions.write`,
:meth:`~GeneratorOptions.output_paths`, :meth:`~GeneratorOptions.check_places`).

Every random choice comes from one ``numpy.random.default_rng(seed)`` stream, and nothing else
(no clock, no hash order) enters the output, so the same kind, seed and options give a
byte-identical file.

**Solvability is certified, not hoped for**: every problem comes with a collision-checked grid
path (:mod:`rrtpso_ompl.groundtruth.certify`); when the certificate fails the obstacles are drawn
again from the same generator stream.

**Options are declared once.** A kind is an option set: a class of
:func:`~rrtpso_ompl.params.param` fields made a frozen, keyword-only dataclass by
:func:`~rrtpso_ompl.params.declared`, extending :class:`GeneratorOptions` (the options
every kind takes). Everything else is derived from the declarations: the checks of the values
(one :class:`~rrtpso_ompl.errors.GenerationError` naming the option), the flags of ``rrtpso
generate`` (:mod:`rrtpso_ompl.cli.generate`), the command line written into a generated file's
header and the option tables of ``problems/README.md`` (``python benchmarks/param_tables.py
--update problems/README.md``). An option whose default depends on others (a radius that is a
fraction of ``size``) defaults to None, its doc says what that stands for, and the kind
resolves it (:meth:`GeneratorOptions.resolved`).

**Adding a kind** is one class and one registration (nothing else lists the kinds)::

    @register_kind
    @declared
    class RoomsOptions(GeneratorOptions):
        \"\"\"Rooms joined by doors.\"\"\"

        KIND: ClassVar[str] = "rooms"
        rooms: int = param(4, "Rooms per side.", low=1, high=MAX_CELLS)

        def resolved(self) -> RoomsOptions: ...  # None defaults filled in, feasibility checked
        def start_goal(self) -> tuple[np.ndarray, np.ndarray]: ...
        def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]: ...  # the obstacles
        def describe(self) -> str: ...  # the first sentences of the problem's description

``generate("rooms", ...)``, ``rrtpso generate rooms --rooms 6``, the header and the docs follow.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar, TypeVar

import numpy as np

from ..errors import GenerationError, ParameterError, ProblemError, RrtpsoError
from ..model.geometry import path_length
from ..model.problem import problem_from_dict
from ..model.problem_file import default_decimals, round_floats, write_problem
from ..params import ParamTable, Rule, declared, param
from ..validation import check_integer
from .certify import GRID_POINTS, grid_path, is_solvable

__all__ = [
    "GENERATORS",
    "KINDS",
    "CirclesOptions",
    "GenerationError",
    "GeneratorOptions",
    "MazeOptions",
    "PolygonsOptions",
    "default_decimals",
    "generate",
    "generate_command",
    "generate_to_file",
    "grid_path",
    "is_solvable",
    "register_kind",
    "write_problem",
]

#: Most obstacles of a circle or polygon field, and most cells per side of a maze: the bounds of
#: every loop and allocation the generator makes (a maze of 200 x 200 cells has about 80,000
#: walls).
MAX_OBSTACLES = 100_000
MAX_CELLS = 200

_G = TypeVar("_G", bound="GeneratorOptions")


# ----------------------------------------------------------------------------------------------
# The options every kind takes, and the registry of kinds
# ----------------------------------------------------------------------------------------------
@declared(
    rules=(
        Rule(("size",), lambda size: size > 0, "size > 0"),
        Rule(("resolution", "size"), lambda r, size: r is None or 0 < r <= size / 2,
             "0 < resolution <= size / 2"),
        Rule(("name",), lambda name: name is None or bool(name.strip()),
             "name is not empty"),
    )
)  # fmt: skip
class GeneratorOptions:
    """Options every kind of generated problem takes (a kind extends them with its own)."""

    #: The kind's name (``rrtpso generate KIND``); set by each kind.
    KIND: ClassVar[str] = ""
    #: The declarations of the kind's options (made by ``declared``).
    PARAMS: ClassVar[ParamTable]

    size: float = param(100.0, "Side of the square workspace [0, size]^2, > 0.", unit="length",
                        low=0.0)  # fmt: skip
    robot_radius: float | None = param(
        None, "Robot radius (0: a point robot). Default: the kind's.", unit="length", low=0.0
    )
    resolution: float | None = param(
        None,
        "Grid spacing of the solvability certificate, at most size / 2. Default: size / 200 (for "
        "the maze at most a quarter of the corridors' free width).",
        unit="length",
        low=0.0,
    )
    max_attempts: int = param(50, "How many times the obstacles are drawn before giving up "
                              "(each draw is certified: at most 10,000).", low=1,
                              high=10_000)  # fmt: skip
    decimals: int | None = param(
        None,
        "Decimal places of every coordinate. Default: about 1e-5 of the workspace "
        "(default_decimals(size)).",
        low=0,
        high=12,
    )
    name: str | None = param(
        None, "The problem's name. Default: the kind and the seed, as circles_7."
    )

    # -- what each kind provides -----------------------------------------------------------------
    def resolved(self: _G) -> _G:
        """The options with every None default replaced by its value and the combination checked
        (a robot that does not fit raises :class:`GenerationError`)."""
        raise NotImplementedError

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        """Start and goal (of the resolved options)."""
        raise NotImplementedError

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        """The obstacles in the file format, drawn from ``rng`` (of the resolved options)."""
        raise NotImplementedError

    def describe(self) -> str:
        """What was generated, in words: the description's first sentences."""
        raise NotImplementedError

    # -- generating and writing (map kinds override these) ------------------------------------
    def problem_dict(self, seed: int) -> dict[str, Any]:
        """The certified problem dictionary of seed ``seed`` (of the resolved options)."""
        return _draw_until_certified(self, seed)

    @classmethod
    def output_paths(cls, out: str | Path) -> list[Path]:
        """The files :meth:`write` makes for ``out``: ``[out]`` (map kinds add the map's two)."""
        return [Path(out)]

    @classmethod
    def check_places(cls, out: str | Path) -> None:
        """Refuse places :meth:`write` cannot use (:class:`GenerationError`); any for one file
        (the command line's output rules apply), map kinds refuse more."""

    def write(self, seed: int, out: str | Path) -> Path:
        """Generate the problem of seed ``seed`` and write it to ``out`` (see
        :func:`generate_to_file`); ``out``."""
        options = self.resolved()
        data = options.problem_dict(seed)
        header = (
            f"Generated by: {generate_command(self, seed)} --out FILE\n"
            "Every obstacle below was drawn from numpy.random.default_rng(seed); the same command\n"
            "writes the same bytes. Solvability is certified by a collision-free grid path\n"
            "(rrtpso generate's certificate), see the description."
        )
        return write_problem(data, out, header=header, decimals=options.decimals)

    # -- shared ----------------------------------------------------------------------------------
    @classmethod
    def from_options(cls: type[_G], options: Mapping[str, Any]) -> _G:
        """The kind's options from keyword arguments (None: not given), checked.

        Raises
        ------
        TypeError
            For a name that no kind has.
        GenerationError
            For an option of another kind, or a value its declaration does not allow.
        """
        given = {k: v for k, v in options.items() if v is not None}
        _check_names(cls, given)
        try:
            return cls(**cls.PARAMS.validate(given))
        except ParameterError as exc:
            raise GenerationError(str(exc)) from None

    def _resolve(self: _G, resolution: float, **values: Any) -> _G:
        """A copy with ``values``, the certificate's ``resolution`` unless one was given, and the
        default decimals."""
        decimals = default_decimals(self.size) if self.decimals is None else self.decimals
        return dataclasses.replace(self, resolution=self.resolution or resolution,
                                   decimals=decimals, **values)  # fmt: skip

    def document(self, name: str, obstacles: list[dict[str, Any]]) -> dict[str, Any]:
        """The problem dictionary around ``obstacles`` (its description filled in later)."""
        start, goal = self.start_goal()
        return {
            "name": name,
            "description": "",  # filled in once the problem is certified
            "bounds": [[0.0, 0.0], [float(self.size), float(self.size)]],
            "start": [float(v) for v in start],
            "goal": [float(v) for v in goal],
            "robot": {"radius": float(self.robot_radius)},
            "obstacles": obstacles,
        }


#: The kinds by name, in registration order: what :func:`generate`, ``rrtpso generate`` (its
#: choices and flags) and the docs read.
GENERATORS: dict[str, type[GeneratorOptions]] = {}


def register_kind(cls: type[_G]) -> type[_G]:
    """Class decorator: make a declared option set a kind of :func:`generate` under its
    ``KIND``."""
    if not cls.KIND or cls.KIND in GENERATORS:
        raise ValueError(f"{cls.__name__}: KIND must be a new kind's name, got {cls.KIND!r}")
    GENERATORS[cls.KIND] = cls
    return cls


def _check_names(cls: type[GeneratorOptions], given: Mapping[str, Any]) -> None:
    """Every option given is the kind's: a name of another kind, or of none, is refused."""
    mine = cls.PARAMS.names()
    for key in given:
        if key in mine:
            continue
        applies = [k for k, c in GENERATORS.items() if key in c.PARAMS]
        if not applies:
            known = dict.fromkeys(n for c in GENERATORS.values() for n in c.PARAMS.names())
            raise TypeError(f"generate() got unknown option(s) {key}; known: {', '.join(known)}")
        raise GenerationError(
            f"option '{key}' does not apply to kind '{cls.KIND}' (it applies to: "
            f"{', '.join(applies)}); options for {cls.KIND}: {', '.join(mine)}"
        )


# ----------------------------------------------------------------------------------------------
# Generating
# ----------------------------------------------------------------------------------------------
def generate(kind: str, seed: int, **options: Any) -> dict[str, Any]:
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
    kind : str
        What to generate: a name of :data:`GENERATORS` (``"circles"``, ``"polygons"``,
        ``"maze"``).
    seed : int
        Seed of ``numpy.random.default_rng``, >= 0. The same seed and options give the same
        problem, byte for byte once written.
    **options
        The kind's options (:class:`CirclesOptions`, :class:`PolygonsOptions`,
        :class:`MazeOptions`: their fields, with types, defaults and ranges); None stands for
        the default.

    Returns
    -------
    dict
        Keys ``name``, ``description``, ``bounds``, ``start``, ``goal``, ``robot``, ``obstacles``
        in the format's order; every number a Python ``float``.

    Raises
    ------
    TypeError
        For an option that no kind has.
    GenerationError
        (a ``ValueError``) For an unknown kind, an option that does not apply to the kind or is
        out of range, or when obstacles cannot be placed or no certified-solvable problem is
        found within ``max_attempts``.
    """
    options_ = _options_of(kind, options)
    return options_.resolved().problem_dict(_seed(seed))


def _options_of(kind: Any, options: Mapping[str, Any]) -> GeneratorOptions:
    if kind not in GENERATORS:
        raise GenerationError(f"unknown kind {kind!r}; known kinds: {', '.join(GENERATORS)}")
    return GENERATORS[kind].from_options(options)


def _seed(seed: Any) -> int:
    try:
        return check_integer(seed, low=0)
    except ValueError as exc:
        raise GenerationError(f"seed {exc}") from None


def _draw_until_certified(options: GeneratorOptions, seed: int) -> dict[str, Any]:
    """Draw obstacles from one seeded stream until the rounded problem is valid and certified."""
    kind = options.KIND
    name = options.name or f"{kind}_{seed}"
    resolution = options.resolution
    rng = np.random.default_rng(seed)
    last_failure = ""
    for attempt in range(1, options.max_attempts + 1):
        obstacles = options.draw(rng)
        data = round_floats(options.document(name, obstacles), options.decimals)
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
            f"{options.describe()} Generated by rrtpso generate (kind {kind}, seed {seed}, "
            f"attempt {attempt}). A collision-free path of length {length:g} exists "
            f"({how}), so the shortest path is at most that long."
        )
        return data
    raise GenerationError(
        f"generate {kind}: no certified-solvable problem in {options.max_attempts} attempts "
        f"(last: {last_failure}); use fewer or smaller obstacles, a smaller robot_radius, "
        "a finer resolution or more max_attempts"
    )


def generate_to_file(kind: str, seed: int, out: str | Path, **options: Any) -> Path:
    """Generate a problem and write it as a problem file.

    Parameters
    ----------
    kind : str
        What to generate (see :func:`generate`).
    seed : int
        Seed of the generator, >= 0.
    out : str or Path
        The YAML file to write (its folder is created if needed; an existing file is replaced
        atomically).
    **options
        The kind's options, as for :func:`generate`.

    Returns
    -------
    Path
        ``out``. The file starts with a comment holding the command that regenerates it
        (:func:`generate_command`), and is byte-identical for the same kind, seed and options
        (the output path is not part of it).

    Raises
    ------
    TypeError
        An option that no kind has.
    GenerationError
        See :func:`generate`.
    """
    options_ = _options_of(kind, options)
    return options_.write(_seed(seed), out)


def generate_command(options: GeneratorOptions, seed: int) -> str:
    """``rrtpso generate KIND --seed N --option value ...``: the command line that makes the
    problem of ``options`` (those that differ from their defaults, in declaration order; a range
    as its two numbers)."""
    words = [f"rrtpso generate {options.KIND} --seed {seed}"]
    for spec in options.PARAMS:
        value = getattr(options, spec.name)
        if value == spec.default:
            continue
        flag = spec.name.replace("_", "-")
        if isinstance(value, bool):  # a switch: --exact, --no-exact
            words.append(f"--{flag}" if value else f"--no-{flag}")
        else:
            words.append(f"--{flag} {_cli_value(value)}")
    return " ".join(words)


# ----------------------------------------------------------------------------------------------
# The kinds
# ----------------------------------------------------------------------------------------------
#: The radii of circles and polygons: 0 < min <= max < size / 2.
_RADII_RULE = Rule(
    ("radius_range", "size"),
    lambda r, size: r is None or 0 < r[0] <= r[1] < size / 2,
    "0 < radius_range min <= max < size / 2",
)


@declared(
    rules=(
        Rule(("robot_radius", "size"), lambda r, size: r is None or r < 0.05 * size,
             "robot_radius < 0.05 size (the start's inset from the corner)"),
    )
)  # fmt: skip
class _FieldOptions(GeneratorOptions):
    """Random non-overlapping obstacles, start and goal in opposite corners (circles and
    polygons: each kind declares ``n``, ``radius_range`` and ``gap`` and draws its shapes)."""

    #: Default radii (circumradii) as fractions of ``size``, for the default number of obstacles.
    RADII: ClassVar[tuple[float, float]] = (0.0, 0.0)

    robot_radius: float | None = param(
        None,
        "Robot radius (0: a point robot), less than 0.05 size (the start's inset from the "
        "corner). Default: 0.01 size, shrunk as the radii beyond 100 obstacles.",
        unit="length",
        low=0.0,
    )

    # Each kind declares n, radius_range and gap (their defaults and docs differ).

    def resolved(self) -> _FieldOptions:
        default_n = self.PARAMS["n"].default
        shrink = _shrink(self.n, default_n)
        radius_range = self.radius_range
        if radius_range is None:
            lo, hi = self.RADII
            radius_range = (lo * self.size * shrink, hi * self.size * shrink)
        robot = 0.01 * self.size * shrink if self.robot_radius is None else self.robot_radius
        return self._resolve(self.size / GRID_POINTS, radius_range=radius_range,
                             robot_radius=robot)  # fmt: skip

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        inset = 0.05 * self.size
        return np.array([inset, inset]), np.array([self.size - inset, self.size - inset])

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        centres, radii = self._place(rng)
        return self._shapes(rng, centres, radii)

    def _shapes(self, rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray
                ) -> list[dict[str, Any]]:  # fmt: skip
        """The obstacles in the circles ``(centres, radii)``."""
        raise NotImplementedError

    def _place(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """n non-overlapping discs by rejection sampling: ``(centres, radii)``.

        Candidates come in batches of 256, each tested against the obstacles placed so far that
        a k-d tree of their centres names within reach (``r + hi + gap``), then accepted in
        order, each also tested against those accepted before it in the same batch. The cost
        per batch grows as ``log n``, not ``n``: 10,000 obstacles take a second or two. The
        stream is consumed batch by batch, so the result depends on the seed only.
        """
        lo, hi = self.radius_range
        centres = np.empty((self.n, 2))
        radii = np.empty(self.n)
        ends = np.array(self.start_goal())
        # Obstacles keep off start and goal: the robot must be able to turn away from them.
        keep_out = max(2.0 * self.robot_radius, 0.03 * self.size)
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
            ok = np.all(clear_ends >= keep_out, axis=1)
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
                f"generate {self.KIND}: placed only {placed} of {self.n} non-overlapping "
                f"obstacles (radius {lo:g}-{hi:g}, gap {self.gap:g}) in {budget} tries; "
                "use fewer or smaller obstacles or a larger size"
            )
        return centres, radii

    def _where(self) -> str:
        return (
            f"in a {self.size:g} x {self.size:g} workspace, robot radius "
            f"{self.robot_radius:g}, start and goal in opposite corners."
        )


@register_kind
@declared(rules=(_RADII_RULE,))
class CirclesOptions(_FieldOptions):
    """Random non-overlapping circles (``rrtpso generate circles``)."""

    KIND: ClassVar[str] = "circles"
    RADII: ClassVar[tuple[float, float]] = (0.02, 0.06)

    n: int = param(30, "Number of circles.", low=1, high=MAX_OBSTACLES)
    radius_range: tuple[float, float] | None = param(
        None,
        "Least and largest radius, 0 < min <= max < size / 2. Default: (0.02 size, 0.06 "
        "size), shrunk by sqrt(30 / n) beyond 100 circles.",
        unit="length",
        low=0.0,
    )
    gap: float = param(0.0, "Least free distance between two circles (0: they may touch).",
                       unit="length", low=0.0)  # fmt: skip

    def _shapes(self, rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray
                ) -> list[dict[str, Any]]:  # fmt: skip
        return [
            {"type": "circle", "center": c.tolist(), "radius": float(r)}
            for c, r in zip(centres, radii, strict=True)
        ]

    def describe(self) -> str:
        lo, hi = self.radius_range
        return (
            f"{self.n} random non-overlapping circles of radius {lo:.3g}-{hi:.3g} {self._where()}"
        )


@register_kind
@declared(
    rules=(
        _RADII_RULE,
        Rule(("vertices",), lambda v: v[0] <= v[1], "vertices min <= max"),
    )
)
class PolygonsOptions(_FieldOptions):
    """Random non-overlapping convex polygons (``rrtpso generate polygons``)."""

    KIND: ClassVar[str] = "polygons"
    RADII: ClassVar[tuple[float, float]] = (0.03, 0.08)

    n: int = param(20, "Number of polygons.", low=1, high=MAX_OBSTACLES)
    radius_range: tuple[float, float] | None = param(
        None,
        "Least and largest circumradius, 0 < min <= max < size / 2. Default: (0.03 size, "
        "0.08 size), shrunk by sqrt(20 / n) beyond 100 polygons.",
        unit="length",
        low=0.0,
    )
    vertices: tuple[int, int] = param((3, 8), "Least and most vertices of a polygon.", low=3)
    gap: float = param(
        0.0,
        "Least free distance between the circumscribed circles of two polygons (0: they may "
        "touch).",
        unit="length",
        low=0.0,
    )

    def _shapes(self, rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray
                ) -> list[dict[str, Any]]:  # fmt: skip
        return [
            {"type": "polygon", "points": _convex_polygon(rng, c, r, self.vertices).tolist()}
            for c, r in zip(centres, radii, strict=True)
        ]

    def describe(self) -> str:
        lo, hi = self.radius_range
        return (
            f"{self.n} random non-overlapping convex polygons with {self.vertices[0]}-"
            f"{self.vertices[1]} vertices and circumradius {lo:.3g}-{hi:.3g} {self._where()}"
        )


@register_kind
@declared(
    rules=(
        Rule(("wall", "size", "cells"), lambda w, size, c: w is None or 0 < w < size / c,
             "0 < wall < size / cells (the cell size)"),
    )
)  # fmt: skip
class MazeOptions(GeneratorOptions):
    """A perfect maze on a cells x cells grid; one rectangle per wall between two cells
    (``rrtpso generate maze``)."""

    KIND: ClassVar[str] = "maze"

    robot_radius: float | None = param(
        None,
        "Robot radius (0: a point robot); the robot must fit the corridors. Default: a fifth of "
        "a cell (size / cells).",
        unit="length",
        low=0.0,
    )
    cells: int = param(8, "Cells per side.", low=2, high=MAX_CELLS)
    wall: float | None = param(
        None,
        "Wall thickness, 0 < wall < size / cells. Default: a tenth of a cell.",
        unit="length",
        low=0.0,
    )
    algorithm: str = param(
        "dfs",
        "dfs: randomised depth-first search (long winding corridors); kruskal: randomised "
        "Kruskal (many short dead ends). Both give a perfect maze.",
        choices=("dfs", "kruskal"),
    )

    def resolved(self) -> MazeOptions:
        cell = self.size / self.cells
        wall = 0.1 * cell if self.wall is None else self.wall
        robot = 0.2 * cell if self.robot_radius is None else self.robot_radius
        corridor = cell - wall - 2.0 * robot  # free width for the robot's centre
        if corridor <= 0:
            raise GenerationError(
                f"the robot (diameter {2 * robot:g}) does not fit the maze corridors "
                f"(cell {cell:g} minus wall {wall:g} = {cell - wall:g}); use a smaller "
                "robot_radius or wall, or fewer cells"
            )
        # At least four grid points across every corridor, so the certificate cannot miss one.
        resolution = min(self.size / GRID_POINTS, corridor / 4.0)
        return self._resolve(resolution, wall=wall, robot_radius=robot)

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        cell = self.size / self.cells
        return (np.array([0.5 * cell, 0.5 * cell]),
                np.array([self.size - 0.5 * cell, self.size - 0.5 * cell]))  # fmt: skip

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


#: The kinds defined here, in order (:data:`GENERATORS` holds every registered kind).
KINDS: tuple[str, ...] = tuple(GENERATORS)

# The shape kinds (slabs, combs, spiral, rooms) and the map kinds (rooms_map, maze_map, ...)
# register themselves on import; they import this module, so they come last.
from . import map_kinds as _map_kinds  # noqa: E402, F401
from . import shape_kinds as _shape_kinds  # noqa: E402, F401
