"""The harness: running planners many times, in processes, and recording what they did.

- :mod:`.batch`: :func:`run_batch`, many problem files x planners x runs in parallel, streamed
  to JSON lines and resumable (:mod:`.results_file`), each run in a process of its own
  (:mod:`.workers`);
- :mod:`.record`: :class:`RunRecord`, one run (a row of a results file), and its identity
  :class:`RunKey`;
- :mod:`.bench`: :func:`run_bench`, a batch written as OMPL benchmark logs, the SQLite database
  Planner Arena opens (:mod:`.ompl_log`) and a report (:mod:`.report`: its markdown tables).

The reference lengths come from :mod:`rrtpso_ompl.groundtruth`. The names below are imported
on first use (:mod:`rrtpso_ompl.lazy`): ``rrtpso batch`` loads no bench, log or database code.
"""

from ..lazy import export_lazily

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

export_lazily(
    __name__,
    {
        **dict.fromkeys(
            ("Task", "expand_inputs", "make_tasks", "read_rows", "run_batch", "run_task"), ".batch"
        ),
        **dict.fromkeys(("BenchResult", "SummaryRow", "run_bench", "summarise"), ".bench"),
        **dict.fromkeys(
            ("Experiment", "PlannerRuns", "build_database", "format_log", "write_log"), ".ompl_log"
        ),
        **dict.fromkeys(("RunKey", "RunRecord"), ".record"),
        "markdown_table": ".report",
    },
)
