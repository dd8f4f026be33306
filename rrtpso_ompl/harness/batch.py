"""Batch solving: many problem files x planners x runs, in parallel, streamed to JSON lines.

Every run gets a process of its own, which seeds OMPL before it builds anything: the local
executor's warm workers fork one child per run
(:mod:`rrtpso_ompl.harness.workers`), after loading the run's problem once per worker; the
Dask executor forks a process per run from a warm fork server. So each row is reproducible from
its seed, whichever worker ran it, and a run that crashes is an error row, not the end of the
batch. Rows are written
by the parent as they finish, one whole line per write, to a locked results file
(:mod:`rrtpso_ompl.harness.results_file`), so an interrupted batch leaves a valid file that
``resume=True`` continues.
"""

from __future__ import annotations

import errno
import glob
import hashlib
import os
import stat
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import MAX_SHOWN_PATH, ProblemError, RrtpsoError, UsageError, shown
from ..model.occupancy import is_map_yaml
from ..model.problem import input_files
from ..model.yamlfile import open_input
from .record import RunKey, RunRecord, resolved_source
from .results_file import ResultsFile, latest_rows, read_rows

__all__ = [
    "Task",
    "expand_inputs",
    "inputs_digest",
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
    nothing): the task then only reports it. ``settings`` is what else makes the run's result
    (:func:`run_settings`; worked out from ``planner``, ``params`` and ``simplify`` when not
    given): part of the run's identity.
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
    source: str | None = None
    digest: str | None = None
    settings: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        if self.settings is None:
            settings = run_settings(self.planner, self.params, self.simplify)
            object.__setattr__(self, "settings", settings)

    @property
    def key(self) -> RunKey:
        """The identity of the task's run, that of its row
        (:attr:`~rrtpso_ompl.harness.record.RunRecord.key`: the problem file resolved, however
        it was spelled, and the settings): how resuming finds the runs done."""
        return RunKey.of(self.file, self.planner, self.seed, self.time_limit, source=self.source,
                         settings=self.settings)  # fmt: skip


def run_settings(planner: str, params: Mapping[str, Any], simplify: bool) -> dict[str, Any]:
    """What makes a run's result besides its problem, planner, seed and budget (a row's
    ``settings``): ``params``, the caller's parameters converted by their declarations (so that
    ``range=5`` and ``range=5.0`` are one setting; as given when the planner cannot take them:
    the run is an error row then), ``simplify`` and ``version``, this package's."""
    from .. import __version__
    from ..planners.request import resolve

    try:
        request = resolve(None, planner, params=dict(params))
        given = {**request.params, **request.post_params}
    except (RrtpsoError, ValueError, TypeError):
        given = {k: str(v) for k, v in params.items()}
    return {"params": dict(sorted(given.items())), "simplify": bool(simplify),
            "version": __version__}  # fmt: skip


def expand_inputs(items: Sequence[str]) -> list[tuple[str, str | None]]:
    """Files, directories (searched recursively for ``*.yaml``/``*.yml``) and glob patterns.

    Returns
    -------
    list of (path, error)
        In the order given, without repeats (one file named twice, however spelled or linked,
        comes once, as first named); ``error`` says why an item gave no file (it becomes an error
        row, so a batch never stops for one bad argument).
    """
    out: list[tuple[str, str | None]] = []
    seen: set[str] = set()

    def add(path: str, error: str | None = None) -> None:
        key = resolved_source(path) if error is None else path  # one file, however spelled
        if key not in seen:
            seen.add(key)
            out.append((path, error))

    for item in items:
        p = Path(item)
        try:
            p.stat()
        except OSError as exc:
            if exc.errno not in (errno.ENOENT, errno.ENOTDIR, errno.ELOOP):
                # A name too long, a folder that may not be read: why, as the system says it.
                add(item, f"cannot read it: {exc.strerror or exc}")
                continue
        if p.is_dir():
            found = folder_problems(p)
            if not found:
                add(item, "directory holds no .yaml problem files")
            for f, error in found:
                add(f, error)
        elif p.exists():
            add(item)
        elif os.path.lexists(item):  # a link to nothing, or a loop of links
            add(item, _not_a_problem(p))
        elif glob.has_magic(item):
            matches = sorted(glob.glob(item, recursive=True))
            if not matches:
                add(item, "no file matches this pattern")
            for f in matches:
                add(f)
        else:
            add(item, "no such file or directory")
    return out


def folder_problems(folder: Path) -> list[tuple[str, str | None]]:
    """The problem files in ``folder`` and its subfolders (links to folders are not followed),
    sorted, as ``(path, error)``.

    A folder's map_server maps belong to its problems and are left out. Whatever else is named
    like a problem file but is not a regular file (a fifo, a socket, a link to nothing, a
    directory named ``x.yaml``) comes with the reason it is none, never opened; so does a
    subfolder that cannot be read: each becomes an error row, none is skipped without a word.
    """
    out: list[tuple[str, str | None]] = []

    def unreadable(exc: OSError) -> None:
        where = exc.filename or str(folder)
        out.append((str(where), f"cannot read this folder: {exc.strerror or exc}"))

    for root, dirs, files in os.walk(folder, onerror=unreadable):
        dirs.sort()
        for name in dirs + files:
            if Path(name).suffix not in PROBLEM_SUFFIXES:
                continue
            path = Path(root, name)
            try:
                regular = stat.S_ISREG(os.stat(path).st_mode)
            except OSError:
                regular = False
            if not regular:
                out.append((str(path), _not_a_problem(path)))
            elif not is_map_yaml(path):
                out.append((str(path), None))
    return sorted(out)


def _not_a_problem(path: Path) -> str:
    """Why ``path``, named like a problem file, is not one (it is not a regular file)."""
    from ..model.yamlfile import file_kind

    try:
        return f"is {file_kind(os.stat(path).st_mode)}, not a problem file"
    except OSError as exc:
        if os.path.islink(path):
            if exc.errno == errno.ELOOP:
                return "is a symbolic link loop, not a problem file"
            return f"is a symbolic link to '{os.readlink(path)}', which does not exist"
        return f"cannot be looked at: {exc.strerror or exc}"


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
    """The tasks of a batch: every file x planner x run, run ``r`` seeded with ``seed + r`` (a
    file or planner named twice counts once).

    ``params`` maps a planner name to its parameters; ``simplify`` may be a function of the
    planner name.

    Raises
    ------
    UsageError
        For more than :data:`~rrtpso_ompl.validation.MAX_RUNS` tasks.
    """
    inputs = expand_inputs(items)
    planners = list(dict.fromkeys(planners))  # a planner named twice runs once
    check_task_count(runs, len(planners), len(inputs))
    tasks = []
    settings = {}
    for planner in planners:  # once per planner, not per task
        given = dict((params or {}).get(planner, {}))
        how = simplify(planner) if callable(simplify) else simplify
        settings[planner] = run_settings(planner, given, how)
    for path, error in inputs:
        source = resolved_source(path) if error is None else None
        digest = inputs_digest(path) if error is None else None
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
                        source=source,
                        digest=digest,
                        settings=settings[planner],
                    )
                )
    return tasks


#: Most bytes of one input file hashed by :func:`inputs_digest`: more than any reader reads.
_DIGEST_BYTES = 1 << 30


def inputs_digest(path: str) -> str:
    """SHA-256 of a problem file and the map files it reads (its ``inputs_sha256``): a resumed
    batch runs again the runs of a file whose content changed since its rows were written.

    A file that cannot be read counts as such (its run reports why).
    """
    h = hashlib.sha256()
    for file in input_files(path):
        size = 0
        try:
            with open_input(file) as fh:
                while size < _DIGEST_BYTES and (chunk := fh.read(min(_DIGEST_BYTES - size,
                                                                    1 << 20))):  # fmt: skip
                    h.update(chunk)
                    size += len(chunk)
        except (ValueError, OSError) as exc:
            h.update(f"unreadable: {exc}".encode())
        h.update(f"\0{size}\0".encode())  # where one file ends and the next begins
    return h.hexdigest()


def check_task_count(runs: int, planners: int, files: int, budgets: int = 1) -> None:
    """Refuse a batch or bench of more than :data:`~rrtpso_ompl.validation.MAX_RUNS` runs
    before building its tasks (a :class:`UsageError` naming the factors)."""
    from ..validation import check_run_count

    try:
        check_run_count(runs, planners, files, budgets)
    except ValueError as exc:
        raise UsageError(f"--runs: the number of runs {exc}") from None


# ----------------------------------------------------------------------------------------------
# One task (runs in a forked child of a warm worker)
# ----------------------------------------------------------------------------------------------
#: Problems a warm worker has loaded: file -> (problem, world) or the error loading it gave.
#: Filled in the worker before it forks (:func:`prepare_task`), so each run's child finds its
#: problem and world built, and loads nothing.
_LOADED: dict[str, Any] = {}


def prepare_task(task: Task) -> None:
    """Load the task's problem and build its world, once per file and worker (no OMPL here: the
    worker must not create any OMPL object before it forks)."""
    if task.error or task.file in _LOADED:
        return
    from ..model import World, load_problem

    try:
        problem = load_problem(task.file)
        _LOADED[task.file] = (problem, World.from_problem(problem))
    except RrtpsoError as exc:
        _LOADED[task.file] = exc


def run_task(task: Task) -> RunRecord:
    """Solve one task and return its row. Never raises for a bad problem: that is the row.

    The row (:class:`~rrtpso_ompl.harness.record.RunRecord`) has the figures of ``rrtpso solve
    --json`` (``problem, planner, status, solved, length, time, seed, path`` and the per-stage
    figures) plus ``file``, ``run``, ``wall`` (s) and ``error`` (None, or the message for a bad
    file or planner), and ``budget``, the time limit the task asked for (None: the file's).
    """
    from ..ompl_setup import set_ompl_log_level
    from ..planners.solve import solve

    set_ompl_log_level(0)
    base = _base_row(task)
    t0 = time.perf_counter()
    if task.error:
        return error_row(task, f"{_where(task)}: {task.error}")
    prepare_task(task)
    loaded = _LOADED[task.file]
    if isinstance(loaded, RrtpsoError):
        return error_row(task, str(loaded) if isinstance(loaded, ProblemError) else
                         f"{_where(task)}: {loaded}")  # fmt: skip
    problem, world = loaded
    try:
        result = solve(problem, task.planner, time_limit=task.time_limit, seed=task.seed,
                       params=dict(task.params), simplify=task.simplify, progress=task.progress,
                       world=world)  # fmt: skip
    except ProblemError as exc:  # it names the file already
        return error_row(task, str(exc))
    except RrtpsoError as exc:  # unknown planner, bad parameter
        return error_row(task, f"{_where(task)}: {exc}")
    solved = result.to_dict()
    if not task.keep_path:
        solved.pop("path", None)
    return RunRecord.from_solve(base, solved, wall=time.perf_counter() - t0)


def _where(task: Task) -> str:
    """The task's file as its messages name it (a long name shortened, ``errors.shown``)."""
    return shown(task.file, MAX_SHOWN_PATH)


def _base_row(task: Task) -> dict[str, Any]:
    """The keys a task gives its row, whatever the solve returns."""
    return {"file": task.file, "planner": task.planner, "seed": task.seed, "run": task.run,
            "budget": task.time_limit, "settings": dict(task.settings or {}),
            "source": task.key.source, "inputs_sha256": task.digest}  # fmt: skip


def error_row(task: Task, message: str) -> RunRecord:
    """The row of a task that produced no result: ``status`` "error" and the reason."""
    return RunRecord(**_base_row(task), status="error", path=[], error=message)


def _timeout(task: Task) -> float:
    """How long a run may take before its process is stopped: its budget plus a grace period
    (the file's own budget is not known here, so the largest allowed one counts)."""
    from ..validation import MAX_SECONDS
    from .workers import GRACE

    budget = task.time_limit if task.time_limit is not None else MAX_SECONDS
    return 2.0 * budget + GRACE


def _warm() -> None:
    """Imports a worker does once, so that its forked children start planning at once."""
    import numpy  # noqa: F401
    import scipy.sparse.csgraph  # noqa: F401
    import shapely  # noqa: F401

    from ..planners import default_registry

    default_registry()  # imports OMPL's modules and every plugin, creates no OMPL object


def _row_of(task: Task, result: Any) -> RunRecord:
    from .workers import ChildFailure

    if isinstance(result, ChildFailure):
        return error_row(task, f"{_where(task)}: {result.message}")
    return result


# ----------------------------------------------------------------------------------------------
# Executors
# ----------------------------------------------------------------------------------------------
def _local_results(tasks: list[Task], jobs: int) -> Iterator[RunRecord]:
    from .workers import run_local

    for task, result in run_local(tasks, run_task, jobs, warm=_warm, prepare=prepare_task,
                                  timeout_of=_timeout):  # fmt: skip
        yield _row_of(task, result)


def _run_isolated(task: Task) -> RunRecord:
    """``run_task`` in a process of its own, inside a long-lived Dask worker: the worker may run
    threads, so the process is forked from a fork server that has done the imports (which the
    Dask worker keeps), not from the worker itself."""
    from .workers import run_spawned

    return _row_of(task, run_spawned(run_task, task, _timeout(task), warm=True))


def _dask_results(tasks: list[Task], scheduler: str | Any) -> Iterator[RunRecord]:
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
    overwrite: bool = False,
    executor: str = "local",
    scheduler: Any = None,
    progress: Callable[[RunRecord], None] | None = None,
    on_start: Callable[[int, int], None] | None = None,
    optimum: bool = True,
    notice: Callable[[str], None] | None = None,
) -> list[RunRecord]:
    """Run ``tasks`` and stream their rows to ``out`` (JSON lines) as they finish.

    Parameters
    ----------
    tasks : iterable of Task
    out : path
        The results file (:class:`~rrtpso_ompl.harness.results_file.ResultsFile`: locked while
        the batch runs, appended to, never replaced).
    jobs : int
        Worker processes of the local executor.
    resume : bool
        Keep the rows ``out`` holds and skip their tasks (error rows are retried).
    overwrite : bool
        Start afresh when ``out`` holds rows of an earlier run (without ``resume`` or this, such
        a file is refused).
    executor : {"local", "dask"}
    scheduler : str or distributed.Client
        Dask scheduler address (or a client) for ``executor="dask"``.
    progress : callable, optional
        Called with each finished row.
    on_start : callable, optional
        Called as ``on_start(n_to_run, n_skipped)`` before the first task starts.
    notice : callable, optional
        Called with a message for the user when resuming finds rows that are not these runs'
        although they look alike: rows of other settings (:func:`run_settings`; they stay in the
        file, are not returned, and these runs are new), and rows of a problem file whose
        content changed since (run again).
    optimum : bool
        Add ``optimum`` (the exact shortest length, :mod:`rrtpso_ompl.groundtruth.optimum`,
        computed once per file in this process) and ``ratio`` (``length / optimum``, null unless
        solved) to every row.

    Returns
    -------
    list of RunRecord
        One row per run (the kept ones and the new ones): the rows of other settings than the
        tasks' of the same problem, planner and budget are left out. A task given twice runs
        once.

    Raises
    ------
    UsageError
        When ``out`` is being written by another batch, holds rows and neither ``resume`` nor
        ``overwrite`` is given, or is not a results file of this package.
    """
    unique: dict[RunKey, Task] = {}
    for t in tasks:  # a task given twice runs once
        unique.setdefault(t.key, t)
    tasks = list(unique.values())
    results_of = _executor(executor, jobs, scheduler)  # checked before the file is touched
    with ResultsFile(out, resume=resume, overwrite=overwrite) as results:
        kept = [r for r in results.kept if not r.is_error]
        todo = _still_to_run(tasks, kept)
        other = _other_settings(tasks, kept)
        for message in _resume_notes(str(out), tasks, kept, other):
            if notice is not None:
                notice(message)
        kept = [r for r in kept if id(r) not in other]
        if on_start is not None:
            on_start(len(todo), len(tasks) - len(todo))
        new = _record(results_of(todo), results, _Optima() if optimum else None, progress)
    return latest_rows([*kept, *new])


def _executor(
    executor: str, jobs: int, scheduler: Any
) -> Callable[[list[Task]], Iterator[RunRecord]]:
    """The function that runs a list of tasks on ``executor`` and yields their rows as they
    finish (``ValueError`` for an unknown executor or a Dask one without its scheduler)."""
    if executor not in ("local", "dask"):
        raise ValueError(f"unknown executor {executor!r} (local or dask)")
    if executor == "dask" and scheduler is None:
        raise ValueError("the dask executor needs a scheduler address")
    if executor == "local":
        return lambda todo: _local_results(todo, max(1, jobs))
    return lambda todo: _dask_results(todo, scheduler)


def _still_to_run(tasks: list[Task], kept: list[RunRecord]) -> list[Task]:
    """The tasks whose run none of the ``kept`` rows (a resumed file's) already is."""
    done = {r.key: r.inputs_sha256 for r in kept}
    return [t for t in tasks if not _done(t, done)]


def _other_settings(tasks: list[Task], kept: list[RunRecord]) -> dict[int, Task]:
    """The kept rows of a configuration (problem, planner, budget) of the tasks but of other
    settings (or of unknown ones: an earlier version's rows), by ``id``, each with a task of its
    configuration: they are not these runs, whatever their seeds."""
    ours: dict[tuple[Any, ...], Task] = {}
    settings: dict[tuple[Any, ...], set[str | None]] = {}
    for t in tasks:
        ours.setdefault(t.key.configuration, t)
        settings.setdefault(t.key.configuration, set()).add(t.key.settings)
    other = {}
    for r in kept:
        config = r.key.configuration
        if config in ours and r.key.settings not in settings[config]:
            other[id(r)] = ours[config]
    return other


#: Most kinds of other settings a resumed batch names (one line each).
_MAX_NOTES = 5


def _resume_notes(out: str, tasks: list[Task], kept: list[RunRecord],
                  other: Mapping[int, Task]) -> list[str]:  # fmt: skip
    """What the user is told when resuming finds rows that are not these runs: rows of other
    settings, one line per kind of difference, and rows of a problem whose content changed."""
    groups: dict[tuple[str, str], int] = {}
    for r in kept:
        if id(r) in other:
            diff = _settings_difference(r.settings, other[id(r)].settings or {})
            groups[diff] = groups.get(diff, 0) + 1
    notes = [
        f"rrtpso: {out}: {_count(n)} of other settings ({there}; these runs: {here}) "
        f"{'stays' if n == 1 else 'stay'} in the file and {'is' if n == 1 else 'are'} not "
        "counted; these runs are new"
        for (there, here), n in list(groups.items())[:_MAX_NOTES]
    ]
    if len(groups) > _MAX_NOTES:
        rest = sum(list(groups.values())[_MAX_NOTES:])
        notes.append(f"rrtpso: {out}: and {_count(rest)} of other settings besides")
    digests = {t.key: t.digest for t in tasks}
    changed = sum(1 for r in kept if r.key in digests and digests[r.key] and r.inputs_sha256
                  and r.inputs_sha256 != digests[r.key])  # fmt: skip
    if changed:
        notes.append(f"rrtpso: {out}: {_count(changed)} of a problem file (or map) that changed "
                     "since; these runs run again")  # fmt: skip
    return notes


def _count(n: int) -> str:
    return f"{n} row" if n == 1 else f"{n} rows"


def _settings_difference(there: Mapping[str, Any] | None, here: Mapping[str, Any]
                         ) -> tuple[str, str]:  # fmt: skip
    """The settings of a row and of a task, in words, only where they differ."""
    if there is None:
        return "none recorded: an earlier version wrote them", _settings_words(here, list(here))
    keys = [k for k in dict.fromkeys((*there, *here)) if there.get(k) != here.get(k)]
    return _settings_words(there, keys), _settings_words(here, keys)


def _settings_words(settings: Mapping[str, Any], keys: Sequence[str]) -> str:
    """``range=5.0, simplify, version 0.1.0``: the ``keys`` of ``settings`` in words."""
    words = []
    for key in keys:
        value = settings.get(key)
        if key == "params":
            given = value or {}
            words.append(", ".join(f"{k}={v}" for k, v in given.items()) or "default parameters")
        elif key == "simplify":
            words.append("OMPL's simplifier" if value else "no simplifier")
        elif key == "version":
            words.append(f"version {value}")
        else:
            words.append(f"{key}={value}")
    return ", ".join(words) or "the same"


def _record(
    stream: Iterator[RunRecord],
    results: ResultsFile,
    optima: _Optima | None,
    progress: Callable[[RunRecord], None] | None,
) -> list[RunRecord]:
    """Append each row of ``stream`` to ``results`` as it arrives (with its optimum and ratio
    when ``optima`` is given), report it to ``progress``, and return the rows."""
    rows = []
    try:
        for row in stream:
            if optima is not None:
                row = optima.annotate(row)
            results.append(row)
            rows.append(row)
            if progress is not None:
                progress(row)
            if len(rows) == 1:
                _hold_for_tests()
    finally:
        stream.close()  # on Ctrl-C: stop the workers before the file is released
    return rows


#: Test hook (environment variable): the path of a fifo. A batch (or bench) that finds one there
#: holds after writing its first row until the fifo is opened for reading, the results file
#: still locked and its workers stopped or idle. Tests that need "a batch still running" (Ctrl-C,
#: a second batch on the same file) get it by construction, on any machine (``tests/helpers.py``,
#: ``held_batch``). A path that is not a fifo is ignored, so the hook can never write a file.
HOLD_ENV = "RRTPSO_TEST_HOLD_BATCH"


def _hold_for_tests() -> None:
    """Wait, when :data:`HOLD_ENV` names a fifo, until a reader opens it (a blocking open:
    Ctrl-C and the termination signals still interrupt it)."""
    fifo = os.environ.get(HOLD_ENV)
    if not fifo:
        return
    try:
        if not stat.S_ISFIFO(os.stat(fifo).st_mode):
            return
    except OSError:
        return
    with open(fifo, "wb"):
        pass


def _done(task: Task, done: Mapping[RunKey, str | None]) -> bool:
    """Whether a kept row is the task's run, of the same problem content (rows written before
    rows had ``inputs_sha256`` match on the key alone)."""
    if task.key not in done:
        return False
    digest = done[task.key]
    return digest is None or task.digest is None or digest == task.digest


class _Optima:
    """The exact optimum of each problem file, computed when its first row arrives."""

    def __init__(self) -> None:
        self._cache: dict[str, float | None] = {}

    def length(self, file: str) -> float | None:
        if file not in self._cache:
            from ..groundtruth.optimum import shortest_path
            from ..model.problem import load_problem

            try:
                self._cache[file] = shortest_path(load_problem(file)).length
            except (RrtpsoError, OSError, MemoryError):
                self._cache[file] = None  # the row already says why
        return self._cache[file]

    def annotate(self, row: RunRecord) -> RunRecord:
        """The row with its problem's optimum and its ratio to it."""
        return row.with_optimum(None if row.is_error else self.length(row.file))
