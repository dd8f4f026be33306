"""Publishing results: files appear whole or not at all, nothing that is not ours is clobbered,
and JSON holds only what JSON can.

Where a result goes decides how it is written (:func:`publish`):

- a new file, or an existing regular file: written to a temporary file beside it and renamed
  over it, so a reader never sees half a file; an existing file keeps its permissions;
- a symbolic link: written through to its target (by the rules for the target), the link stays;
- a fifo, a character device or ``-`` (standard output): streamed directly, since renaming over
  them would replace the fifo (its reader would get nothing) or the device node.

Everything that writes a file goes through :func:`atomic_path` (for writers that need a file
name: matplotlib, SQLite) or :func:`write_text_atomic`.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import stat
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "STDOUT",
    "atomic_path",
    "finite",
    "is_stream",
    "json_line",
    "publish",
    "silence_stdout",
    "write_json_atomic",
    "write_text_atomic",
]

#: The output name that means standard output.
STDOUT = "-"


def is_stream(path: str | Path) -> bool:
    """Whether ``path`` is written as a stream: ``-``, or an existing fifo or character device
    (after following links)."""
    if str(path) == STDOUT:
        return True
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISCHR(mode)


def silence_stdout() -> None:
    """Point standard output at /dev/null once its reader went away (a closed pipe).

    What is still buffered or written later is dropped instead of raising BrokenPipeError again,
    also in Python's own flush at exit (the way Python's documentation of SIGPIPE advises).
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    finally:
        os.close(devnull)


def _resolved(path: str | Path) -> Path:
    """``path`` with symbolic links followed (also a dangling link's target)."""
    return Path(os.path.realpath(path))


def publish(tmp: str | Path, path: str | Path) -> None:
    """Move a finished temporary file to ``path`` by the rules of the module docstring."""
    if str(path) == STDOUT:
        with open(tmp, "rb") as src:
            try:
                sys.stdout.flush()
                shutil.copyfileobj(src, sys.stdout.buffer)
                sys.stdout.buffer.flush()
            except BrokenPipeError:
                # The reader left (`--json - | head -c 100`): its choice, not an error; the
                # command goes on and exits with its own status (0 solved, 1 unsolved).
                silence_stdout()
        Path(tmp).unlink(missing_ok=True)
        return
    target = _resolved(path)
    if is_stream(target):
        with open(tmp, "rb") as src, open(target, "wb") as dst:
            shutil.copyfileobj(src, dst)
        Path(tmp).unlink(missing_ok=True)
        return
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)  # an existing file keeps its permissions
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask  # what any new file gets (mkstemp's files are owner-only)
    os.chmod(tmp, mode)
    os.replace(tmp, target)


@contextmanager
def atomic_path(path: str | Path, suffix: str | None = None) -> Iterator[str]:
    """A temporary file name to write to; published to ``path`` (:func:`publish`) when the block
    ends without an exception, removed otherwise.

    The temporary file lies beside the (resolved) target, so the final rename is atomic; for a
    stream target it lies in the system's temporary folder. Its name ends in ``suffix`` (default:
    ``path``'s), for writers that choose the format by it (matplotlib, Pillow).
    """
    name = Path(path)
    if is_stream(path):
        folder = None
    else:
        folder = _resolved(path).parent
        folder.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{name.stem or 'out'}.",
                               suffix=suffix or name.suffix or ".tmp", dir=folder)  # fmt: skip
    os.close(fd)
    try:
        yield tmp
        publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text_atomic(text: str, path: str | Path) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) by the rules of :func:`publish`."""
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    return Path(path)


def write_json_atomic(data: Any, path: str | Path) -> None:
    """Write JSON (NaN and infinities as null) by the rules of :func:`publish`."""
    text = json.dumps(finite(data), indent=2, allow_nan=False, default=_json_default) + "\n"
    write_text_atomic(text, path)


def json_line(row: Any) -> str:
    """One JSON-lines row: compact, NaN and infinities as null, ending in a newline."""
    return json.dumps(finite(row), allow_nan=False, default=_json_default) + "\n"


def finite(obj: Any) -> Any:
    """The same data with NaN and infinities as None (JSON has neither)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [finite(v) for v in obj]
    return obj


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return finite(obj.tolist())
    if isinstance(obj, np.generic):
        return finite(obj.item())
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
