"""The JSON-lines results file of a batch: one writer at a time, appended to, never replaced.

- **One writer.** The file is locked (``flock``) for as long as a batch writes it; a second batch
  with the same ``--out`` is refused at once instead of racing the first.
- **Never replaced, only appended to.** Rows are written one whole line per ``write`` as runs
  finish, so an interrupted batch leaves a valid file. A resumed batch appends the rows of the
  runs still to do (an error row is retried, and the retry's row comes later: the last row of a
  run counts, :func:`latest_rows`). A torn last line (a batch killed mid-write) is cut off.
- **Only ours.** A file that is not empty is continued only with ``resume`` and started afresh
  only with ``overwrite``, and either only when it is a results file: every line a row of this
  package, and an unterminated last line only when it is the beginning of one (rows are written
  ``file`` first: :data:`ROW_START`). Anything else (notes, another program's output, a stray
  ``{"keep": 1}``, binary data, a file of blank lines) is refused, never touched. ``overwrite``
  empties the file only when the first new row is ready, and puts the earlier rows back if that
  row cannot be written, so a batch that fails before its first row leaves them as they were.
- **Nothing left behind.** A row that cannot be written (the disk is full) is cut back off, so
  the file stays valid line by line, and the batch ends with an
  :class:`~rrtpso_ompl.errors.OutputError`; a file the batch created and left empty is removed.
- **Streams.** ``-`` (standard output), a fifo or a character device is written as a stream: no
  lock, nothing to resume.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any, BinaryIO, NoReturn

from ..errors import OutputError, UsageError
from ..outputs import (
    STDOUT,
    is_stream,
    json_line,
    make_folders,
    os_reason,
    remove_folders,
    stdout_closed,
)
from ..ownership import ROW_KEYS, ROW_START, is_row
from .record import RunKey, RunRecord, resolved_source

try:  # advisory locks; absent on Windows, where a second writer is not detected
    import fcntl
except ImportError:  # pragma: no cover - platform dependent
    fcntl = None  # type: ignore[assignment]

__all__ = [
    "ROW_KEYS",
    "ROW_START",
    "ResultsFile",
    "is_row",
    "is_torn_row",
    "latest_rows",
    "read_rows",
    "resolved_source",
]

#: Attempts at opening and locking the file while other batches create and remove it.
_OPEN_ATTEMPTS = 10


def is_torn_row(tail: bytes) -> bool:
    """Whether an unterminated last line is a row of this package cut short (by a kill)."""
    try:
        obj = json.loads(tail)
    except (json.JSONDecodeError, UnicodeDecodeError):
        return tail.startswith(ROW_START) or ROW_START.startswith(tail)
    return is_row(obj)  # a whole row whose newline was not written


def latest_rows(rows: Iterable[RunRecord]) -> list[RunRecord]:
    """One row per run (:attr:`RunRecord.key`), the last written (a retried error row is
    superseded by its retry), in the order the runs first appear."""
    latest: dict[RunKey, RunRecord] = {}
    for row in rows:
        latest.pop(row.key, None)  # re-insert: the retry takes the place of its run
        latest[row.key] = row
    return list(latest.values())


def read_rows(path: str | Path) -> list[RunRecord]:
    """The complete rows of a results file, one per run (:func:`latest_rows`); a torn last line
    and lines that are not rows are skipped. Rows of earlier versions are read too
    (:meth:`RunRecord.from_json`)."""
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
            record = _record(obj)
            if record is not None:
                rows.append(record)
    return latest_rows(rows)


def _record(obj: Any) -> RunRecord | None:
    """The record of a parsed line, or None when it is not a row of this package."""
    if not is_row(obj):
        return None
    try:
        return RunRecord.from_json(obj)
    except ValueError:
        return None


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

    Raises
    ------
    UsageError
        On entering: the file is being written by another batch, is not a results file, or holds
        rows and neither ``resume`` nor ``overwrite`` is given.
    OutputError
        The file cannot be opened, or (:meth:`append`) a row cannot be written.
    """

    def __init__(self, path: str | Path, *, resume: bool = False, overwrite: bool = False,
                 flag: str = "--out") -> None:  # fmt: skip
        self.path = str(path)
        self.resume = resume
        self.overwrite = overwrite
        self.flag = flag
        self.kept: list[RunRecord] = []
        self._fh: BinaryIO | None = None
        self._fd: int | None = None
        self._target: Path | None = None
        self._created = False  # the file did not exist before this batch
        self._made: list[Path] = []  # the folders made for it
        self._empty_first = False  # --overwrite: empty the file before the first new row
        self._earlier = b""  # --overwrite: what the file held, until a new row is written

    # -- opening -------------------------------------------------------------------------------
    def __enter__(self) -> ResultsFile:
        if is_stream(self.path):
            if self.resume:
                raise UsageError(f"{self.flag} {self.path}: a stream cannot be resumed")
            if self.path == STDOUT:
                if stdout_closed():
                    raise OutputError(STDOUT, "it is closed")
                self._fh = sys.stdout.buffer
                return self
            try:
                self._fh = open(os.path.realpath(self.path), "wb")  # closed on exit
            except OSError as exc:
                raise OutputError(self.path, os_reason(exc)) from None
            return self
        target = Path(os.path.realpath(self.path))
        try:
            self._made = make_folders(target.parent)
            self._open(target)
        except OSError as exc:  # OutputError included
            remove_folders(self._made)
            raise OutputError(self.path, os_reason(exc)) from None
        try:
            self.kept = self._take_over()
        except BaseException as exc:
            self._close()
            if isinstance(exc, OSError) and not isinstance(exc, OutputError):
                raise OutputError(self.path, os_reason(exc)) from None
            raise
        return self

    def _open(self, target: Path) -> None:
        """Open and lock ``target``, creating it when absent (and remembering that we did)."""
        flags = os.O_RDWR | os.O_APPEND | getattr(os, "O_CLOEXEC", 0)
        for _ in range(_OPEN_ATTEMPTS):
            try:
                self._fd = os.open(target, flags | os.O_CREAT | os.O_EXCL, 0o666)
                self._created = True
            except FileExistsError:
                try:
                    self._fd = os.open(target, flags)
                except FileNotFoundError:
                    continue  # removed in between (another batch's empty file): create it
                self._created = False
            self._target = target
            try:
                self._lock()
            except BaseException:
                self._created = False  # not ours to remove: another batch holds it
                self._close()
                raise
            if self._names_our_file():
                return
            self._created = False
            self._close()  # removed or replaced before we held the lock: open it again
        raise OSError(0, "other batches keep creating and removing this file")

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

    def _names_our_file(self) -> bool:
        """Whether the path still names the file we hold (not one removed meanwhile)."""
        try:
            ours, now = os.fstat(self._fd), os.stat(self._target)
        except OSError:
            return False
        return (ours.st_dev, ours.st_ino) == (now.st_dev, now.st_ino)

    def _take_over(self) -> list[RunRecord]:
        """Check what the file holds and prepare it for appending; the rows to keep."""
        content = self._read()
        if not content:
            return []  # a new or empty file: nothing to lose
        complete, _, torn = content.rpartition(b"\n")
        lines = complete.split(b"\n") if complete else []
        rows = self._rows(lines)
        if torn and not is_torn_row(torn):
            self._refuse(f"its last line, {len(lines) + 1}, is not one of its rows")
        if not rows and not torn:
            self._refuse("it holds blank lines only")
        if not (self.resume or self.overwrite):
            cut = " (and a row cut short)" if torn else ""
            raise UsageError(
                f"{self.flag} {self.path}: the file already holds {len(rows)} rows{cut} of an "
                "earlier run; continue them with --resume or start afresh with --overwrite"
            )
        if self.overwrite:
            self._empty_first = True  # when the first new row is ready, not before
            self._earlier = content  # put back if that row cannot be written
            return []
        if torn:  # a batch killed mid-write: drop the half line, its run runs again
            os.ftruncate(self._fd, len(content) - len(torn))
        return latest_rows(rows)

    def _refuse(self, why: str) -> NoReturn:
        raise UsageError(
            f"{self.flag} {self.path}: not a results file of rrtpso batch or bench ({why}); it is "
            "left as it is: choose another file"
        )

    def _read(self) -> bytes:
        chunks = []
        offset = 0
        while chunk := os.pread(self._fd, 1 << 20, offset):
            chunks.append(chunk)
            offset += len(chunk)
        return b"".join(chunks)

    def _rows(self, lines: list[bytes]) -> list[RunRecord]:
        rows = []
        for number, line in enumerate(lines, start=1):
            if not line.strip():
                continue
            try:
                obj = json.loads(line)
            except (json.JSONDecodeError, UnicodeDecodeError):
                obj = None
            record = _record(obj)
            if record is None:
                self._refuse(f"line {number} is not one of its rows")
            rows.append(record)
        return rows

    # -- writing -------------------------------------------------------------------------------
    def append(self, row: RunRecord) -> None:
        """Write one row as one whole line (:meth:`RunRecord.to_json`: ``file`` first,
        :data:`ROW_START`).

        Raises
        ------
        OutputError
            When the line cannot be written (the disk is full, the reader of a stream went away);
            a file is cut back to the rows before it, so it stays valid line by line.
        """
        data = json_line(row.to_json()).encode("utf-8")
        if self._fh is not None:
            try:
                self._fh.write(data)
                self._fh.flush()
            except BrokenPipeError:
                if self.path == STDOUT:
                    raise  # the reader went away: the batch stops quietly (cli.main)
                raise OutputError(self.path, "its reader went away") from None
            except OSError as exc:
                raise OutputError(self.path, os_reason(exc)) from None
            return
        start, earlier = None, b""
        try:
            if self._empty_first:  # --overwrite: the earlier rows go now that a new one is here
                earlier, self._earlier = self._earlier, b""
                self._empty_first = False
                os.ftruncate(self._fd, 0)
            start = os.fstat(self._fd).st_size
            self._write(data)
        except OSError as exc:
            with contextlib.suppress(OSError):
                if start is not None:
                    os.ftruncate(self._fd, start)  # no torn line left behind
                if earlier:  # the first new row failed: the earlier rows stay after all
                    try:
                        self._write(earlier)
                    except OSError:
                        os.ftruncate(self._fd, 0)  # valid, if empty
            raise OutputError(self.path, os_reason(exc)) from None

    def _write(self, data: bytes) -> None:
        view = memoryview(data)
        while view:
            view = view[os.write(self._fd, view) :]

    def __exit__(self, *exc: Any) -> None:
        self._close()
        if self._fh is not None and self._fh is not getattr(sys.stdout, "buffer", None):
            with contextlib.suppress(OSError):  # a failed write has said so already
                self._fh.close()
        self._fh = None

    def _close(self) -> None:
        """Release the file (closing releases the lock); one we created and left empty goes."""
        if self._fd is None:
            return
        try:
            if self._created and os.fstat(self._fd).st_size == 0 and self._names_our_file():
                os.unlink(self._target)
                remove_folders(self._made)
        except OSError:
            pass  # the file stays, empty and valid
        finally:
            os.close(self._fd)
            self._fd = None
