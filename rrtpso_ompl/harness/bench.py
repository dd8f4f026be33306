"""Benchmarks in OMPL's format: every planner through the same harness, logs, database, report.

``run_bench`` solves every problem x time budget x planner x run as a batch task
(:mod:`rrtpso_ompl.harness.batch`: one fresh process per run, seeded, with the same exact
collision checker for every planner), then writes

- ``runs.jsonl``: one row per run (the batch format, with the optimum and the ratio to it);
- ``<problem>_<budget>s.log``: OMPL's benchmark log, one experiment per problem and budget
  (:mod:`rrtpso_ompl.harness.ompl_log`);
- ``benchmark.db``: the SQLite database that Planner Arena opens, built from the logs by OMPL's
  own converter;
- ``report.csv`` and ``report.md``: per problem, budget and planner, the success rate, the median
  path length over the exact optimum (:mod:`rrtpso_ompl.groundtruth.optimum`) and the median time;
- ``ratio.png`` and ``success.png`` (drawn by the command line; this module draws nothing).

How runs map to OMPL's properties, as Planner Arena expects them: each planner's stats say it
themselves (:class:`~rrtpso_ompl.planners.result.BenchmarkRun`, carried in every row), so nothing
here knows a planner by name.

- Planners whose registry entry asks for it (OMPL's own) are followed by OMPL's path simplifier,
  as in OMPL's ``Benchmark``: ``time`` is the planner's, ``solution length`` its raw path,
  ``simplified solution length`` the simplified one, ``simplification time`` the simplifier's.
- A planner spec with post-passes (``BITstar+simplify+pso``, :mod:`rrtpso_ompl.planners.post`) is
  a configuration of its own: ``solution length`` is the planner's path, ``simplified solution
  length`` the path after its post-passes and ``simplification time`` their time (all within the
  one budget), so Planner Arena shows the gain per planner.
- For RRTstarPSO the RRT* stage is the planner and the swarm the simplifier: ``simplification
  time`` is the PSO's time, ``time`` the rest of the solve (the RRT* stage and OMPL's simplifier,
  when on), so ``time + simplification time`` is the whole solve, within the budget;
  ``solution length`` is the RRT* path and ``simplified solution length`` the PSO result. The PSO
  baseline has no simplification stage.
- Planner-specific figures (RRT*'s ``iterations``, the swarm's ``pso iterations``) are further
  run properties, and every planner gets progress rows ``time, best cost``.
"""

from __future__ import annotations

import csv
import math
import re
import socket
import statistics
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from ..errors import UsageError
from ..outputs import atomic_path, make_folders, remove_folders, write_text_atomic
from ..ownership import BENCH_FILES, BENCH_LOG_MARK, RUNS_FILE, describe, is_bench_log
from .batch import Task, check_task_count, expand_inputs, make_tasks, run_batch
from .ompl_log import Experiment, PlannerRuns, build_database, write_log
from .record import RunRecord
from .report import markdown_table

__all__ = [
    "BenchResult",
    "SummaryRow",
    "bench_tasks",
    "overview_markdown",
    "read_report_csv",
    "run_bench",
    "summarise",
    "write_report",
]

#: Run properties of every planner, in log order.
RUN_PROPERTIES: list[tuple[str, str]] = [
    ("time", "REAL"),
    ("solved", "BOOLEAN"),
    ("status", "ENUM"),
    ("correct solution", "BOOLEAN"),
    ("solution length", "REAL"),
    ("simplified solution length", "REAL"),
    ("simplification time", "REAL"),
    ("total time", "REAL"),
    ("solution clearance", "REAL"),
    ("solution cost", "REAL"),
    ("length over optimum", "REAL"),
    ("seed", "INTEGER"),
]
_COMMON_NAMES = {name for name, _ in RUN_PROPERTIES}
PROGRESS_PROPERTIES: list[tuple[str, str]] = [("time", "REAL"), ("best cost", "REAL")]


def _simplified_in_benchmarks(planner: str) -> bool:
    """Whether benchmarks follow ``planner`` with OMPL's simplifier (its registry entry says); a
    spec with post-passes (``BITstar+simplify+pso``) says itself what follows the planner."""
    from ..planners.post import split_spec
    from ..planners.registry import default_registry

    name, steps = split_spec(planner)
    return not steps and default_registry().get(name).capabilities.simplify_in_benchmark


def bench_tasks(
    items: Sequence[str],
    planners: Sequence[str],
    runs: int,
    times: Sequence[float],
    seed: int = 1,
    params: Mapping[str, Mapping[str, Any]] | None = None,
    simplify: bool | None = None,
) -> list[Task]:
    """Every problem x budget x planner x run (run ``r`` seeded ``seed + r`` at every budget);
    a budget or planner named twice counts once.

    ``simplify`` None follows each planner's registry entry (OMPL's planners are simplified, as
    in OMPL's Benchmark); True or False applies to every planner.
    """
    how = _simplified_in_benchmarks if simplify is None else simplify
    times = list(dict.fromkeys(float(t) for t in times))  # a budget named twice runs once
    planners = list(dict.fromkeys(planners))
    check_task_count(runs, len(planners), len(expand_inputs(items)), len(times))
    tasks = []
    for budget in times:
        tasks += make_tasks(items, planners, runs=runs, seed=seed, time_limit=budget,
                            params=params, simplify=how, keep_path=False,
                            progress=True)  # fmt: skip
    return tasks


# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SummaryRow:
    """One line of the report: a planner on a problem at a budget.

    Lengths are in problem units, times in seconds; ratios are over the exact optimum.
    """

    problem: str
    budget: float
    planner: str
    runs: int
    solved: int
    success: float
    optimum: float | None
    median_length: float | None
    median_ratio: float | None
    q1_ratio: float | None
    q3_ratio: float | None
    best_ratio: float | None
    median_raw_ratio: float | None
    median_time: float | None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class BenchResult:
    """What :func:`run_bench` produced."""

    rows: list[RunRecord]
    summary: list[SummaryRow]
    out_dir: Path
    logs: list[Path] = field(default_factory=list)
    database: Path | None = None
    errors: list[str] = field(default_factory=list)


def run_bench(
    items: Sequence[str],
    planners: Sequence[str],
    out_dir: str | Path,
    *,
    runs: int = 10,
    times: Sequence[float] = (1.0,),
    seed: int = 1,
    params: Mapping[str, Mapping[str, Any]] | None = None,
    jobs: int = 1,
    executor: str = "local",
    scheduler: Any = None,
    resume: bool = False,
    progress: Callable[[RunRecord], None] | None = None,
    on_start: Callable[[int, int], None] | None = None,
    command: str | None = None,
    simplify: bool | None = None,
    overwrite: bool = False,
    notice: Callable[[str], None] | None = None,
) -> BenchResult:
    """Run a benchmark and write its results to ``out_dir`` (see the module docstring).

    Parameters
    ----------
    items : sequence of str
        Problem files, directories or glob patterns.
    planners : sequence of str
        Registered planner names.
    out_dir : path
        Output folder (created).
    runs : int
        Runs per problem, budget and planner.
    times : sequence of float
        Time budgets, seconds; one experiment per problem and budget.
    seed, params, jobs, executor, scheduler, resume, overwrite, progress, on_start, notice
        As for :func:`~rrtpso_ompl.harness.run_batch` and
        :func:`~rrtpso_ompl.harness.make_tasks` (``resume`` and ``overwrite`` apply to the
        folder: without either, one that holds an earlier bench is refused).
    command : str, optional
        The command line that ran the benchmark, quoted at the top of ``report.md``.
    simplify : bool, optional
        Follow every planner with OMPL's simplifier (True), none (False, e.g. the paper's
        Table 3 of raw paths), or as its registry entry says (None).

    Returns
    -------
    BenchResult

    Raises
    ------
    UsageError
        When the folder holds files of this bench's names that no bench wrote, another bench is
        writing it, or it holds an earlier bench and neither ``resume`` nor ``overwrite`` is given.
    """
    planners = list(dict.fromkeys(planners))  # one block per planner in the logs
    tasks = bench_tasks(items, planners, runs, times, seed, params, simplify)  # checked first
    out = Path(out_dir)
    batch = dict(jobs=jobs, resume=resume, overwrite=overwrite, executor=executor, notice=notice,
                 scheduler=scheduler, progress=progress, on_start=on_start)  # fmt: skip
    return _write_outputs(_run_in_folder(tasks, out, batch), out, planners, runs, seed, command)


def _run_in_folder(tasks: list[Task], out: Path, batch: dict[str, Any]) -> list[RunRecord]:
    """Run ``tasks`` into ``out/runs.jsonl`` (``batch``: :func:`run_batch`'s keywords) after
    checking the folder; a folder made for a bench that wrote nothing is removed again."""
    _check_out_dir(out)
    made = make_folders(out)
    try:
        return run_batch(tasks, out / RUNS_FILE, **batch)
    except BaseException:
        remove_folders(made)
        raise


def _write_outputs(
    rows: list[RunRecord],
    out: Path,
    planners: Sequence[str],
    runs: int,
    seed: int,
    command: str | None,
) -> BenchResult:
    """Write the bench's logs (replacing an earlier bench's), database and report from its
    rows."""
    errors = sorted({r.error for r in rows if r.error})
    good = [r for r in rows if not r.is_error]
    experiments = to_experiments(good, planners, runs, seed)
    for stale in _our_logs(out):  # from an earlier bench into the same folder
        stale.unlink()
    logs = [write_log(e, _free_log_name(out, e.name)) for e in experiments]
    database = build_database(logs, out / "benchmark.db") if logs else None
    summary = summarise(good, planners)
    write_report(summary, out, errors=errors, command=command)
    return BenchResult(rows, summary, out, logs, database, errors)


#: The files a bench writes into its folder besides runs.jsonl and the logs.
OUTPUT_FILES = BENCH_FILES
#: The line of a log's setup block that says this harness wrote it.
_HARNESS = BENCH_LOG_MARK


def _check_out_dir(out: Path) -> None:
    """Refuse a folder whose output files were not written by a bench (no runs.jsonl), or one
    of whose output files is a results file (a batch's, named like a bench's file): the bench
    would replace it at the end."""
    for name in OUTPUT_FILES:
        owned = describe(out / name)
        if owned is not None and owned.kind in ("results", "locked"):
            raise UsageError(f"--out {out}: its {name} is {owned.what}; a bench would replace "
                             "it: choose another folder")  # fmt: skip
    if (out / RUNS_FILE).exists():
        return  # an earlier bench: run_batch decides (resume, overwrite, or refuse)
    foreign = [name for name in OUTPUT_FILES if (out / name).exists()]
    if foreign:
        raise UsageError(
            f"--out {out}: the folder holds {', '.join(foreign)} but no runs.jsonl, so no rrtpso "
            "bench wrote them; they are left as they are: choose an empty or new folder"
        )


def _is_our_log(path: Path) -> bool:
    return is_bench_log(path)


def _our_logs(out: Path) -> list[Path]:
    """The OMPL logs an earlier bench wrote into ``out`` (any other ``.log`` is left alone)."""
    return [p for p in out.glob("*.log") if p.is_file() and _is_our_log(p)]


def _free_log_name(out: Path, name: str) -> Path:
    """``out/<name>.log``, or ``<name>_2.log`` ... when a file not written by a bench has it."""
    path = out / f"{name}.log"
    k = 2
    while path.exists() and not _is_our_log(path):
        path = out / f"{name}_{k}.log"
        k += 1
    return path


# ----------------------------------------------------------------------------------------------
# Rows -> OMPL experiments
# ----------------------------------------------------------------------------------------------
def run_properties(row: RunRecord) -> dict[str, Any]:
    """One batch row as OMPL run properties: the planner's own figures (its ``benchmark`` run),
    the checks of the harness and the ratio to the optimum."""
    run = row.benchmark_run
    solved = bool(row.solved)
    final = row.length if solved else None
    has_path = row.status in ("exact", "approximate")
    optimum = row.optimum
    return {
        "time": run.time,
        "solved": solved,
        "status": row.ompl_status or "Unknown status",
        "correct solution": bool(row.valid),
        "solution length": run.solution_length if has_path else None,
        "simplified solution length": run.simplified_length if solved else None,
        "simplification time": run.simplification_time,
        "total time": run.total_time,
        "solution clearance": row.clearance if solved else None,
        "solution cost": row.cost if solved else None,
        "length over optimum": final / optimum if final is not None and optimum else None,
        "seed": row.seed,
        **{name: value for name, (_, value) in run.properties.items()},
    }


def _planner_properties(rows: Iterable[RunRecord]) -> list[tuple[str, str]]:
    """The run properties of one planner's block: the common ones, then its own (typed)."""
    own: dict[str, str] = {}
    for r in rows:
        for name, (ptype, _) in r.benchmark_run.properties.items():
            own.setdefault(name, ptype)
    return RUN_PROPERTIES + [(n, own[n]) for n in sorted(own) if n not in _COMMON_NAMES]


#: Longest problem part of an experiment's name (ASCII): its log file's name, with the budget, a
#: ``_2`` suffix and ``.log``, stays within the 255 bytes file systems allow.
_NAME_CHARS = 200


def _experiment_name(problem: str, budget: float) -> str:
    word = re.sub(r"[^A-Za-z0-9_.-]+", "_", problem or "problem")[:_NAME_CHARS]
    return f"{word}_{budget:g}s"


def to_experiments(
    rows: Iterable[RunRecord],
    planners: Sequence[str],
    runs: int,
    seed: int,
) -> list[Experiment]:
    """Group rows (not error rows) into one experiment per problem and budget."""
    groups: dict[tuple[str, float], list[RunRecord]] = defaultdict(list)
    for r in rows:  # one problem file, however its rows spelled it (the run's identity)
        groups[(r.key.source, r.effective_budget)].append(r)
    names: dict[str, int] = {}
    experiments = []
    host = re.sub(r"\s+", "_", socket.gethostname()) or "localhost"
    for (_, budget), group in sorted(groups.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        file = group[0].file  # as the command line named it
        name = _experiment_name(group[0].problem or Path(file).stem, budget)
        names[name] = names.get(name, 0) + 1
        if names[name] > 1:  # two files with the same problem name
            name = f"{name}_{names[name]}"
        blocks = []
        for planner in planners:
            mine = sorted((r for r in group if r.planner == planner), key=lambda r: r.seed)
            if not mine:
                continue
            # The configuration, not the run: the seed and the budget are run/experiment data.
            settings = {
                k: v
                for k, v in mine[0].params.items()
                if v is not None and k not in ("seed", "budget")
            }
            blocks.append(
                PlannerRuns(
                    name=planner,
                    settings=settings,
                    run_properties=_planner_properties(mine),
                    runs=[run_properties(r) for r in mine],
                    progress_properties=PROGRESS_PROPERTIES,
                    progress=[list(r.benchmark.progress if r.benchmark else []) for r in mine],
                )
            )
        optimum = group[0].optimum
        props: dict[str, object] = {"time budget": float(budget)}
        if optimum is not None:
            props["optimum"] = float(optimum)
        experiments.append(
            Experiment(
                name=name,
                planners=blocks,
                time_limit=float(budget),
                run_count=runs,
                seed=seed,
                total_time=sum(r.wall or 0.0 for r in group),
                host=host,
                setup=f"problem file: {file}\nplanners: {', '.join(planners)}\n{_HARNESS}",
                properties=props,
            )
        )
    return experiments


# ----------------------------------------------------------------------------------------------
# Report
# ----------------------------------------------------------------------------------------------
def _median(xs: list[float]) -> float | None:
    return statistics.median(xs) if xs else None


def _quartiles(xs: list[float]) -> tuple[float | None, float | None]:
    if len(xs) < 2:
        return (xs[0], xs[0]) if xs else (None, None)
    q = statistics.quantiles(xs, n=4, method="inclusive")
    return q[0], q[2]


def summarise(rows: Iterable[RunRecord], planners: Sequence[str]) -> list[SummaryRow]:
    """Per problem, budget and planner: success rate, length over optimum, time."""
    groups: dict[tuple[str, float, str], list[RunRecord]] = defaultdict(list)
    for r in rows:
        if r.is_error:
            continue
        groups[(r.problem or r.file, r.effective_budget, r.planner)].append(r)
    order = {p: i for i, p in enumerate(planners)}
    out = []
    for (problem, budget, planner), group in sorted(
        groups.items(), key=lambda kv: (kv[0][0], kv[0][1], order.get(kv[0][2], 99))
    ):
        props = [run_properties(r) for r in group]
        ok = [r for r in group if r.solved]
        optimum = group[0].optimum
        ratios = sorted(p["length over optimum"] for p in props if p["length over optimum"])
        raw = sorted(
            p["solution length"] / optimum
            for p in props
            if optimum and p["solved"] and p["solution length"] is not None
        )
        q1, q3 = _quartiles(ratios)
        out.append(
            SummaryRow(
                problem=problem,
                budget=budget,
                planner=planner,
                runs=len(group),
                solved=len(ok),
                success=len(ok) / len(group),
                optimum=optimum,
                median_length=_median([r.length for r in ok]),
                median_ratio=_median(ratios),
                q1_ratio=q1,
                q3_ratio=q3,
                best_ratio=ratios[0] if ratios else None,
                median_raw_ratio=_median(raw),
                median_time=_median([p["total time"] for p in props if p["total time"]]),
            )
        )
    return out


def read_report_csv(path: str | Path) -> list[SummaryRow]:
    """The summary back from a ``report.csv`` written by :func:`write_report`."""
    types = {"problem": str, "planner": str, "runs": int, "solved": int}
    with Path(path).open(newline="") as fh:
        return [
            SummaryRow(**{k: None if v == "" else types.get(k, float)(v) for k, v in r.items()})
            for r in csv.DictReader(fh)
        ]


def write_report(
    summary: Sequence[SummaryRow],
    out_dir: str | Path,
    *,
    errors: Sequence[str] = (),
    command: str | None = None,
) -> tuple[Path, Path]:
    """Write ``report.csv`` (every column) and ``report.md`` (one table per budget)."""
    out = Path(out_dir)
    csv_path, md_path = out / "report.csv", out / "report.md"
    fields = list(SummaryRow.__dataclass_fields__)
    with atomic_path(csv_path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for s in summary:
            w.writerow({k: "" if v is None else v for k, v in s.to_dict().items()})
    write_text_atomic(report_markdown(summary, errors=errors, command=command), md_path)
    return csv_path, md_path


def _fmt(x: float | None, spec: str = ".3f") -> str:
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def _excess(ratio: float | None) -> str:
    """A ratio over the optimum as the excess in percent: 1.0017 -> "+0.17 %"."""
    return "–" if ratio is None else f"+{100 * (ratio - 1):.2f} %"


def overview_markdown(summary: Sequence[SummaryRow]) -> str:
    """The across-problem view a reader wants first: which planner, how far from optimal.

    Three parts, each over all problems: per planner and budget, the median of the per-problem
    median excess over the optimum with the success rate over all runs and the median time; the
    same excess before simplification (``solution length`` in the log: RRTstarPSO's RRT* stage, a
    stock planner's raw path); and the cells in which the first planner is not the shortest.
    """
    planners = list(dict.fromkeys(s.planner for s in summary))
    budgets = sorted({s.budget for s in summary})
    first = planners[0] if planners else ""
    lost, ties, total = _cells_lost(summary, first, budgets)
    alone = total - len(lost) - ties
    tied = f" and ties for it in {ties}" if ties else ""
    standing = f"{first} has the shortest median path alone in {alone} of {total} problem x budget"
    standing += f" cells{tied}."
    behind = (["In the others, the shortest median path was:", "", *lost] if lost
              else [f"{first} is behind in none."])  # fmt: skip
    return "\n".join(
        [
            "## Overview",
            "",
            "Per planner and budget, over all problems: the median of each problem's median "
            "excess length over the exact optimum, the success rate over all runs, and the median "
            "of each problem's median time (planning plus simplification or PSO).",
            "",
            _overview_table(summary, planners, budgets, _final_cell),
            "",
            "The same excess before simplification (`solution length` in the log: RRTstarPSO's "
            "RRT* stage, a stock planner's raw path):",
            "",
            _overview_table(summary, planners, budgets, _raw_cell),
            "",
            standing,
            "",
            *behind,
            "",
        ]
    )


def _overview_table(
    summary: Sequence[SummaryRow],
    planners: Sequence[str],
    budgets: Sequence[float],
    cell: Callable[[list[SummaryRow]], str],
) -> str:
    """A table of planners x budgets; ``cell`` makes each cell from the summary rows (one per
    problem) of its planner and budget."""

    def pooled(planner: str, budget: float) -> list[SummaryRow]:
        return [s for s in summary if s.planner == planner and s.budget == budget]

    rows = [[p, *(cell(pooled(p, b)) for b in budgets)] for p in planners]
    return markdown_table(["planner", *(f"{b:g} s" for b in budgets)], rows)


def _final_cell(cells: list[SummaryRow]) -> str:
    """Median over problems of the median excess, success over all runs, median time."""
    runs = sum(s.runs for s in cells)
    ratio = _median([s.median_ratio for s in cells if s.median_ratio is not None])
    time = _median([s.median_time for s in cells if s.median_time is not None])
    success = sum(s.solved for s in cells) / runs if runs else 0.0
    return f"{_excess(ratio)}, {success:.0%}, {_fmt(time, '.2f')} s"


def _raw_cell(cells: list[SummaryRow]) -> str:
    """Median over problems of the median excess before simplification."""
    return _excess(_median([s.median_raw_ratio for s in cells if s.median_raw_ratio]))


def _cells_lost(
    summary: Sequence[SummaryRow], first: str, budgets: Sequence[float]
) -> tuple[list[str], int, int]:
    """The problem x budget cells in which ``first`` has not the shortest median path (one line
    each: who has it, and by how much), how many it shares with another planner (a tie is no
    win), and how many cells have any solved run."""
    lost, ties, total = [], 0, 0
    for budget in budgets:
        for problem in dict.fromkeys(s.problem for s in summary if s.budget == budget):
            cell = {s.planner: s.median_ratio for s in summary
                    if s.budget == budget and s.problem == problem and s.median_ratio}  # fmt: skip
            if not cell:
                continue
            total += 1
            best = min(cell, key=cell.__getitem__)
            if first not in cell:
                lost.append(f"- {budget:g} s, {problem}: {best}; {first} solved no run")
            elif cell[best] < cell[first]:
                margin = 100 * (cell[first] - cell[best])
                lost.append(
                    f"- {budget:g} s, {problem}: {best}, shorter by {margin:.3f} % of the optimum"
                )
            elif sum(r == cell[first] for r in cell.values()) > 1:
                ties += 1
    return lost, ties, total


def report_markdown(
    summary: Sequence[SummaryRow], *, errors: Sequence[str] = (), command: str | None = None
) -> str:
    """The report as markdown: the :func:`overview_markdown`, then per budget a table of
    problems x planners."""
    lines = ["# Benchmark report", ""]
    if command:
        lines += [f"Command: `{command}`", ""]
    lines += [overview_markdown(summary), ""]
    lines += [
        "Cells below: median path length over the exact optimum (first and third quartile) "
        "[success rate], median time in seconds (planning plus simplification or PSO). "
        "The optimum comes from `rrtpso optimum`.",
        "",
    ]
    planners = list(dict.fromkeys(s.planner for s in summary))
    for budget in sorted({s.budget for s in summary}):
        lines += [f"## Budget {budget:g} s", "", _budget_table(summary, planners, budget), ""]
    if errors:
        lines += ["## Errors", ""] + [f"- {e}" for e in errors] + [""]
    return "\n".join(lines)


def _budget_table(summary: Sequence[SummaryRow], planners: Sequence[str], budget: float) -> str:
    """Problems x planners at one budget: median ratio (quartiles) [success], median time."""
    cells = {(s.problem, s.planner): s for s in summary if s.budget == budget}
    rows = []
    for problem in dict.fromkeys(s.problem for s in summary if s.budget == budget):
        opt = next((s.optimum for s in summary if s.problem == problem), None)
        row = [problem, _fmt(opt, ".2f")]
        for planner in planners:
            s = cells.get((problem, planner))
            row.append(
                ""
                if s is None
                else f"{_fmt(s.median_ratio, '.4f')} ({_fmt(s.q1_ratio, '.3f')}–"
                f"{_fmt(s.q3_ratio, '.3f')}) [{s.success:.0%}], {_fmt(s.median_time, '.2f')}"
            )
        rows.append(row)
    return markdown_table(["problem", "optimum", *planners], rows, align="-r" + "r" * len(planners))
