"""Parameter tables of docs/planners.md, docs/dynamic.md and problems/README.md, generated from
the declarations so the docs cannot drift: the planners' from the registry, the generator's from
its kinds, the dynamic stage's from its option sets.

Usage::

    python benchmarks/param_tables.py RRTstarPSO PSO          # print the tables
    python benchmarks/param_tables.py --update docs/planners.md
    python benchmarks/param_tables.py --update docs/dynamic.md
    python benchmarks/param_tables.py --update problems/README.md

``--update`` rewrites every block between ``<!-- params:NAME -->`` and ``<!-- /params:NAME -->``
(planner NAME), between ``<!-- generate:KIND -->`` and ``<!-- /generate:KIND -->`` (the
options of ``rrtpso generate KIND``) and between ``<!-- options:CLASS -->`` and
``<!-- /options:CLASS -->`` (an option set of the dynamic stage, with its ``rrtpso simulate``
flags).
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


def options_table(name: str) -> str:
    """The markdown table of the dynamic stage's option set ``name`` (``DynamicOptions``, or
    ``DWAOptions``, the ``dwa`` strategy's), with the ``rrtpso simulate`` flag of each option."""
    from rrtpso_ompl.cli.simulate import OPTION_FLAGS
    from rrtpso_ompl.dynamic import DynamicOptions
    from rrtpso_ompl.dynamic.strategies import DWAOptions

    table = {"DynamicOptions": DynamicOptions, "DWAOptions": DWAOptions}[name].PARAMS
    rows = ["| name | flag | type | default | unit | range | meaning |",
            "|---|---|---|---|---|---|---|"]  # fmt: skip
    for p in table:
        flag = f"`{OPTION_FLAGS[p.name]}`" if p.name in OPTION_FLAGS else "–"
        rows.append(f"| `{p.name}` | {flag} | {p.type_text()} | {p.default} | {p.unit or '–'} | "
                    f"{p.range_text()} | {p.doc} |")  # fmt: skip
    if table.rules:
        rows += ["", "Also: " + "; ".join(f"`{r.text}`" for r in table.rules) + "."]
    return "\n".join(rows)


def update(path: Path) -> None:
    """Regenerate every marked table in ``path``."""
    text = path.read_text()
    makers = (("params", table), ("generate", generator_table), ("options", options_table))
    for marker, make in makers:
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
