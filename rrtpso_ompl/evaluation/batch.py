"""Batch solving: many problem files x planners x runs, in parallel, streamed to JSON lines.

Every task runs in a fresh process (spawn start method): OMPL's random generator can be seeded only
once per process, so this is what makes each row reproducible from its seed, whichever worker ran
it. The local executor is :class:`concurrent.futures.ProcessPoolExecutor` with one task per child;
``executor="dask"`` sends the same tasks to a Dask cluster, where each task again spawns its own
process. Rows are written by the parent as they finish, one whole line per write, so an interrupted
batch leaves a valid JSON-lines file that ``resume=True`` continues.
"""

from __future__ import annotations

import glob
import json
import multiprocessing as mp
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import RrtpsoError
from ..outputs import json_line, write_text_atomic

__all__ = [
    "Task",
    "expand_inputs",
    "make_tasks",
    "read_rows",
    "run_batch",
    "run_task",
]

PROBLEM_SUFFIXES = (".yaml", ".yml")


@dataclass(frozen=True)
class Task:
    """One solve: a problem file, a planner, a seed. Plain data, so it pickles to any worker.

    ``error`` carries an input problem found before solving (a missing file, a glob that matched
    nothing): the task then only reports it.
    """

    file: str
    planner: str
    seed: int
    run: int
    time_limit: float | None = None
    params: Mapping[str, Any] = field(default_factory=dict)
    simplify: bool = False
    keep_path: bool = True
    progress: bool = False
    error: str | None = None

    @property
    def key(self) -> tuple[str, str, int, float | None]:
        """Identifies the row in a results file (for resuming)."""
        return (self.file, self.planner, self.seed, self.time_limit)


def expand_inputs(items: Sequence[str]) -> list[tuple[str, str | None]]:
    """Files, directories (searched recursively for ``*.yaml``/``*.yml``) and glob patterns.

    Returns
    -------
    list of (path, error)
        In the order given, without repeats; ``error`` says why an item gave no file (it becomes an
        error row, so a batch never stops for one bad argument).
    """
    out: list[tuple[str, str | None]] = []
    seen: set[str] = set()

    def add(path: str, error: str | None = None) -> None:
        if path not in seen:
            seen.add(path)
            out.append((path, error))

    for item in items:
        p = Path(item)
        if p.is_dir():
            found = sorted(
                str(f) for f in p.rglob("*") if f.suffix in PROBLEM_SUFFIXES and f.is_file()
            )
            if not found:
                add(item, "directory holds no .yaml problem files")
            for f in found:
                add(f)
        elif p.exists():
            add(item)
        elif glob.has_magic(item):
            matches = sorted(glob.glob(item, recursive=True))
            if not matches:
                add(item, "no file matches this pattern")
            for f in matches:
                add(f)
        else:
            add(item, "no such file or directory")
    return out


def make_tasks(
    items: Sequence[str],
    planners: Sequence[str],
    runs: int = 1,
    seed: int = 1,
    time_limit: float | None = None,
    params: Mapping[str, Mapping[str, Any]] | None = None,
    simplify: bool | Callable[[str], bool] = False,
    keep_path: bool = True,
    progress: bool = False,
) -> list[Task]:
    """The tasks of a batch: every file x planner x run, run ``r`` seeded with ``seed + r``.

    ``params`` maps a planner name to its parameters; ``simplify`` may be a function of the
    planner name.
    """
    tasks = []
    for path, error in expand_inputs(items):
        for planner in planners:
            for r in range(runs):
                tasks.append(
                    Task(
                        file=path,
                        planner=planner,
                        seed=seed + r,
                        run=r,
                        time_limit=time_limit,
                        params=dict((params or {}).get(planner, {})),
                        simplify=simplify(planner) if callable(simplify) else simplify,
                        keep_path=keep_path,
                        progress=progress,
                        error=error,
                    )
                )
    return tasks


# ----------------------------------------------------------------------------------------------
# One task (runs in a worker process)
# ----------------------------------------------------------------------------------------------
def run_task(task: Task) -> dict[str, Any]:
    """Solve one task and return its row. Never raises for a bad problem: that is the row.

    The row has the keys of ``rrtpso solve --json`` (``problem, planner, status, solved, length,
    time, seed, path`` and the per-stage figures) plus ``file``, ``run``, ``wall`` (s) and
    ``error`` (None, or the message for a bad file or planner), and ``budget``, the time limit
    the task asked for (None: the file's).
    """
    from ..model.problem import ProblemError, load_problem
    from ..ompl_setup import set_ompl_log_level
    from ..planners.solve import solve

    set_ompl_log_level(0)
    base = {
        "file": task.file,
        "planner": task.planner,
        "seed": task.seed,
        "run": task.run,
        "budget": task.time_limit,
    }
    t0 = time.perf_counter()
    if task.error:
        return _error_row(base, f"{task.file}: {task.error}")
    try:
        problem = load_problem(task.file)
        result = solve(
            problem,
            task.planner,
            task.time_limit,
            task.seed,
            dict(task.params),
            simplify=task.simplify,
            progress=task.progress,
        )
    except ProblemError as exc:  # it names the file already
        return _error_row(base, str(exc))
    except RrtpsoError as exc:  # unknown planner, bad parameter
        return _error_row(base, f"{task.file}: {exc}")
    row = {**base, **result.to_dict()}
    row["file"] = task.file
    row["run"] = task.run
    row["budget"] = task.time_limit
    if not task.keep_path:
        row.pop("path", None)
    row["wall"] = time.perf_counter() - t0
    row["error"] = None
    return row


def _error_row(base: dict[str, Any], message: str) -> dict[str, Any]:
    return {
        **base,
        "problem": None,
        "status": "error",
        "solved": False,
        "length": None,
        "time": 0.0,
        "path": [],
        "error": message,
    }


def _run_isolated(task: Task) -> dict[str, Any]:
    """``run_task`` in a fresh spawned process (used inside long-lived Dask workers)."""
    ctx = mp.get_context("spawn")
    with ProcessPoolExecutor(1, mp_context=ctx) as pool:
        return pool.submit(run_task, task).result()


# ----------------------------------------------------------------------------------------------
# Results files
# ----------------------------------------------------------------------------------------------
def read_rows(path: str | Path) -> list[dict[str, Any]]:
    """The complete rows of a JSON-lines results file (a torn last line is ignored)."""
    rows = []
    p = Path(path)
    if not p.exists():
        return rows
    with p.open() as fh:
        for line in fh:
            try:
                row = json.loads(line)
            except json.JSONDecodeError:
                continue  # an interrupted write; the task runs again
            if isinstance(row, dict):
                rows.append(row)
    return rows


def _row_key(row: Mapping[str, Any]) -> tuple[str, str, int, float | None]:
    return (row.get("file"), row.get("planner"), row.get("seed"), row.get("budget"))


# ----------------------------------------------------------------------------------------------
# Executors
# ----------------------------------------------------------------------------------------------
def _local_results(tasks: list[Task], jobs: int) -> Iterator[dict[str, Any]]:
    ctx = mp.get_context("spawn")
    # One task per child: a fresh process, so OMPL takes each task's seed.
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, max_tasks_per_child=1)
    try:
        pending: set[Future] = {pool.submit(run_task, t) for t in tasks}
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                yield fut.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _dask_results(tasks: list[Task], scheduler: str | Any) -> Iterator[dict[str, Any]]:
    try:
        from distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - depends on the optional extra
        raise RuntimeError(
            "the dask executor needs the optional extra: pip install 'rrtpso-ompl[dask]'"
        ) from exc
    client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
    try:
        futures = client.map(_run_isolated, tasks, pure=False)
        try:
            for fut in as_completed(futures):
                yield fut.result()
        finally:
            client.cancel(futures)
    finally:
        if client is not scheduler:
            client.close()


def run_batch(
    tasks: Iterable[Task],
    out: str | Path,
    *,
    jobs: int = 1,
    resume: bool = False,
    executor: str = "local",
    scheduler: Any = None,
    progress: Callable[[dict[str, Any]], None] | None = None,
    on_start: Callable[[int, int], None] | None = None,
    optimum: bool = True,
) -> list[dict[str, Any]]:
    """Run ``tasks`` and stream their rows to ``out`` (JSON lines) as they finish.

    Parameters
    ----------
    tasks : iterable of Task
    out : path
        The results file. Without ``resume`` it is started afresh; with ``resume`` the rows it
        already holds are kept and their tasks skipped (error rows are retried).
    jobs : int
        Worker processes of the local executor.
    executor : {"local", "dask"}
    scheduler : str or distributed.Client
        Dask scheduler address (or a client) for ``executor="dask"``.
    progress : callable, optional
        Called with each finished row.
    on_start : callable, optional
        Called as ``on_start(n_to_run, n_skipped)`` before the first task starts.
    optimum : bool
        Add ``optimum`` (the exact shortest length, :mod:`rrtpso_ompl.evaluation.optimum`,
        computed once per file in this process) and ``ratio`` (``length / optimum``, null unless
        solved) to every row.

    Returns
    -------
    list of dict
        All rows of the file: the kept ones and the new ones.
    """
    tasks = list(tasks)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    kept: list[dict[str, Any]] = []
    if resume:
        kept = [r for r in read_rows(out) if not r.get("error")]
    done = {_row_key(r) for r in kept}
    todo = [t for t in tasks if t.key not in done]
    if on_start is not None:
        on_start(len(todo), len(tasks) - len(todo))
    # Rewrite the kept rows first: this drops a torn last line and retried error rows.
    write_text_atomic("".join(json_line(r) for r in kept), out)
    rows = list(kept)
    if executor == "local":
        results = _local_results(todo, max(1, jobs))
    elif executor == "dask":
        if scheduler is None:
            raise ValueError("the dask executor needs a scheduler address")
        results = _dask_results(todo, scheduler)
    else:
        raise ValueError(f"unknown executor {executor!r} (local or dask)")
    optima = _Optima() if optimum else None
    with out.open("a", buffering=1) as fh:
        for row in results:
            if optima is not None:
                optima.annotate(row)
            fh.write(json_line(row))  # one whole line per write: never a torn row mid-file
            fh.flush()
            rows.append(row)
            if progress is not None:
                progress(row)
    return rows


class _Optima:
    """The exact optimum of each problem file, computed when its first row arrives."""

    def __init__(self) -> None:
        self._cache: dict[str, float | None] = {}

    def length(self, file: str) -> float | None:
        if file not in self._cache:
            from ..model.problem import ProblemError, load_problem
            from .optimum import shortest_path

            try:
                self._cache[file] = shortest_path(load_problem(file)).length
            except (ProblemError, OSError):
                self._cache[file] = None  # the row already says why
        return self._cache[file]

    def annotate(self, row: dict[str, Any]) -> None:
        opt = None if row.get("error") else self.length(row["file"])
        row["optimum"] = opt
        # Only a solved path has a ratio: an approximate one stops short of the goal and can be
        # shorter than the optimum.
        length = row.get("length") if row.get("solved") else None
        row["ratio"] = length / opt if length is not None and opt else None
