"""Recognising the files of this program that another command must never replace.

A results file (``rrtpso batch --out``, a bench's ``runs.jsonl``) and a bench folder's files hold
hours of runs; ``rrtpso solve --json res.jsonl`` or ``rrtpso generate --overwrite --out
benchmark.db`` would replace them in an instant. Every output of ``solve``, ``optimum``,
``simulate`` and ``generate`` is therefore looked at before planning (:func:`describe`, from the
command line's output checks), and every file published over is looked at again just before the
rename (:func:`inspected`, from :func:`rrtpso_ompl.outputs.publish`), with a shared lock held
across the rename.

What is recognised (:class:`Owned`):

- ``locked``: a regular file another process holds an advisory lock (``flock``) on. A batch
  locks its results file from the moment it opens it (empty at first) until it ends; testing the
  lock takes a *shared* lock for an instant, without blocking, and writes nothing.
- ``results``: a file whose first line is a row of a results file (:func:`is_row`: a JSON object
  with every key of :data:`ROW_KEYS`), or the beginning of one (:data:`ROW_START`, for a row longer
  than what is read or cut short).
- ``bench``: a file of a bench folder: ``runs.jsonl`` beside a bench's report, database or log,
  one of :data:`BENCH_FILES` beside a results file ``runs.jsonl``, or an OMPL log whose setup
  names the bench (:data:`BENCH_LOG_MARK`) anywhere.

Reading is bounded (:data:`HEAD_BYTES` decide whether a first line is a row, :data:`COUNT_BYTES`
are counted for the message) and never blocks: a file is opened without waiting and read only
when it is a regular file, so a fifo or device is never read.

The race with a batch that starts while a command plans is closed where the lock can close it:
the last look takes a shared lock and the rename happens under it, so a batch cannot be holding
the file then, and one that tries is refused (its lock is exclusive and it does not wait); a
new file is linked into place only where nothing is (:func:`rrtpso_ompl.outputs.link_new`), so
a results file made meanwhile is not renamed over. Not seen: a program that writes rows without
``flock`` (and on Windows, where ``fcntl`` is absent, no lock at all).

This module sits below everything (like :mod:`rrtpso_ompl.outputs`): it knows the rows' keys and
the bench folder's names, not the classes that write them.
"""

from __future__ import annotations

import contextlib
import json
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any, NamedTuple

try:  # advisory locks; absent on Windows, where no lock is seen
    import fcntl
except ImportError:  # pragma: no cover - platform dependent
    fcntl = None  # type: ignore[assignment]

__all__ = [
    "ABSENT",
    "BENCH_FILES",
    "BENCH_LOG_MARK",
    "COUNT_BYTES",
    "HEAD_BYTES",
    "MOVED",
    "ROW_KEYS",
    "ROW_START",
    "RUNS_FILE",
    "Owned",
    "describe",
    "inspected",
    "is_bench_log",
    "is_row",
]

#: Keys every row has (error rows and rows of every earlier version included): what makes a
#: JSON line recognisably a row of this package.
ROW_KEYS = ("file", "planner", "seed", "run", "status")
#: How every row's line begins (``file`` is written first): a line cut short, or longer than
#: what is read of it, is a row when it begins so (or is a beginning of this).
ROW_START = b'{"file": '
#: A bench folder's results file.
RUNS_FILE = "runs.jsonl"
#: The files a bench writes into its folder besides :data:`RUNS_FILE` and its OMPL logs.
BENCH_FILES = ("benchmark.db", "report.md", "report.csv", "ratio.png", "success.png")
#: The line of an OMPL log's setup block that says a bench of this package wrote it.
BENCH_LOG_MARK = "harness: rrtpso bench (one process per run, exact collision checks)"
#: How a bench's OMPL log begins.
BENCH_LOG_START = "rrtpso-ompl version"

#: Bytes read to find a file's first line (a longer first line is judged by its beginning).
HEAD_BYTES = 1 << 16
#: Bytes read to count a results file's rows (beyond them the count is a lower bound).
COUNT_BYTES = 1 << 24
#: Bytes of a log read to find :data:`BENCH_LOG_MARK`.
_LOG_HEAD_BYTES = 4096


def is_row(obj: Any) -> bool:
    """Whether a parsed JSON line is a row of this package's batches."""
    return isinstance(obj, dict) and all(k in obj for k in ROW_KEYS)


class Owned(NamedTuple):
    """A file of this program, as :func:`describe` found it.

    Attributes
    ----------
    kind : {"locked", "results", "bench"}
        Being written by another process; a results file; a file of a bench folder.
    what : str
        What it is, in words for a message after its name (``"a results file of rrtpso batch or
        bench (6 rows)"``).
    """

    kind: str
    what: str


#: What :func:`inspected` yields for a path where no file is.
ABSENT = Owned("absent", "")
#: What :func:`inspected` yields when the path was renamed over while it was opened and locked.
MOVED = Owned("moved", "")


@contextlib.contextmanager
def inspected(path: str | Path) -> Iterator[Owned | None]:
    """Look at the file at ``path`` and hold a shared lock on it while the block runs.

    Yields :data:`ABSENT` when nothing is there; an :class:`Owned` of kind ``locked`` or
    ``results`` when the file is one (kind ``locked`` when another process holds a lock); None
    for anything else (any other file, a directory, a fifo, a file that cannot be opened: the
    output checks say what is wrong with those). A batch that tries to take the file while the
    block runs is refused (its lock is exclusive), so a caller that renames over the file inside
    the block never replaces a file a batch holds.

    The path is opened once; when it names another file by the time the lock is held (renamed
    over or removed meanwhile), :data:`MOVED` is yielded, and the caller that cares looks again
    (:func:`rrtpso_ompl.outputs.publish` does).
    """
    fd, missing = _open(path)
    if fd is None:
        yield missing
        return
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            yield None  # a fifo or device is never read, a directory has no rows
            return
        if not _share_lock(fd):
            rows = _count_rows(fd)
            yield Owned("locked", _locked_text(rows))
            return
        if not _names(path, info):
            yield MOVED
            return
        rows = _count_rows(fd)
        yield None if rows is None else Owned("results", _results_text(rows))
    finally:
        os.close(fd)  # releases the lock


def _open(path: str | Path) -> tuple[int | None, Owned | None]:
    """``(fd, None)`` for ``path`` opened to read without waiting, else ``(None, ABSENT)`` when
    nothing is there and ``(None, None)`` when it cannot be opened (unreadable, a loop of
    links, ...: not ours to judge)."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        return os.open(path, flags | getattr(os, "O_CLOEXEC", 0)), None
    except FileNotFoundError:
        return None, ABSENT
    except (OSError, ValueError):
        return None, None


def describe(path: str | Path) -> Owned | None:
    """What file of this program ``path`` is (see the module docstring), or None (nothing there,
    or anything else). Reads at most :data:`COUNT_BYTES` of it and never blocks."""
    with inspected(path) as found:
        owned = None if found in (ABSENT, MOVED) else found
    member = _bench_member(Path(path))
    if member is None or (owned is not None and not _is_runs_name(path, owned)):
        return owned  # a lock says more; rows in a bench's report.md are no bench's
    return member


def _is_runs_name(path: str | Path, owned: Owned) -> bool:
    """Whether ``owned`` (rows) is what a bench folder's results file at ``path`` holds."""
    return owned.kind == "results" and Path(os.path.realpath(path)).name == RUNS_FILE


def is_bench_log(path: str | Path) -> bool:
    """Whether ``path`` is an OMPL benchmark log a bench of this package wrote (its first
    :data:`_LOG_HEAD_BYTES` name it)."""
    head = _head(path, _LOG_HEAD_BYTES)
    if head is None:
        return False
    text = head.decode("utf-8", errors="replace")
    return text.startswith(BENCH_LOG_START) and BENCH_LOG_MARK in text


# ----------------------------------------------------------------------------------------------
def _share_lock(fd: int) -> bool:
    """Take a shared lock without waiting; False when another process holds an exclusive one
    (a lock the file system does not support counts as none)."""
    if fcntl is None:
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    except OSError:
        return True
    return True


def _names(path: str | Path, info: os.stat_result) -> bool:
    """Whether ``path`` still names the file of ``info`` (not one renamed over it)."""
    try:
        now = os.stat(path)
    except OSError:
        return False
    return (now.st_dev, now.st_ino) == (info.st_dev, info.st_ino)


def _count_rows(fd: int) -> int | None:
    """The rows of a results file (a lower bound past :data:`COUNT_BYTES`), or None when its
    first line is not a row."""
    try:
        if not _starts_with_row(os.pread(fd, HEAD_BYTES, 0)):
            return None
        lines, offset = 0, 0
        last = b""
        while offset < COUNT_BYTES and (chunk := os.pread(fd, 1 << 20, offset)):
            lines += chunk.count(b"\n")
            offset += len(chunk)
            last = chunk
    except OSError:  # a read error: the file is not judged by what could not be read
        return None
    return lines + (1 if last and not last.endswith(b"\n") else 0)


def _starts_with_row(head: bytes) -> bool:
    """Whether the first line of ``head`` (leading blank lines skipped) is a row or the
    beginning of one."""
    head = head.lstrip(b" \t\r\n")
    if not head:
        return False
    line, newline, _ = head.partition(b"\n")
    if not newline:  # longer than what was read, or a row cut short
        return line.startswith(ROW_START) or ROW_START.startswith(line)
    try:
        return is_row(json.loads(line))
    except (json.JSONDecodeError, UnicodeDecodeError):
        return False


def _results_text(rows: int) -> str:
    return f"a results file of rrtpso batch or bench ({_rows(rows)})"


def _locked_text(rows: int | None) -> str:
    if rows:
        return (f"a results file locked by another process (a running rrtpso batch or bench "
                f"writes it), {_rows(rows)} so far")  # fmt: skip
    return ("a file locked by another process (a running rrtpso batch or bench that has not "
            "written a row yet, or another program writing it)")  # fmt: skip


def _rows(n: int | None) -> str:
    return f"{n} row" if n == 1 else f"{n} rows"


def _head(path: str | Path, size: int) -> bytes | None:
    """The first ``size`` bytes of a regular file (never opens anything else), or None."""
    fd, _ = _open(path)
    if fd is None:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        return os.pread(fd, size, 0)
    except OSError:
        return None
    finally:
        os.close(fd)


def _bench_member(path: Path) -> Owned | None:
    """The :class:`Owned` of a file of a bench folder (by its name and its neighbours), else
    None."""
    path, named = Path(os.path.realpath(path)), Path(path).parent
    # The folder for messages: as named, unless a link leads elsewhere.
    folder = named if os.path.realpath(named) == str(path.parent) else path.parent
    if path.name == RUNS_FILE:
        if path.is_file() and _has_bench_outputs(path.parent):
            rows = _rows_of(path)
            return Owned("bench", f"the results file of the rrtpso bench in '{folder}' "
                                  f"({_rows(rows)})")  # fmt: skip
        return None
    if path.suffix == ".log" and path.is_file() and is_bench_log(path):
        return Owned("bench", "an OMPL benchmark log written by rrtpso bench")
    if path.name in BENCH_FILES and path.exists() and _is_runs_file(path.parent / RUNS_FILE):
        return Owned("bench", f"the {path.name} of the rrtpso bench in '{folder}'")
    return None


def _rows_of(path: str | Path) -> int | None:
    """The rows of the results file at ``path`` (None: not one, or not readable)."""
    fd, _ = _open(path)
    if fd is None:
        return None
    try:
        return _count_rows(fd) if stat.S_ISREG(os.fstat(fd).st_mode) else None
    finally:
        os.close(fd)


def _is_runs_file(path: Path) -> bool:
    """Whether a bench folder's ``runs.jsonl`` is a results file (rows, or locked: a bench
    writing its first row)."""
    with inspected(path) as found:
        return found is not None and found not in (ABSENT, MOVED)


def _has_bench_outputs(folder: Path) -> bool:
    """Whether ``folder`` holds what a bench writes besides its rows (a report, the database, a
    log of a bench)."""
    if any((folder / name).is_file() for name in BENCH_FILES):
        return True
    try:
        with os.scandir(folder) as entries:
            for n, entry in enumerate(entries):
                if n >= 10_000:  # bounded: a folder that large is not a bench's
                    return False
                if entry.name.endswith(".log") and is_bench_log(entry.path):
                    return True
    except OSError:
        return False
    return False
