"""Problem files: load and validate the YAML format of ``docs/problem-format.md``.

A problem file describes one planning query for a disc-shaped differential-drive robot in the
plane: the bounds of the robot's centre, start and goal, the robot, static obstacles (circles,
rectangles, polygons), optional moving obstacles (paper eqs. 14-15) and optional planner defaults.

Everything here is plain data: frozen dataclasses, no OMPL, no matplotlib. Every way a file can be
wrong is reported by one :class:`ProblemError` that names the file, the key and the problem.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
import shapely
import yaml

__all__ = [
    "Circle",
    "MovingObstacle",
    "Obstacle",
    "PlannerConfig",
    "Polygon",
    "Problem",
    "ProblemError",
    "Robot",
    "load_problem",
    "problem_from_dict",
]

Point = tuple[float, float]


class ProblemError(ValueError):
    """A problem file (or dictionary) is not a valid problem.

    Parameters
    ----------
    source : str
        The file the problem came from (or a label such as ``"<dict>"``).
    key : str
        The offending key as a dotted path, e.g. ``"obstacles[2].radius"``; empty for the
        whole file.
    message : str
        What is wrong, in words a user can act on.
    """

    def __init__(self, source: str, key: str, message: str) -> None:
        self.source = str(source)
        self.key = key
        self.message = message
        where = f"{self.source}: {key}" if key else self.source
        super().__init__(f"{where}: {message}")


@dataclass(frozen=True)
class Circle:
    """A static circular obstacle. Clearance to it is computed exactly (never on a polygon)."""

    center: Point
    radius: float
    kind: str = field(default="circle", init=False)


@dataclass(frozen=True)
class Polygon:
    """A static polygonal obstacle (a ``rectangle`` from the file is stored as its 4 corners).

    ``points`` is a simple (non-self-intersecting) ring of at least 3 vertices with non-zero area,
    in counter-clockwise order, without the closing repeat of the first vertex.
    """

    points: tuple[Point, ...]
    kind: str = "polygon"  # "polygon" or "rectangle": how it was written in the file


Obstacle = Circle | Polygon


@dataclass(frozen=True)
class MovingObstacle:
    """A disc moving at constant velocity (paper eqs. 14-15).

    Parameters
    ----------
    radius : float
        Radius of the obstacle's disc (its safety zone SO), in problem units.
    start : (float, float)
        Centre at t = 0.
    speed : float
        Speed in problem units per second, >= 0.
    heading_deg : float
        Direction of motion in degrees, counter-clockwise from +x.
    """

    radius: float
    start: Point
    speed: float
    heading_deg: float

    @property
    def velocity(self) -> np.ndarray:
        """Velocity vector (vx, vy) in units per second."""
        h = math.radians(self.heading_deg)
        return np.array([self.speed * math.cos(h), self.speed * math.sin(h)])

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Centre at time(s) ``t`` in seconds: eqs. 14-15 in closed form, shape ``(..., 2)``."""
        t = np.asarray(t, dtype=float)
        return np.asarray(self.start, dtype=float) + t[..., None] * self.velocity


@dataclass(frozen=True)
class Robot:
    """The robot: a disc of radius ``radius`` (the safety zone SR) plus drive parameters.

    Attributes are in problem units (lengths), units per second (speed) and seconds
    (sample_time). The drive parameters are optional until velocities or simulations are asked for.
    """

    radius: float
    wheel_radius: float | None = None
    track_width: float | None = None
    speed: float | None = None
    sample_time: float | None = None
    sensor_range: float | None = None
    max_speed: float | None = None
    max_wheel_speed: float | None = None
    max_accel: float | None = None


@dataclass(frozen=True)
class PlannerConfig:
    """Optional planner defaults from the file; command-line flags override them."""

    type: str | None = None
    time_limit: float | None = None
    seed: int | None = None
    params: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))


@dataclass(frozen=True)
class Problem:
    """One validated planning problem. Build it with :func:`load_problem`."""

    name: str
    bounds: tuple[Point, Point]
    start: Point
    goal: Point
    robot: Robot
    obstacles: tuple[Obstacle, ...] = ()
    moving_obstacles: tuple[MovingObstacle, ...] = ()
    goal_tolerance: float = 0.0
    planner: PlannerConfig = field(default_factory=PlannerConfig)
    description: str = ""
    units: str = ""
    source: str = "<dict>"


def load_problem(path: str | Path) -> Problem:
    """Read and validate a problem file.

    Parameters
    ----------
    path : str or Path
        A YAML file in the format of ``docs/problem-format.md``.

    Raises
    ------
    ProblemError
        For anything wrong with the file: unreadable, malformed YAML, missing, unknown or mistyped
        keys, negative radii, degenerate polygons, start or goal outside ``bounds`` or with the
        robot disc overlapping an obstacle, non-positive time limit.
    """
    path = Path(path)
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ProblemError(source, "", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ProblemError(source, "", f"cannot read the file: {exc}") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ProblemError(source, "", f"malformed YAML{where}: {problem}") from None
    return problem_from_dict(data, source=source, name=path.stem)


def problem_from_dict(data: Any, source: str = "<dict>", name: str | None = None) -> Problem:
    """Validate an already-parsed mapping (as from YAML) into a :class:`Problem`.

    Parameters
    ----------
    data : Any
        The parsed document; anything that is not a valid problem raises :class:`ProblemError`.
    source : str
        Named in error messages (the file path).
    name : str, optional
        Default for the ``name`` key (the file's stem).
    """
    v = _Validator(source)
    doc = v.mapping(data, "", _TOP_KEYS, required=("bounds", "start", "goal", "robot"))
    bounds = v.bounds(doc["bounds"], "bounds")
    robot = v.robot(doc["robot"], "robot")
    obstacles = tuple(
        v.obstacle(o, f"obstacles[{i}]") for i, o in enumerate(v.sequence(doc, "obstacles"))
    )
    moving = tuple(
        v.moving(o, f"moving_obstacles[{i}]")
        for i, o in enumerate(v.sequence(doc, "moving_obstacles"))
    )
    problem = Problem(
        name=v.string(doc.get("name", name or "problem"), "name"),
        description=v.string(doc.get("description", ""), "description", empty=True),
        units=v.string(doc.get("units", ""), "units", empty=True),
        bounds=bounds,
        start=v.point(doc["start"], "start"),
        goal=v.point(doc["goal"], "goal"),
        goal_tolerance=v.number(doc.get("goal_tolerance", 0.0), "goal_tolerance", low=0.0),
        robot=robot,
        obstacles=obstacles,
        moving_obstacles=moving,
        planner=v.planner(doc.get("planner", {}), "planner"),
        source=source,
    )
    for key in ("start", "goal"):
        v.free_position(problem, key)
    return problem


# ----------------------------------------------------------------------------------------------
# Validation helpers: each takes the key path it is checking, so every error can name it.
# ----------------------------------------------------------------------------------------------
_TOP_KEYS = (
    "name",
    "description",
    "units",
    "bounds",
    "start",
    "goal",
    "goal_tolerance",
    "robot",
    "obstacles",
    "moving_obstacles",
    "planner",
)
_ROBOT_KEYS = (
    "radius",
    "wheel_radius",
    "track_width",
    "speed",
    "sample_time",
    "sensor_range",
    "max_speed",
    "max_wheel_speed",
    "max_accel",
)
_PLANNER_KEYS = ("type", "time_limit", "seed", "params")
_OBSTACLE_KEYS = {
    "circle": ("type", "center", "radius"),
    "rectangle": ("type", "min", "max"),
    "polygon": ("type", "points"),
}
_MOVING_KEYS = ("radius", "start", "speed", "heading_deg")


class _Validator:
    def __init__(self, source: str) -> None:
        self.source = source

    def error(self, key: str, message: str) -> ProblemError:
        return ProblemError(self.source, key, message)

    # -- containers ------------------------------------------------------------------------------
    def mapping(
        self, value: Any, key: str, allowed: tuple[str, ...], required: tuple[str, ...] = ()
    ) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            what = "the file" if not key else "this key"
            raise self.error(
                key, f"{what} must be a mapping of keys to values, got {_describe(value)}"
            )
        for k in value:
            if not isinstance(k, str) or k not in allowed:
                hint = difflib.get_close_matches(str(k), allowed, n=1)
                did = f" (did you mean '{hint[0]}'?)" if hint else ""
                raise self.error(
                    _join(key, str(k)), f"unknown key{did}; allowed keys: {', '.join(allowed)}"
                )
        for k in required:
            if k not in value or value[k] is None:
                raise self.error(_join(key, k), "required key is missing")
        return value

    def sequence(self, doc: Mapping[str, Any], key: str) -> list[Any]:
        value = doc.get(key)
        if value is None:
            return []
        if not isinstance(value, list):
            raise self.error(key, f"must be a list, got {_describe(value)}")
        return value

    # -- scalars -----------------------------------------------------------------------------------
    def number(self, value: Any, key: str, low: float | None = None, strict: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(key, f"must be a number, got {_describe(value)}")
        x = float(value)
        if not math.isfinite(x):
            raise self.error(key, f"must be a finite number, got {value}")
        if low is not None and (x <= low if strict else x < low):
            raise self.error(key, f"must be {'>' if strict else '>='} {low:g}, got {value}")
        return x

    def string(self, value: Any, key: str, empty: bool = False) -> str:
        if not isinstance(value, str) or (not empty and not value.strip()):
            raise self.error(
                key, f"must be a {'' if empty else 'non-empty '}string, got {_describe(value)}"
            )
        return value

    def point(self, value: Any, key: str) -> Point:
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.error(key, f"must be a point [x, y], got {_describe(value)}")
        return (self.number(value[0], f"{key}[0]"), self.number(value[1], f"{key}[1]"))

    # -- sections ----------------------------------------------------------------------------------
    def bounds(self, value: Any, key: str) -> tuple[Point, Point]:
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise self.error(key, f"must be [[xmin, ymin], [xmax, ymax]], got {_describe(value)}")
        lo, hi = self.point(value[0], f"{key}[0]"), self.point(value[1], f"{key}[1]")
        if not (lo[0] < hi[0] and lo[1] < hi[1]):
            raise self.error(key, f"needs xmin < xmax and ymin < ymax, got {lo} and {hi}")
        return lo, hi

    def robot(self, value: Any, key: str) -> Robot:
        doc = self.mapping(value, key, _ROBOT_KEYS, required=("radius",))
        radius = self.number(doc["radius"], f"{key}.radius", low=0.0)
        optional = {
            k: self.number(doc[k], f"{key}.{k}", low=0.0, strict=True)
            for k in _ROBOT_KEYS[1:]
            if doc.get(k) is not None
        }
        return Robot(radius=radius, **optional)

    def planner(self, value: Any, key: str) -> PlannerConfig:
        if value is None:
            return PlannerConfig()
        doc = self.mapping(value, key, _PLANNER_KEYS)
        ptype = self.string(doc["type"], f"{key}.type") if doc.get("type") is not None else None
        limit = doc.get("time_limit")
        if limit is not None:
            limit = self.number(limit, f"{key}.time_limit", low=0.0, strict=True)
        seed = doc.get("seed")
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
            raise self.error(
                f"{key}.seed", f"must be a non-negative integer, got {_describe(seed)}"
            )
        params = doc.get("params") or {}
        if not isinstance(params, Mapping) or not all(isinstance(k, str) for k in params):
            raise self.error(f"{key}.params", "must be a mapping of parameter names to values")
        return PlannerConfig(ptype, limit, seed, MappingProxyType(dict(params)))

    def obstacle(self, value: Any, key: str) -> Obstacle:
        if not isinstance(value, Mapping):
            raise self.error(key, f"must be a mapping with a 'type', got {_describe(value)}")
        kind = value.get("type")
        if kind is None:
            raise self.error(
                f"{key}.type", "required key is missing (circle, rectangle or polygon)"
            )
        if not isinstance(kind, str) or kind not in _OBSTACLE_KEYS:
            raise self.error(
                f"{key}.type",
                f"unknown obstacle type {_describe(kind)}; known "
                f"types: {', '.join(_OBSTACLE_KEYS)}",
            )
        doc = self.mapping(value, key, _OBSTACLE_KEYS[kind], required=_OBSTACLE_KEYS[kind])
        if kind == "circle":
            center = self.point(doc["center"], f"{key}.center")
            radius = self.number(doc["radius"], f"{key}.radius", low=0.0, strict=True)
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
            raise self.error(key, f"must be a list of points, got {_describe(value)}")
        pts = [self.point(p, f"{key}[{i}]") for i, p in enumerate(value)]
        if len(pts) > 1 and pts[0] == pts[-1]:
            pts = pts[:-1]  # a closed ring written out: drop the repeated first vertex
        if len(pts) < 3:
            raise self.error(key, f"a polygon needs at least 3 distinct vertices, got {len(pts)}")
        ring = shapely.Polygon(pts)
        if _signed_area(pts) == 0.0 and all(_cross3(pts[0], pts[1], p) == 0.0 for p in pts[2:]):
            raise self.error(key, "degenerate polygon: all vertices are collinear (zero area)")
        if not ring.is_valid:
            reason = shapely.is_valid_reason(ring)
            raise self.error(key, f"not a simple polygon (edges cross or touch): {reason}")
        if ring.area <= 0.0:
            raise self.error(key, "degenerate polygon: zero area")
        if not ring.exterior.is_ccw:
            pts = pts[::-1]
        return Polygon(tuple(pts))

    def moving(self, value: Any, key: str) -> MovingObstacle:
        doc = self.mapping(value, key, _MOVING_KEYS, required=_MOVING_KEYS)
        return MovingObstacle(
            radius=self.number(doc["radius"], f"{key}.radius", low=0.0, strict=True),
            start=self.point(doc["start"], f"{key}.start"),
            speed=self.number(doc["speed"], f"{key}.speed", low=0.0),
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
        from .world import clearance_threshold  # world imports this module's types

        r = problem.robot.radius
        need = clearance_threshold(r, 1e-9 * max(xmax - xmin, ymax - ymin, 1.0))
        for i, obs in enumerate(problem.obstacles):
            d = _clearance(obs, x, y)
            if d < need:
                raise self.error(
                    key,
                    f"the robot disc (radius {r:g}) at ({x:g}, {y:g}) overlaps obstacles[{i}] "
                    f"({obs.kind}): clearance {max(d, 0.0):.4g} < {r:g}",
                )


def _clearance(obstacle: Obstacle, x: float, y: float) -> float:
    """Distance from (x, y) to an obstacle (0 inside); circles analytically."""
    if isinstance(obstacle, Circle):
        cx, cy = obstacle.center
        return max(0.0, math.hypot(x - cx, y - cy) - obstacle.radius)
    return float(shapely.Polygon(obstacle.points).distance(shapely.Point(x, y)))


def _signed_area(pts: list[Point]) -> float:
    return 0.5 * sum(
        x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True)
    )


def _cross3(o: Point, a: Point, b: Point) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _join(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


def _describe(value: Any) -> str:
    """A short description of a wrong value for error messages."""
    if value is None:
        return "nothing (null)"
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{type(value).__name__} {text}"
