"""Benchmark the replanning strategies and a DWA local planner among moving obstacles.

Cases, each run in its own spawned process (OMPL's RNG is seeded once per process):

* ``random``: the static world of ``problems/dynamic/paper_dynamic.yaml`` plus 1-4 moving
  obstacles that cross the robot's static path: each picks a point of the path, a heading (any
  direction, so crossings from either side, head-on and overtaking all occur) and a speed up to
  the robot's, and starts where it would reach that point when the undisturbed robot does (plus a
  little jitter);
* ``turning``: the same with obstacles that turn at random (``--heading-changes``: 0.2 turns
  per second, 45 degrees standard deviation), so the constant-velocity prediction is wrong;
* ``map``: the same generator on the office occupancy-grid map of
  ``problems/dynamic/office_people.yaml`` (its two people replaced by the random obstacles);
* every named scenario in ``problems/dynamic/`` with several seeds (the static path differs).

Four strategies drive from the same static path in the same case:

* ``contour``: the paper's method (RRTstarPSO detours up and down, and waiting, chosen by
  predicted arrival; verified; the rest re-shortened once the obstacle has passed);
* ``global``: replan the whole remaining path with stock RRT* at each prediction (same prediction,
  sweep model, verification and fallbacks);
* ``none``: drive the static path blindly;
* ``dwa``: a Dynamic Window Approach local planner built as Nav2's DWB controller
  (:mod:`rrtpso_ompl.dynamic.dwa`) following a guide path planned with clearance for it; its
  parameters were tuned on cases none of which is reported (:data:`DWA_TUNING`).

Usage::

    python benchmarks/dynamic.py        # writes docs/dynamic-benchmark.md(.jsonl)
    python benchmarks/dynamic.py --scenarios 10 --turning 0 --map 0 --named-seeds 1 --out /tmp/d.md
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import shlex
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DYNAMIC = REPO / "problems" / "dynamic"
BASE = DYNAMIC / "paper_dynamic.yaml"
MAP_BASE = DYNAMIC / "office_people.yaml"
#: The strategies the benchmark runs (names of the strategy registry), each with the planner of
#: its static path, replans or guide path.
STRATEGIES = (
    ("contour", "RRTstarPSO"),
    ("global", "RRTstar"),
    ("none", "RRTstarPSO"),
    ("dwa", "RRTstarPSO"),
)
#: Options of their own (the strategy's declared option set): the DWA's guide path gets 0.5 s.
STRATEGY_OPTIONS = {"dwa": {"guide_time": 0.5}}
#: Random heading changes of the ``turning`` family: per obstacle per second, and degrees.
TURN_RATE, TURN_DEG = 0.2, 45.0
#: The cases the DWA's parameters were tuned on (``--first``, ``--first-turning``,
#: ``--first-map`` seeds), disjoint from the reported ones; the named scenarios were not used.
DWA_TUNING = "random seeds 301-360, turning seeds 5001-5030, map seeds 3001-3030"
#: The DWA's target (issue 22): the goal reached without collision in this share of the
#: ``random`` and ``map`` cases.
DWA_TARGET = 0.9
#: Longest a case may run before its process is stopped, s.
CASE_TIMEOUT = 1800.0
#: Longest wait the clairvoyant baseline tries, s.
MAX_CLAIRVOYANT_WAIT = 120.0


def make_scenario(seed: int, static_path, problem):
    """The moving obstacles of scenario ``seed`` (a list of MovingObstacle)."""
    import numpy as np

    from rrtpso_ompl.model.problem import MovingObstacle

    rng = np.random.default_rng(seed)
    path = np.asarray(static_path)
    seg = np.hypot(*np.diff(path, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    v = problem.robot.speed
    sr = problem.robot.radius
    out = []
    for _ in range(int(rng.integers(1, 5))):
        for _attempt in range(100):
            frac = rng.uniform(0.2, 0.85)
            x = np.array(
                [np.interp(frac * s[-1], s, path[:, 0]), np.interp(frac * s[-1], s, path[:, 1])]
            )
            t_x = frac * s[-1] / v
            heading = rng.uniform(-math.pi, math.pi)
            speed = rng.uniform(0.2, 1.0) * v
            radius = rng.uniform(0.53, 1.05) * sr  # 15-30 cm for the paper's robot
            start = x - speed * t_x * np.array([math.cos(heading), math.sin(heading)])
            start += rng.uniform(-0.5, 0.5, 2) * sr
            # Not on top of the robot at the start (that scenario has no collision-free motion).
            if math.hypot(*(start - path[0])) > 2.0 * (sr + radius):
                break
        out.append(MovingObstacle(float(radius), (float(start[0]), float(start[1])), float(speed),
                                  float(math.degrees(heading))))  # fmt: skip
    return out


@dataclass(frozen=True)
class Case:
    """One benchmark case: a family (or a named scenario), its base problem and its seed."""

    group: str
    base: str
    seed: int
    randomize: bool
    heading_changes: float = 0.0


def run_case(case: Case, replan_time: float, initial_time: float,
             optimum_path: list | None = None,
             strategies: tuple[str, ...] | None = None) -> list[dict]:  # fmt: skip
    """The strategies (default all) on one case, in one fresh process; one row per strategy,
    each with the case's limits (the optimum at full speed; the clairvoyant wait-then-drive)."""
    import dataclasses

    import numpy as np

    from rrtpso_ompl.dynamic import (
        DynamicOptions,
        ObstacleTrack,
        arrival_lower_bound,
        clairvoyant_wait,
        default_strategies,
    )
    from rrtpso_ompl.dynamic.manager import FALLBACK_KINDS
    from rrtpso_ompl.model.geometry import path_length
    from rrtpso_ompl.model.problem import load_problem
    from rrtpso_ompl.ompl_setup import set_ompl_log_level
    from rrtpso_ompl.planners import solve

    set_ompl_log_level(0)
    seed = case.seed
    head = {"group": case.group, "seed": seed, "obstacles_turn": case.heading_changes > 0}
    base = load_problem(case.base)
    static = solve(base, "RRTstarPSO", time_limit=initial_time, seed=seed)
    chosen = [(s, p) for s, p in STRATEGIES if strategies is None or s in strategies]
    if not static.solved:
        return [{**head, "strategy": s, "error": "no static path"} for s, _ in chosen]
    problem = base
    if case.randomize:
        moving = make_scenario(seed, static.path, base)
        problem = dataclasses.replace(base, name=f"{case.group}_{seed}",
                                      moving_obstacles=tuple(moving))  # fmt: skip
    robot = problem.robot
    limits = {"lower_bound_time": None, "clairvoyant_time": None}
    if optimum_path is not None:
        best = np.asarray(optimum_path)
        turn = 2.0 * (robot.max_wheel_speed or robot.speed) / robot.track_width
        limits["lower_bound_time"] = arrival_lower_bound(path_length(best), robot.speed)
        if case.heading_changes == 0:  # the obstacles' future is known only without random turns
            tracks = [ObstacleTrack.from_obstacle(m) for m in problem.moving_obstacles]
            wait = clairvoyant_wait(best, tracks, robot.radius, robot.speed, turn,
                                    robot.sample_time, MAX_CLAIRVOYANT_WAIT)  # fmt: skip
            limits["clairvoyant_time"] = wait.arrival if wait else None
    rows = []
    for strategy, planner in chosen:
        t0 = time.perf_counter()
        opts = DynamicOptions(planner=planner, strategy=strategy, replan_time=replan_time,
                              heading_changes=case.heading_changes,
                              heading_change_deg=TURN_DEG)  # fmt: skip
        runner = default_strategies().make(strategy, STRATEGY_OPTIONS.get(strategy))
        sim = runner.simulate(problem, opts, seed=seed, initial_path=static.path)
        planned = [r for r in sim.replans if r.kind not in FALLBACK_KINDS]
        clearance = [d - c for d, c in
                     zip(sim.min_separation_continuous, sim.contact_distance, strict=True)
                     if d is not None]  # fmt: skip
        rows.append(
            {
                **head,
                "scenario": problem.name,
                "strategy": strategy,
                "planner": sim.planner,
                "status": sim.status,
                "obstacles": len(problem.moving_obstacles),
                "reached_goal": sim.reached_goal,
                "collisions": sim.collisions,
                "success": sim.success and sim.status == "ok",
                "min_clearance": min(clearance, default=None),
                "path_length": sim.path_length,
                "static_length": sim.static_length,
                "total_time": sim.total_time,
                "replans": len(sim.replans),
                "detours": sum(r.side != "wait" for r in planned),
                "waits": sum(r.side == "wait" for r in planned),
                "fallbacks": {
                    k: sum(r.kind == k for r in sim.replans)
                    for k in FALLBACK_KINDS
                },
                "planning_times": [r.planning_time for r in planned],
                "wall": time.perf_counter() - t0,
                **limits,
            }
        )
    return rows


def _run(job: tuple) -> list[dict]:
    return run_case(*job)


def _case_timeout(job: tuple) -> float:
    return CASE_TIMEOUT


def _warm() -> None:
    """What a worker imports once, before it forks a process per case."""
    import rrtpso_ompl.dynamic.dwa
    import rrtpso_ompl.groundtruth.optimum  # noqa: F401
    from rrtpso_ompl.dynamic import default_strategies
    from rrtpso_ompl.planners import default_registry

    default_registry()
    default_strategies()


def summarise(rows: list[dict], group: str) -> list[dict]:
    """Per strategy, over the rows of ``group``."""
    out = []
    for strategy, _ in STRATEGIES:
        rs = [r for r in rows if r["group"] == group and r["strategy"] == strategy
              and "error" not in r]  # fmt: skip
        if not rs:
            continue
        planner = rs[0]["planner"]
        reached = [r for r in rs if r["reached_goal"]]
        plan_t = [t for r in rs for t in r["planning_times"]]
        over_lb = [100 * (r["total_time"] / r["lower_bound_time"] - 1) for r in reached
                   if r.get("lower_bound_time")]  # fmt: skip
        over_cw = [100 * (r["total_time"] / r["clairvoyant_time"] - 1) for r in reached
                   if r.get("clairvoyant_time")]  # fmt: skip
        feasible = [r for r in rs if r.get("clairvoyant_time")]
        out.append(
            {
                "strategy": strategy,
                "planner": planner,
                "runs": len(rs),
                "success": sum(r["success"] for r in rs),
                "reached": len(reached),
                "collision_runs": sum(r["collisions"] > 0 for r in rs),
                "collision_runs_feasible": sum(r["collisions"] > 0 for r in feasible),
                "feasible": len(feasible),
                "median_arrival": _median([r["total_time"] for r in reached]),
                "median_length": _median([r["path_length"] for r in reached]),
                "median_over_lb": _median(over_lb),
                "median_over_cw": _median(over_cw),
                "mean_replans": statistics.fmean(r["replans"] for r in rs),
                "waits": sum(r.get("waits", 0) for r in rs),
                "fallbacks": sum(sum(r["fallbacks"].values()) for r in rs),
                "median_plan_time": _median(plan_t),
                "p90_plan_time": _quantile(plan_t, 0.9),
                "max_plan_time": max(plan_t) if plan_t else None,
                "min_clearance": min((r["min_clearance"] for r in rs
                                      if r["min_clearance"] is not None), default=None),
            }
        )  # fmt: skip
    return out


def verdict(summary: list[dict]) -> str:
    """Whether contour is no worse than global in median arrival and in median length."""
    by = {s["strategy"]: s for s in summary}
    c, g = by.get("contour"), by.get("global")
    if not c or not g or c["median_arrival"] is None or g["median_arrival"] is None:
        return "–"
    ok = c["median_arrival"] <= g["median_arrival"] + 1e-9
    ok &= c["median_length"] <= g["median_length"] + 1e-9
    return "yes" if ok else "**no**"


def _median(xs: list[float]) -> float | None:
    return statistics.median(xs) if xs else None


def _quantile(xs: list[float], q: float) -> float | None:
    if not xs:
        return None
    xs = sorted(xs)
    return xs[min(len(xs) - 1, math.ceil(q * len(xs)) - 1)]


def _fmt(x, spec=".1f") -> str:
    return "–" if x is None else format(x, spec)


GROUP_TEXT = {
    "random": "static world of `paper_dynamic.yaml` (500 x 500 cm, robot SR 28.5 cm at 20 cm/s, "
    "sensor range 100 cm), 1-4 random obstacles at constant velocity",
    "turning": f"the same, the obstacles turning at random ({TURN_RATE} turns/s, "
    f"{TURN_DEG:g} degrees standard deviation): the prediction is wrong after every turn",
    "map": "office occupancy-grid map of `office_people.yaml` (30 x 20 m, SR 0.25 m at 0.5 m/s, "
    "sensor range 3 m), 1-4 random obstacles at constant velocity",
}


def strategy_table(summary: list[dict]) -> str:
    """One family's table: a line per strategy (:func:`summarise`)."""
    from rrtpso_ompl.harness.report import markdown_table

    header = ["strategy", "runs", "success", "collision runs (of those with a free motion)",
              "median arrival s", "median length", "over lower bound %", "over clairvoyant %",
              "replans/run", "waits chosen", "fallbacks", "planning s median / p90 / max",
              "min clearance"]  # fmt: skip
    return markdown_table(header, [
        [s["strategy"], s["runs"], s["success"],
         f"{s['collision_runs']} ({s['collision_runs_feasible']} of {s['feasible']})",
         _fmt(s["median_arrival"]), _fmt(s["median_length"], ".2f"), _fmt(s["median_over_lb"]),
         _fmt(s["median_over_cw"]), f"{s['mean_replans']:.2f}", s["waits"], s["fallbacks"],
         f"{_fmt(s['median_plan_time'], '.3f')} / {_fmt(s['p90_plan_time'], '.3f')} / "
         f"{_fmt(s['max_plan_time'], '.3f')}", _fmt(s["min_clearance"], ".2f")]
        for s in summary
    ])  # fmt: skip


def report(rows: list[dict], groups: dict[str, list[Case]], args, wall: float) -> str:
    lines = [
        "# Dynamic benchmark: replanning strategies and a DWA among moving obstacles",
        "",
        f"Generated by `{' '.join(['python benchmarks/dynamic.py', *map(shlex.quote, args.argv)])}`"
        f" on {platform.platform()}, Python {platform.python_version()}, "
        f"{args.jobs} processes, {wall / 60:.1f} min.",
        "",
        "Every case starts from one static RRTstarPSO path (1 s); `contour`, `global` and `none` "
        "drive it, `dwa` (a DWB-like local planner) follows a guide path planned with clearance "
        f"for it; the DWA's parameters were tuned on {DWA_TUNING}, none of them reported here. "
        "Replanning budget "
        f"{args.replan_time} s of simulated time per replan (contour: both detours and the wait "
        "search; global: one RRT* plan). Arrival is the simulated time to the goal, length the "
        "distance driven, both medians over the runs that reached the goal. The lower bound is "
        "the static exact optimum (`rrtpso optimum`) driven at full speed with no turning time: "
        "no strategy can arrive earlier. The clairvoyant baseline knows every obstacle's future, "
        "waits at the start for the least multiple of the control period after which driving "
        "the static optimum (stop-and-turn) never touches an obstacle, checked exactly: it is "
        "achievable, so it also proves that a collision-free motion exists (not computed when "
        "obstacles turn at random). Planning time is measured wall-clock per replan.",
        "",
    ]
    from rrtpso_ompl.harness.report import markdown_table

    verdicts = []
    for group, cases in groups.items():
        if not cases:
            continue
        summary = summarise(rows, group)
        text = GROUP_TEXT.get(group, f"named scenario `problems/dynamic/{group}.yaml`")
        seeds = f"seeds {cases[0].seed}..{cases[-1].seed}"
        verdicts.append((group, len(cases), verdict(summary), summary))
        lines += [f"## {group}: {len(cases)} cases ({seeds})", "", text + ".", "",
                  strategy_table(summary), ""]  # fmt: skip
    target = []
    for group, n, ok, summary in verdicts:
        by = {s["strategy"]: s for s in summary}
        c, g = by.get("contour", {}), by.get("global", {})
        arrival = f"{_fmt(c.get('median_arrival'))} / {_fmt(g.get('median_arrival'))}"
        length = f"{_fmt(c.get('median_length'), '.2f')} / {_fmt(g.get('median_length'), '.2f')}"
        target.append([group, n, arrival, length, ok])
    lines += [
        "## Target: contour no worse than global",
        "",
        "Median arrival and median driven length of `contour` against `global`, per family and per "
        "named scenario.",
        "",
        markdown_table(["cases", "n", "contour arrival / global arrival s",
                        "contour length / global length", "contour no worse"], target),
    ]  # fmt: skip
    lines += dwa_target(verdicts, rows)
    bad = [r for r in rows if r.get("strategy") in ("contour", "global")
           and not r.get("success", False)]  # fmt: skip
    lines += ["", "Runs of the replanning strategies that did not succeed:", ""]
    if not bad:
        lines.append("none.")
    for r in bad:
        lines.append(
            f"- {r['group']} seed {r['seed']} ({r['strategy']}): reached {r.get('reached_goal')}, "
            f"collisions {r.get('collisions')}, min clearance {_fmt(r.get('min_clearance'))}, "
            f"clairvoyant {_fmt(r.get('clairvoyant_time'))} s, fallbacks {r.get('fallbacks')} "
            f"{r.get('error', '')}"
        )
    return "\n".join(lines) + "\n"


def dwa_target(verdicts: list, rows: list[dict]) -> list[str]:
    """The DWA's success per family and named scenario against its target, and its failed
    runs with what the clairvoyant baseline says about them."""
    from rrtpso_ompl.harness.report import markdown_table

    lines = [
        "",
        f"## Target: the DWA a competent peer (success >= {DWA_TARGET:.0%} on random and map)",
        "",
        "Success: the goal reached within the time limit (4 times the guide path's duration at "
        "full speed plus 60 s) without a collision.",
        "",
    ]
    table = []
    for group, _n, _, summary in verdicts:
        d = {s["strategy"]: s for s in summary}.get("dwa")
        if not d:
            continue
        share = d["success"] / d["runs"]
        met = ("yes" if share >= DWA_TARGET else "**no**") if group in ("random", "map") else "–"
        table.append([group, d["runs"], d["success"], d["collision_runs"], f"{100 * share:.0f} %",
                      met])  # fmt: skip
    lines.append(markdown_table(["family or scenario", "n", "DWA success", "collision runs",
                                 "share", "target met"], table))  # fmt: skip
    failed = [r for r in rows if r.get("strategy") == "dwa" and not r.get("success", False)]
    lines += ["", "Runs of the DWA that did not succeed:", ""]
    if not failed:
        lines.append("none.")
    for r in failed:
        free = r.get("clairvoyant_time")
        lines.append(
            f"- {r['group']} seed {r['seed']}: reached {r.get('reached_goal')}, collisions "
            f"{r.get('collisions')}, min clearance {_fmt(r.get('min_clearance'))}, "
            f"arrival {_fmt(r.get('total_time'))} s, status {r.get('status', '–')}; "
            + ("a collision-free motion exists (clairvoyant arrival " + _fmt(free) + " s)"
               if free else "the obstacles turn at random (no clairvoyant baseline)"
               if r.get("obstacles_turn") else "no collision-free motion is known")
            + f" {r.get('error', '')}".rstrip()
        )  # fmt: skip
    return lines


def figure(rows: list[dict], path: Path) -> None:
    """Box plots of arrival over the lower bound per strategy, for each family."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    families = [g for g in ("random", "turning", "map") if any(r["group"] == g for r in rows)]
    if not families:
        return
    fig, axes = plt.subplots(1, len(families), figsize=(4.2 * len(families), 3.6), squeeze=False)
    names = [s for s, _ in STRATEGIES]
    for ax, group in zip(axes[0], families, strict=True):
        data = []
        for strategy in names:
            rs = [r for r in rows if r["group"] == group and r["strategy"] == strategy
                  and r.get("reached_goal") and r.get("lower_bound_time")]  # fmt: skip
            data.append([100 * (r["total_time"] / r["lower_bound_time"] - 1) for r in rs])
        ax.boxplot(data, whis=(5, 95), showfliers=False)
        ax.set_xticks(range(1, len(names) + 1), names)
        ax.set_title(f"{group} ({len(data[0])} cases)")
        ax.set_ylabel("arrival over the lower bound, %")
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle("Arrival time over the static optimum at full speed, runs that reached the goal "
                 "(whiskers: 5-95 %)")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cases(args) -> dict[str, list[Case]]:
    """The benchmark's cases by group (family or named scenario)."""
    out: dict[str, list[Case]] = {
        "random": [Case("random", str(BASE), args.first + i, True) for i in range(args.scenarios)],
        "turning": [Case("turning", str(BASE), args.first_turning + i, True, TURN_RATE)
                    for i in range(args.turning)],
        "map": [Case("map", str(MAP_BASE), args.first_map + i, True) for i in range(args.map)],
    }  # fmt: skip
    for path in sorted(DYNAMIC.glob("*.yaml")):
        out[path.stem] = [Case(path.stem, str(path), 1 + i, False)
                          for i in range(args.named_seeds)]  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", type=int, default=100, help="random cases")
    ap.add_argument("--first", type=int, default=1, help="first seed of the random cases")
    ap.add_argument("--turning", type=int, default=50, help="cases with turning obstacles")
    ap.add_argument("--first-turning", type=int, default=1001, help="first seed of turning")
    ap.add_argument("--map", type=int, default=50, help="random cases on the office map")
    ap.add_argument("--first-map", type=int, default=2001, help="first seed of the map cases")
    ap.add_argument("--named-seeds", type=int, default=5, help="seeds per named scenario")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--strategies", default=",".join(s for s, _ in STRATEGIES),
                    help="comma-separated strategies to run (tuning runs one)")  # fmt: skip
    ap.add_argument("--replan-time", type=float, default=0.1)
    ap.add_argument("--initial-time", type=float, default=1.0)
    ap.add_argument("--out", default=str(REPO / "docs" / "dynamic-benchmark.md"))
    ap.add_argument("--figure", default=str(REPO / "docs" / "img" / "dynamic-benchmark.png"),
                    help="box plots of arrival time (empty: none)")  # fmt: skip
    args = ap.parse_args(argv)
    args.argv = list(argv if argv is not None else sys.argv[1:])
    known = [s for s, _ in STRATEGIES]
    picked = tuple(s.strip() for s in args.strategies.split(",") if s.strip())
    if not picked or any(s not in known for s in picked):
        ap.error(f"--strategies: a comma-separated subset of {', '.join(known)}")

    from tqdm import tqdm

    from rrtpso_ompl.groundtruth.optimum import shortest_path
    from rrtpso_ompl.harness.workers import ChildFailure, run_local
    from rrtpso_ompl.model import World
    from rrtpso_ompl.model.problem import load_problem

    groups = cases(args)
    todo = [c for cs in groups.values() for c in cs]
    # One exact optimum per static world, the reference of every case built on it.
    optimum: dict[str, list] = {}
    for base in sorted({c.base for c in todo}):
        problem = load_problem(base)
        best = shortest_path(problem)
        optimum[base] = best.valid_polyline(World.from_problem(problem)).tolist()
    rows: list[dict] = []
    t0 = time.perf_counter()
    # One case per process, forked from a warm worker (imports done once per worker): OMPL
    # takes each case's seed, and a case that crashes is its error rows.
    jobs = [(c, args.replan_time, args.initial_time, optimum[c.base], picked) for c in todo]
    results = run_local(jobs, _run, args.jobs, warm=_warm, timeout_of=_case_timeout)
    for job, result in tqdm(results, total=len(jobs), file=sys.stderr,
                            disable=not sys.stderr.isatty(), desc="cases"):  # fmt: skip
        if isinstance(result, ChildFailure):
            case = job[0]
            head = {"group": case.group, "seed": case.seed, "error": result.message}
            rows.extend({**head, "strategy": s} for s in picked)
        else:
            rows.extend(result)
    wall = time.perf_counter() - t0
    rows.sort(key=lambda r: (r["group"], r["seed"], r["strategy"]))
    out = Path(args.out)
    out.with_suffix(".jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    out.write_text(report(rows, groups, args, wall))
    if args.figure:
        figure(rows, Path(args.figure))
    print(out.read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
