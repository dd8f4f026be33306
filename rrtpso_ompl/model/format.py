"""The problem format, declared once: every key, its kind, unit, range and meaning.

The loader (:mod:`rrtpso_ompl.model.problem`) takes its key names, required keys and the checks
of each kind from these tables; :func:`json_schema` turns the same tables into a JSON Schema
(``docs/problem.schema.json``, draft 2020-12) that editors use to complete and check problem
files. A key added here is known to both at once.

The schema checks what a schema can (names, types, ranges); a few rules need the geometry and
stay with the loader: a polygon must be simple, ``min < max`` of bounds and rectangles, start and
goal must lie in the bounds and clear of the obstacles.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from ..validation import MAX_COORDINATE, MAX_SECONDS, MIN_EXTENT, SEED_MAX

__all__ = [
    "CIRCLE",
    "MAP",
    "MOVING",
    "PLANNER",
    "POLYGON",
    "RECTANGLE",
    "ROBOT",
    "TOP",
    "Key",
    "Section",
    "json_schema",
    "schema_text",
]

#: The kinds of value, each with its JSON Schema (the loader checks the same, and more).
_NUMBER = {"type": "number"}
_COORDINATE = {"type": "number", "minimum": -MAX_COORDINATE, "maximum": MAX_COORDINATE}
_POINT = {"type": "array", "items": _COORDINATE, "minItems": 2, "maxItems": 2}
KINDS: dict[str, dict[str, Any]] = {
    "text": {"type": "string"},
    "name": {"type": "string", "minLength": 1, "pattern": r"\S"},
    "number": _NUMBER,
    "length": {"type": "number", "minimum": 0, "maximum": MAX_COORDINATE},
    "positive": {"type": "number", "exclusiveMinimum": 0, "maximum": MAX_COORDINATE},
    "seconds": {"type": "number", "exclusiveMinimum": 0, "maximum": MAX_SECONDS},
    "seed": {"type": "integer", "minimum": 0, "maximum": SEED_MAX},
    "point": _POINT,
    "bounds": {"type": "array", "items": _POINT, "minItems": 2, "maxItems": 2},
    "points": {"type": "array", "items": _POINT, "minItems": 3},
    "params": {
        "type": "object",
        "description": "planner parameters by name; see `rrtpso planners NAME`",
    },
    # The short form (the map YAML's path) or the long form (a mapping).
    "map": {"anyOf": [{"type": "string", "minLength": 1}, {"$ref": "#/$defs/map"}]},
    "unknown": {"enum": ["obstacle", "free"]},
    "bool": {"type": "boolean"},
}


@dataclass(frozen=True)
class Key:
    """One key of the format.

    Attributes
    ----------
    name : str
        The key as written.
    kind : str
        A kind of :data:`KINDS`, or a section name for a nested mapping (``"robot"``), or
        ``"list:<section>"`` for a list of such mappings.
    doc : str
        What it means.
    required : bool
        Whether a file must give it.
    unit : str
        ``"length"`` (the problem's unit), ``"length/s"``, ``"s"``, ``"deg"`` or "".
    """

    name: str
    kind: str
    doc: str
    required: bool = False
    unit: str = ""


@dataclass(frozen=True)
class Section:
    """A mapping of the format: its keys, in the documented order."""

    name: str
    keys: tuple[Key, ...]
    doc: str = ""

    def names(self) -> tuple[str, ...]:
        return tuple(k.name for k in self.keys)

    def required(self) -> tuple[str, ...]:
        return tuple(k.name for k in self.keys if k.required)


ROBOT = Section("robot", (
    Key("radius", "length", "safety-zone radius SR: the robot is a disc of this radius "
        "(0: a point robot)", True, "length"),
    Key("wheel_radius", "positive", "r in eqs. 11-12", unit="length"),
    Key("track_width", "positive", "L, distance between the wheels (eqs. 9-12)", unit="length"),
    Key("speed", "positive", "nominal linear speed along the path", unit="length/s"),
    Key("sample_time", "positive", "Ts, the control period", unit="s"),
    Key("sensor_range", "positive", "SD: how far the robot sees moving obstacles", unit="length"),
    Key("max_speed", "positive", "speed limit of the velocity profile", unit="length/s"),
    Key("max_wheel_speed", "positive", "speed limit of each wheel", unit="length/s"),
    Key("max_accel", "positive", "acceleration limit of the velocity profile",
        unit="length/s^2"),
    Key("inflation_radius", "positive", "Nav2's inflation_radius: how far from obstacles the "
        "clearance cost reaches (default: none, the shortest path)", unit="length"),
    Key("cost_scaling_factor", "positive", "Nav2's cost_scaling_factor k: the clearance cost "
        "falls as exp(-k (d - radius)) (default: Nav2's 3.0 per metre, in the problem's units)",
        unit="1/length"),
    Key("cost_travel_multiplier", "positive", "w, Smac 2D's name: driving at the radius from a "
        "wall costs 1 + w times the length (default: 2.0)"),
    Key("turning_radius", "positive", "a car-like robot: its smallest turning radius; its path "
        "is arcs of this radius and straight lines, Dubins curves (forwards only) or "
        "Reeds-Shepp curves (with reverse); default: none, a differential-drive robot that turns "
        "in place", unit="length"),
    Key("reverse", "bool", "a car-like robot that may also drive backwards (Reeds-Shepp "
        "curves); default false (Dubins curves)"),
), "the robot: a disc plus its drive parameters")  # fmt: skip

PLANNER = Section("planner", (
    Key("type", "name", "planner name or alias (see `rrtpso planners`)"),
    Key("time_limit", "seconds", "time budget", unit="s"),
    Key("seed", "seed", "seeds OMPL's random generator and the planners' own"),
    Key("params", "params", "planner parameters by name"),
), "planner defaults; command-line flags override them")  # fmt: skip

CIRCLE = Section("circle", (
    Key("type", "name", "circle", True),
    Key("center", "point", "centre", True, "length"),
    Key("radius", "positive", "radius", True, "length"),
))  # fmt: skip
RECTANGLE = Section("rectangle", (
    Key("type", "name", "rectangle", True),
    Key("min", "point", "lower-left corner", True, "length"),
    Key("max", "point", "upper-right corner", True, "length"),
))  # fmt: skip
POLYGON = Section("polygon", (
    Key("type", "name", "polygon", True),
    Key("points", "points", "vertices of a simple polygon, at least 3", True, "length"),
))  # fmt: skip
OBSTACLES = {"circle": CIRCLE, "rectangle": RECTANGLE, "polygon": POLYGON}

MOVING = Section("moving_obstacle", (
    Key("radius", "positive", "radius SO of the obstacle's disc", True, "length"),
    Key("start", "point", "centre at t = 0", True, "length"),
    Key("speed", "length", "constant speed (eqs. 14-15)", True, "length/s"),
    Key("heading_deg", "number", "direction of motion, counter-clockwise from +x", True, "deg"),
), "a disc moving at constant velocity (paper eqs. 14-15)")  # fmt: skip

MAP = Section("map", (
    Key("file", "name", "the map_server YAML file, relative to this problem file", True),
    Key("unknown", "unknown", "unknown cells: obstacle (default) or free"),
), "an occupancy-grid map in ROS map_server's format (YAML and image)")  # fmt: skip

TOP = Section("problem", (
    Key("name", "name", "problem name (default: the file's stem)"),
    Key("description", "text", "free text"),
    Key("units", "text", "label of the length unit for plots and reports (m with a map)"),
    Key("map", "map", "the static world from an occupancy-grid map (besides obstacles)"),
    Key("bounds", "bounds", "[[xmin, ymin], [xmax, ymax]]: where the robot's centre may be; "
        "required unless a map gives them (its extent)", unit="length"),
    Key("start", "point", "start position", True, "length"),
    Key("goal", "point", "goal position", True, "length"),
    Key("goal_tolerance", "length", "how close to the goal a path must end", unit="length"),
    Key("goal_yaw", "number", "heading wanted at the goal, counter-clockwise from +x (any "
        "number, read modulo 360): a disc robot turns in place there, a car-like robot's path "
        "arrives with it (default for a car: the direction from the start to the goal)",
        unit="deg"),
    Key("start_yaw", "number", "a car-like robot's heading at the start, counter-clockwise "
        "from +x (default: the direction from the start to the goal); only with "
        "robot.turning_radius", unit="deg"),
    Key("robot", "robot", "the robot", True),
    Key("obstacles", "list:obstacle", "static obstacles (circles, rectangles, polygons)"),
    Key("moving_obstacles", "list:moving_obstacle", "moving obstacles"),
    Key("planner", "planner", "planner defaults"),
), "a planning problem for a disc-shaped differential-drive robot")  # fmt: skip

_SECTIONS = {"robot": ROBOT, "planner": PLANNER, "moving_obstacle": MOVING, "map": MAP}


def _section_schema(section: Section, type_const: str | None = None) -> dict[str, Any]:
    props = {}
    for key in section.keys:
        schema = dict(_kind_schema(key.kind))
        if key.name == "type" and type_const:
            schema = {"const": type_const}
        if not key.required:  # the loader reads an optional key written as null as absent
            schema = {"anyOf": [schema, {"type": "null"}]}
        unit = f" [{key.unit}]" if key.unit else ""
        schema["description"] = f"{key.doc}{unit}"
        props[key.name] = schema
    out: dict[str, Any] = {"type": "object", "properties": props, "additionalProperties": False}
    if section.required():
        out["required"] = list(section.required())
    if section.doc:
        out["description"] = section.doc
    return out


def _kind_schema(kind: str) -> dict[str, Any]:
    if kind in KINDS:
        return KINDS[kind]
    if kind.startswith("list:"):
        return {"type": "array", "items": {"$ref": f"#/$defs/{kind[5:]}"}}
    return {"$ref": f"#/$defs/{kind}"}


def json_schema() -> dict[str, Any]:
    """The problem format as a JSON Schema (draft 2020-12)."""
    defs = {name: _section_schema(s) for name, s in _SECTIONS.items()}
    defs["obstacle"] = {
        "description": "a static obstacle; the robot disc must never overlap one",
        "oneOf": [_section_schema(s, kind) for kind, s in OBSTACLES.items()],
    }
    schema = {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "rrtpso-ompl problem file",
        **_section_schema(TOP),
        "$defs": defs,
    }
    schema["properties"]["bounds"]["description"] += (
        f"; each side at least {MIN_EXTENT:g} and {MIN_EXTENT:g} of the coordinates' magnitude, "
        "xmin < xmax and ymin < ymax"
    )
    schema["anyOf"] = [{"required": ["bounds"]}, {"required": ["map"]}]
    return schema


def schema_text() -> str:
    """:func:`json_schema` as the text of ``docs/problem.schema.json``."""
    return json.dumps(json_schema(), indent=2) + "\n"
