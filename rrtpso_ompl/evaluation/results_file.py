"""The JSON-lines results file of a batch: one writer at a time, appended to, never replaced.

- **One writer.** The file is locked (``flock``) for as long as a batch writes it; a second batch
  with the same ``--out`` is refused at once instead of racing the first.
- **Never replaced, only appended to.** Rows are written one whole line per ``write`` as runs
  finish, so an interrupted batch leaves a valid file. A resumed batch appends the rows of the
  runs still to do (an error row is retried, and the retry's row comes later: the last row of a
  run counts, :func:`latest_rows`). A torn last line (a batch killed mid-write) is cut off.
- **Only ours.** A file that is not empty is continued only with ``resume`` and started afresh
  only with ``overwrite``, and either only when every line is a row of this package; anything
  else (notes, another program's output, a stray ``{"keep": 1}``) is refused, never touched.
- **Streams.** ``-`` (standard output), a fifo or a character device is written as a stream: no
  lock, nothing to resume.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, BinaryIO

from ..errors import UsageError
from ..outputs import STDOUT, is_stream, json_line

try:  # advisory locks; absent on Windows, where a second writer is not detected
    import fcntl
except ImportError:  # pragma: no cover - platform dependent
    fcntl = None  # type: ignore[assignment]

__all__ = ["ROW_KEYS", "ResultsFile", "is_row", "latest_rows", "read_rows", "row_key"]

#: Keys every row of a batch has (error rows included): what makes a line recognisably ours.
ROW_KEYS = ("file", "planner", "seed", "run", "status")


def is_row(obj: Any) -> bool:
    """Whether a parsed JSON line is a row of this package's batches."""
    return isinstance(obj, dict) and all(k in obj for k in ROW_KEYS)


def row_key(row: Mapping[str, Any]) -> tuple[Any, ...]:
    """What identifies a run: ``(file, planner, seed, budget)``."""
    return (row.get("file"), row.get("planner"), row.get("seed"), row.get("budget"))


def latest_rows(rows: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """One row per run, the last written (a retried error row is superseded by its retry), in
    the order the runs first appear."""
    latest: dict[tuple[Any, ...], dict[str, Any]] = {}
    for row in rows:
        latest.pop(row_key(row), None)  # re-insert: the retry takes the place of its run
        latest[row_key(row)] = dict(row)
    return list(latest.values())


def read_rows(path: str | Path) -> list[dict[str, Any]]:
    """The complete rows of a results file, one per run (:func:`latest_rows`); a torn last line
    and lines that are not rows are skipped."""
    p = Path(path)
    if not p.exists():
        return []
    rows = []
    with p.open("rb") as fh:
        for line in fh:
            try:
                obj = json.loads(line)
            except (json.JSONDecodeError, UnicodeDecodeError):
                continue
            if is_row(obj):
                rows.append(obj)
    return latest_rows(rows)


class ResultsFile:
    """A results file held for writing (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The file (a link is followed), ``-`` for standard output, or a fifo.
    resume : bool
        Continue the rows the file holds.
    overwrite : bool
        Start afresh even when the file holds rows (of this package: nothing else is replaced).
    flag : str
        How the command line names the file (``--out``), for messages.

    Use as a context manager; :attr:`kept` holds the rows kept from the file (with ``resume``).
    """

    def __init__(self, path: str | Path, *, resume: bool = False, overwrite: bool = False,
                 flag: str = "--out") -> None:  # fmt: skip
        self.path = str(path)
        self.resume = resume
        self.overwrite = overwrite
        self.flag = flag
        self.kept: list[dict[str, Any]] = []
        self._fh: BinaryIO | None = None
        self._fd: int | None = None

    # -- opening -------------------------------------------------------------------------------
    def __enter__(self) -> ResultsFile:
        if is_stream(self.path):
            if self.resume:
                raise UsageError(f"{self.flag} {self.path}: a stream cannot be resumed")
            if self.path == STDOUT:
                self._fh = sys.stdout.buffer
            else:
                self._fh = open(os.path.realpath(self.path), "wb")
            return self
        target = Path(os.path.realpath(self.path))
        target.parent.mkdir(parents=True, exist_ok=True)
        self._fd = os.open(target, os.O_RDWR | os.O_CREAT | os.O_APPEND, 0o666)
        try:
            self._lock()
            self.kept = self._take_over()
        except BaseException:
            os.close(self._fd)
            self._fd = None
            raise
        return self

    def _lock(self) -> None:
        if fcntl is None:
            return
        try:
            fcntl.flock(self._fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise UsageError(
                f"{self.flag} {self.path}: another rrtpso batch or bench is writing this file; "
                "wait for it to finish or choose another file"
            ) from None

    def _take_over(self) -> list[dict[str, Any]]:
        """Check what the file holds and prepare it for appending; the rows to keep."""
        content = self._read()
        if not content.strip():
            os.ftruncate(self._fd, 0)
            return []
        complete, _, torn = content.rpartition(b"\n")
        rows = self._rows(complete.split(b"\n") if complete else [])
        if not (self.resume or self.overwrite):
            raise UsageError(
                f"{self.flag} {self.path}: the file already holds {len(rows)} rows of an earlier "
                "run; continue them with --resume or start afresh with --overwrite"
            )
        if self.overwrite:
            os.ftruncate(self._fd, 0)
            return []
        if torn:  # a batch killed mid-write: drop the half line, its run runs again
            os.ftruncate(self._fd, len(complete) + 1 if complete else 0)
        return latest_rows(rows)

    def _read(self) -> bytes:
        chunks = []
        offset = 0
        while chunk := os.pread(self._fd, 1 << 20, offset):
            chunks.append(chunk)
            offset += len(chunk)
        return b"".join(chunks)

    def _rows(self, lines: list[bytes]) -> list[dict[str, Any]]:
        rows = []
        for number, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except (json.JSONDecodeError, UnicodeDecodeError):
                obj = None
            if not is_row(obj):
                raise UsageError(
                    f"{self.flag} {self.path}: not a results file of rrtpso batch or bench (line "
                    f"{number} is not one of its rows); it is left as it is: choose another file"
                )
            rows.append(obj)
        return rows

    # -- writing -------------------------------------------------------------------------------
    def append(self, row: Mapping[str, Any]) -> None:
        """Write one row as one whole line."""
        data = json_line(row).encode("utf-8")
        if self._fh is not None:
            self._fh.write(data)
            self._fh.flush()
            return
        view = memoryview(data)
        while view:
            view = view[os.write(self._fd, view) :]

    def __exit__(self, *exc: Any) -> None:
        if self._fd is not None:
            os.close(self._fd)  # closing releases the lock
            self._fd = None
        if self._fh is not None and self._fh is not sys.stdout.buffer:
            self._fh.close()
        self._fh = None
