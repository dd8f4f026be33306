"""Write docs/problem.schema.json, the JSON Schema of problem files, from the format's
declarations (rrtpso_ompl.model.format), the same tables the loader takes its keys from.

Usage::

    python benchmarks/problem_schema.py            # writes docs/problem.schema.json
"""

from __future__ import annotations

import sys
from pathlib import Path

from rrtpso_ompl.model.format import schema_text

OUT = Path(__file__).resolve().parent.parent / "docs" / "problem.schema.json"


def main() -> int:
    OUT.write_text(schema_text())
    print(f"wrote {OUT}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
