"""One query in one line: ``--map``, ``--start``, ``--goal`` and the robot, with or without a
problem file (issue 36).

A Nav2 user has a map YAML and two poses::

    rrtpso solve --map office_map.yaml --start 1.0 1.5 --goal 29.5 14.5 90 --radius 0.25

With a problem file the same flags override its values. Either way the query is validated as a
file is (:func:`~rrtpso_ompl.model.problem_from_dict`), and a message about a value a flag gave
names the flag (``command line: --start: the robot disc (radius 0.25) at (1, 1) touches ...``).
"""

from __future__ import annotations

import argparse
import os
from typing import Any

from ..errors import ProblemError, UsageError

__all__ = ["COMMAND_LINE", "add_query_flags", "load_query"]

#: The label of a query given by flags alone (its messages' first word; no file of that name).
COMMAND_LINE = "command line"

#: Which flag gives which key of the format (a message about the key names the flag).
_FLAG_OF_KEY = {
    "map": "--map",
    "start": "--start",
    "start_yaw": "--start",
    "goal": "--goal",
    "goal_yaw": "--goal",
    "robot": "--radius",
    "robot.radius": "--radius",
    "robot.inflation_radius": "--inflation-radius",
    "robot.turning_radius": "--turning-radius",
    "robot.reverse": "--reverse",
}


def add_query_flags(p: argparse.ArgumentParser) -> None:
    """The problem file (optional) and the flags that give or override its query."""
    p.add_argument("problem", nargs="?", help="problem file (YAML, see docs/problem-format.md); "
                   "or give the query by --map, --start and --goal")  # fmt: skip
    g = p.add_argument_group(
        "a query without a problem file (or overriding the file's values)",
        "Positions in the map frame, in the problem's units (metres with a map); headings in "
        "degrees counter-clockwise from +x.",
    )
    g.add_argument("--map", metavar="MAP.yaml", help="an occupancy-grid map (ROS map_server YAML "
                   "and image): the world and, without a file, the bounds")  # fmt: skip
    g.add_argument("--start", nargs="+", type=float, metavar=("X Y", "YAW"),
                   help="the start position, and a car-like robot's heading there")  # fmt: skip
    g.add_argument("--goal", nargs="+", type=float, metavar=("X Y", "YAW"),
                   help="the goal position, and the heading wanted there")  # fmt: skip
    g.add_argument("--radius", type=float, metavar="R",
                   help="the robot's radius (required without a problem file)")  # fmt: skip
    g.add_argument("--inflation-radius", type=float, metavar="R",
                   help="Nav2's inflation_radius: the clearance cost reaches this far")  # fmt: skip
    g.add_argument("--turning-radius", type=float, metavar="R",
                   help="a car-like robot's turning radius (Dubins curves)")  # fmt: skip
    g.add_argument("--reverse", action="store_true",
                   help="the car may back (Reeds-Shepp curves; with --turning-radius)")  # fmt: skip


def load_query(args: argparse.Namespace) -> Any:
    """The problem of ``args``: its file with the query flags over it, or the flags alone.

    Sets ``args.problem`` to :data:`COMMAND_LINE` for a query without a file (the label its
    messages start with).

    Raises
    ------
    UsageError
        For a query that is neither a file nor a map with a start and a goal, or a position that
        is not ``X Y`` or ``X Y YAW``.
    ProblemError
        As a file's, naming the flag that gave a wrong value.
    """
    from ..model.problem import problem_from_dict
    from ..model.yamlfile import read_yaml_file

    given = _given(args)
    if args.problem is None:
        needed = (("--map", args.map), ("--start", args.start), ("--goal", args.goal),
                  ("--radius", args.radius))  # fmt: skip
        missing = [flag for flag, value in needed if value is None]
        if missing:
            raise UsageError(f"give a problem file, or a query by --map, --start, --goal and "
                             f"--radius (missing: {', '.join(missing)})")  # fmt: skip
        doc: dict[str, Any] = {"robot": {}}
        source, name, base = (
            f"<{COMMAND_LINE}>",
            os.path.splitext(os.path.basename(args.map))[0],
            ".",
        )
    else:
        doc = read_yaml_file(args.problem)  # not a mapping: the loader says what is wrong
        source, name = args.problem, os.path.splitext(os.path.basename(args.problem))[0]
        base = os.path.dirname(args.problem) or "."
    if given and isinstance(doc, dict):
        doc = _overridden(doc, args)
    try:
        problem = problem_from_dict(doc, source=source, name=name, base=base)
    except ProblemError as exc:
        flag = _FLAG_OF_KEY.get(exc.key) or _FLAG_OF_KEY.get(exc.key.split("[")[0])
        if flag is None or flag not in given:
            if args.problem is None:
                raise ProblemError(COMMAND_LINE, exc.key, exc.message) from None
            raise
        message = exc.message
        if exc.key == "start_yaw":  # the file's wording names a key the flags do not have
            message = ("a heading (YAW) at the start applies to a car-like robot only "
                       "(--turning-radius); a differential-drive robot turns in place: "
                       "give X Y")  # fmt: skip
        raise ProblemError(COMMAND_LINE if args.problem is None else args.problem, flag,
                           message) from None  # fmt: skip
    if args.problem is None:
        args.problem = COMMAND_LINE
    return problem


def _given(args: argparse.Namespace) -> set[str]:
    """The query flags given."""
    flags = {"--map": args.map, "--start": args.start, "--goal": args.goal,
             "--radius": args.radius, "--inflation-radius": args.inflation_radius,
             "--turning-radius": args.turning_radius}  # fmt: skip
    given = {f for f, v in flags.items() if v is not None}
    if args.reverse:
        given.add("--reverse")
    return given


def _overridden(doc: dict[str, Any], args: argparse.Namespace) -> dict[str, Any]:
    """The file's mapping with the flags' values over it (a copy)."""
    out = dict(doc)
    robot = dict(out.get("robot") or {}) if isinstance(out.get("robot") or {}, dict) else {}
    if args.map is not None:
        out["map"] = os.path.abspath(args.map)  # from here, not from the problem file's folder
        if args.problem is not None:
            out.pop("bounds", None)  # the new map's extent
    for flag, key, yaw_key in (("--start", "start", "start_yaw"), ("--goal", "goal", "goal_yaw")):
        values = getattr(args, key)
        if values is None:
            continue
        if len(values) not in (2, 3):
            raise UsageError(f"{flag}: give X Y or X Y YAW, got {len(values)} numbers")
        out[key] = list(values[:2])
        if len(values) == 3:
            out[yaw_key] = values[2]
    for name, key in (("radius", "radius"), ("inflation_radius", "inflation_radius"),
                      ("turning_radius", "turning_radius")):  # fmt: skip
        if getattr(args, name) is not None:
            robot[key] = getattr(args, name)
    if args.reverse:
        robot["reverse"] = True
    out["robot"] = robot
    return out
