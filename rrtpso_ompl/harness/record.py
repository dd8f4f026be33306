"""One run of a batch or a bench, typed: :class:`RunRecord`, the row of a results file.

A results file (``rrtpso batch --out``, a bench's ``runs.jsonl``) holds one JSON object per line,
one per run. :class:`RunRecord` is that row as a frozen dataclass: the batch makes it, the
results file writes and reads it (:meth:`RunRecord.to_json`, :meth:`RunRecord.from_json`), and
the bench, the report, the command line's progress and the benchmark scripts read its
attributes. The JSON keys, their order and their meaning are the results-file format of
``docs/benchmarking.md`` and do not change with this class: outside tools read the files, and
rows written by earlier versions (without the keys added since) are read back.

A run's identity is :attr:`RunRecord.key`, a :class:`RunKey`: the problem file resolved, the
planner, the seed, the budget and the settings (the caller's parameters, OMPL's simplifier, the
package's version). A batch task has the same identity
(:attr:`~rrtpso_ompl.harness.batch.Task.key`), which is how ``--resume`` finds the runs done.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from ..ownership import ROW_KEYS
from ..planners.result import BenchmarkRun

__all__ = ["ROW_KEYS", "RunKey", "RunRecord", "resolved_source", "settings_key"]


def resolved_source(file: str) -> str:
    """A problem file's path resolved: absolute, links followed (the ``source`` of its rows)."""
    try:
        return os.path.realpath(file)
    except (OSError, ValueError):
        return file


def settings_key(settings: Mapping[str, Any] | None) -> str | None:
    """The settings of a run as canonical JSON (sorted keys, compact): equal settings give
    equal text however they were built (a tuple or a list, keys in any order). None stays None
    (a row written before rows had ``settings``: not known)."""
    if settings is None:
        return None
    return json.dumps(settings, sort_keys=True, separators=(",", ":"), default=str)


class RunKey(NamedTuple):
    """What identifies a run: the same problem file, planner, seed, budget and settings is the
    same run.

    ``source`` is the problem file resolved (:func:`resolved_source`), so that ``probs/p.yaml``
    and ``/abs/probs/p.yaml`` name the same run; ``budget`` is the time limit asked for (None:
    the file's own); ``settings`` is :func:`settings_key` of everything else that changes the
    result (the caller's parameters, OMPL's simplifier, this package's version), None when not
    known (rows written before rows had it: they are the run of no task).
    """

    source: str
    planner: str
    seed: int
    budget: float | None
    settings: str | None = None

    @classmethod
    def of(cls, file: str, planner: str, seed: int, budget: float | None,
           source: str | None = None, settings: Mapping[str, Any] | None = None
           ) -> RunKey:  # fmt: skip
        """The key of a run of ``file``; ``source`` when already resolved (else resolved here,
        relative to the working directory: rows written before rows had ``source``)."""
        where = resolved_source(file) if source is None else source
        return cls(where, planner, seed, budget, settings_key(settings))

    @property
    def configuration(self) -> tuple[str, str, float | None]:
        """The problem, planner and budget: the runs of one configuration, whatever their seed
        and settings (a resumed batch finds rows of other settings by it)."""
        return (self.source, self.planner, self.budget)


#: The keys a solve adds to a row (``rrtpso solve --json``'s beyond the first ones, and the
#: harness's ``wall``): an error row, which has no solve, has none of them.
_SOLVE_KEYS = frozenset(
    (
        "ompl_status",
        "time_limit",
        "valid",
        "clearance",
        "cost",
        "params",
        "stages",
        "benchmark",
        "wall",
    )
)
#: Keys written only when the batch looked the optimum up (``run_batch(optimum=True)``).
_OPTIMUM_KEYS = frozenset(("optimum", "ratio"))
#: Attributes that are not JSON keys.
_NOT_KEYS = frozenset(("has_optimum", "extra"))


@dataclass(frozen=True, kw_only=True)
class RunRecord:
    """One run: a problem file solved by one planner with one seed (a row of a results file).

    The attributes are the row's JSON keys, in the order the file writes them.

    Attributes
    ----------
    file : str
        The problem file as the command line named it.
    planner : str
        The planner spec as asked (``"BITstar+simplify+pso"``).
    seed : int
        The run's seed (``--seed`` plus ``run``).
    run : int
        The run's index, from 0.
    budget : float or None
        The time limit asked for, seconds (None: the file's ``planner.time_limit``).
    settings : dict or None
        What else makes the run's result (part of its identity, :class:`RunKey`): ``params``,
        the parameters the caller gave (converted, by name: the problem file's own count through
        ``inputs_sha256``), ``simplify``, whether OMPL's simplifier followed the planner, and
        ``version``, this package's. None in rows written before it existed.
    source : str or None
        ``file`` resolved (absolute, links followed); None in rows written before it existed.
    inputs_sha256 : str or None
        SHA-256 of the problem file and its map files when the run was made.
    problem : str or None
        The problem's name (None for an error row).
    status : str
        ``"exact"``, ``"approximate"``, ``"none"`` or, for a run that produced no result,
        ``"error"``.
    solved : bool
        An exact path that passed the exact validity check.
    length : float or None
        The path's length, problem units.
    time : float
        Seconds the planner spent (0 for an error row).
    path : list of [x, y] or None
        The returned path; None when the batch left paths out (``--no-path``: no ``path`` key).
    ompl_status : str or None
        OMPL's own status text.
    time_limit : float or None
        The budget the solve ran with, seconds (the file's when ``budget`` is None).
    valid : bool
        Whether the path passed the exact check.
    clearance : float or None
        Least distance from the path to an obstacle beyond the robot radius.
    cost : float or None
        The problem's objective of the path (its length without an inflation cost), problem
        units (None in rows written before it existed).
    params : dict
        The planner's parameters as applied.
    stages : dict
        The planner's per-stage figures.
    benchmark : BenchmarkRun or None
        The run in OMPL's Benchmark terms (None in rows written before it existed).
    wall : float or None
        Wall-clock seconds of the whole run in its worker, loading included.
    error : str or None
        Why the run produced no result (a bad file or planner, a crash); None otherwise.
    optimum : float or None
        The exact shortest length of the problem (None: start and goal are not connected, or an
        error row).
    ratio : float or None
        ``length / optimum`` for a solved run, else None.
    has_optimum : bool
        Whether the batch looked the optimum up: ``optimum`` and ``ratio`` are written only then.
    extra : dict
        Keys of the row this class does not know (from a newer version or another tool): kept,
        and written back after the known ones.
    """

    file: str
    planner: str
    seed: int
    run: int
    budget: float | None = None
    settings: dict[str, Any] | None = None
    source: str | None = None
    inputs_sha256: str | None = None
    problem: str | None = None
    status: str = "none"
    solved: bool = False
    length: float | None = None
    time: float = 0.0
    path: list[list[float]] | None = None
    ompl_status: str | None = None
    time_limit: float | None = None
    valid: bool = False
    clearance: float | None = None
    cost: float | None = None
    params: dict[str, Any] = field(default_factory=dict)
    stages: dict[str, Any] = field(default_factory=dict)
    benchmark: BenchmarkRun | None = None
    wall: float | None = None
    error: str | None = None
    optimum: float | None = None
    ratio: float | None = None
    has_optimum: bool = False
    extra: dict[str, Any] = field(default_factory=dict)

    # -- identity ----------------------------------------------------------------------------------
    @property
    def key(self) -> RunKey:
        """The run's identity (:class:`RunKey`): the last row of a key in a results file counts,
        and ``--resume`` skips the tasks whose key has a row."""
        return RunKey.of(self.file, self.planner, self.seed, self.budget, source=self.source,
                         settings=self.settings)  # fmt: skip

    # -- derived ---------------------------------------------------------------------------------
    @property
    def is_error(self) -> bool:
        """Whether the run produced no result (``error`` says why)."""
        return bool(self.error)

    @property
    def effective_budget(self) -> float:
        """The budget the run had, seconds: ``budget``, else the file's ``time_limit`` (0 when
        neither is known)."""
        return float(self.budget or self.time_limit or 0.0)

    @property
    def benchmark_run(self) -> BenchmarkRun:
        """:attr:`benchmark`, or for a row without one all of ``time`` as planning time."""
        return self.benchmark or BenchmarkRun(time=self.time or 0.0)

    def with_optimum(self, optimum: float | None) -> RunRecord:
        """The record with the problem's optimum and the ratio to it. Only a solved path gets a
        ratio: an approximate one stops short of the goal and can be shorter than the optimum."""
        length = self.length if self.solved else None
        ratio = length / optimum if length is not None and optimum else None
        return dataclasses.replace(self, optimum=optimum, ratio=ratio, has_optimum=True)

    # -- JSON ------------------------------------------------------------------------------------
    def to_json(self) -> dict[str, Any]:
        """The row as the results file writes it: a JSON-ready dict, ``file`` first, in the
        format's key order. Left out: ``path`` when paths were not kept, the solve's keys in an
        error row, ``optimum`` and ``ratio`` when they were not looked up."""
        out: dict[str, Any] = {}
        for f in _FIELDS:
            left_out = (
                f in _NOT_KEYS
                or (f == "path" and self.path is None)
                or (f in _SOLVE_KEYS and self.is_error)
                or (f in _OPTIMUM_KEYS and not self.has_optimum)
            )
            if left_out:
                continue
            value = getattr(self, f)
            out[f] = value.to_dict() if isinstance(value, BenchmarkRun) else value
        for k, v in self.extra.items():
            out.setdefault(k, v)
        return out

    @classmethod
    def from_json(cls, row: Mapping[str, Any]) -> RunRecord:
        """A record from a row as written by :meth:`to_json` or by any earlier version (keys
        added since are missing there and take their defaults).

        Raises
        ------
        ValueError
            When ``row`` lacks a key of :data:`ROW_KEYS` or its ``benchmark`` is malformed.
        """
        missing = [k for k in ROW_KEYS if k not in row]
        if missing:
            raise ValueError(f"not a row of a results file: no {', '.join(missing)}")
        known = {k: v for k, v in row.items() if k in _FIELDS and k not in _NOT_KEYS}
        if known.get("benchmark"):
            try:
                known["benchmark"] = BenchmarkRun.from_dict(known["benchmark"])
            except (KeyError, TypeError, ValueError, AttributeError):
                raise ValueError("not a row of a results file: a malformed benchmark") from None
        else:
            known["benchmark"] = None
        for k in ("params", "stages"):
            if known.get(k) is None:
                known.pop(k, None)
        for k, default in (("solved", False), ("valid", False), ("time", 0.0)):
            if known.get(k) is None:
                known[k] = default
        extra = {k: v for k, v in row.items() if k not in _FIELDS or k in _NOT_KEYS}
        return cls(**known, has_optimum="optimum" in row, extra=extra)

    @classmethod
    def from_solve(cls, base: Mapping[str, Any], solve: Mapping[str, Any], wall: float
                   ) -> RunRecord:  # fmt: skip
        """The record of a finished solve: ``base`` (the task's keys: ``file, planner, seed,
        run, budget, settings, source, inputs_sha256``) over ``solve`` (a
        :meth:`~rrtpso_ompl.planners.result.SolveResult.to_dict`), with its ``wall`` time."""
        return cls.from_json({**solve, **base, "wall": wall, "error": None})


_FIELDS = tuple(f.name for f in dataclasses.fields(RunRecord))
