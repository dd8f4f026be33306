"""Problem files: load and validate the YAML format of ``docs/problem-format.md``.

A problem file describes one planning query for a disc-shaped differential-drive robot in the
plane: the bounds of the robot's centre, start and goal, the robot, static obstacles (circles,
rectangles, polygons), optional moving obstacles (paper eqs. 14-15) and optional planner defaults.
The result is plain data (:mod:`.problem_types`, whose names are re-exported here): no OMPL, no
matplotlib. Every way a file can be wrong is reported by one :class:`ProblemError` that names
the file, the key and the problem.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from collections.abc import Callable, Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any, TypeVar

import numpy as np

from ..errors import ArgumentError, ProblemError, did_you_mean, shown
from ..gc_pause import cyclic_gc_paused
from ..validation import (
    MAX_COORDINATE,
    MIN_EXTENT,
    check_number,
    check_seconds,
    check_seed,
    describe,
    number_hint,
)
from .format import MAP, MOVING, OBSTACLES, PLANNER, ROBOT, TOP
from .objective import default_scaling
from .occupancy import OccupancyMap, load_map, map_image_path
from .problem_types import (
    Circle,
    MovingObstacle,
    Obstacle,
    PlannerConfig,
    Point,
    Polygon,
    Problem,
    Robot,
    clearance_threshold,
    normalise_degrees,
    outside_boxes,
    touch_tolerance,
)
from .yamlfile import read_yaml_file

#: Why coordinates and lengths are bounded (for messages).
_SCALE = "exact checks allow for round-off of 1e-9 of the workspace's scale"

__all__ = [
    "Circle",
    "MovingObstacle",
    "Obstacle",
    "PlannerConfig",
    "Polygon",
    "Problem",
    "ProblemError",
    "Robot",
    "clearance_threshold",
    "input_files",
    "load_problem",
    "map_file_path",
    "normalise_degrees",
    "problem_from_dict",
    "touch_tolerance",
]

_T = TypeVar("_T")


def load_problem(path: str | Path) -> Problem:
    """Read and validate a problem file.

    Parameters
    ----------
    path : str or Path
        A YAML file in the format of ``docs/problem-format.md``.

    Returns
    -------
    Problem
        The validated problem; its ``name`` defaults to the file's stem and its ``source`` is
        ``str(path)``.

    Raises
    ------
    ProblemError
        For anything wrong with the file: unreadable, malformed YAML, missing, unknown or mistyped
        keys, negative radii, degenerate polygons, start or goal outside ``bounds`` or with the
        robot disc overlapping an obstacle, non-positive time limit.
    ArgumentError
        When ``path`` is not a file name (None, a number).
    """
    if not isinstance(path, str | os.PathLike):
        raise ArgumentError(f"load_problem: path must be a file name (str or os.PathLike), got "
                            f"{describe(path)}")  # fmt: skip
    path = Path(path)
    with cyclic_gc_paused():  # the parsed document's objects live until the problem is built
        data = read_yaml_file(path)
        return problem_from_dict(data, source=str(path), name=path.stem, base=path.parent)


def input_files(path: str | Path) -> tuple[str, ...]:
    """The files a problem file reads, resolved (as :attr:`Problem.inputs`), found without
    loading it: the file, and the map YAML and image it names.

    Best effort and quick (no image is decoded, nothing is validated): it stops at the first file
    that cannot be read, which loading the problem reports.
    """
    files = [Path(path)]
    try:
        doc = read_yaml_file(path)
        value = doc.get("map") if isinstance(doc, Mapping) else None
        file = value.get("file") if isinstance(value, Mapping) else value
        if isinstance(file, str) and file.strip() and "\0" not in file:
            map_yaml = map_file_path(file, Path(path).parent)
            files.append(map_yaml)
            image = read_yaml_file(map_yaml).get("image")
            if isinstance(image, str) and image.strip() and "\0" not in image:
                files.append(map_image_path(map_yaml, image))
    except (ProblemError, AttributeError):
        pass  # an unreadable file or map, or not a mapping: its run reports it
    return tuple(dict.fromkeys(os.path.realpath(f) for f in files))


def map_file_path(file: str, base: Path) -> Path:
    """The map YAML a problem's ``map`` names: relative to ``base``, the problem's folder."""
    return Path(file) if Path(file).is_absolute() else base / file


def problem_from_dict(
    data: Any, source: str = "<dict>", name: str | None = None, base: str | Path | None = None
) -> Problem:
    """Validate an already-parsed mapping (as from YAML) into a :class:`Problem`.

    Parameters
    ----------
    data : Any
        The parsed document; anything that is not a valid problem raises :class:`ProblemError`.
    source : str
        Named in error messages (the file path) and stored as ``Problem.source``.
    name : str, optional
        Default for the ``name`` key (the file's stem); ``"problem"`` when neither is given.
    base : str or Path, optional
        The folder a relative ``map`` path is taken from; default the folder of ``source``, or
        the working directory for a ``source`` such as ``"<dict>"``.

    Returns
    -------
    Problem
        The validated problem: rectangles become counter-clockwise 4-gons, polygons are stored
        counter-clockwise, ``planner.params`` is read-only.

    Raises
    ------
    ProblemError
        For anything that is not a valid problem (the same checks as :func:`load_problem`).
    """
    _check_arguments(source, name)
    v = _Validator(source)
    doc = v.document(data)
    if base is None:  # a map path is relative to the problem file, when there is one
        base = Path.cwd() if source.startswith("<") else Path(source).parent
    occupancy, bounds = v.region(doc, Path(base))
    robot = v.robot(doc["robot"], "robot")
    obstacles = v.each(doc, "obstacles", v.obstacle)
    moving = v.each(doc, "moving_obstacles", v.moving)
    units = v.string(_get(doc, "units", "m" if occupancy else ""), "units", empty=True)
    problem = Problem(
        name=v.string(_get(doc, "name", name or "problem"), "name"),
        description=v.string(_get(doc, "description", ""), "description", empty=True),
        units=units,
        bounds=bounds,
        start=v.point(doc["start"], "start"),
        goal=v.point(doc["goal"], "goal"),
        goal_tolerance=v.number(_get(doc, "goal_tolerance", 0.0), "goal_tolerance", low=0.0),
        goal_yaw=v.degrees(doc.get("goal_yaw"), "goal_yaw"),
        start_yaw=v.degrees(doc.get("start_yaw"), "start_yaw"),
        robot=_with_default_scaling(robot, units),
        obstacles=obstacles,
        moving_obstacles=moving,
        planner=v.planner(_get(doc, "planner", {}), "planner"),
        source=source,
        map=occupancy,
    )
    v.car(problem)
    for key in ("start", "goal"):
        v.free_position(problem, key)
    return problem


def _check_arguments(source: Any, name: Any) -> None:
    """:func:`problem_from_dict`'s own arguments (a caller's mistake, not the file's)."""
    if not isinstance(source, str):
        raise ArgumentError(f"problem_from_dict: source must be a str naming where the data came "
                            f"from, got {describe(source)}")  # fmt: skip
    if name is not None and not isinstance(name, str):
        raise ArgumentError(f"problem_from_dict: name must be a str, got {describe(name)}")


def _with_default_scaling(robot: Robot, units: str) -> Robot:
    """The robot with an inflation radius but no ``cost_scaling_factor`` given Nav2's default,
    which is per metre: the same falling cost in the problem's units."""
    if robot.inflation_radius and robot.cost_scaling_factor is None:
        return dataclasses.replace(robot, cost_scaling_factor=default_scaling(units))
    return robot


# ----------------------------------------------------------------------------------------------
# Validation helpers: each takes the key path it is checking, so every error can name it.
# ----------------------------------------------------------------------------------------------
# The key tables come from the format's declarations (:mod:`rrtpso_ompl.model.format`), which
# also make the JSON Schema: one list of keys for both.
_TOP_KEYS = TOP.names()
_ROBOT_KEYS = ROBOT.names()
_ROBOT_FLAGS = frozenset(k.name for k in ROBOT.keys if k.kind == "bool")
_PLANNER_KEYS = PLANNER.names()
_OBSTACLE_KEYS = {kind: section.names() for kind, section in OBSTACLES.items()}
_MOVING_KEYS = MOVING.names()
_MAP_KEYS = MAP.names()
_REQUIRED = TOP.required()


class _Validator:
    """The checks, bound to the source they report (each method takes the key path it checks)."""

    def __init__(self, source: str) -> None:
        self.source = source

    def error(self, key: str, message: str) -> ProblemError:
        return ProblemError(self.source, key, message)

    # -- the document ----------------------------------------------------------------------------
    def document(self, data: Any) -> Mapping[str, Any]:
        """The top-level mapping, or an error that says what the file is instead (empty, a map)."""
        if data is None:
            raise self.error(
                "", "the file is empty; a problem needs at least bounds, start, goal, robot"
            )
        if (
            isinstance(data, Mapping)
            and {"image", "resolution"} <= set(data)
            and "start" not in data
        ):
            raise self.error(
                "",
                "this is an occupancy-grid map (map_server YAML), not a problem; "
                "name it in a problem's map key",
            )
        return self.mapping(data, "", _TOP_KEYS, required=_REQUIRED)

    def region(
        self, doc: Mapping[str, Any], base: Path
    ) -> tuple[OccupancyMap | None, tuple[Point, Point]]:
        """The map (read, or None) and the bounds: the ``bounds`` key, else the map's extent (the
        box around a turned map)."""
        occupancy = self.map(doc.get("map"), "map", base)
        if doc.get("bounds") is not None:
            return occupancy, self.bounds(doc["bounds"], "bounds")
        if occupancy is None:
            raise self.error(
                "bounds", "required key is missing (or give a map, whose extent it is)"
            )
        small = _too_small(occupancy.bounding_box)
        if small:
            raise self.error("map", f"its extent (image size x resolution) is {small}; give bounds "
                             "or a map of larger cells")  # fmt: skip
        return occupancy, occupancy.bounding_box

    # -- containers ------------------------------------------------------------------------------
    def mapping(
        self,
        value: Any,
        key: str,
        allowed: tuple[str, ...],
        required: tuple[str, ...] = (),
        what: str = "",
    ) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            subject = "the file" if not key else "this key"
            raise self.error(
                key, f"{subject} must be a mapping of keys to values, got {describe(value)}"
            )
        for k in value:
            if not isinstance(k, str) or k not in allowed:
                raise self.error(
                    _join(key, _key_label(k)),
                    f"unknown key{what}{did_you_mean(_key_label(k), allowed)}; "
                    f"allowed keys: {', '.join(allowed)}",
                )
        for k in required:
            # ``radius:`` with nothing after it is null in YAML: as good as absent.
            if value.get(k) is None:
                raise self.error(_join(key, k), "required key is missing")
        return value

    def sequence(self, doc: Mapping[str, Any], key: str) -> list[Any] | tuple[Any, ...]:
        value = _get(doc, key, [])
        if not isinstance(value, list | tuple):
            raise self.error(key, f"must be a list, got {describe(value)}")
        return value

    def each(
        self, doc: Mapping[str, Any], key: str, check: Callable[[Any, str], _T]
    ) -> tuple[_T, ...]:
        """The list under ``key`` (default empty), each item checked as ``key[i]``."""
        return tuple(check(item, f"{key}[{i}]") for i, item in enumerate(self.sequence(doc, key)))

    # -- scalars -----------------------------------------------------------------------------------
    def number(self, value: Any, key: str, low: float | None = None, strict: bool = False) -> float:
        try:
            return check_number(value, low=low, strict_low=strict)
        except ValueError as exc:
            raise self.error(key, f"{exc}{number_hint(value)}") from None

    def degrees(self, value: Any, key: str) -> float | None:
        """An optional heading in degrees, as ``heading_deg``: any finite number, normalised to
        (-180, 180] (None when absent)."""
        if value is None:
            return None
        return normalise_degrees(self.number(value, key))

    def string(self, value: Any, key: str, empty: bool = False) -> str:
        if not isinstance(value, str) or (not empty and not value.strip()):
            kind = "string" if empty else "non-empty string"
            raise self.error(key, f"must be a {kind}, got {describe(value)}")
        return value

    def point(self, value: Any, key: str) -> Point:
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.error(key, f"must be a point [x, y], got {describe(value)}")
        return (self.coordinate(value[0], f"{key}[0]"), self.coordinate(value[1], f"{key}[1]"))

    def coordinate(self, value: Any, key: str) -> float:
        """A coordinate: a number of magnitude at most :data:`MAX_COORDINATE`."""
        x = self.number(value, key)
        if abs(x) > MAX_COORDINATE:
            raise self.error(key, f"must be within +-{MAX_COORDINATE:g} ({_SCALE}), got {x:g}")
        return x

    def length(self, value: Any, key: str, strict: bool = False) -> float:
        """A length or speed: a number >= 0 (> 0 with ``strict``), at most ``MAX_COORDINATE``."""
        x = self.number(value, key, low=0.0, strict=strict)
        if x > MAX_COORDINATE:
            raise self.error(key, f"must be at most {MAX_COORDINATE:g} ({_SCALE}), got {x:g}")
        return x

    # -- sections ----------------------------------------------------------------------------------
    def bounds(self, value: Any, key: str) -> tuple[Point, Point]:
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.error(key, f"must be [[xmin, ymin], [xmax, ymax]], got {describe(value)}")
        lo, hi = self.point(value[0], f"{key}[0]"), self.point(value[1], f"{key}[1]")
        if not (lo[0] < hi[0] and lo[1] < hi[1]):
            raise self.error(key, f"needs xmin < xmax and ymin < ymax, got {lo} and {hi}")
        small = _too_small((lo, hi))
        if small:
            raise self.error(key, f"the workspace is {small}")
        return lo, hi

    def robot(self, value: Any, key: str) -> Robot:
        doc = self.mapping(value, key, _ROBOT_KEYS, required=ROBOT.required())
        # Radius 0 is a point robot, which is a legitimate (classic) planning problem.
        radius = self.length(doc["radius"], f"{key}.radius")
        optional = {
            k: self.flag(doc[k], f"{key}.{k}") if k in _ROBOT_FLAGS
            else self.length(doc[k], f"{key}.{k}", strict=True)
            for k in _ROBOT_KEYS[1:]
            if doc.get(k) is not None
        }  # fmt: skip
        return Robot(radius=radius, **optional)

    def flag(self, value: Any, key: str) -> bool:
        """A yes/no key: YAML's true or false, nothing else (not 0, 1 or "yes" in quotes)."""
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, got {describe(value)}")
        return value

    def car(self, problem: Problem) -> None:
        """Reject the keys a car-like robot needs or refuses in the wrong company: ``reverse``
        and ``start_yaw`` without ``robot.turning_radius``, and the inflation cost with it (a
        car is planned by the length of its curves alone)."""
        robot = problem.robot
        if robot.turning_radius is None:
            for name, given in (("robot.reverse", robot.reverse),
                                ("start_yaw", problem.start_yaw is not None)):  # fmt: skip
                if given:
                    raise self.error(name, "applies to a car-like robot only: give "
                                           "robot.turning_radius too (a disc robot turns in "
                                           "place)")  # fmt: skip
        elif robot.inflation_radius is not None:
            raise self.error(
                "robot.inflation_radius",
                "is not supported for a car-like robot "
                "(robot.turning_radius): its path is planned by length alone",
            )

    def planner(self, value: Any, key: str) -> PlannerConfig:
        doc = self.mapping(value, key, _PLANNER_KEYS)
        ptype = doc.get("type")
        if ptype is not None:
            # Whether the name is registered is the CLI's business: plugins may add planners.
            ptype = self.string(ptype, f"{key}.type")
        limit = doc.get("time_limit")
        if limit is not None:
            try:
                limit = check_seconds(self.number(limit, f"{key}.time_limit"))
            except ValueError as exc:
                raise self.error(f"{key}.time_limit", str(exc)) from None
        seed = doc.get("seed")
        if seed is not None:
            if not isinstance(seed, numbers.Integral):  # 1.0 is a typo here, not a seed
                raise self.error(f"{key}.seed", f"must be an integer, got {describe(seed)}")
            try:
                seed = check_seed(seed)
            except ValueError as exc:
                raise self.error(f"{key}.seed", str(exc)) from None
        params = _get(doc, "params", {})
        if not isinstance(params, Mapping) or not all(isinstance(k, str) for k in params):
            raise self.error(
                f"{key}.params",
                f"must be a mapping of parameter names to values, got {describe(params)}",
            )
        return PlannerConfig(ptype, limit, seed, MappingProxyType(dict(params)))

    def obstacle(self, value: Any, key: str) -> Obstacle:
        if not isinstance(value, Mapping):
            raise self.error(key, f"must be a mapping with a 'type', got {describe(value)}")
        known = ", ".join(_OBSTACLE_KEYS)
        kind = value.get("type")
        if kind is None:
            raise self.error(f"{key}.type", f"required key is missing (one of {known})")
        if not isinstance(kind, str) or kind not in _OBSTACLE_KEYS:
            did = did_you_mean(str(kind), tuple(_OBSTACLE_KEYS)) if isinstance(kind, str) else ""
            raise self.error(
                f"{key}.type", f"unknown obstacle type {describe(kind)}{did}; known types: {known}"
            )
        allowed = _OBSTACLE_KEYS[kind]
        doc = self.mapping(value, key, allowed, required=allowed, what=f" for a {kind}")
        if kind == "circle":
            center = self.point(doc["center"], f"{key}.center")
            radius = self.length(doc["radius"], f"{key}.radius", strict=True)
            return Circle(center, radius)
        if kind == "rectangle":
            lo = self.point(doc["min"], f"{key}.min")
            hi = self.point(doc["max"], f"{key}.max")
            if not (lo[0] < hi[0] and lo[1] < hi[1]):
                raise self.error(key, f"needs min < max in x and y, got min {lo}, max {hi}")
            corners = (lo, (hi[0], lo[1]), hi, (lo[0], hi[1]))  # counter-clockwise
            return Polygon(corners, kind="rectangle")
        return self.polygon(doc["points"], f"{key}.points")

    def polygon(self, value: Any, key: str) -> Polygon:
        if not isinstance(value, list | tuple):
            raise self.error(key, f"must be a list of points, got {describe(value)}")
        ring: list[Point] = []
        for i, p in enumerate(value):
            q = self.point(p, f"{key}[{i}]")
            # A vertex written twice in a row only adds a zero-length edge: drop the repeat.
            if not ring or q != ring[-1]:
                ring.append(q)
        if len(ring) > 1 and ring[0] == ring[-1]:
            ring.pop()  # a closed ring written out in full
        if len(ring) < 3:
            raise self.error(key, f"a polygon needs at least 3 distinct vertices, got {len(ring)}")
        if all(_cross3(ring[0], ring[1], p) == 0.0 for p in ring[2:]):
            # Checked before shapely, which would call this a self-intersection.
            raise self.error(key, "degenerate polygon: all vertices are collinear (zero area)")
        import shapely  # here: a problem of circles (or a map) is read without it

        shape = shapely.Polygon(ring)
        if not math.isfinite(shape.area):
            raise self.error(key, "the coordinates are too large for floating-point arithmetic")
        if not shape.is_valid:
            reason = shapely.is_valid_reason(shape)
            raise self.error(key, f"not a simple polygon (edges cross or touch): {reason}")
        if shape.area <= 0.0:
            raise self.error(key, "degenerate polygon: zero area")
        if not shape.exterior.is_ccw:
            ring.reverse()
        return Polygon(tuple(ring))

    def map(self, value: Any, key: str, base: Path) -> OccupancyMap | None:
        """The ``map`` key: a path (short form) or ``{file, unknown}``; the map it names, read."""
        if value is None:
            return None
        if isinstance(value, str):
            doc: Mapping[str, Any] = {"file": value}
        else:
            doc = self.mapping(value, key, _MAP_KEYS, required=MAP.required())
        doc_key = f"{key}.file" if not isinstance(value, str) else key
        file = self.string(doc["file"], doc_key)
        unknown = _get(doc, "unknown", "obstacle")
        if unknown not in ("obstacle", "free"):
            raise self.error(f"{key}.unknown", f"must be obstacle or free, got {describe(unknown)}")
        if "\0" in file:
            raise self.error(doc_key, "the file name holds a NUL byte")
        try:
            return load_map(map_file_path(file, base), unknown_blocks=unknown == "obstacle")
        except ProblemError as exc:
            # The map's own message names the map file (and its key); this file and its key
            # go first, so that `map: /dev/zero` says which problem and key it came from.
            raise self.error(doc_key, str(exc)) from None

    def moving(self, value: Any, key: str) -> MovingObstacle:
        doc = self.mapping(value, key, _MOVING_KEYS, required=_MOVING_KEYS)
        # No bounds check: a moving obstacle may well enter the workspace from outside.
        return MovingObstacle(
            radius=self.length(doc["radius"], f"{key}.radius", strict=True),
            start=self.point(doc["start"], f"{key}.start"),
            speed=self.length(doc["speed"], f"{key}.speed"),
            heading_deg=self.number(doc["heading_deg"], f"{key}.heading_deg"),
        )

    # -- geometry -------------------------------------------------------------------------------
    def free_position(self, problem: Problem, key: str) -> None:
        """Reject a start or goal outside the bounds or where the robot disc hits an obstacle."""
        x, y = getattr(problem, key)
        (xmin, ymin), (xmax, ymax) = problem.bounds
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            raise self.error(
                key,
                f"({x:g}, {y:g}) lies outside the bounds "
                f"[{xmin:g}, {xmax:g}] x [{ymin:g}, {ymax:g}]",
            )
        r = problem.robot.radius
        tol = touch_tolerance(problem.bounds)
        need = clearance_threshold(r, tol)
        if problem.map is not None:
            self.clear_of_map(problem, key, need)
        for i, obs in enumerate(problem.obstacles):
            d = _clearance(obs, x, y)
            if d >= need:
                continue
            if r == 0.0:
                raise self.error(
                    key, f"the point ({x:g}, {y:g}) lies in or on obstacles[{i}] ({obs.kind})"
                )
            if d >= r:  # only within the round-off allowance: say so, not "overlaps"
                raise self.error(
                    key,
                    f"the robot disc (radius {r:g}) at ({x:g}, {y:g}) touches obstacles[{i}] "
                    f"({obs.kind}) within the round-off allowance {tol:.3g} of this workspace: "
                    f"clearance {d:.6g}",
                )
            raise self.error(
                key,
                f"the robot disc (radius {r:g}) at ({x:g}, {y:g}) overlaps obstacles[{i}] "
                f"({obs.kind}): clearance {d:.4g} < {r:g}",
            )

    def clear_of_map(self, problem: Problem, key: str, need: float) -> None:
        """Reject a start or goal in, or within the robot radius of, a blocked map cell."""
        x, y = getattr(problem, key)
        grid = problem.map
        hit = grid.nearest_blocked(x, y, need)
        r = problem.robot.radius
        state = "occupied" if hit and grid.state[hit[0], hit[1]] == 1 else "unknown"
        if hit is not None and hit[2] < need:
            row, col, d = hit
            if grid.frame is None:
                x0, y0, x1, y1 = grid.cell_box(row, col)
                square = f"x {x0:g}..{x1:g}, y {y0:g}..{y1:g}"
            else:
                cx, cy = grid.cell_centre(row, col)
                square = (f"the {grid.resolution:g} square centred at ({cx:g}, {cy:g}), turned "
                          f"{grid.yaw:g} rad with the map")  # fmt: skip
            where = (f"the {state} map cell at image row {row}, column {col} ({square}) of "
                     f"{grid.source}")  # fmt: skip
            if d == 0.0:
                raise self.error(key, f"({x:g}, {y:g}) lies in {where}")
            if d >= r:  # only within the round-off allowance: say so, not "overlaps"
                tol = touch_tolerance(problem.bounds)
                raise self.error(
                    key,
                    f"the robot disc (radius {r:g}) at ({x:g}, {y:g}) touches {where} within the "
                    f"round-off allowance {tol:.3g} of this workspace: clearance {d:.6g}",
                )
            raise self.error(
                key,
                f"the robot disc (radius {r:g}) at ({x:g}, {y:g}) overlaps {where}: "
                f"clearance {d:.4g} < {r:g}",
            )
        if grid.unknown_blocks:
            if grid.frame is None:
                outside = outside_boxes(problem.bounds, grid.extent)
                dx = np.maximum.reduce([outside[:, 0] - x, 0 * outside[:, 0], x - outside[:, 2]])
                dy = np.maximum.reduce([outside[:, 1] - y, 0 * outside[:, 1], y - outside[:, 3]])
                d = float(np.hypot(dx, dy).min(initial=math.inf))
            else:
                d = min((_clearance(p, x, y) for p in problem.map_outside), default=math.inf)
            if d < need:
                raise self.error(
                    key,
                    f"the robot disc (radius {r:g}) at ({x:g}, {y:g}) reaches beyond the map "
                    f"{grid.source} (unknown space, blocked; set map.unknown: free to allow)",
                )


# ----------------------------------------------------------------------------------------------
# Small pure helpers.
# ----------------------------------------------------------------------------------------------


def _too_small(bounds: tuple[Point, Point]) -> str:
    """Why a workspace is too small to plan in exactly (empty when it is not): a side under
    :data:`~rrtpso_ompl.validation.MIN_EXTENT`, or under that share of the coordinates'
    magnitude (then the round-off allowance, :func:`touch_tolerance`, would exceed a thousandth
    of the side)."""
    (xmin, ymin), (xmax, ymax) = bounds
    side = min(xmax - xmin, ymax - ymin)
    magnitude = max(abs(xmin), abs(ymin), abs(xmax), abs(ymax))
    need = max(MIN_EXTENT, MIN_EXTENT * magnitude)
    if side >= need:
        return ""
    why = f"{MIN_EXTENT:g}" if need == MIN_EXTENT else (
        f"{need:g} ({MIN_EXTENT:g} of its coordinates' magnitude {magnitude:g})")  # fmt: skip
    return (f"too small to plan in: sides {xmax - xmin:g} x {ymax - ymin:g}, each must be at "
            f"least {why}")  # fmt: skip


def _clearance(obstacle: Obstacle, x: float, y: float) -> float:
    """Distance from (x, y) to an obstacle, 0 inside; exact for circles (no polygon stand-in)."""
    if isinstance(obstacle, Circle):
        cx, cy = obstacle.center
        return max(0.0, math.hypot(x - cx, y - cy) - obstacle.radius)
    import shapely

    return float(shapely.Polygon(obstacle.points).distance(shapely.Point(x, y)))


def _cross3(o: Point, a: Point, b: Point) -> float:
    """z of (a - o) x (b - o): zero when the three points are collinear."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _get(doc: Mapping[str, Any], key: str, default: Any) -> Any:
    """An optional key; written with no value (null) it means the same as absent."""
    value = doc.get(key)
    return default if value is None else value


def _join(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


def _key_label(key: Any) -> str:
    """A mapping key as the user wrote it, for messages (YAML spells None as null), shortened
    when long (:func:`~rrtpso_ompl.errors.shown`)."""
    if key is None:
        return "null"
    if isinstance(key, bool):
        return "true" if key else "false"
    return shown(key) or "''"
