"""OMPL benchmark logs: write them, and turn them into Planner Arena's SQLite database.

The text format is the one ``ompl::tools::Benchmark::saveResultsToStream`` emits and that OMPL's
``ompl_benchmark_statistics`` (``ompl._benchmark_statistics.readBenchmarkLog``) parses into the
database Planner Arena reads::

    rrtpso-ompl version 0.1.0
    Experiment single_circle
    1 experiment properties
    num_obstacles INTEGER = 1
    Running on host
    Starting at 2026-11-22 17:49:20
    <<<|
    free-text setup
    |>>>
    42 is the random seed
    5.0 seconds per run
    4096.0 MB per run
    3 runs per planner
    12.5 seconds spent to collect the data
    1 enum type
    status|Unknown status|Invalid start|...|Exact solution|Crash|Abort|Infeasible
    1 planners
    geometric_RRTstarPSO
    1 common properties
    range = 25.0
    2 properties for each run
    time REAL
    status ENUM
    3 runs
    0.51; 6;
    ...
    2 progress properties for each run
    time REAL
    best cost REAL
    3 runs
    0.05,13.1,;0.1,12.5,;
    ...
    .

What the parser makes of it (``readBenchmarkLog``):

- ``experiments.version`` is ``"<library> <version>"`` (``"rrtpso-ompl 0.1.0"``).
- Run and progress property names become columns with spaces replaced by ``_``
  (``solution length`` -> ``solution_length``); experiment property names lose their spaces and
  have ``-`` replaced by ``_``.
- A run value that is empty, ``nan`` or ``inf`` is stored as NULL. This writer writes None and
  missing values as empty fields, NaN as ``nan`` and ±inf as ``inf`` / empty, so every one of them
  becomes NULL (the sign of an infinity is lost, as it is with OMPL's own logs).
- ``status`` is stored as the integer enum code; the ``enums`` table maps codes to
  :data:`STATUS_ENUM` names (only if the database has no ``status`` enum yet).

:func:`build_database` runs that converter in a child process, so OMPL's nanobind messages and any
crash stay out of the caller's process.
"""

from __future__ import annotations

import datetime
import math
import numbers
import os
import re
import shutil
import socket
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import OutputError
from ..outputs import atomic_path, write_text_atomic

__all__ = [
    "PROPERTY_TYPES",
    "STATUS_ENUM",
    "Experiment",
    "PlannerRuns",
    "build_database",
    "format_log",
    "status_code",
    "write_log",
]

#: OMPL's ``PlannerStatus::StatusType`` names, in enum order (the index is the ENUM value).
#: OMPL 2.0.1's ``asString`` returns "Unknown status" for ABORT (8) and INFEASIBLE (9); this
#: writer names them properly.
STATUS_ENUM: tuple[str, ...] = (
    "Unknown status",
    "Invalid start",
    "Invalid goal",
    "Unrecognized goal type",
    "Timeout",
    "Approximate solution",
    "Exact solution",
    "Crash",
    "Abort",
    "Infeasible",
)

#: Property types the log format (and Planner Arena) understands.
PROPERTY_TYPES: tuple[str, ...] = ("BOOLEAN", "INTEGER", "REAL", "ENUM")

#: This project's short status labels (:class:`~rrtpso_ompl.planners.SolveResult.status`).
_SHORT_STATUS = {"exact": 6, "approximate": 5, "none": 4}

#: Planner-name prefixes Planner Arena strips.
_PLANNER_PREFIXES = ("geometric_", "control_")

#: Columns the parser creates itself; a property may not reuse them.
_EXPERIMENT_COLUMNS = frozenset(
    {
        "id",
        "name",
        "totaltime",
        "timelimit",
        "memorylimit",
        "runcount",
        "version",
        "hostname",
        "cpuinfo",
        "date",
        "seed",
        "setup",
    }
)
_RUN_COLUMNS = frozenset({"id", "experimentid", "plannerid"})
_PROGRESS_COLUMNS = frozenset({"runid"})

# A property name: words of letters, digits and underscores separated by single spaces (the parser
# pastes the name straight into ``ALTER TABLE ... ADD <name> <type>`` after replacing spaces).
_PROPERTY_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?: [A-Za-z0-9_]+)*")
_EXPERIMENT_PROPERTY_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*(?: [A-Za-z0-9_-]+)*")


@dataclass
class PlannerRuns:
    """All runs of one planner configuration within an experiment.

    Attributes
    ----------
    name : str
        Planner name, e.g. ``"RRTstarPSO"``; written as ``geometric_<name>`` (a name that already
        starts with ``geometric_`` or ``control_`` is written unchanged). No whitespace or ``|``.
    settings : dict of str to object
        The planner's common properties, written sorted by key as ``key = value`` lines (stored
        in ``plannerConfigs.settings``). Booleans are written as 1/0, floats with full precision.
    run_properties : list of (str, str)
        ``(name, TYPE)`` per run property, TYPE one of :data:`PROPERTY_TYPES`, e.g.
        ``("time", "REAL")``; column order of the ``runs`` table.
    runs : list of dict of str to object
        One dict per run, keyed by property name. A missing key or None is an empty field (NULL).
        A ``status`` ENUM value may be a status name or label (see :func:`status_code`).
    progress_properties : list of (str, str), optional
        ``(name, TYPE)`` per progress property, e.g. ``[("time", "REAL"), ("best cost", "REAL")]``.
    progress : list of list of tuple of float, optional
        Per run (same order as ``runs``): the sampled rows, values in ``progress_properties``
        order. Runs without progress data may be left out at the end.
    """

    name: str
    settings: dict[str, object]
    run_properties: list[tuple[str, str]]
    runs: list[dict[str, object]]
    progress_properties: list[tuple[str, str]] = field(default_factory=list)
    progress: list[list[tuple[float, ...]]] = field(default_factory=list)


@dataclass
class Experiment:
    """One benchmark experiment: a problem, several planners, ``run_count`` runs each.

    Attributes
    ----------
    name : str
        Experiment (problem) name; no whitespace (the parser keeps only the last word).
    planners : list of PlannerRuns
        The planners' data, in log order.
    time_limit : float
        Seconds allowed per run.
    run_count : int
        Runs per planner.
    seed : int or None, optional
        The random seed; None is written as 0 (what the parser itself stores for MoveIt logs).
    memory_limit : float, optional
        MB allowed per run.
    total_time : float, optional
        Seconds spent collecting the data.
    host : str, optional
        Host name; default :func:`socket.gethostname`. No whitespace.
    date : str, optional
        Start date; default now, as OMPL writes it (``2026-11-22 17:49:20``).
    setup : str, optional
        Free-text setup description (the required ``<<<| ... |>>>`` block).
    cpuinfo : str, optional
        Free-text CPU description; the optional block is left out when empty (NULL).
    properties : dict of str to object, optional
        Experiment properties, written ``name TYPE = value``. The type is inferred: bool ->
        BOOLEAN, integer -> INTEGER, real -> REAL, anything else -> TEXT; pass a
        ``(value, "TYPE")`` tuple to choose the SQL type yourself.
    library : str, optional
        Library name of the version line ``<library> version <version>``.
    version : str, optional
        Version; default ``rrtpso_ompl.__version__``.
    """

    name: str
    planners: list[PlannerRuns]
    time_limit: float
    run_count: int
    seed: int | None = None
    memory_limit: float = 4096.0
    total_time: float = 0.0
    host: str = ""
    date: str = ""
    setup: str = ""
    cpuinfo: str = ""
    properties: dict[str, object] = field(default_factory=dict)
    library: str = "rrtpso-ompl"
    version: str = ""


def status_code(status: object) -> int:
    """The OMPL ``status`` ENUM code of a planner status.

    Parameters
    ----------
    status : str or int or ompl.base.PlannerStatus
        OMPL's status text (``"Exact solution"``, case-insensitive; ``"EXACT_SOLUTION"`` works
        too), one of this project's labels ``"exact"`` / ``"approximate"`` / ``"none"``
        (-> Timeout), an integer code, or an object with OMPL's ``asString()``.

    Returns
    -------
    int
        Index into :data:`STATUS_ENUM`; 0 ("Unknown status") for anything unrecognised.
    """
    if isinstance(status, (bool, np.bool_)):
        return 0
    if isinstance(status, numbers.Integral):
        code = int(status)
        return code if 0 <= code < len(STATUS_ENUM) else 0
    if not isinstance(status, str) and hasattr(status, "asString"):
        status = status.asString()
    if not isinstance(status, str):
        return 0
    key = " ".join(status.strip().lower().replace("_", " ").split())
    if key in _SHORT_STATUS:
        return _SHORT_STATUS[key]
    for code, text in enumerate(STATUS_ENUM):
        if key == text.lower():
            return code
    return 0


# --------------------------------------------------------------------------- formatting helpers


def _check_word(what: str, value: str) -> str:
    """A single non-empty token without whitespace (the parser reads one token)."""
    if not isinstance(value, str) or not value or len(value.split()) != 1 or value != value.strip():
        raise ValueError(f"{what} must be one word without whitespace, got {value!r}")
    return value


def _check_line(what: str, value: str) -> str:
    if "\n" in value or "\r" in value:
        raise ValueError(f"{what} must not contain a line break: {value!r}")
    return value


def _format_real(value: object, where: str) -> str:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{where}: expected a real number, got {value!r}")
    x = float(value)
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else ""
    return repr(x)


def _format_integer(value: object, where: str) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(int(value))
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        x = float(value)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf" if x > 0 else ""
        if x.is_integer():
            return str(int(x))
    raise ValueError(f"{where}: expected an integer, got {value!r}")


def _format_boolean(value: object, where: str) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, numbers.Real):
        x = float(value)
        if math.isnan(x):
            return "nan"
        if x in (0.0, 1.0):
            return str(int(x))
    raise ValueError(f"{where}: expected a boolean, got {value!r}")


def _format_enum(value: object, where: str, *, is_status: bool) -> str:
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{where}: expected an enum code, got {value!r}")
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if is_status and (isinstance(value, str) or hasattr(value, "asString")):
        return str(status_code(value))
    raise ValueError(f"{where}: expected an integer enum code, got {value!r}")


def _format_value(value: object, ptype: str, name: str, where: str) -> str:
    """One run/progress field; None is an empty field."""
    if value is None:
        return ""
    if ptype == "REAL":
        return _format_real(value, where)
    if ptype == "INTEGER":
        return _format_integer(value, where)
    if ptype == "BOOLEAN":
        return _format_boolean(value, where)
    return _format_enum(value, where, is_status=name == "status")


def _check_properties(
    props: Sequence[tuple[str, str]], what: str, reserved: frozenset[str]
) -> list[tuple[str, str]]:
    """Validate ``(name, TYPE)`` pairs; return them with upper-case types."""
    out: list[tuple[str, str]] = []
    columns: set[str] = set()
    for item in props:
        try:
            name, ptype = item
        except (TypeError, ValueError):
            raise ValueError(f"{what}: expected (name, TYPE) pairs, got {item!r}") from None
        if not isinstance(name, str) or ";" in name or "," in name:
            raise ValueError(f"{what}: property name {name!r} must not contain ';' or ','")
        if not _PROPERTY_NAME.fullmatch(name):
            raise ValueError(
                f"{what}: property name {name!r} must be words of letters, digits and '_' "
                "separated by single spaces"
            )
        ptype = str(ptype).upper()
        if ptype not in PROPERTY_TYPES:
            raise ValueError(
                f"{what}: property {name!r} has type {ptype!r}, not one of {PROPERTY_TYPES}"
            )
        column = name.replace(" ", "_").lower()
        if column in reserved:
            raise ValueError(f"{what}: property name {name!r} is reserved by the database")
        if column in columns:
            raise ValueError(f"{what}: property {name!r} given twice")
        columns.add(column)
        out.append((name, ptype))
    return out


def _format_setting(value: object) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "1" if value else "0"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    return str(value)


def _planner_lines(planner: PlannerRuns) -> list[str]:
    name = planner.name
    if not isinstance(name, str) or not name or any(c.isspace() for c in name) or "|" in name:
        raise ValueError(f"planner name must be non-empty, without whitespace or '|': {name!r}")
    if not name.startswith(_PLANNER_PREFIXES):
        name = "geometric_" + name
    lines = [name]

    settings = sorted((str(k), _format_setting(v)) for k, v in planner.settings.items())
    lines.append(f"{len(settings)} common properties")
    for key, value in settings:
        if not key.strip():
            raise ValueError(f"{name}: empty setting name")
        _check_line(f"{name}: setting {key!r}", key + value)
        lines.append(f"{key} = {value}")

    props = _check_properties(planner.run_properties, f"{name} run properties", _RUN_COLUMNS)
    known = {p for p, _ in props}
    lines.append(f"{len(props)} properties for each run")
    lines.extend(f"{p} {t}" for p, t in props)
    lines.append(f"{len(planner.runs)} runs")
    for i, run in enumerate(planner.runs):
        unknown = set(run) - known
        if unknown:
            raise ValueError(f"{name} run {i}: properties not declared: {sorted(unknown)}")
        fields = [_format_value(run.get(p), t, p, f"{name} run {i} {p!r}") for p, t in props]
        lines.append("".join(f + "; " for f in fields))

    if planner.progress and not planner.progress_properties:
        raise ValueError(f"{name}: progress rows given without progress_properties")
    if planner.progress_properties:
        pprops = _check_properties(
            planner.progress_properties, f"{name} progress properties", _PROGRESS_COLUMNS
        )
        if len(planner.progress) > len(planner.runs):
            raise ValueError(
                f"{name}: progress for {len(planner.progress)} runs but only "
                f"{len(planner.runs)} runs"
            )
        lines.append(f"{len(pprops)} progress properties for each run")
        lines.extend(f"{p} {t}" for p, t in pprops)
        lines.append(f"{len(planner.progress)} runs")
        for i, rows in enumerate(planner.progress):
            parts = []
            for row in rows:
                if len(row) != len(pprops):
                    raise ValueError(
                        f"{name} progress of run {i}: row {tuple(row)!r} has {len(row)} values, "
                        f"expected {len(pprops)}"
                    )
                values = [
                    _format_value(v, t, p, f"{name} progress of run {i} {p!r}")
                    for v, (p, t) in zip(row, pprops, strict=True)
                ]
                parts.append("".join(v + "," for v in values) + ";")
            lines.append("".join(parts))
    lines.append(".")
    return lines


def _experiment_property_lines(properties: dict[str, object]) -> list[str]:
    lines = []
    columns: set[str] = set()
    for name, raw in properties.items():
        if not isinstance(name, str) or not _EXPERIMENT_PROPERTY_NAME.fullmatch(name):
            raise ValueError(
                f"experiment property name {name!r} must be words of letters, digits, '_' and '-'"
            )
        column = name.replace(" ", "").replace("-", "_").lower()
        if column in _EXPERIMENT_COLUMNS or column in columns:
            raise ValueError(f"experiment property {name!r} clashes with another column")
        columns.add(column)
        if isinstance(raw, tuple) and len(raw) == 2 and isinstance(raw[1], str):
            value, ptype = raw
            ptype = ptype.upper()
            if not re.fullmatch(r"[A-Z][A-Z0-9_]*(\(\d+\))?", ptype):
                raise ValueError(f"experiment property {name!r}: bad type {ptype!r}")
        else:
            value, ptype = raw, None
        if ptype is None:
            if isinstance(value, (bool, np.bool_)):
                ptype = "BOOLEAN"
            elif isinstance(value, numbers.Integral):
                ptype = "INTEGER"
            elif isinstance(value, numbers.Real):
                ptype = "REAL"
            else:
                ptype = "TEXT"
        where = f"experiment property {name!r}"
        if value is None:
            raise ValueError(f"{where}: None cannot be written (the parser has no NULL here)")
        if ptype in ("REAL", "INTEGER", "BOOLEAN"):
            text = _format_value(value, ptype, name, where)
            if text in ("", "nan", "inf"):
                raise ValueError(f"{where}: non-finite value {value!r} cannot be written")
        else:
            text = _format_setting(value)
        _check_line(where, text)
        if not text or " = " in text or text != text.strip():
            raise ValueError(
                f"{where}: value {text!r} must be non-empty, without ' = ' or surrounding blanks"
            )
        lines.append(f"{name} {ptype} = {text}")
    return [f"{len(lines)} experiment properties", *lines]


def _block(text: str) -> list[str]:
    """A ``<<<| ... |>>>`` block; its text must end with a line break before ``|>>>``."""
    body = text if not text or text.endswith("\n") else text + "\n"
    for line in body.splitlines():
        if line.startswith("|>>>"):
            raise ValueError("a multiline block must not contain a line starting with '|>>>'")
    return ["<<<|", body + "|>>>"] if body else ["<<<|", "|>>>"]


def format_log(experiment: Experiment) -> str:
    """Render an experiment as an OMPL benchmark log.

    Parameters
    ----------
    experiment : Experiment
        The data to write.

    Returns
    -------
    str
        The log text, ending with a line break.

    Raises
    ------
    ValueError
        If a name or value cannot be written so that OMPL's parser reads it back unchanged.
    """
    exp = experiment
    version = exp.version
    if not version:
        from .. import __version__

        version = __version__
    lines = [
        f"{_check_word('library', exp.library)} version {_check_word('version', version)}",
        f"Experiment {_check_word('experiment name', exp.name)}",
    ]
    lines.extend(_experiment_property_lines(exp.properties))
    host = exp.host or socket.gethostname() or "UNKNOWN"
    lines.append(f"Running on {_check_word('host', host)}")
    date = exp.date or datetime.datetime.now().strftime("%Y-%m-%d %H:%M:%S")
    lines.append(f"Starting at {_check_line('date', date)}")
    lines.extend(_block(exp.setup))
    if exp.cpuinfo:
        lines.extend(_block(exp.cpuinfo))
    seed = 0 if exp.seed is None else int(exp.seed)
    lines.append(f"{seed} is the random seed")
    lines.append(f"{_format_real(exp.time_limit, 'time_limit') or 'inf'} seconds per run")
    lines.append(f"{_format_real(exp.memory_limit, 'memory_limit') or 'inf'} MB per run")
    lines.append(f"{int(exp.run_count)} runs per planner")
    lines.append(f"{_format_real(exp.total_time, 'total_time')} seconds spent to collect the data")
    lines.append("1 enum type")
    lines.append("|".join(("status", *STATUS_ENUM)))
    lines.append(f"{len(exp.planners)} planners")
    for planner in exp.planners:
        lines.extend(_planner_lines(planner))
    return "\n".join(lines) + "\n"


def write_log(experiment: Experiment, path: str | os.PathLike[str]) -> Path:
    """Write an experiment's log atomically (temporary file in the same folder, then rename).

    Parameters
    ----------
    experiment : Experiment
        The data to write.
    path : path-like
        Destination ``.log`` file; its folder is created if needed.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    text = format_log(experiment)  # fail before touching the file system
    return write_text_atomic(text, path)


_CONVERTER = (
    "import sys\n"
    "from ompl._benchmark_statistics import readBenchmarkLog\n"
    "readBenchmarkLog(sys.argv[1], sys.argv[2:], False)\n"
)


def _stderr_tail(stderr: str, lines: int = 20) -> str:
    kept = [
        line
        for line in stderr.splitlines()
        if "leaked" not in line and "nanobind" not in line and line.strip()
    ]
    return "\n".join(kept[-lines:])


def build_database(
    logs: Sequence[str | os.PathLike[str]],
    db_path: str | os.PathLike[str],
    *,
    append: bool = False,
) -> Path:
    """Convert benchmark logs into a Planner Arena SQLite database with OMPL's own converter.

    ``ompl._benchmark_statistics.readBenchmarkLog`` runs in a child process (``sys.executable``),
    so OMPL's nanobind messages and any crash stay out of this process. The database is built in
    a temporary file next to ``db_path`` and renamed over it only on success.

    Parameters
    ----------
    logs : sequence of path-like
        Log files, one experiment each, in order.
    db_path : path-like
        The database to write.
    append : bool, optional
        Add to an existing ``db_path`` instead of replacing it.

    Returns
    -------
    Path
        ``db_path``.

    Raises
    ------
    FileNotFoundError
        If a log does not exist.
    RuntimeError
        If the converter fails (the message holds the end of its stderr).
    OutputError
        If the database cannot be written (SQLite says so: the disk is full, ...).
    """
    if isinstance(logs, (str, os.PathLike)):
        logs = [logs]
    log_paths = [Path(p).resolve() for p in logs]
    for p in log_paths:
        if not p.is_file():
            raise FileNotFoundError(f"benchmark log not found: {p}")
    db = Path(db_path)
    with atomic_path(db, suffix=".tmp") as tmp:
        if append and db.exists():
            shutil.copy2(db, tmp)
        proc = subprocess.run(
            [sys.executable, "-c", _CONVERTER, tmp, *map(str, log_paths)],
            capture_output=True,
            text=True,
            check=False,
        )
        if proc.returncode != 0:
            failed = re.search(r"^sqlite3\.OperationalError: (.+)$", proc.stderr, re.MULTILINE)
            if failed:  # the database could not be written (a full disk): not the logs' fault
                raise OutputError(str(db), failed.group(1).strip())
            raise RuntimeError(
                f"OMPL's benchmark log converter failed (exit code {proc.returncode}) on "
                f"{', '.join(map(str, log_paths))}:\n{_stderr_tail(proc.stderr)}"
            )
    return db
