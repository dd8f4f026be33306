"""What the subcommands share: exit codes, loading and resolving a problem's planner, parameter
and output checks, progress bars on stderr, and the options of ``batch`` and ``bench``.

Every check here runs before planning, so that a bad flag costs no time budget, and raises a
:class:`~rrtpso_ompl.errors.UsageError` whose message names where the bad value came from (the
file and its key, or the flag); :func:`rrtpso_ompl.cli.main` turns it into exit status 2.
"""

from __future__ import annotations

import argparse
import errno
import os
import stat
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import ParameterError, UnknownPlannerError, UsageError, did_you_mean
from ..model import Problem, load_problem
from ..model.yamlfile import file_kind
from ..outputs import STDOUT, is_stream, name_max, os_reason, stdout_closed
from ..validation import check_seconds, check_seed

if TYPE_CHECKING:
    from ..harness.record import RunRecord

__all__ = [
    "EXIT_BAD_INPUT",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_UNSOLVED",
    "Output",
    "PlannerChoice",
    "RunProgress",
    "add_run_options",
    "add_shared_flags",
    "batch_inputs",
    "check_output",
    "check_outputs",
    "check_planners",
    "check_positive_seconds",
    "check_run_options",
    "check_seed_flag",
    "choose_planner",
    "note",
    "parse_params",
    "planner_list",
    "progress_bar",
    "set_quiet",
]

EXIT_OK, EXIT_UNSOLVED, EXIT_BAD_INPUT, EXIT_INTERRUPTED = 0, 1, 2, 130

#: ``-q``: only errors on stderr (no summary lines, no progress bars).
_quiet = False


def set_quiet(quiet: bool) -> None:
    """Silence (or not) :func:`note` and the progress bars for this command."""
    global _quiet
    _quiet = bool(quiet)


def note(message: str) -> None:
    """A line for the user on stderr (the summary of a command), unless ``-q``."""
    if not _quiet:
        print(message, file=sys.stderr)


def add_shared_flags(parser: argparse.ArgumentParser) -> None:
    """``-v`` and ``-q``, which every subcommand takes."""
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more detail: OMPL's Info (-v) and Debug (-vv) messages")  # fmt: skip
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="only errors on stderr: no summary line, no progress bar")  # fmt: skip


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
        The ``--param`` values alone (as text), the post-passes' included.
    post : tuple of str
        The post-passes after the planner: the spec's (``BITstar+pso``), then ``--post``'s.
    """

    problem: Problem
    entry: Any
    params: dict[str, Any]
    cli_params: dict[str, str]
    post: tuple[str, ...] = ()


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
    from ..planners.post import split_params, split_spec

    if args.planner is not None and not args.planner.strip():
        raise UsageError("--planner: give a planner name (see 'rrtpso planners')")
    problem = load_problem(args.problem)
    src = args.problem
    name = args.planner or problem.planner.type or DEFAULT_PLANNER
    origin = (
        "--planner" if args.planner else ("planner.type" if problem.planner.type else "planner")
    )
    try:
        base, steps = split_spec(name)
        steps = (*steps, *post_steps(args, src))
        entry = default_registry().get(base)
    except UnknownPlannerError as exc:
        raise UsageError(f"{src}: {origin}: {exc}") from None
    except ParameterError as exc:
        raise UsageError(f"{src}: {origin}: {exc}") from None
    cli_params = parse_params(args.param, src)
    try:
        _, post_params = split_params(entry, cli_params, steps)
    except ParameterError as exc:
        raise UsageError(f"{src}: --param {exc.name}: {exc}") from None
    for key, value in problem.planner.params.items():
        _check_param(entry, key, value, f"{src}: planner.params.{key}", text=False)
    for key, value in cli_params.items():
        if key not in post_params:
            _check_param(entry, key, value, f"{src}: --param {key}")
    params = {**problem.planner.params, **{k: v for k, v in cli_params.items()
                                           if k not in post_params}}  # fmt: skip
    try:
        entry.validate(params)  # the rules over several parameters (c1 + c2 < 4)
    except ParameterError as exc:
        raise UsageError(f"{src}: planner parameters: {exc}") from None
    return PlannerChoice(problem, entry, params, cli_params, tuple(dict.fromkeys(steps)))


def post_steps(args: argparse.Namespace, src: str = "") -> tuple[str, ...]:
    """``--post STEPS`` (a comma list) and ``--simplify`` (its alias for ``simplify``), checked:
    an unknown step is a usage error that names the known ones."""
    from ..planners.post import parse_steps

    text = getattr(args, "post", None)
    steps = [s for s in (text.split(",") if text else []) if s.strip()]
    if getattr(args, "simplify", False) and "simplify" not in steps:
        steps.insert(0, "simplify")
    try:
        return parse_steps(steps, "--post")
    except ParameterError as exc:
        raise UsageError(f"{src}: --post: {exc}" if src else f"--post: {exc}") from None


def parse_params(items: list[str], src: str = "") -> dict[str, str]:
    """``--param NAME=VALUE`` items as a mapping (values stay text: the planner converts them).

    A name given twice is refused (which one was meant cannot be known), naming both values.
    ``src`` (the problem file, when there is one) prefixes the messages.
    """
    where = f"{src}: --param" if src else "--param"
    params: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key:
            raise UsageError(f"{where}: expected NAME=VALUE, got '{item}'")
        if key in params:
            raise UsageError(f"{where} {key}: given twice ({key}={params[key]} and {key}={value}); "
                             "give it once")  # fmt: skip
        params[key] = value
    return params


def _check_param(entry: Any, key: str, value: Any, where: str, text: bool = True) -> None:
    try:
        entry.param(key).convert(value, entry.name, text)
    except ParameterError as exc:
        raise UsageError(f"{where}: {exc}") from None


def check_positive_seconds(value: float | None, flag: str, src: str = "") -> None:
    """A time flag must be a positive number of seconds, at most ``MAX_SECONDS`` (when given)."""
    if value is None:
        return
    try:
        check_seconds(value)
    except ValueError as exc:
        where = f"{src}: {flag}" if src else flag
        raise UsageError(f"{where}: a time in seconds {exc}") from None


def check_seed_flag(value: int | None, flag: str = "--seed", runs: int = 1) -> None:
    """A seed flag (and the seeds ``value .. value + runs - 1`` of the runs) in OMPL's range."""
    if value is None:
        return
    for seed in (value, value + runs - 1):
        try:
            check_seed(seed)
        except ValueError as exc:
            what = "the seed of the last run" if seed != value else "the seed"
            raise UsageError(f"{flag}: {what} {exc}") from None


# ----------------------------------------------------------------------------------------------
# Outputs
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Output:
    """An output a command was asked to write.

    Attributes
    ----------
    flag : str
        How the command line names it (``--json``).
    path : str or None
        Where; None when not asked for. ``-`` is standard output (text outputs only).
    kind : {"text", "image", "gif", "folder"}
        What is written there.
    """

    flag: str
    path: str | None
    kind: str = "text"


def check_outputs(outputs: Sequence[Output], inputs: Sequence[str | Path] = ()) -> None:
    """Refuse outputs that cannot be written, before any time is spent planning.

    Refused: an empty name; standard output (``-``) for an image or folder, for two outputs, or
    when it is closed; a folder where a file goes (or a file where a folder goes); a parent that
    is a file, not writable, or a symbolic link loop; a name longer than the file system allows;
    an existing target that is neither a regular file nor a stream (a socket, a block device);
    an image suffix matplotlib cannot write; an output that is one of the inputs (it would be
    destroyed: pass every file a problem reads, :attr:`~rrtpso_ompl.model.Problem.inputs`) or the
    same file as another output (one would be lost).
    """
    given = [o for o in outputs if o.path is not None]
    targets: dict[str, str] = {}
    for out in given:
        _check_one(out)
        key = STDOUT if out.path == STDOUT else os.path.realpath(out.path)
        if key in targets:
            where = "standard output" if key == STDOUT else f"the same file '{out.path}'"
            raise UsageError(f"{targets[key]} and {out.flag} both name {where}; give each its own")
        targets[key] = out.flag
    for src in inputs:
        for out in given:
            if out.path != STDOUT and _same_file(out.path, src):
                raise UsageError(
                    f"{out.flag}: '{out.path}' is an input ({src}); writing it would destroy it"
                )


def _check_one(out: Output) -> None:
    path, flag = out.path, out.flag
    if not path or not path.strip():
        raise UsageError(f"{flag}: give a file name (got an empty one)")
    if path == STDOUT:
        if out.kind != "text":
            raise UsageError(f"{flag}: '-' (standard output) is only for text outputs")
        if stdout_closed():
            raise UsageError(f"{flag}: standard output is closed; nothing can be written there")
        return
    try:
        _check_place(out)
    except OSError as exc:  # a loop of links, a parent that is a file, ...
        raise UsageError(f"{flag}: cannot write '{path}': {os_reason(exc)}") from None


def _check_place(out: Output) -> None:
    """The checks of :func:`_check_one` on the file system (they may raise OSError)."""
    path, flag = out.path, out.flag
    target = Path(os.path.realpath(path))  # where it is written: links are written through
    parent = _nearest_existing(target)
    _check_names(target, parent, flag, path)
    if parent == target:
        mode = os.stat(target).st_mode
        if out.kind == "folder":
            if not stat.S_ISDIR(mode):
                raise UsageError(f"{flag}: '{path}' exists and is not a directory")
        elif stat.S_ISDIR(mode):
            raise UsageError(f"{flag}: '{path}' is a directory")
        elif not (stat.S_ISREG(mode) or is_stream(target)):
            raise UsageError(f"{flag}: '{path}' is {file_kind(mode)}; it is left as it is")
        parent = target.parent if out.kind != "folder" else target
    if not parent.is_dir():
        raise UsageError(f"{flag}: cannot write '{path}': '{parent}' is a file, not a directory")
    if not os.access(parent, os.W_OK):
        raise UsageError(f"{flag}: cannot write '{path}': '{parent}' is not writable")
    if out.kind == "image":
        from ..plotting import image_formats

        kinds = image_formats()
        if Path(path).suffix.lower().lstrip(".") not in kinds:
            raise UsageError(
                f"{flag}: cannot draw '{path}': use one of the suffixes "
                f"{', '.join('.' + k for k in sorted(kinds))}"
            )
    if out.kind == "gif" and Path(path).suffix.lower() != ".gif":
        raise UsageError(f"{flag}: '{path}' must end in .gif")


def _nearest_existing(path: Path) -> Path:
    """``path`` or its nearest ancestor that exists (missing folders are created when the file is
    written); OSError when one cannot be looked at (a loop of links, a file as a folder)."""
    while True:
        try:
            os.stat(path)
            return path
        except OSError as exc:
            # Missing, below a file (said below), or a name too long to exist (_check_names).
            if exc.errno not in (errno.ENOENT, errno.ENOTDIR, errno.ENAMETOOLONG):
                raise
            if path.parent == path:
                raise
            path = path.parent


def _check_names(target: Path, existing: Path, flag: str, path: str) -> None:
    """Every name still to be made (the file, missing folders) fits the file system's limit, and
    the whole path fits the system's; checked here so that nothing fails after planning."""
    limit = name_max(existing if existing.is_dir() else existing.parent)
    for part in target.relative_to(existing).parts:
        size = len(os.fsencode(part))
        if size > limit:
            short = part if len(part) <= 40 else f"{part[:20]}...{part[-12:]}"
            raise UsageError(
                f"{flag}: cannot write '{short}': the name is {size} bytes long, and the file "
                f"system allows at most {limit}"
            )
    try:
        path_max = int(os.pathconf(existing if existing.is_dir() else existing.parent,
                                   "PC_PATH_MAX"))  # fmt: skip
    except (OSError, ValueError):
        path_max = 4096
    if len(os.fsencode(str(target))) >= path_max:
        raise UsageError(
            f"{flag}: cannot write '{path[:40]}...': the path is longer than the system allows "
            f"({path_max} bytes)"
        )


def _same_file(a: str | Path, b: str | Path) -> bool:
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)  # hard links
    except OSError:
        return False


def check_output(path: str | None, flag: str, image: bool = False) -> None:
    """:func:`check_outputs` for one output."""
    check_outputs([Output(flag, path, "image" if image else "text")])


# ----------------------------------------------------------------------------------------------
# Progress on stderr
# ----------------------------------------------------------------------------------------------
def progress_bar(desc: str, **kwargs: Any) -> Any:
    """A tqdm bar on stderr, silent when stderr is not a terminal (logs, CI, pipes)."""
    from tqdm import tqdm

    quiet = _quiet or not sys.stderr.isatty()
    return tqdm(desc=desc, file=sys.stderr, disable=quiet, leave=False, **kwargs)


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
            note(f"rrtpso: resuming: {skipped} {self.noun} already done")

    def row(self, row: RunRecord) -> None:
        kind = "error" if row.is_error else ("solved" if row.solved else "unsolved")
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
    p.add_argument("--resume", action="store_true", help=f"keep {kept} and run the rest")
    p.add_argument(
        "--overwrite",
        action="store_true",
        help=f"start afresh although {kept.removeprefix('the ')} exist (without "
        "--resume or --overwrite an earlier run's results are refused, never replaced)",
    )
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
    if not names:
        raise UsageError("--planner: name at least one planner (see 'rrtpso planners')")
    return list(dict.fromkeys(names))


def check_run_options(args: argparse.Namespace) -> None:
    """The shared options of ``batch`` and ``bench``, checked before anything runs."""
    check_positive_seconds(args.time, "--time")
    for flag in ("runs", "jobs"):
        if getattr(args, flag) < 1:
            raise UsageError(f"--{flag}: must be at least 1, got {getattr(args, flag)}")
    from ..validation import MAX_RUNS

    if args.runs > MAX_RUNS:
        raise UsageError(f"--runs: must be at most {MAX_RUNS:,} (the runs of one batch or bench), "
                         f"got {args.runs}")  # fmt: skip
    max_jobs = 4 * (os.cpu_count() or 1)
    if args.jobs > max_jobs:
        raise UsageError(f"--jobs: must be at most {max_jobs} (4 per CPU of this machine; each "
                         f"worker is a Python process with OMPL), got {args.jobs}")  # fmt: skip
    check_seed_flag(args.seed, runs=args.runs)
    if args.executor == "dask":
        if not args.scheduler:
            raise UsageError("--executor dask: needs --scheduler ADDRESS")
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise UsageError(
                "--executor dask: Dask is not installed: pip install 'rrtpso-ompl[dask]'"
            ) from None


def batch_inputs(items: Sequence[str]) -> list[str]:
    """Every file the problems of a batch or bench read (:func:`check_outputs`' ``inputs``): the
    problem files and their maps' YAML and images, found without loading the problems."""
    from ..harness import expand_inputs
    from ..model.problem import input_files

    files = (input_files(path) for path, error in expand_inputs(items) if error is None)
    return list(dict.fromkeys(f for group in files for f in group))


def check_planners(names: list[str], items: list[str], flag: str) -> dict[str, dict[str, str]]:
    """Resolve planner names and check ``--param`` against each; returns params per planner.

    A ``--param`` applies to the planners that have it; one that none of them has is an error.
    """
    from ..planners import ParamTable, PathOptimizerOptions, default_registry
    from ..planners.post import POST_PARAMS, split_spec

    registry = default_registry()
    params = parse_params(items)
    out = {}
    for name in names:
        try:
            base, steps = split_spec(name)
            entry = registry.get(base)
        except (UnknownPlannerError, ParameterError) as exc:
            raise UsageError(f"{flag}: {exc}") from None
        post = POST_PARAMS + PathOptimizerOptions.PARAMS if steps else ParamTable()
        for key in params:
            if key in post and not entry.takes(key):
                try:
                    post[key].convert(params[key], "post-pass")
                except ParameterError as exc:
                    raise UsageError(f"--param {key}: {exc}") from None
        mine = {k: v for k, v in params.items() if entry.takes(k) or k in post}
        for key, value in mine.items():
            if entry.takes(key):  # the post-passes' own were checked above
                _check_param(entry, key, value, f"--param {key}")
        out[name] = mine
    for key in params:
        if not any(key in p for p in out.values()):
            known = {n for name in names for n in _param_names(registry, name)}
            raise UsageError(f"--param {key}: none of the planners {', '.join(names)} has it"
                             f"{did_you_mean(key, sorted(known))}")  # fmt: skip
    return out


def _param_names(registry: Any, spec: str) -> list[str]:
    """The parameters a planner spec (``BITstar+pso``) takes: the planner's and its post-passes'."""
    from ..planners import PathOptimizerOptions
    from ..planners.post import POST_PARAMS, split_spec

    base, steps = split_spec(spec)
    post = (POST_PARAMS + PathOptimizerOptions.PARAMS).names() if steps else []
    return [*registry.get(base).params.names(), *post]
