"""``rrtpso bench``: benchmark planners; OMPL benchmark logs, a Planner Arena database, a report."""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path
from typing import Any

from ..errors import UsageError
from .common import (
    EXIT_OK,
    EXIT_UNSOLVED,
    Output,
    RunProgress,
    add_run_options,
    batch_inputs,
    check_outputs,
    check_planners,
    check_positive_seconds,
    check_run_options,
    note,
    planner_list,
    report_errors,
    run_keywords,
)

__all__ = ["HELP", "add_parser", "run"]

#: The line of ``rrtpso --help``.
HELP = "benchmark planners: OMPL benchmark logs, a Planner Arena database and a report"


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    b = sub.add_parser(
        "bench",
        parents=parents,
        help=HELP,
        description="Run every problem x time budget x planner x run in its own process with the "
        "same collision checker, then write to --out: runs.jsonl, one OMPL benchmark log per "
        "problem and budget (*.log), benchmark.db (built by OMPL's converter; open it in Planner "
        "Arena), report.md, report.csv, ratio.png and success.png (docs/benchmarking.md). Exit "
        "status 1 when a problem file was bad, 130 when interrupted (continue with --resume).",
    )
    b.add_argument("inputs", nargs="+", metavar="FILE|DIR|GLOB", help="problem files")
    b.add_argument("--planner", "--planners", dest="planner", action="append", required=True,
                   metavar="NAME[,NAME...]",
                   help="planners to compare, repeatable or comma-separated")  # fmt: skip
    b.add_argument("--runs", type=int, default=10, help="runs per problem, budget and planner")
    b.add_argument(
        "--time",
        default="1",
        metavar="S[,S2,...]",
        help="time budget(s) in seconds, comma-separated (default 1)",
    )
    b.add_argument("--out", required=True, metavar="DIR", help="output folder")
    add_run_options(b, "the runs already in DIR/runs.jsonl")
    b.set_defaults(func=run)


def _budgets(text: str) -> list[float]:
    try:
        times = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise UsageError(f"--time: expected seconds like 0.25,1,4, got '{text}'") from None
    if not times:
        raise UsageError(f"--time: every budget must be a positive number of seconds: {text}")
    for t in times:
        check_positive_seconds(t, "--time")
    unique = list(dict.fromkeys(times))
    for t in unique:
        if times.count(t) > 1:
            note(f"rrtpso: --time: the budget {t:g} s is given {times.count(t)} times; it is run "
                 "once")  # fmt: skip
    return unique


def run(args: argparse.Namespace) -> int:
    from ..harness import run_bench
    from ..harness.bench import OUTPUT_FILES

    times = _budgets(args.time)
    args.time = None  # checked above, one budget at a time
    check_run_options(args)
    planners = planner_list(args.planner, "")
    params = check_planners(planners, args.param, "--planner")
    out = Path(args.out)
    inputs = batch_inputs(args.inputs)
    check_outputs([Output("--out", args.out, "folder")], inputs)
    # No input may be one of the files the bench writes into the folder (which ones it may
    # replace there, run_bench decides).
    written = ["runs.jsonl", *OUTPUT_FILES]
    check_outputs([Output(f"--out ({name})", str(out / name)) for name in written], inputs,
                  own_folder=True)  # fmt: skip
    with RunProgress("bench", "runs") as bar:
        result = run_bench(
            args.inputs,
            planners,
            out,
            runs=args.runs,
            times=times,
            seed=args.seed,
            params=params,
            command="rrtpso " + shlex.join(args.argv),
            **run_keywords(args, bar),
        )
    from ..plotting import plot_bench, save_figure

    if result.summary:
        save_figure(plot_bench(result.summary, "ratio"), out / "ratio.png")
        save_figure(plot_bench(result.summary, "success"), out / "success.png")
    report_errors(result.errors)
    note(
        f"bench: {len(result.rows)} runs, {len(result.logs)} experiments -> {out}/ "
        f"(benchmark.db, report.md)",
    )
    return EXIT_UNSOLVED if result.errors else EXIT_OK
