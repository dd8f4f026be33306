"""The ``rrtpso`` command line: a thin layer over :mod:`rrtpso_ompl.solve` and the registry.

Exit status: 0 solved, 1 no valid path within the time limit, 2 bad input or usage (one message on
stderr, no traceback, nothing written).
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["main"]

EXIT_SOLVED, EXIT_UNSOLVED, EXIT_BAD_INPUT = 0, 1, 2


class InputError(Exception):
    """Bad input found before planning: reported as ``rrtpso: error: <message>``, exit 2."""


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rrtpso",
        description="Plan 2-D paths for wheeled robots with RRT*PSO and OMPL's planners.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser(
        "solve",
        help="solve one problem file",
        description="Solve one problem file and report the path.",
    )
    p.add_argument("problem", help="problem file (YAML, see docs/problem-format.md)")
    p.add_argument(
        "--planner",
        help="planner name (default: the file's planner.type, else "
        "RRTstarPSO); see 'rrtpso planners'",
    )
    p.add_argument(
        "--time",
        type=float,
        metavar="SECONDS",
        help="time limit (default: the file's planner.time_limit, else 1.0)",
    )
    p.add_argument("--seed", type=int, help="random seed (default: the file's planner.seed)")
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="planner parameter, repeatable (e.g. --param swarm_size=50)",
    )
    p.add_argument("--json", metavar="OUT", help="write the result as JSON")
    p.add_argument(
        "--plot", metavar="OUT.png", help="draw the world, the paths and the PSO best-cost curve"
    )
    p.add_argument(
        "--simplify",
        action="store_true",
        help="run OMPL's path simplifier on the result within the time limit",
    )
    p.add_argument(
        "--trajectory",
        metavar="OUT.csv",
        help="write the wheel commands every robot.sample_time: "
        "t,x,y,theta,v,omega,v_right,v_left,omega_right,omega_left",
    )
    p.add_argument(
        "--plot-velocities",
        metavar="OUT.png",
        help="draw v and omega (paper Fig. 17) and the wheel speeds (Fig. 18)",
    )
    p.add_argument(
        "--profile",
        choices=("auto", "constant", "limits"),
        default="auto",
        help="velocity profile: the paper's constant robot.speed, or within the robot's limits "
        "from rest to rest (auto: limits when any limit is given)",
    )
    p.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0,
        help="show OMPL's Info (-v) and Debug (-vv) messages",
    )
    p.set_defaults(func=_cmd_solve)

    m = sub.add_parser(
        "simulate",
        help="drive among moving obstacles with collision prediction and replanning",
        description="Drive the robot from start to goal among the problem's moving obstacles: it "
        "senses them within robot.sensor_range, predicts collisions and replans contour detours "
        "(docs/dynamic.md). Exit status 0 when the goal is reached without a collision, else 1.",
    )
    m.add_argument("problem", help="problem file with moving_obstacles")
    m.add_argument("--json", metavar="OUT", help="write the simulation as JSON")
    m.add_argument("--gif", metavar="OUT.gif", help="write an animation")
    m.add_argument("--plot", metavar="OUT.png", help="draw the driven path (paper Fig. 24)")
    m.add_argument("--seed", type=int, help="random seed (default: the file's planner.seed)")
    m.add_argument(
        "--planner",
        help="planner of the static path and the detours (default: the file's planner.type, "
        "else RRTstarPSO)",
    )
    m.add_argument(
        "--time",
        type=float,
        metavar="SECONDS",
        help="budget of the initial static path (default: the file's planner.time_limit, else 1.0)",
    )
    m.add_argument(
        "--replan-time",
        type=float,
        default=0.5,
        metavar="SECONDS",
        help="simulated time one replan takes, split between the two detours (default 0.5)",
    )
    m.add_argument(
        "--strategy",
        choices=("contour", "global", "none"),
        default="contour",
        help="contour: detours up and down around the collision zone (the paper); global: replan "
        "the whole remaining path; none: never replan (default: contour)",
    )
    m.add_argument(
        "--heading-changes",
        type=float,
        default=0.0,
        metavar="RATE",
        help="random heading changes per obstacle per second (default 0: constant velocity)",
    )
    m.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="planner parameter, repeatable",
    )
    m.add_argument("-v", "--verbose", action="count", default=0, help="show OMPL's messages")
    m.set_defaults(func=_cmd_simulate)

    _add_batch_parser(sub)
    _add_generate_parser(sub)
    _add_optimum_parser(sub)
    _add_bench_parser(sub)

    q = sub.add_parser(
        "planners",
        help="list the planners and their parameters",
        description="List the registered planners and their parameters.",
    )
    q.add_argument("name", nargs="?", help="show only this planner")
    q.add_argument("--json", action="store_true", help="machine-readable output")
    q.set_defaults(func=_cmd_planners)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    logging.basicConfig(
        level=logging.INFO if getattr(args, "verbose", 0) else logging.WARNING,
        format="%(levelname)s: %(name)s: %(message)s",
    )
    try:
        return args.func(args)
    except InputError as exc:
        print(f"rrtpso: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("rrtpso: interrupted", file=sys.stderr)
        return 130


# --------------------------------------------------------------------------------------------
def _cmd_solve(args: argparse.Namespace) -> int:
    from ..model.problem import ProblemError, load_problem
    from ..ompl_setup.context import set_ompl_log_level
    from ..planners.registry import UnknownPlannerError, default_registry
    from ..planners.solve import DEFAULT_PLANNER

    set_ompl_log_level(args.verbose)
    try:
        problem = load_problem(args.problem)
    except ProblemError as exc:
        raise InputError(str(exc)) from None
    src = args.problem
    registry = default_registry()

    # Everything is validated here, before planning, so that each error names its origin.
    name = args.planner or problem.planner.type or DEFAULT_PLANNER
    origin = "--planner" if args.planner else ("planner.type" if problem.planner.type else "")
    try:
        entry = registry.get(name)
    except UnknownPlannerError as exc:
        raise InputError(f"{src}: {origin or 'planner'}: {exc}") from None
    if args.time is not None and not (args.time > 0 and math.isfinite(args.time)):
        raise InputError(f"{src}: --time: must be a positive number of seconds, got {args.time}")
    cli_params = _parse_params(args.param, src)
    for key, value in problem.planner.params.items():
        _check_param(entry, key, value, f"{src}: planner.params.{key}")
    for key, value in cli_params.items():
        _check_param(entry, key, value, f"{src}: --param {key}")
    try:
        entry.validate({**problem.planner.params, **cli_params})
    except ValueError as exc:
        raise InputError(f"{src}: planner parameters: {exc}") from None
    _check_output(args.json, "--json")
    _check_output(args.plot, "--plot", image=True)
    _check_output(args.trajectory, "--trajectory")
    _check_output(args.plot_velocities, "--plot-velocities", image=True)
    wants_motion = args.trajectory or args.plot_velocities
    if wants_motion:
        from ..kinematics.core import REQUIRED_ROBOT_KEYS

        flag = "--trajectory" if args.trajectory else "--plot-velocities"
        for key in REQUIRED_ROBOT_KEYS:
            if getattr(problem.robot, key) is None:
                raise InputError(f"{src}: robot.{key}: required for {flag}")

    from ..planners.solve import solve

    result = solve(problem, name, args.time, args.seed, cli_params, simplify=args.simplify)
    motion = None
    if wants_motion and result.solved:
        from ..kinematics.core import drive
        from ..model.world import World

        motion = drive(result.path, World.from_problem(problem), problem.robot, args.profile)
    if args.plot:
        from ..plotting import plot_solution, save_figure

        curve = motion.curve if motion else None
        save_figure(plot_solution(problem, result, curve), args.plot)
    if motion and args.plot_velocities:
        from ..plotting import plot_velocities, save_figure

        save_figure(plot_velocities(motion.trajectory, problem.units), args.plot_velocities)
    if motion and args.trajectory:
        motion.trajectory.write_csv(args.trajectory)
    if args.json:
        from ..outputs import write_json_atomic

        data = result.to_dict()
        if motion:
            data["kinematics"] = motion.summary()
        write_json_atomic(data, args.json)
    length = f"{result.length:.3f}" if result.length is not None else "-"
    print(
        f"{problem.name}: {result.planner} {result.status} length={length} time={result.time:.3f}s",
        file=sys.stderr,
    )
    return EXIT_SOLVED if result.solved else EXIT_UNSOLVED


def _cmd_simulate(args: argparse.Namespace) -> int:
    from ..model.problem import ProblemError, load_problem
    from ..ompl_setup.context import set_ompl_log_level
    from ..planners.registry import UnknownPlannerError, default_registry
    from ..planners.solve import DEFAULT_PLANNER

    set_ompl_log_level(args.verbose)
    try:
        problem = load_problem(args.problem)
    except ProblemError as exc:
        raise InputError(str(exc)) from None
    src = args.problem
    for key in ("speed", "sample_time", "sensor_range"):
        if getattr(problem.robot, key) is None:
            raise InputError(f"{src}: robot.{key}: required for simulate")
    name = args.planner or problem.planner.type or DEFAULT_PLANNER
    try:
        entry = default_registry().get(name)
    except UnknownPlannerError as exc:
        origin = "--planner" if args.planner else "planner.type"
        raise InputError(f"{src}: {origin}: {exc}") from None
    for flag, value in (("--time", args.time), ("--replan-time", args.replan_time)):
        if value is not None and not (value > 0 and math.isfinite(value)):
            raise InputError(f"{src}: {flag}: must be a positive number of seconds, got {value}")
    if not (args.heading_changes >= 0 and math.isfinite(args.heading_changes)):
        raise InputError(f"{src}: --heading-changes: must be >= 0, got {args.heading_changes}")
    cli_params = _parse_params(args.param, src)
    for key, value in problem.planner.params.items():
        _check_param(entry, key, value, f"{src}: planner.params.{key}")
    for key, value in cli_params.items():
        _check_param(entry, key, value, f"{src}: --param {key}")
    params = {**problem.planner.params, **cli_params}
    try:
        entry.validate(params)
    except ValueError as exc:
        raise InputError(f"{src}: planner parameters: {exc}") from None
    _check_output(args.json, "--json")
    _check_output(args.plot, "--plot", image=True)
    _check_output(args.gif, "--gif")
    if args.gif and Path(args.gif).suffix.lower() != ".gif":
        raise InputError(f"--gif: '{args.gif}' must end in .gif")

    from ..dynamic.simulation import DynamicOptions, simulate

    options = DynamicOptions(
        planner=entry.name,
        strategy=args.strategy,
        replan_time=args.replan_time,
        initial_time=args.time,
        heading_changes=args.heading_changes,
        params=params,
    )
    seed = args.seed if args.seed is not None else problem.planner.seed
    with _progress_bar("simulating", unit="s") as bar:

        def progress(t: float, t_end: float) -> None:
            bar.total = round(t_end, 1)
            bar.n = round(t, 1)
            bar.refresh()

        sim = simulate(problem, options, seed=seed, progress=progress)
    if args.plot:
        from ..plotting import plot_simulation, save_figure

        save_figure(plot_simulation(problem, sim), args.plot)
    if args.gif and sim.motion is not None:
        from ..plotting import animate_simulation

        animate_simulation(problem, sim, args.gif)
    if args.json:
        from ..outputs import write_json_atomic

        write_json_atomic(sim.to_dict(), args.json)
    verdict = "reached the goal" if sim.reached_goal else f"did not reach the goal ({sim.status})"
    print(
        f"{problem.name}: {verdict}, {sim.collisions} collisions, {len(sim.replans)} replans, "
        f"time {sim.total_time:.1f}s, length {sim.path_length:.1f}",
        file=sys.stderr,
    )
    return EXIT_SOLVED if sim.success else EXIT_UNSOLVED


def _progress_bar(desc: str, **kwargs: Any) -> Any:
    """A tqdm bar on stderr, silent when stderr is not a terminal (logs, CI, pipes)."""
    from tqdm import tqdm

    return tqdm(desc=desc, file=sys.stderr, disable=not sys.stderr.isatty(), leave=False, **kwargs)


class _RunProgress:
    """The progress bar of a batch or a bench: solved / unsolved / error counts per finished row."""

    def __init__(self, desc: str, noun: str) -> None:
        self.noun = noun
        self.counts = {"solved": 0, "unsolved": 0, "error": 0}
        self._bar = _progress_bar(desc, unit="run")

    def __enter__(self) -> _RunProgress:
        self._bar.__enter__()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._bar.__exit__(*exc)

    def started(self, n: int, skipped: int) -> None:
        self._bar.total = n
        self._bar.refresh()
        if skipped:
            print(f"rrtpso: resuming: {skipped} {self.noun} already done", file=sys.stderr)

    def row(self, row: dict[str, Any]) -> None:
        kind = "error" if row.get("error") else ("solved" if row["solved"] else "unsolved")
        self.counts[kind] += 1
        self._bar.set_postfix(self.counts, refresh=False)
        self._bar.update(1)


def _add_batch_parser(sub: Any) -> None:
    b = sub.add_parser(
        "batch",
        help="solve many problem files in parallel, streaming JSON lines",
        description="Solve every problem file x planner x run in its own process and stream one "
        "JSON row per run to --out as it finishes. A bad file becomes an error row and the batch "
        "goes on; exit status 1 when any row is unsolved or an error, 130 when interrupted (the "
        "file stays valid: continue it with --resume).",
    )
    b.add_argument("inputs", nargs="+", metavar="FILE|DIR|GLOB", help="problem files")
    b.add_argument(
        "--planner",
        action="append",
        metavar="NAME[,NAME...]",
        help="planner(s), repeatable or comma-separated (default: RRTstarPSO)",
    )
    b.add_argument("--time", type=float, metavar="SECONDS", help="time limit per run (default: "
                   "each file's planner.time_limit, else 1.0)")  # fmt: skip
    b.add_argument("--runs", type=int, default=1, help="runs per problem and planner (default 1)")
    b.add_argument("--out", required=True, metavar="OUT.jsonl", help="results, one JSON per line")
    _add_run_options(b, "the rows already in --out")
    b.add_argument("--simplify", action="store_true", help="run OMPL's simplifier after each run")
    b.add_argument("--no-path", action="store_true", help="leave the paths out of the rows")
    b.set_defaults(func=_cmd_batch)


def _add_run_options(p: argparse.ArgumentParser, kept: str) -> None:
    """The options ``batch`` and ``bench`` share: seeds, parallelism, resuming, executors."""
    p.add_argument("--seed", type=int, default=1, help="seed of run 0; run r uses seed + r")
    p.add_argument("--jobs", type=int, default=1, help="parallel worker processes (default 1)")
    p.add_argument("--resume", action="store_true", help=f"keep {kept}")
    p.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="planner parameter"
    )
    _add_executor_options(p)


def _add_executor_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--executor",
        choices=("local", "dask"),
        default="local",
        help="local process pool (default) or a Dask cluster (pip install 'rrtpso-ompl[dask]')",
    )
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler, e.g. tcp://host:8786")


def _planner_list(values: list[str] | None, default: str) -> list[str]:
    names = [n.strip() for v in (values or [default]) for n in v.split(",") if n.strip()]
    return list(dict.fromkeys(names))


def _check_run_options(args: argparse.Namespace) -> None:
    if args.time is not None and not (args.time > 0 and math.isfinite(args.time)):
        raise InputError(f"--time: must be a positive number of seconds, got {args.time}")
    for flag in ("runs", "jobs"):
        if getattr(args, flag) < 1:
            raise InputError(f"--{flag}: must be at least 1, got {getattr(args, flag)}")
    if args.seed is not None and args.seed < 0:
        raise InputError(f"--seed: must be >= 0, got {args.seed}")
    if args.executor == "dask":
        if not args.scheduler:
            raise InputError("--executor dask: needs --scheduler ADDRESS")
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise InputError(
                "--executor dask: Dask is not installed: pip install 'rrtpso-ompl[dask]'"
            ) from None


def _check_planners(names: list[str], items: list[str], flag: str) -> dict[str, dict[str, str]]:
    """Resolve planner names and check --param against each; returns params per planner."""
    from ..planners.registry import UnknownPlannerError, default_registry

    registry = default_registry()
    params = _parse_params(items, flag)
    out = {}
    for name in names:
        try:
            entry = registry.get(name)
        except UnknownPlannerError as exc:
            raise InputError(f"{flag}: {exc}") from None
        # A --param applies to the planners that have it.
        mine = {k: v for k, v in params.items() if any(p.name == k for p in entry.params)}
        for key, value in mine.items():
            _check_param(entry, key, value, f"--param {key}")
        out[name] = mine
    for key in params:
        if not any(key in p for p in out.values()):
            raise InputError(f"--param {key}: none of the planners {', '.join(names)} has it")
    return out


def _cmd_batch(args: argparse.Namespace) -> int:
    from ..evaluation.batch import make_tasks, run_batch

    _check_run_options(args)
    planners = _planner_list(args.planner, "RRTstarPSO")
    params = _check_planners(planners, args.param, "--planner")
    _check_output(args.out, "--out")
    tasks = make_tasks(
        args.inputs, planners, runs=args.runs, seed=args.seed, time_limit=args.time,
        params=params, simplify=args.simplify,
        keep_path=not args.no_path,
    )  # fmt: skip
    with _RunProgress("batch", "rows") as bar:
        rows = run_batch(
            tasks, args.out, jobs=args.jobs, resume=args.resume, executor=args.executor,
            scheduler=args.scheduler, progress=bar.row, on_start=bar.started,
        )  # fmt: skip
    failed = [r for r in rows if not r.get("solved")]
    for r in rows:
        if r.get("error"):
            print(f"rrtpso: {r['error']}", file=sys.stderr)
    print(
        f"batch: {len(rows)} rows, {len(rows) - len(failed)} solved, "
        f"{sum(bool(r.get('error')) for r in rows)} errors -> {args.out}",
        file=sys.stderr,
    )
    return EXIT_UNSOLVED if failed else EXIT_SOLVED


def _add_generate_parser(sub: Any) -> None:
    g = sub.add_parser(
        "generate",
        help="write a seeded random problem (circles, polygons or a maze)",
        description="Write a seeded random problem file whose start and goal are free and "
        "connected (certified by a collision-checked grid path). The same seed and options give "
        "the same file, byte for byte.",
    )
    g.add_argument("kind", choices=("circles", "polygons", "maze"))
    g.add_argument("--seed", type=int, required=True, help="seed (>= 0)")
    g.add_argument("--out", required=True, metavar="FILE.yaml", help="where to write the problem")
    g.add_argument("--size", type=float, help="side of the square workspace (default 100)")
    g.add_argument("--n", type=int, help="number of obstacles (circles 30, polygons 20)")
    g.add_argument("--cells", type=int, help="maze cells per side (default 8)")
    g.add_argument("--robot-radius", type=float, help="robot radius (0: a point robot)")
    g.add_argument("--radius-range", type=float, nargs=2, metavar=("LO", "HI"),
                   help="obstacle radii (circles) or circumradii (polygons)")  # fmt: skip
    g.add_argument("--vertices", type=int, nargs=2, metavar=("LO", "HI"),
                   help="polygon vertex counts (default 3 8)")  # fmt: skip
    g.add_argument("--gap", type=float, help="least free distance between obstacles")
    g.add_argument("--wall", type=float, help="maze wall thickness")
    g.add_argument("--algorithm", choices=("dfs", "kruskal"), help="maze algorithm")
    g.add_argument("--name", help="problem name (default: from kind and seed)")
    g.set_defaults(func=_cmd_generate)


def _cmd_generate(args: argparse.Namespace) -> int:
    from ..evaluation.generate import generate_to_file

    keys = ("size", "n", "cells", "robot_radius", "radius_range", "vertices", "gap", "wall",
            "algorithm", "name")  # fmt: skip
    options = {k: getattr(args, k) for k in keys if getattr(args, k) is not None}
    _check_output(args.out, "--out")
    try:
        path = generate_to_file(args.kind, args.seed, args.out, **options)
    except ValueError as exc:
        raise InputError(f"generate {args.kind}: {exc}") from None
    print(f"wrote {path}", file=sys.stderr)
    return EXIT_SOLVED


def _add_bench_parser(sub: Any) -> None:
    b = sub.add_parser(
        "bench",
        help="benchmark planners: OMPL benchmark logs, a Planner Arena database and a report",
        description="Run every problem x time budget x planner x run in its own process with the "
        "same collision checker, then write to --out: runs.jsonl, one OMPL benchmark log per "
        "problem and budget (*.log), benchmark.db (built by OMPL's converter; open it in Planner "
        "Arena), report.md, report.csv, ratio.png and success.png (docs/benchmarking.md). Exit "
        "status 1 when a problem file was bad, 130 when interrupted (continue with --resume).",
    )
    b.add_argument("inputs", nargs="+", metavar="FILE|DIR|GLOB", help="problem files")
    b.add_argument("--planners", required=True, metavar="A,B,...", help="planners to compare")
    b.add_argument("--runs", type=int, default=10, help="runs per problem, budget and planner")
    b.add_argument("--time", default="1", metavar="S[,S2,...]",
                   help="time budget(s) in seconds, comma-separated (default 1)")  # fmt: skip
    b.add_argument("--out", required=True, metavar="DIR", help="output folder")
    _add_run_options(b, "the runs already in DIR/runs.jsonl")
    b.set_defaults(func=_cmd_bench)


def _cmd_bench(args: argparse.Namespace) -> int:
    from ..evaluation.bench import run_bench

    try:
        times = [float(t) for t in args.time.split(",") if t.strip()]
    except ValueError:
        raise InputError(f"--time: expected seconds like 0.25,1,4, got '{args.time}'") from None
    if not times or not all(t > 0 and math.isfinite(t) for t in times):
        raise InputError(f"--time: every budget must be a positive number of seconds: {args.time}")
    args.time = None
    _check_run_options(args)
    planners = _planner_list([args.planners], "")
    if not planners:
        raise InputError("--planners: name at least one planner")
    params = _check_planners(planners, args.param, "--planners")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: '{args.out}' exists and is not a folder")
    _check_output(str(out / "report.md"), "--out")
    with _RunProgress("bench", "runs") as bar:
        result = run_bench(
            args.inputs, planners, out, runs=args.runs, times=times, seed=args.seed,
            params=params, jobs=args.jobs, executor=args.executor, scheduler=args.scheduler,
            resume=args.resume, progress=bar.row, on_start=bar.started,
            command="rrtpso " + shlex.join(args.argv),
        )  # fmt: skip
    from ..plotting import plot_bench, save_figure

    if result.summary:
        save_figure(plot_bench(result.summary, "ratio"), out / "ratio.png")
        save_figure(plot_bench(result.summary, "success"), out / "success.png")
    for e in result.errors:
        print(f"rrtpso: {e}", file=sys.stderr)
    print(
        f"bench: {len(result.rows)} runs, {len(result.logs)} experiments -> {out}/ "
        f"(benchmark.db, report.md)",
        file=sys.stderr,
    )
    return EXIT_UNSOLVED if result.errors else EXIT_SOLVED


def _add_optimum_parser(sub: Any) -> None:
    o = sub.add_parser(
        "optimum",
        help="compute the exact shortest path (the reference for path-length ratios)",
        description="Compute the exact shortest path for the problem's disc robot among its "
        "circles and polygons: a tangent graph with arcs around the inflated obstacles, searched "
        "with Dijkstra's algorithm (docs/benchmarking.md). Moving obstacles are ignored. Exit "
        "status 0 when a path exists, 1 when none does.",
    )
    o.add_argument("problem", help="problem file (YAML)")
    o.add_argument("--json", metavar="OUT", help='write {"length": ..., "path": [...], ...}')
    o.add_argument("--plot", metavar="OUT.png", help="draw the world and the shortest path")
    o.set_defaults(func=_cmd_optimum)


def _cmd_optimum(args: argparse.Namespace) -> int:
    from ..evaluation.optimum import shortest_path
    from ..model.problem import ProblemError, load_problem

    try:
        problem = load_problem(args.problem)
    except ProblemError as exc:
        raise InputError(str(exc)) from None
    _check_output(args.json, "--json")
    _check_output(args.plot, "--plot", image=True)
    result = shortest_path(problem)
    if args.plot:
        from ..plotting import plot_optimum, save_figure

        save_figure(plot_optimum(problem, result), args.plot)
    if args.json:
        from ..outputs import write_json_atomic

        write_json_atomic(result.to_dict(), args.json)
    if result.found:
        print(f"{problem.name}: optimum length={result.length:.6f}", file=sys.stderr)
        return EXIT_SOLVED
    print(f"{problem.name}: no path exists", file=sys.stderr)
    return EXIT_UNSOLVED


def _check_output(path: str | None, flag: str, image: bool = False) -> None:
    """Refuse an output that cannot be written before spending the time budget on planning."""
    if not path:
        return
    target = Path(path)
    if target.is_dir():
        raise InputError(f"{flag}: '{path}' is a directory")
    parent = target.parent
    while not parent.exists():
        parent = parent.parent  # missing folders are created when the file is written
    if not os.access(parent, os.W_OK):
        raise InputError(f"{flag}: cannot write '{path}': '{parent}' is not writable")
    if image:
        from matplotlib.figure import Figure

        kinds = Figure().canvas.get_supported_filetypes()
        suffix = target.suffix.lower().lstrip(".")
        if suffix not in kinds:
            raise InputError(
                f"{flag}: cannot draw '{path}': use one of the suffixes "
                f"{', '.join('.' + k for k in sorted(kinds))}"
            )


def _parse_params(items: list[str], src: str) -> dict[str, str]:
    params: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"{src}: --param: expected NAME=VALUE, got '{item}'")
        params[key.strip()] = value.strip()
    return params


def _check_param(entry: Any, key: str, value: Any, where: str) -> None:
    try:
        entry.param(key).convert(value)
    except KeyError as exc:
        raise InputError(f"{where}: {exc.args[0]}") from None
    except ValueError as exc:
        raise InputError(f"{where}: {exc}") from None


# --------------------------------------------------------------------------------------------
def _cmd_planners(args: argparse.Namespace) -> int:
    from ..planners.registry import UnknownPlannerError, default_registry

    registry = default_registry()
    try:
        entries = [registry.get(args.name)] if args.name else registry.entries()
    except UnknownPlannerError as exc:
        raise InputError(str(exc)) from None
    if args.json:
        rows = [
            {
                "name": e.name,
                "aliases": list(e.aliases),
                "description": e.description,
                "optimizing": e.optimizing,
                "source": e.source,
                "params": [
                    {
                        "name": p.name,
                        "type": p.type.__name__,
                        "default": p.default,
                        "unit": p.unit,
                        "range": p.range_text(),
                        "doc": p.doc,
                    }
                    for p in e.params
                ],
            }
            for e in entries
        ]
        print(json.dumps(rows, indent=2))
        return EXIT_SOLVED
    for e in entries:
        aliases = f"  (also: {', '.join(e.aliases)})" if e.aliases else ""
        print(f"{e.name}{aliases}\n    {e.description}  [{e.source}]")
        for p in e.params:
            unit = f" {p.unit}" if p.unit else ""
            print(
                f"    {p.name:<28} {p.type.__name__:<5} default {p.default!s:<8}{unit} "
                f"in {p.range_text()}"
            )
            if args.name:
                print(f"        {p.doc}")
    return EXIT_SOLVED


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("rrtpso-ompl")
    except PackageNotFoundError:
        return "unknown"


if __name__ == "__main__":
    sys.exit(main())
