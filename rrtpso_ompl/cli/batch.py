"""``rrtpso batch``: many problem files x planners x runs in parallel, streamed to JSON lines."""

from __future__ import annotations

import argparse
from typing import Any

from .common import (
    EXIT_OK,
    EXIT_UNSOLVED,
    Output,
    RunProgress,
    add_run_options,
    batch_inputs,
    check_outputs,
    check_planners,
    check_run_options,
    note,
    planner_list,
    report_errors,
    run_keywords,
)

__all__ = ["HELP", "add_parser", "run"]

#: The line of ``rrtpso --help``.
HELP = "solve many problem files in parallel, streaming JSON lines"


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    b = sub.add_parser(
        "batch",
        parents=parents,
        help=HELP,
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
    b.add_argument(
        "--time",
        type=float,
        metavar="SECONDS",
        help="time limit per run (default: each file's planner.time_limit, else 1.0)",
    )
    b.add_argument("--runs", type=int, default=1, help="runs per problem and planner (default 1)")
    b.add_argument("--out", required=True, metavar="OUT.jsonl", help="results, one JSON per line")
    add_run_options(b, "the rows already in --out")
    b.add_argument("--simplify", action="store_true", help="run OMPL's simplifier after each run")
    b.add_argument("--no-path", action="store_true", help="leave the paths out of the rows")
    b.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..harness import make_tasks, run_batch

    check_run_options(args)
    planners = planner_list(args.planner, "RRTstarPSO")
    params = check_planners(planners, args.param, "--planner")
    check_outputs([Output("--out", args.out, "results")], batch_inputs(args.inputs))
    tasks = make_tasks(
        args.inputs,
        planners,
        runs=args.runs,
        seed=args.seed,
        time_limit=args.time,
        params=params,
        simplify=args.simplify,
        keep_path=not args.no_path,
    )
    with RunProgress("batch", "rows") as bar:
        rows = run_batch(tasks, args.out, **run_keywords(args, bar))
    failed = [r for r in rows if not r.solved]
    errors = [r.error for r in rows if r.is_error]
    report_errors(errors)
    note(f"batch: {len(rows)} rows, {len(rows) - len(failed)} solved, {len(errors)} errors -> "
         f"{args.out}")  # fmt: skip
    return EXIT_UNSOLVED if failed else EXIT_OK
