"""The harness: running planners many times, in processes, and recording what they did.

- :mod:`.batch`: :func:`run_batch`, many problem files x planners x runs in parallel, streamed
  to JSON lines and resumable (:mod:`.results_file`), each run in a process of its own
  (:mod:`.workers`);
- :mod:`.record`: :class:`RunRecord`, one run (a row of a results file), and its identity
  :class:`RunKey`;
- :mod:`.bench`: :func:`run_bench`, a batch written as OMPL benchmark logs, the SQLite database
  Planner Arena opens (:mod:`.ompl_log`) and a report (:mod:`.report`: its markdown tables).

The reference lengths come from :mod:`rrtpso_ompl.groundtruth`.
"""

from .batch import Task, expand_inputs, make_tasks, read_rows, run_batch, run_task
from .bench import BenchResult, SummaryRow, run_bench, summarise
from .ompl_log import Experiment, PlannerRuns, build_database, format_log, write_log
from .record import RunKey, RunRecord
from .report import markdown_table

__all__ = [
    "BenchResult",
    "Experiment",
    "PlannerRuns",
    "RunKey",
    "RunRecord",
    "SummaryRow",
    "Task",
    "build_database",
    "expand_inputs",
    "format_log",
    "make_tasks",
    "markdown_table",
    "read_rows",
    "run_batch",
    "run_bench",
    "run_task",
    "summarise",
    "write_log",
]
