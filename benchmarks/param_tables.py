"""Parameter tables of docs/planners.md, generated from the registry so the docs cannot drift.

Usage::

    python benchmarks/param_tables.py RRTstarPSO PSO          # print the tables
    python benchmarks/param_tables.py --update docs/planners.md

``--update`` rewrites every block between ``<!-- params:NAME -->`` and ``<!-- /params:NAME -->``.
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


def update(path: Path) -> None:
    """Regenerate every marked table in ``path``."""
    pattern = re.compile(r"(<!-- params:(\S+) -->\n).*?(\n<!-- /params:\2 -->)", re.S)
    text = path.read_text()
    path.write_text(pattern.sub(lambda m: m.group(1) + table(m.group(2)) + m.group(3), text))


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
