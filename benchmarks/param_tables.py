"""Print the parameter tables of docs/planners.md from the registry (so the docs cannot drift).

Usage: python benchmarks/param_tables.py RRTstarPSO PSO
"""

from __future__ import annotations

import sys

from rrtpso_ompl.registry import default_registry


def table(name: str) -> str:
    entry = default_registry().get(name)
    rows = ["| name | type | default | unit | range | meaning |", "|---|---|---|---|---|---|"]
    for p in entry.params:
        rows.append(
            f"| `{p.name}` | {p.type.__name__} | {p.default} | {p.unit or '–'} | "
            f"{p.range_text()} | {p.doc} |"
        )
    return "\n".join(rows)


if __name__ == "__main__":
    for name in sys.argv[1:] or ["RRTstarPSO", "PSO"]:
        print(f"### {name}\n\n{table(name)}\n")
