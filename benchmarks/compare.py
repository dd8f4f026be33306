"""Compare RRTstarPSO with OMPL's stock planners at equal time budgets.

Every run goes through :func:`rrtpso_ompl.planners.solve.solve` (same OMPL setup, same exact
collision checker) in a fresh process (OMPL's RNG can be seeded only once per process).
Stock planners are
followed by OMPL's path simplifier, as OMPL's Benchmark does, and their simplification time is
reported separately (it is *not* charged to their budget); RRTstarPSO's simplifier and PSO run
inside its budget.

Usage::

    python benchmarks/compare.py                       # defaults below, writes docs/benchmark.md
    python benchmarks/compare.py --seeds 3 --budgets 0.25,1 --out /tmp/bench.md

Writes a markdown report (``--out``) and the raw rows as JSON lines next to it.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import platform
import shlex
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_PLANNERS = "RRTstarPSO,RRTstar,InformedRRTstar,BITstar,RRTConnect"
PSO_PLANNERS = {"RRTstarPSO", "PSO"}


def parse_spec(spec: str) -> tuple[str, dict[str, str]]:
    """``"Name[k=v k2=v2]"`` -> ``("Name", {"k": "v", "k2": "v2"})`` (OMPL's planner-spec style,
    as in AnytimePathShortening)."""
    name, _, rest = spec.partition("[")
    params = dict(item.split("=", 1) for item in rest.rstrip("]").split() if "=" in item)
    return name.strip(), params


def run_one(
    problem_path: str, planner: str, budget: float, seed: int, simplify: bool = True
) -> dict:
    """One run in a fresh worker process; returns a plain row. ``planner`` may be a spec."""
    from rrtpso_ompl.model.problem import load_problem
    from rrtpso_ompl.ompl_setup.context import set_ompl_log_level
    from rrtpso_ompl.planners.solve import solve

    set_ompl_log_level(0)
    problem = load_problem(problem_path)
    t0 = time.perf_counter()
    name, params = parse_spec(planner)
    result = solve(
        problem, name, budget, seed, params, simplify=simplify and name not in PSO_PLANNERS
    )
    wall = time.perf_counter() - t0
    stages = result.stages
    return {
        "problem": problem.name,
        "planner": planner,
        "budget": budget,
        "seed": seed,
        "solved": result.solved,
        "length": result.length,
        "time": result.time,
        "wall": wall,
        "simplification_time": stages.get("simplification_time"),
        "rrt_length": stages.get("rrt_length"),
        "simplified_length": stages.get("simplified_length"),
        "pso_time": stages.get("pso_time"),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "problems", nargs="*", help="problem files (default: problems/static/*.yaml)"
    )
    parser.add_argument("--planners", default=DEFAULT_PLANNERS)
    parser.add_argument("--budgets", default="0.25,1,4", help="seconds, comma-separated")
    parser.add_argument("--seeds", type=int, default=5, help="runs per cell (seeds 1..N)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument(
        "--no-simplify",
        action="store_true",
        help="report the stock planners' raw paths (the paper's Table 3), not simplified ones",
    )
    parser.add_argument("--out", default=str(REPO / "docs" / "benchmark.md"))
    args = parser.parse_args(argv)

    problems = [Path(p) for p in args.problems] or sorted(
        (REPO / "problems" / "static").glob("*.yaml")
    )
    planners = [p.strip() for p in args.planners.split(",")]
    budgets = [float(b) for b in args.budgets.split(",")]
    simplify = not args.no_simplify
    tasks = [
        (str(p), pl, b, s, simplify)
        for p in problems
        for b in budgets
        for pl in planners
        for s in range(1, args.seeds + 1)
    ]

    from tqdm import tqdm

    rows: list[dict] = []
    t0 = time.perf_counter()
    # spawn + one task per process: every run gets a fresh, correctly seeded OMPL.
    ctx = mp.get_context("spawn")
    with ProcessPoolExecutor(args.jobs, mp_context=ctx, max_tasks_per_child=1) as pool:
        futures = {pool.submit(run_one, *t): t for t in tasks}
        for fut in tqdm(
            as_completed(futures), total=len(futures), file=sys.stderr, disable=None, desc="runs"
        ):
            try:
                rows.append(fut.result())
            except Exception as exc:  # one failed run is a data point, not the end of the study
                path, planner, budget, seed, _ = futures[fut]
                rows.append(
                    {
                        "problem": Path(path).stem,
                        "planner": planner,
                        "budget": budget,
                        "seed": seed,
                        "solved": False,
                        "length": None,
                        "time": math.nan,
                        "error": f"{type(exc).__name__}: {exc}",
                        "pso_time": None,
                        "rrt_length": None,
                        "simplified_length": None,
                    }
                )
    total = time.perf_counter() - t0

    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    raw = out.with_suffix(".jsonl")
    raw.write_text("".join(json.dumps(r) + "\n" for r in rows))
    command = "python benchmarks/compare.py " + shlex.join(
        argv if argv is not None else sys.argv[1:]
    )
    from rrtpso_ompl.evaluation.optimum import shortest_path
    from rrtpso_ompl.model.problem import load_problem

    # The reference of every cell: the exact shortest path (`rrtpso optimum`), once per problem.
    optima = {}
    for path in problems:
        problem = load_problem(path)
        optima[problem.name] = shortest_path(problem).length
    out.write_text(report(rows, planners, budgets, command, total, simplify, optima, args.jobs))
    print(f"wrote {out} and {raw}", file=sys.stderr)
    return 0


def _median(xs: list[float]) -> float:
    return statistics.median(xs) if xs else math.nan


def report(
    rows: list[dict],
    planners: list[str],
    budgets: list[float],
    command: str,
    total: float,
    simplify: bool = True,
    optima: dict[str, float | None] | None = None,
    jobs: int = 2,
) -> str:
    """The markdown report: one table per problem, plus the targets checked.

    ``optima`` maps a problem name to its exact shortest length (None: no path exists); a
    problem missing from it is measured against the shortest path any run found.
    """
    optima = optima or {}
    by_problem: dict[str, list[dict]] = {}
    for r in rows:
        by_problem.setdefault(r["problem"], []).append(r)
    lines = [
        "# Benchmark: RRTstarPSO against OMPL's planners",
        "",
        f"Generated by `{command}` in {total:.0f} s on {platform.machine()} "
        f"({mp.cpu_count()} cores, {jobs} run{'s' if jobs > 1 else ''} at a time), "
        f"Python {platform.python_version()}.",
        "",
        "Cells: median path length over the solved runs (+ excess over `ref`) [success rate], "
        "median planning time in seconds. `ref` is the exact shortest path (`rrtpso optimum`). "
        + (
            "Stock planners are followed by OMPL's simplifier (its time is not charged to the "
            "budget, as in OMPL's Benchmark); RRTstarPSO's simplifier and PSO run inside its "
            "budget."
            if simplify
            else "Stock planners' raw paths, without simplification (as in the paper's Table 3)."
        ),
        "",
    ]
    checks: list[str] = []
    for name, prs in sorted(by_problem.items()):
        lengths = [r["length"] for r in prs if r["solved"]]
        exact = optima.get(name)
        ref = exact if exact is not None else (min(lengths) if lengths else math.nan)
        kind = "exact optimum" if exact is not None else "best found"
        lines += [
            f"## {name} (ref = {ref:.2f}, {kind})",
            "",
            "| planner | " + " | ".join(f"{b:g} s" for b in budgets) + " |",
            "|---|" + "---|" * len(budgets),
        ]
        med: dict[tuple[str, float], float] = {}
        for pl in planners:
            cells = []
            for b in budgets:
                cell = [r for r in prs if r["planner"] == pl and r["budget"] == b]
                ok = [r["length"] for r in cell if r["solved"]]
                m = _median(ok)
                med[pl, b] = m
                t = _median([r["time"] for r in cell if math.isfinite(r["time"])])
                extra = ""
                if parse_spec(pl)[0] in PSO_PLANNERS and cell and cell[0]["pso_time"] is not None:
                    share = _median([r["pso_time"] / b for r in cell if r["pso_time"]])
                    extra = f", PSO {100 * share:.1f}% of budget"
                cells.append(
                    f"{m:.2f} (+{100 * (m / ref - 1):.2f}%) [{len(ok)}/{len(cell)}] "
                    f"{t:.2f} s{extra}"
                    if ok
                    else f"– [0/{len(cell)}]"
                )
            lines.append(f"| {pl} | " + " | ".join(cells) + " |")
        lines.append("")
        for b in budgets:
            ours = med.get(("RRTstarPSO", b), math.nan)
            for other, from_budget in (("RRTstar", 0.0), ("BITstar", 1.0)):
                if b >= from_budget and (other, b) in med:
                    theirs = med[other, b]
                    ok = ours < theirs
                    checks.append(
                        f"- {name}, {b:g} s: RRTstarPSO {ours:.2f} vs {other} "
                        f"{theirs:.2f}: {'met' if ok else '**not met**'}"
                    )
            if exact is not None:
                ok = ours <= 1.01 * ref
                checks.append(
                    f"- {name}, {b:g} s: within 1% of the optimum ({ours:.2f} vs "
                    f"{ref:.2f}): {'met' if ok else '**not met**'}"
                )
    failed = [r for r in rows if r.get("error")]
    if failed:
        lines += [f"**{len(failed)} runs failed** (counted as unsolved):", ""]
        lines += [
            f"- {r['problem']}, {r['planner']}, seed {r['seed']}: {r['error']}" for r in failed
        ]
        lines.append("")
    if checks:
        lines += ["## Targets", "", *checks, ""]
    lines += ["## Where RRTstarPSO is not the shortest", ""]
    beaten = []
    for name, prs in sorted(by_problem.items()):
        for b in budgets:
            meds = {
                pl: _median(
                    [
                        r["length"]
                        for r in prs
                        if r["planner"] == pl and r["budget"] == b and r["solved"]
                    ]
                )
                for pl in planners
            }
            ours = meds.get("RRTstarPSO", math.nan)
            for pl, m in sorted(meds.items(), key=lambda kv: kv[1]):
                if pl != "RRTstarPSO" and m < ours:
                    beaten.append(
                        f"- {name}, {b:g} s: {pl} {m:.2f} < RRTstarPSO {ours:.2f} "
                        f"({100 * (ours / m - 1):.2f}% longer)"
                    )
    lines += beaten or ["- nowhere: RRTstarPSO has the shortest median path in every cell."]
    ours = [r for r in rows if r["planner"] == "RRTstarPSO" and r["solved"] and r["rrt_length"]]
    gains = [(r["rrt_length"] - r["length"]) / r["rrt_length"] for r in ours]
    simp = [(r["rrt_length"] - r["simplified_length"]) / r["rrt_length"] for r in ours]
    swarm = [(r["simplified_length"] - r["length"]) / r["simplified_length"] for r in ours]
    shares = [
        r["pso_time"] / r["budget"]
        for r in rows
        if r["planner"] == "RRTstarPSO" and r["pso_time"] is not None
    ]
    if gains:
        lines += [
            "",
            "## The PSO stage",
            "",
            f"Over {len(gains)} RRTstarPSO runs, the stages after RRT* shortened its path by "
            f"{100 * statistics.median(gains):.2f}% in the median (max {100 * max(gains):.2f}%): "
            f"OMPL's simplifier by {100 * statistics.median(simp):.2f}%, then the swarm by "
            f"{100 * statistics.median(swarm):.2f}% of what was left (max "
            f"{100 * max(swarm):.2f}%). The PSO used {100 * statistics.median(shares):.1f}% of "
            f"the budget in the median (max {100 * max(shares):.1f}%).",
        ]
    lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
