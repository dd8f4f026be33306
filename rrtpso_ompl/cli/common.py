"""What the subcommands share: exit codes, loading and resolving a problem's planner, parameter
and output checks, progress bars on stderr, and the options of ``batch`` and ``bench``.

Every check here runs before planning, so that a bad flag costs no time budget, and raises a
:class:`~rrtpso_ompl.errors.UsageError` whose message names where the bad value came from (the
file and its key, or the flag); :func:`rrtpso_ompl.cli.main` turns it into exit status 2.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ParameterError, UnknownPlannerError, UsageError
from ..model import Problem, load_problem

__all__ = [
    "EXIT_BAD_INPUT",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_UNSOLVED",
    "PlannerChoice",
    "RunProgress",
    "add_run_options",
    "check_output",
    "check_planners",
    "check_positive_seconds",
    "check_run_options",
    "choose_planner",
    "parse_params",
    "planner_list",
    "progress_bar",
]

EXIT_OK, EXIT_UNSOLVED, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130


# ----------------------------------------------------------------------------------------------
# One problem and its planner (solve, simulate)
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PlannerChoice:
    """A problem file loaded and its planner resolved and checked, before anything runs.

    Attributes
    ----------
    problem : Problem
        The validated problem.
    entry : PlannerEntry
        The registered planner (``--planner``, else the file's ``planner.type``, else the
        default).
    params : dict
        The file's ``planner.params`` under the ``--param`` values, checked against the planner.
    cli_params : dict
        The ``--param`` values alone (as text).
    """

    problem: Problem
    entry: Any
    params: dict[str, Any]
    cli_params: dict[str, str]


def choose_planner(args: argparse.Namespace) -> PlannerChoice:
    """Load ``args.problem`` and resolve ``args.planner`` and ``args.param`` against it.

    Raises
    ------
    ProblemError
        For a bad problem file.
    UsageError
        For an unknown planner or a bad parameter, naming the file and where the value came from
        (``--planner``, ``planner.type``, ``--param NAME``, ``planner.params.NAME``).
    """
    from ..planners import DEFAULT_PLANNER, default_registry

    problem = load_problem(args.problem)
    src = args.problem
    name = args.planner or problem.planner.type or DEFAULT_PLANNER
    origin = (
        "--planner" if args.planner else ("planner.type" if problem.planner.type else "planner")
    )
    try:
        entry = default_registry().get(name)
    except UnknownPlannerError as exc:
        raise UsageError(f"{src}: {origin}: {exc}") from None
    cli_params = parse_params(args.param, src)
    for key, value in problem.planner.params.items():
        _check_param(entry, key, value, f"{src}: planner.params.{key}")
    for key, value in cli_params.items():
        _check_param(entry, key, value, f"{src}: --param {key}")
    params = {**problem.planner.params, **cli_params}
    try:
        entry.validate(params)  # the rules over several parameters (c1 + c2 < 4)
    except ParameterError as exc:
        raise UsageError(f"{src}: planner parameters: {exc}") from None
    return PlannerChoice(problem, entry, params, cli_params)


def parse_params(items: list[str], src: str) -> dict[str, str]:
    """``--param NAME=VALUE`` items as a mapping (values stay text: the planner converts them)."""
    params: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise UsageError(f"{src}: --param: expected NAME=VALUE, got '{item}'")
        params[key.strip()] = value.strip()
    return params


def _check_param(entry: Any, key: str, value: Any, where: str) -> None:
    try:
        entry.param(key).convert(value, entry.name)
    except ParameterError as exc:
        raise UsageError(f"{where}: {exc}") from None


def check_positive_seconds(value: float | None, flag: str, src: str = "") -> None:
    """A time flag must be a positive, finite number of seconds (when given)."""
    if value is not None and not (value > 0 and math.isfinite(value)):
        where = f"{src}: {flag}" if src else flag
        raise UsageError(f"{where}: must be a positive number of seconds, got {value}")


# ----------------------------------------------------------------------------------------------
# Outputs
# ----------------------------------------------------------------------------------------------
def check_output(path: str | None, flag: str, image: bool = False) -> None:
    """Refuse an output that cannot be written before spending the time budget on planning."""
    if not path:
        return
    target = Path(path)
    if target.is_dir():
        raise UsageError(f"{flag}: '{path}' is a directory")
    parent = target.parent
    while not parent.exists():
        parent = parent.parent  # missing folders are created when the file is written
    if not os.access(parent, os.W_OK):
        raise UsageError(f"{flag}: cannot write '{path}': '{parent}' is not writable")
    if image:
        from ..plotting import image_formats

        kinds = image_formats()
        suffix = target.suffix.lower().lstrip(".")
        if suffix not in kinds:
            raise UsageError(
                f"{flag}: cannot draw '{path}': use one of the suffixes "
                f"{', '.join('.' + k for k in sorted(kinds))}"
            )


# ----------------------------------------------------------------------------------------------
# Progress on stderr
# ----------------------------------------------------------------------------------------------
def progress_bar(desc: str, **kwargs: Any) -> Any:
    """A tqdm bar on stderr, silent when stderr is not a terminal (logs, CI, pipes)."""
    from tqdm import tqdm

    return tqdm(desc=desc, file=sys.stderr, disable=not sys.stderr.isatty(), leave=False, **kwargs)


class RunProgress:
    """The progress bar of a batch or a bench: solved / unsolved / error counts per finished row."""

    def __init__(self, desc: str, noun: str) -> None:
        self.noun = noun
        self.counts = {"solved": 0, "unsolved": 0, "error": 0}
        self._bar = progress_bar(desc, unit="run")

    def __enter__(self) -> RunProgress:
        self._bar.__enter__()
        return self

    def __exit__(self, *exc: Any) -> None:
        self._bar.__exit__(*exc)

    def started(self, n: int, skipped: int) -> None:
        self._bar.total = n
        self._bar.refresh()
        if skipped:
            print(f"rrtpso: resuming: {skipped} {self.noun} already done", file=sys.stderr)

    def row(self, row: Mapping[str, Any]) -> None:
        kind = "error" if row.get("error") else ("solved" if row["solved"] else "unsolved")
        self.counts[kind] += 1
        self._bar.set_postfix(self.counts, refresh=False)
        self._bar.update(1)


# ----------------------------------------------------------------------------------------------
# Many runs (batch, bench)
# ----------------------------------------------------------------------------------------------
def add_run_options(p: argparse.ArgumentParser, kept: str) -> None:
    """The options ``batch`` and ``bench`` share: seeds, parallelism, resuming, executors."""
    p.add_argument("--seed", type=int, default=1, help="seed of run 0; run r uses seed + r")
    p.add_argument("--jobs", type=int, default=1, help="parallel worker processes (default 1)")
    p.add_argument("--resume", action="store_true", help=f"keep {kept}")
    p.add_argument(
        "--param", action="append", default=[], metavar="NAME=VALUE", help="planner parameter"
    )
    p.add_argument(
        "--executor",
        choices=("local", "dask"),
        default="local",
        help="local process pool (default) or a Dask cluster (pip install 'rrtpso-ompl[dask]')",
    )
    p.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler, e.g. tcp://host:8786")


def planner_list(values: list[str] | None, default: str) -> list[str]:
    """Planner names from repeated and comma-separated flags, in order, without repeats."""
    names = [n.strip() for v in (values or [default]) for n in v.split(",") if n.strip()]
    return list(dict.fromkeys(names))


def check_run_options(args: argparse.Namespace) -> None:
    """The shared options of ``batch`` and ``bench``, checked before anything runs."""
    check_positive_seconds(args.time, "--time")
    for flag in ("runs", "jobs"):
        if getattr(args, flag) < 1:
            raise UsageError(f"--{flag}: must be at least 1, got {getattr(args, flag)}")
    if args.seed is not None and args.seed < 0:
        raise UsageError(f"--seed: must be >= 0, got {args.seed}")
    if args.executor == "dask":
        if not args.scheduler:
            raise UsageError("--executor dask: needs --scheduler ADDRESS")
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise UsageError(
                "--executor dask: Dask is not installed: pip install 'rrtpso-ompl[dask]'"
            ) from None


def check_planners(names: list[str], items: list[str], flag: str) -> dict[str, dict[str, str]]:
    """Resolve planner names and check ``--param`` against each; returns params per planner.

    A ``--param`` applies to the planners that have it; one that none of them has is an error.
    """
    from ..planners import default_registry

    registry = default_registry()
    params = parse_params(items, flag)
    out = {}
    for name in names:
        try:
            entry = registry.get(name)
        except UnknownPlannerError as exc:
            raise UsageError(f"{flag}: {exc}") from None
        mine = {k: v for k, v in params.items() if entry.takes(k)}
        for key, value in mine.items():
            _check_param(entry, key, value, f"--param {key}")
        out[name] = mine
    for key in params:
        if not any(key in p for p in out.values()):
            raise UsageError(f"--param {key}: none of the planners {', '.join(names)} has it")
    return out
