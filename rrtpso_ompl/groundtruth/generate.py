"""Random problem generators with a certificate of solvability.

``generate("circles", seed=7, n=40)`` returns a problem *dictionary* in the file format of
``docs/problem-format.md``: plain ``dict``/``list``/``float``/``str`` values, in the format's key
order, so it round-trips through :func:`~rrtpso_ompl.model.problem_from_dict` and
``yaml.safe_dump``. :func:`~rrtpso_ompl.model.problem_file.write_problem` writes such a
dictionary as a problem file and :func:`generate_to_file` does both (the ``rrtpso generate``
command is a thin wrapper around it).

The kinds (:data:`GENERATORS`, by name), each in its own module, registered in this order when
this module imports them:

* :mod:`.field_kinds`: ``"circles"`` and ``"polygons"``, random non-overlapping circles or convex
  polygons (:class:`CirclesOptions`, :class:`PolygonsOptions`);
* :mod:`.maze_kind`: ``"maze"``, a perfect maze (exactly one route between any two cells) on a
  grid of cells, its walls as rectangles, start and goal in opposite corner cells
  (:class:`MazeOptions`);
* :mod:`.map_kinds`: ``rooms_map``, ``maze_map``, ``city_map``, ``warehouse_map``, ``caves_map``,
  ``random_map``: occupancy-grid maps written beside the problem; :func:`generate` returns the
  problem dictionary, whose ``map`` names the map relatively, and :func:`generate_map` the map
  too;
* :mod:`.shape_kinds`: ``slabs``, ``combs``, ``spiral``, ``rooms``: shapes, certified as the first
  three.

What a kind is, the registry and the default way of generating one live in :mod:`.kinds` (below
every kind: the kinds import it, never this module).

Every random choice comes from one ``numpy.random.default_rng(seed)`` stream, and nothing else
(no clock, no hash order) enters the output, so the same kind, seed and options give a
byte-identical file.

**Solvability is certified, not hoped for**: every problem comes with a collision-checked grid
path (:mod:`rrtpso_ompl.groundtruth.certify`); when the certificate fails the obstacles are drawn
again from the same generator stream.

**Options are declared once** (:mod:`.kinds`). Everything is derived from a kind's declarations:
the checks of the values (one :class:`~rrtpso_ompl.errors.GenerationError` naming the option), the
flags of ``rrtpso generate`` (:mod:`rrtpso_ompl.cli.generate`), the command line written into a
generated file's header and the option tables of ``problems/README.md`` (``python
benchmarks/param_tables.py --update problems/README.md``). Adding a kind is one class, one
registration and one import here (:mod:`.kinds` shows how).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import GenerationError
from ..model.problem_file import default_decimals, write_problem
from .certify import grid_path, is_solvable
from .field_kinds import MAX_OBSTACLES, CirclesOptions, PolygonsOptions
from .kinds import (
    GENERATORS,
    GeneratorOptions,
    checked_seed,
    generate_command,
    options_of,
    register_kind,
)
from .maze_kind import MAX_CELLS, MazeOptions

# isort: split
# The kinds register on import, in this order (the order of ``rrtpso generate``'s choices): the
# first three above, the map kinds (rooms_map, maze_map, ...), then the shape kinds (slabs, ...).
from .map_kinds import GeneratedMap, MapKindOptions

# isort: split
from . import shape_kinds as _shape_kinds  # noqa: F401
from .map_problem import generate_map_from

__all__ = [
    "GENERATORS",
    "KINDS",
    "MAX_CELLS",
    "MAX_OBSTACLES",
    "CirclesOptions",
    "GenerationError",
    "GeneratorOptions",
    "MazeOptions",
    "PolygonsOptions",
    "default_decimals",
    "generate",
    "generate_command",
    "generate_map",
    "generate_to_file",
    "grid_path",
    "is_solvable",
    "register_kind",
    "write_problem",
]

#: The first three kinds, in order (:data:`GENERATORS` holds every registered kind).
KINDS: tuple[str, ...] = (CirclesOptions.KIND, PolygonsOptions.KIND, MazeOptions.KIND)


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
    options_ = options_of(kind, options)
    return options_.resolved().problem_dict(checked_seed(seed))


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
    options_ = options_of(kind, options)
    return options_.write(checked_seed(seed), out)


def generate_map(kind: str, seed: int, **options: Any) -> GeneratedMap:
    """The map and problem of a map kind (:mod:`.map_kinds`).

    Parameters are those of :func:`generate`; ``kind`` must be a map kind (its name ends in
    ``_map``).

    Returns
    -------
    GeneratedMap
        The problem dictionary, the blocked cells and the map YAML keys
        (:meth:`GeneratedMap.write` writes the three files).

    Raises
    ------
    GenerationError
        As :func:`generate`, and for a kind that is not a map kind.
    """
    options_ = options_of(kind, options)
    if not isinstance(options_, MapKindOptions):
        raise GenerationError(f"generate_map: {kind!r} is not a map kind")
    seed = checked_seed(seed)
    return generate_map_from(options_.resolved(), seed, generate_command(options_, seed))
