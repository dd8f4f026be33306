"""A batch from Python: several problem files, two planners, every result typed.

Run: ``python examples/batch.py [OUT.jsonl]`` (about 3 s). ``rrtpso batch`` does the same from the
command line, in worker processes, with resuming and a progress bar.
"""

from __future__ import annotations

import json
import statistics
import sys
from pathlib import Path

from rrtpso_ompl import load_problem, solve

REPO = Path(__file__).resolve().parent.parent
FILES = ("paper_static", "single_circle", "cluttered_circles")
PLANNERS = ("RRTstarPSO", "BITstar+simplify")


def main(out: Path | None = None) -> None:
    rows = []
    for name in FILES:
        problem = load_problem(REPO / "problems" / "static" / f"{name}.yaml")
        for planner in PLANNERS:
            # seed: OMPL's and the planner's; the time limit covers planner and post-passes.
            result = solve(problem, planner, time_limit=0.3, seed=1)
            rows.append({"problem": name, "planner": planner, "solved": result.solved,
                         "length": result.length, "time": result.time})
            length = f"{result.length:.2f} {problem.units}" if result.solved else "no path"
            print(f"{name:18} {planner:18} {length:>12}  {result.time:.2f} s")
    for planner in PLANNERS:
        lengths = [r["length"] for r in rows if r["planner"] == planner and r["solved"]]
        print(f"{planner}: solved {len(lengths)}/{len(FILES)}, "
              f"median length {statistics.median(lengths):.2f}")
    if out is not None:
        out.write_text("".join(json.dumps(r) + "\n" for r in rows))
        print(f"wrote {out}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else None)
