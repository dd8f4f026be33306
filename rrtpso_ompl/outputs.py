"""Publishing results: files appear whole or not at all, and JSON holds only what JSON can."""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "atomic_path",
    "finite",
    "json_line",
    "publish_atomic",
    "write_json_atomic",
    "write_text_atomic",
]


def publish_atomic(tmp: str | Path, path: str | Path) -> None:
    """Give a finished temporary file the usual permissions and rename it to ``path``.

    ``tempfile.mkstemp`` creates files readable by their owner only; a result file should get the
    permissions any new file gets (0666 less the umask).
    """
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, path)


@contextmanager
def atomic_path(path: str | Path, suffix: str | None = None) -> Iterator[str]:
    """A temporary file name next to ``path`` to write to; renamed to ``path`` when the block ends
    without an exception, removed otherwise. A reader never sees half a file.

    The temporary name ends in ``suffix`` (default: ``path``'s), for writers that choose the
    format by it (matplotlib, Pillow).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=suffix or path.suffix or ".tmp",
                               dir=path.parent)  # fmt: skip
    os.close(fd)
    try:
        yield tmp
        publish_atomic(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text_atomic(text: str, path: str | Path) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    return Path(path)


def write_json_atomic(data: Any, path: str | Path) -> None:
    """Write JSON through a temporary file and a rename, so a reader never sees half a file."""
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
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
