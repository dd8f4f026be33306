"""Parameter tables of docs/planners.md and problems/README.md, generated from the declarations
so the docs cannot drift: the planners' from the registry, the generator's from its kinds.

Usage::

    python benchmarks/param_tables.py RRTstarPSO PSO          # print the tables
    python benchmarks/param_tables.py --update docs/planners.md
    python benchmarks/param_tables.py --update problems/README.md

``--update`` rewrites every block between ``<!-- params:NAME -->`` and ``<!-- /params:NAME -->``
(planner NAME) and between ``<!-- generate:KIND -->`` and ``<!-- /generate:KIND -->`` (the
options of ``rrtpso generate KIND``).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from rrtpso_ompl.planners.registry import default_registry


def table(name: str) -> str:
    """The markdown table of planner ``name``'s parameters (from its declarations)."""
    return default_registry().get(name).params.markdown()


def generator_table(kind: str) -> str:
    """The markdown table of the options of ``rrtpso generate KIND`` (from its declarations)."""
    from rrtpso_ompl.groundtruth.generate import GENERATORS

    return GENERATORS[kind].PARAMS.markdown()


def update(path: Path) -> None:
    """Regenerate every marked table in ``path``."""
    text = path.read_text()
    for marker, make in (("params", table), ("generate", generator_table)):
        pattern = re.compile(rf"(<!-- {marker}:(\S+) -->\n).*?(\n<!-- /{marker}:\2 -->)", re.S)
        text = pattern.sub(lambda m, make=make: m.group(1) + make(m.group(2)) + m.group(3), text)
    path.write_text(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("planners", nargs="*", default=["RRTstarPSO", "PSO"])
    parser.add_argument("--update", type=Path, metavar="MARKDOWN")
    args = parser.parse_args(argv)
    if args.update:
        update(args.update)
        return 0
    for name in args.planners:
        print(f"### {name}\n\n{table(name)}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
