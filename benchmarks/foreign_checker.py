"""RRTstarPSO with a user's own validity checker, in the environments of OMPL's Python tests.

- ``geo_env`` (ompl/ompl ``tests/pytests/geo_env.py``): [-1, 1]^2, a checker that sleeps 1 ms
  per state and accepts everything. Measured: how long ``ss.solve(T)`` takes, against stock RRT*.
- ``square`` (``tests/pytests/test_optimal_planning.py``): the unit square with the obstacle
  (0.3, 0.7)^2, start (0.1, 0.1), goal (0.9, 0.9), exact shortest path 1.26491. Measured: the
  returned length and how deep the path goes into the obstacle, measured densely (20,000 points
  per segment), against the RRT* path it was made from.

Every run is a fresh process (OMPL's seed is per process), seeded 1..N.

Usage::

    python benchmarks/foreign_checker.py                 # writes docs/foreign-checker.md
    python benchmarks/foreign_checker.py --runs 3 --out -
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import platform
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "tests" / "planners"))


def run(env: str, planner: str, budget: float, seed: int) -> dict:
    """One solve in this (fresh) process."""
    import numpy as np
    from ompl import geometric as og
    from ompl import util as ou
    from test_foreign_checker import geo_env, penetration, square_env

    from rrtpso_ompl.ompl_setup import path_to_array
    from rrtpso_ompl.planners.rrtstar_pso.planner import RRTstarPSO

    ou.RNG.setSeed(seed)
    ou.setLogLevel(ou.LOG_WARN)
    ss, si = geo_env() if env == "geo_env" else square_env()
    if planner == "RRTstar":
        p = og.RRTstar(si)
        if env == "square":
            p.setRange(0.1)  # as test_optimal_planning.py
    else:
        p = RRTstarPSO(si, budget=budget)
    ss.setPlanner(p)
    t0 = time.perf_counter()
    ss.solve(budget)
    elapsed = time.perf_counter() - t0
    out = {"env": env, "planner": planner, "budget": budget, "seed": seed, "elapsed": elapsed,
           "solved": bool(ss.haveExactSolutionPath())}  # fmt: skip
    if out["solved"] and env == "square":
        xy = path_to_array(ss.getSolutionPath())
        out["length"] = float(ss.getSolutionPath().length())
        out["depth"] = penetration(xy)
        stats = getattr(p, "last_stats", None)
        if stats is not None:
            seed = getattr(stats, "seed_path", stats.rrt_path)  # (before issue 17: the first)
            out["seed_depth"] = penetration(np.array(seed))
            out["pso_improved"] = stats.pso_improved
    return out


def _job(args):
    return run(*args)


def deadline_table(rows: list[dict]) -> str:
    """geo_env: per planner and budget, how long ``ss.solve(T)`` took."""
    from rrtpso_ompl.harness.report import markdown_table

    cells = []
    for budget in (0.25, 0.5, 1.0):
        for planner in ("RRTstar", "RRTstarPSO"):
            rs = [r for r in rows if r["env"] == "geo_env" and r["budget"] == budget
                  and r["planner"] == planner]  # fmt: skip
            t = [r["elapsed"] for r in rs]
            cells.append([planner, f"{budget:g}", f"{statistics.median(t):.3f}", f"{max(t):.3f}",
                          f"{100 * (max(t) / budget - 1):+.1f}",
                          f"{sum(r['solved'] for r in rs)}/{len(rs)}"])  # fmt: skip
    return markdown_table(["planner", "budget s", "median solve s", "max solve s",
                           "max overrun %", "solved"], cells)  # fmt: skip


def depth_table(rows: list[dict]) -> str:
    """square: per planner and budget, the returned length and how deep the path goes into the
    obstacle (for RRTstarPSO also its RRT* path's depth)."""
    from rrtpso_ompl.harness.report import markdown_table

    cells = []
    for budget in (0.25, 1.0):
        for planner in ("RRTstar", "RRTstarPSO"):
            rs = [r for r in rows if r["env"] == "square" and r["budget"] == budget
                  and r["planner"] == planner and r["solved"]]  # fmt: skip
            seed_d = [r["seed_depth"] for r in rs if "seed_depth" in r]
            deeper = sum(r["depth"] > r["seed_depth"] + 1e-12 for r in rs if "seed_depth" in r)
            swarm = (
                [f"{max(seed_d):.5f}", f"{deeper}/{len(rs)}",
                 f"{sum(r['pso_improved'] for r in rs)}/{len(rs)}"]
                if seed_d else ["–", "–", "–"]
            )  # fmt: skip
            cells.append([planner, f"{budget:g}",
                          f"{statistics.median(r['length'] for r in rs):.5f}",
                          f"{statistics.median(r['depth'] for r in rs):.5f}",
                          f"{max(r['depth'] for r in rs):.5f}", *swarm])  # fmt: skip
    return markdown_table(["planner", "budget s", "median length", "median depth", "max depth",
                           "max depth of its RRT* path", "runs deeper than their RRT* path",
                           "swarm improved"], cells)  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=10)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=str(REPO / "docs" / "foreign-checker.md"))
    args = ap.parse_args(argv)
    from rrtpso_ompl.harness.report import write_markdown

    jobs = [(env, planner, budget, seed)
            for env, budgets in (("geo_env", (0.25, 0.5, 1.0)), ("square", (0.25, 1.0)))
            for budget in budgets for planner in ("RRTstar", "RRTstarPSO")
            for seed in range(1, args.runs + 1)]  # fmt: skip
    t0 = time.perf_counter()
    with mp.get_context("spawn").Pool(args.jobs, maxtasksperchild=1) as pool:
        rows = pool.map(_job, jobs, chunksize=1)
    wall = time.perf_counter() - t0
    lines = [
        "# RRTstarPSO with a user's validity checker",
        "",
        f"Generated by `python benchmarks/foreign_checker.py {' '.join(argv or sys.argv[1:])}` "
        f"on {platform.machine()}, Python {platform.python_version()}, {args.jobs} processes, "
        f"{wall / 60:.1f} min; {args.runs} seeded runs per row, each in its own process.",
        "",
        "## The deadline with a slow checker (geo_env: 1 ms per state)",
        "",
        deadline_table(rows),
        "",
        "## The gaps of the discrete check (test_optimal_planning's square)",
        "",
        "Depth: how far the returned path goes into the obstacle, measured densely; for "
        "RRTstarPSO also the depth of the RRT* path it was made from (its `seed_path`).",
        "",
        depth_table(rows),
    ]
    write_markdown(lines, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
