"""Where the swarm post-pass pays: every stock OMPL planner with ``+simplify`` and with
``+simplify+pso`` at 0.25, 1 and 4 s, on the report set and on fresh generated problems.

The runs go through ``rrtpso bench`` (warm workers, one fresh OMPL per run, OMPL's log format).
Within one ``+simplify+pso`` run the path is measured three times: as the planner returned it,
after OMPL's simplifier and after the swarm, so the swarm's gain is paired (same run, same path).
The ``+simplify`` configuration is the same planner with the simplifier alone. Every length is
reported over the problem's exact optimum (``rrtpso optimum``).

Problems (none of them was used to tune anything):

- the report part of ``problems/static`` (``benchmarks/families.py``: not in ``TUNING_FILES``)
  and two occupancy-grid maps;
- one fresh seed (301) of each generated family of ``benchmarks/families.py``.

Usage::

    python benchmarks/post_pass.py                     # writes docs/post-pass.md (about 20 min)
    python benchmarks/post_pass.py --times 0.25 --planners RRT,BITstar --out /tmp/p.md
"""

from __future__ import annotations

import argparse
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from families import REPO, SHAPE_FAMILIES, TUNING_FILES

#: OMPL's planners as registered (RRTstarPSO and the PSO baseline are ours).
STOCK = ("BFMT", "BITstar", "BKPIECE1", "FMT", "InformedRRTstar", "KPIECE1", "LBKPIECE1", "PRM",
         "PRMstar", "RRT", "RRTConnect", "RRTstar", "SORRTstar")  # fmt: skip
MAPS = ("maps/lab_clutter.yaml", "maps/office_corridor.yaml")
FRESH_SEED = 301
#: The generated families docs/post-pass.md was measured on.
FAMILIES = {k: SHAPE_FAMILIES[k] for k in ("circles", "circles_point", "polygons", "maze",
                                           "maze_narrow")}  # fmt: skip


def problems(folder: Path) -> list[tuple[str, Path]]:
    """``(set, path)``: the report part of the library, two maps, fresh generated problems."""
    from rrtpso_ompl.groundtruth.generate import generate_to_file

    out = []
    for path in sorted((REPO / "problems" / "static").glob("*.yaml")):
        if str(path.relative_to(REPO / "problems")) not in TUNING_FILES:
            out.append(("library", path))
    out += [("library", REPO / "problems" / m) for m in MAPS]
    for family, (kind, options) in FAMILIES.items():
        path = folder / f"{family}_{FRESH_SEED}.yaml"
        generate_to_file(kind, FRESH_SEED, path, **options)
        out.append(("generated", path))
    return out


def _median(xs):
    return statistics.median(xs) if xs else None


def _fmt(x, spec="+.2f", suffix=" %"):
    return "–" if x is None else format(x, spec) + suffix


def summarise(rows: list, optimum: dict[str, float], planners, times) -> list[str]:
    """Per planner and budget (rows: :class:`~rrtpso_ompl.harness.record.RunRecord`): excess
    over the optimum raw / simplified / after the swarm, the swarm's paired gain and time."""
    from rrtpso_ompl.harness.report import markdown_table

    table = []
    for planner in planners:
        for budget in times:
            both = [r for r in rows if r.planner == f"{planner}+simplify+pso"
                    and r.budget == budget and not r.is_error]  # fmt: skip
            simp = [r for r in rows if r.planner == f"{planner}+simplify"
                    and r.budget == budget and not r.is_error]  # fmt: skip
            raw, after_s, after_p, gain, took, improved = [], [], [], [], [], 0
            for r in both:
                post = r.stages.get("post") or []
                best = optimum.get(r.file)
                if not (r.solved and len(post) == 2 and best):
                    continue
                raw.append(100 * (post[0]["length_before"] / best - 1))
                after_p.append(100 * (post[1]["length_after"] / best - 1))
                gain.append(100 * (1 - post[1]["length_after"] / post[1]["length_before"]))
                took.append(post[1]["time"])
                improved += post[1]["length_after"] < post[1]["length_before"] - 1e-9
            for r in simp:
                best = optimum.get(r.file)
                if r.solved and best:
                    after_s.append(100 * (r.length / best - 1))
            table.append([planner, f"{budget:g}", f"{len(raw)}/{len(both)}", _fmt(_median(raw)),
                          _fmt(_median(after_s)), _fmt(_median(after_p)),
                          _fmt(_median(gain), ".3f"), f"{improved}/{len(raw)}",
                          _fmt(_median(took), ".3f", "")])  # fmt: skip
    return markdown_table(["planner", "budget s", "runs solved", "raw", "+simplify",
                           "+simplify+pso", "pso gain (paired)", "pso improved", "pso time s"],
                          table).splitlines()  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--planners", default=",".join(STOCK))
    ap.add_argument("--times", default="0.25,1,4")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=str(REPO / "docs" / "post-pass.md"))
    args = ap.parse_args(argv)
    planners = args.planners.split(",")
    times = [float(t) for t in args.times.split(",")]

    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.harness import read_rows
    from rrtpso_ompl.model import load_problem

    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        items = problems(Path(tmp))
        optimum = {str(p): shortest_path(load_problem(p)).length for _, p in items}
        specs = [f"{p}+simplify{extra}" for p in planners for extra in ("", "+pso")]
        out_dir = Path(tmp) / "bench"
        cmd = [sys.executable, "-m", "rrtpso_ompl", "bench", *map(str, (p for _, p in items)),
               "--planner", ",".join(specs), "--runs", "1", "--time", args.times,
               "--jobs", str(args.jobs), "--out", str(out_dir), "-q"]  # fmt: skip
        subprocess.run(cmd, check=True)
        rows = read_rows(out_dir / "runs.jsonl")
    wall = time.perf_counter() - t_start
    sets = {str(p): s for s, p in items}
    lines = [
        "# The swarm as a post-pass for every planner",
        "",
        f"Generated by `python benchmarks/post_pass.py {' '.join(argv or sys.argv[1:])}` on "
        f"{platform.machine()}, Python {platform.python_version()}, {args.jobs} processes, "
        f"{wall / 60:.1f} min. {len(items)} problems ({sum(s == 'library' for s in sets.values())} "
        f"from the report part of `problems/`, {sum(s == 'generated' for s in sets.values())} "
        f"generated with seed {FRESH_SEED}), one run per configuration and budget. The planner "
        "gets 80 % of the budget, the post-passes the rest (`post_fraction` 0.2). Lengths are "
        "the median excess over each problem's exact optimum: *raw* as the planner returned it "
        "(in the `+simplify+pso` runs), then after `+simplify` (its own runs) and after "
        "`+simplify+pso`. *pso gain* is the paired median shortening by the swarm of the "
        "simplified path of the same run; *pso improved* counts the runs it shortened; *pso "
        "time* is the swarm's wall time.",
        "",
    ]
    for which in ("library", "generated"):
        subset = [r for r in rows if sets.get(r.file) == which]
        lines += [f"## {which}", ""]
        lines += summarise(subset, optimum, planners, times)
        lines.append("")
    Path(args.out).write_text("\n".join(lines))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
