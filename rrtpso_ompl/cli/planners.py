"""``rrtpso planners``: every registered planner and its declared parameters."""

from __future__ import annotations

import argparse
import json
from typing import Any

from ..outputs import write_stdout
from .common import EXIT_OK

__all__ = ["HELP", "add_parser", "run"]

#: The line of ``rrtpso --help``.
HELP = "list the planners and their parameters"


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    q = sub.add_parser(
        "planners",
        parents=parents,
        help=HELP,
        description="List the registered planners and their parameters.",
    )
    q.add_argument("name", nargs="?", help="show only this planner")
    q.add_argument("--json", action="store_true", help="machine-readable output")
    q.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..planners import default_registry

    registry = default_registry()
    entries = [registry.get(args.name)] if args.name else registry.entries()
    if args.json:
        write_stdout(json.dumps([_entry_dict(e) for e in entries], indent=2) + "\n")
        return EXIT_OK
    lines = []
    for e in entries:
        aliases = f"  (also: {', '.join(e.aliases)})" if e.aliases else ""
        lines.append(f"{e.name}{aliases}\n    {e.description}  [{e.source}]")
        lines += _param_lines(e.params, bool(args.name))
    write_stdout("".join(f"{line}\n" for line in lines))  # one message if it cannot be written
    return EXIT_OK


def _param_lines(table: Any, docs: bool) -> list[str]:
    """A planner's parameters, by stage when they have one, the columns as wide as the longest
    name and default; those worth tuning first marked with ``*`` (and said so)."""
    params = list(table)
    if not params:
        return []
    name_w = max(len(p.name) for p in params) + 2
    default_w = max(len(str(p.default)) for p in params)
    out, group, any_key = [], None, False
    for p in params:
        stage, key = table.group_of(p.name)
        any_key = any_key or key
        if stage and stage != group:
            group = stage
            out.append(f"  {group}:")
        unit = f" {p.unit}" if p.unit else ""
        mark = "*" if key else " "
        out.append(f"  {mark} {p.name:<{name_w}}{p.type.__name__:<6}default "
                   f"{p.default!s:<{default_w}}{unit} in {p.range_text()}")  # fmt: skip
        if docs:
            out.append(f"        {p.doc}")
    if any_key:
        out.append("  (* worth tuning first)")
    return out


def _entry_dict(e: Any) -> dict[str, Any]:
    """A registry entry as JSON: names, capabilities and every declared parameter."""
    from dataclasses import asdict

    return {
        "name": e.name,
        "aliases": list(e.aliases),
        "description": e.description,
        "optimizing": e.optimizing,
        "capabilities": asdict(e.capabilities),
        "source": e.source,
        "params": [
            {
                "name": p.name,
                "type": p.type.__name__,
                "default": p.default,
                "unit": p.unit,
                "range": p.range_text(),
                "doc": p.doc,
                "group": e.params.group_of(p.name)[0],
                "key": e.params.group_of(p.name)[1],
            }
            for p in e.params
        ],
    }
