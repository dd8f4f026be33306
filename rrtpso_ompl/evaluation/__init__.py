"""Measuring planners: the exact optimum, batches, benchmarks in OMPL's format, generated problems.

- :mod:`.optimum`: :func:`shortest_path`, the exact shortest path for the disc robot (the
  reference of every length ratio);
- :mod:`.batch`: :func:`run_batch`, many problem files x planners x runs in parallel, streamed
  to JSON lines and resumable;
- :mod:`.bench`: :func:`run_bench`, a batch written as OMPL benchmark logs, the SQLite database
  Planner Arena opens (:mod:`.ompl_log`) and a report;
- :mod:`.generate`: seeded random problems with a certificate of solvability.
"""

from .batch import Task, expand_inputs, make_tasks, read_rows, run_batch, run_task
from .bench import BenchResult, SummaryRow, run_bench, summarise
from .generate import generate, generate_to_file
from .ompl_log import Experiment, PlannerRuns, build_database, format_log, write_log
from .optimum import OptimumResult, shortest_path

__all__ = [
    "BenchResult",
    "Experiment",
    "OptimumResult",
    "PlannerRuns",
    "SummaryRow",
    "Task",
    "build_database",
    "expand_inputs",
    "format_log",
    "generate",
    "generate_to_file",
    "make_tasks",
    "read_rows",
    "run_batch",
    "run_bench",
    "run_task",
    "shortest_path",
    "summarise",
    "write_log",
]
