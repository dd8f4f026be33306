"""Typed results: what a solve returns and what ``rrtpso solve --json`` writes."""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "SolveResult",
    "atomic_path",
    "publish_atomic",
    "write_json_atomic",
    "write_text_atomic",
]


@dataclass(frozen=True)
class SolveResult:
    """The outcome of solving one problem with one planner.

    Attributes
    ----------
    problem : str
        Problem name.
    planner : str
        Planner name as selected.
    status : str
        ``"exact"``, ``"approximate"`` or ``"none"`` (the contract's three values).
    ompl_status : str
        OMPL's own status text (``"Exact solution"``, ``"Timeout"``, ``"Crash"``, ...).
    solved : bool
        True only for an exact path that passed the exact validity check.
    length : float or None
        Euclidean length of ``path`` in problem units.
    time : float
        Wall-clock seconds spent in the planner.
    seed : int or None
        The seed OMPL and numpy ran with.
    path : (n, 2) ndarray
        The returned polyline (empty when there is none).
    time_limit : float
        The budget, seconds.
    params : dict
        Planner parameters as applied.
    stages : dict
        Per-stage figures (for RRTstarPSO: RRT* and PSO lengths, times, iterations, PSO best cost
        per iteration).
    clearance : float or None
        Smallest distance from the path to an obstacle, minus the robot radius (>= 0 when valid).
    valid : bool
        Whether ``path`` passed the exact check (bounds, every segment, robot radius).
    """

    problem: str
    planner: str
    status: str
    ompl_status: str
    solved: bool
    length: float | None
    time: float
    seed: int | None
    path: np.ndarray = field(repr=False)
    time_limit: float = 0.0
    params: dict[str, Any] = field(default_factory=dict)
    stages: dict[str, Any] = field(default_factory=dict)
    clearance: float | None = None
    valid: bool = False

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary with the contract's keys first."""
        return {
            "problem": self.problem,
            "planner": self.planner,
            "status": self.status,
            "solved": self.solved,
            "length": self.length,
            "time": self.time,
            "seed": self.seed,
            "path": np.asarray(self.path, dtype=float).reshape(-1, 2).tolist(),
            "ompl_status": self.ompl_status,
            "time_limit": self.time_limit,
            "valid": self.valid,
            "clearance": _finite(self.clearance),
            "params": self.params,
            "stages": self.stages,
        }


def _finite(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


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
    text = json.dumps(data, indent=2, allow_nan=False, default=_json_default) + "\n"
    write_text_atomic(text, path)


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")
