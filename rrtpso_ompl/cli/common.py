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
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import (
    MAX_SHOWN,
    ParameterError,
    UnknownPlannerError,
    UsageError,
    did_you_mean,
    shown,
)
from ..outputs import STDOUT, is_stream, name_max, os_reason, stdout_closed
from ..validation import check_seconds, check_seed

if TYPE_CHECKING:
    from ..harness.record import RunRecord
    from ..planners.request import PlannerRequest

__all__ = [
    "EXIT_BAD_INPUT",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_UNSOLVED",
    "Output",
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


def with_unit(value: float, units: str, digits: int = 3) -> str:
    """A length in a summary line with its unit: ``"34.807 m"`` (``"units"`` for a problem with
    no ``units`` key: its lengths are in whatever unit its numbers are)."""
    return f"{value:.{digits}f} {units or 'units'}"


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
def add_planner_flags(p: argparse.ArgumentParser, *, planner: str, time: str, param: str) -> None:
    """``--planner``, ``--time``, ``--seed`` and ``--param``, the flags :func:`choose_planner`
    resolves against the problem file; ``planner``, ``time`` and ``param`` are their help (what
    the planner plans and its time is for, in the command's words)."""
    p.add_argument("--planner", help=planner)
    p.add_argument("--time", type=float, metavar="SECONDS", help=time)
    p.add_argument("--seed", type=int, help="random seed (default: the file's planner.seed)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE", help=param)


def choose_planner(args: argparse.Namespace) -> PlannerRequest:
    """Load ``args.problem`` and resolve ``--planner``, ``--post``/``--simplify``, ``--param``,
    ``--time`` and ``--seed`` against it (:func:`~rrtpso_ompl.planners.request.resolve`).

    Returns
    -------
    PlannerRequest

    Raises
    ------
    ProblemError
        For a bad problem file, or a value of its ``planner`` section its planner cannot take.
    UsageError
        For an unknown planner or a bad flag, the message naming the file and where the value
        came from (``--planner``, ``planner.type``, ``--param NAME``, ...).
    """
    from ..planners.request import command_line, resolve
    from .query import load_query

    problem = load_query(args)
    try:
        return resolve(
            problem,
            args.planner,
            params=parse_params(args.param, args.problem),
            time_limit=getattr(args, "time", None),
            seed=args.seed,
            post=_post_steps(args),
            sources=command_line(args.problem),
        )
    except (ParameterError, UnknownPlannerError) as exc:
        raise UsageError(str(exc)) from None


def _post_steps(args: argparse.Namespace) -> list[str]:
    """``--post STEPS`` (a comma list) and ``--simplify`` (its alias for ``simplify``, first)."""
    text = getattr(args, "post", None)
    steps = [s for s in (text.split(",") if text else []) if s.strip()]
    if getattr(args, "simplify", False) and "simplify" not in steps:
        steps.insert(0, "simplify")
    return steps


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
            raise UsageError(f"{where}: expected NAME=VALUE, got '{shown(item)}'")
        if key in params:
            name, first, then = shown(key), shown(params[key]), shown(value)
            raise UsageError(f"{where} {name}: given twice ({name}={first} and {name}={then}); "
                             "give it once")  # fmt: skip
        params[key] = value
    return params


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
    kind : {"text", "image", "gif", "folder", "bag", "results"}
        What is written there (``bag``: a ROS 2 bag, one MCAP file or a bag directory;
        ``results``: a batch's results file, appended to: its own checks decide about the rows
        it holds and its lock, :class:`~rrtpso_ompl.harness.results_file.ResultsFile`).
    """

    flag: str
    path: str | None
    kind: str = "text"


def check_outputs(
    outputs: Sequence[Output], inputs: Sequence[str | Path] = (), *, own_folder: bool = False
) -> None:
    """Refuse outputs that cannot be written, before any time is spent planning.

    Refused: an empty name; standard output (``-``) for an image or folder, for two outputs, or
    when it is closed; a folder where a file goes (or a file where a folder goes); a parent that
    is a file, not writable, or a symbolic link loop; a name longer than the file system allows;
    an existing target that is neither a regular file nor a stream (a socket, a block device);
    an image suffix matplotlib cannot write; an output that is one of the inputs (it would be
    destroyed: pass every file a problem reads, :attr:`~rrtpso_ompl.model.Problem.inputs`) or the
    same file as another output (one would be lost); a ROS 2 bag over anything but an MCAP
    file (``.mcap``) or an empty folder; a file of this program that holds runs
    (:func:`rrtpso_ompl.ownership.describe`: a results file, finished or being written, a bench
    folder's files), which only its own command continues (``results`` outputs: a bench's files
    are refused there, the rest is the results file's to judge). ``own_folder``: the outputs are
    a bench's files in its own folder, which the bench checks itself.
    """
    given = [o for o in outputs if o.path is not None]
    targets: dict[str, str] = {}
    for out in given:
        _check_one(out)
        if not own_folder:
            _check_not_ours(out)
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


def _check_not_ours(out: Output) -> None:
    """Refuse an output that would replace a file of this program holding runs (see
    :func:`check_outputs`)."""
    if out.path == STDOUT or out.kind == "folder" or is_stream(out.path):
        return
    from ..ownership import describe

    owned = describe(out.path)
    if owned is None or (out.kind == "results" and owned.kind != "bench"):
        return
    if out.kind == "results":
        raise UsageError(f"{out.flag}: '{out.path}' is {owned.what}; a batch does not write into "
                         "a bench's folder: continue it with rrtpso bench --resume, or choose "
                         "another file")  # fmt: skip
    raise UsageError(f"{out.flag}: '{out.path}' is {owned.what}; it is not replaced: choose "
                     "another file")  # fmt: skip


def _check_one(out: Output) -> None:
    path, flag = out.path, out.flag
    if not path or not path.strip():
        raise UsageError(f"{flag}: give a file name (got an empty one)")
    if path == STDOUT:
        if out.kind not in ("text", "results"):
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
    from ..model.yamlfile import file_kind

    path, flag = out.path, out.flag
    target = Path(os.path.realpath(path))  # where it is written: links are written through
    parent = _nearest_existing(target)
    _check_names(target, parent, flag, path)
    if parent == target:
        mode = os.stat(target).st_mode
        if out.kind == "folder":
            if not stat.S_ISDIR(mode):
                raise UsageError(f"{flag}: '{path}' exists and is not a directory")
        elif out.kind == "bag":
            _check_existing_bag(target, mode, flag, path)
        elif stat.S_ISDIR(mode):
            raise UsageError(f"{flag}: '{path}' is a directory")
        elif not (stat.S_ISREG(mode) or is_stream(target)):
            raise UsageError(f"{flag}: '{path}' is {file_kind(mode)}; it is left as it is")
        parent = target.parent if out.kind != "folder" else target
    if out.kind == "bag":
        _check_bag_name(target, parent, flag, path)
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


def _check_existing_bag(target: Path, mode: int, flag: str, path: str) -> None:
    """A ROS 2 bag over something that exists: an MCAP file is replaced like any output file
    (only an MCAP file: a bag name over another kind of file is a mistake), a stream written
    through; a sqlite3 bag directory is only made over an empty folder, never over anything
    with content (a folder is not ours to empty)."""
    from ..model.yamlfile import file_kind
    from ..ros.bag import is_mcap, is_mcap_file

    if is_mcap(path):
        if stat.S_ISDIR(mode):
            raise UsageError(f"{flag}: '{path}' is a directory; an MCAP bag is one file")
        if is_stream(target):
            return
        if not stat.S_ISREG(mode):
            raise UsageError(f"{flag}: '{path}' is {file_kind(mode)}; it is left as it is")
        if not is_mcap_file(target):
            raise UsageError(f"{flag}: '{path}' exists and is not an MCAP file; it is left as "
                             "it is")  # fmt: skip
        return
    if not stat.S_ISDIR(mode):
        raise UsageError(
            f"{flag}: '{path}' is {file_kind(mode)}; a bag directory is made where nothing is "
            "(or in an empty folder); name the bag OUT.mcap for one file"
        )
    with os.scandir(target) as entries:
        if next(entries, None) is not None:
            raise UsageError(
                f"{flag}: '{path}' exists and is not empty; a bag directory is never replaced: "
                "remove it or name another"
            )


def _check_bag_name(target: Path, existing: Path, flag: str, path: str) -> None:
    """A bag directory holds its database named after it (``run/run.db3``): that name must fit
    the file system too."""
    from ..ros.bag import DATABASE_SUFFIX, is_mcap

    if is_mcap(path):
        return
    limit = name_max(existing if existing.is_dir() else existing.parent)
    size = len(os.fsencode(target.name + DATABASE_SUFFIX))
    if size > limit:
        raise UsageError(f"{flag}: cannot write '{path[:40]}...': the bag's database would be "
                         f"named {size} bytes long, and the file system allows at most "
                         f"{limit}")  # fmt: skip


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
    """A tqdm bar on stderr; a silent stand-in when stderr is not a terminal (logs, CI, pipes)
    or with ``-q``, so that tqdm is imported only to draw."""
    if _quiet or not sys.stderr.isatty():
        return _NoBar()
    from tqdm import tqdm

    return tqdm(desc=desc, file=sys.stderr, leave=False, **kwargs)


class _NoBar:
    """What the commands use of a tqdm bar, doing nothing (tqdm's ``disable=True``)."""

    total: float | None = None
    n: float = 0

    def __enter__(self) -> _NoBar:
        return self

    def __exit__(self, *exc: Any) -> None:
        pass

    def update(self, n: float = 1) -> None:
        pass

    def refresh(self) -> None:
        pass

    def set_postfix(self, *args: Any, **kwargs: Any) -> None:
        pass


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
    unique = list(dict.fromkeys(names))
    for name in unique:
        if names.count(name) > 1:
            note(f"rrtpso: --planner: {name} is given {names.count(name)} times; it is run once")
    return unique


def check_run_options(args: argparse.Namespace) -> None:
    """The shared options of ``batch`` and ``bench``, checked before anything runs."""
    check_positive_seconds(args.time, "--time")
    for flag in ("runs", "jobs"):
        if getattr(args, flag) < 1:
            raise UsageError(f"--{flag}: must be at least 1, got {shown(getattr(args, flag))}")
    from ..validation import MAX_RUNS

    if args.runs > MAX_RUNS:
        raise UsageError(f"--runs: must be at most {MAX_RUNS:,} (the runs of one batch or bench), "
                         f"got {shown(args.runs)}")  # fmt: skip
    max_jobs = 4 * (os.cpu_count() or 1)
    if args.jobs > max_jobs:
        raise UsageError(f"--jobs: must be at most {max_jobs} (4 per CPU of this machine; each "
                         "worker is a Python process with OMPL), "
                         f"got {shown(args.jobs)}")  # fmt: skip
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


def run_keywords(args: argparse.Namespace, bar: RunProgress) -> dict[str, Any]:
    """The keywords of :func:`~rrtpso_ompl.harness.run_batch` (and ``run_bench``) from the flags
    of :func:`add_run_options`, with ``bar`` reporting the runs as they start and finish."""
    return {"jobs": args.jobs, "resume": args.resume, "overwrite": args.overwrite,
            "executor": args.executor, "scheduler": args.scheduler,
            "progress": bar.row, "on_start": bar.started, "notice": note}  # fmt: skip


def report_errors(errors: Iterable[str]) -> None:
    """Print each error of a batch or bench to stderr (errors are printed also with ``-q``)."""
    for error in errors:
        print(f"rrtpso: {error}", file=sys.stderr)


def batch_inputs(items: Sequence[str]) -> list[str]:
    """Every file the problems of a batch or bench read (:func:`check_outputs`' ``inputs``): the
    problem files and their maps' YAML and images, found without loading the problems."""
    from ..harness import expand_inputs
    from ..model.problem import input_files

    files = (input_files(path) for path, error in expand_inputs(items) if error is None)
    return list(dict.fromkeys(f for group in files for f in group))


def check_planners(names: list[str], items: list[str], flag: str) -> dict[str, dict[str, str]]:
    """Resolve planner specs and check ``--param`` against each (without a problem: the files
    are loaded by the runs); returns the ``--param`` values (text) per spec.

    A ``--param`` applies to the specs that take it (the planner, or its post-passes); one that
    none of them takes is an error.
    """
    import dataclasses

    from ..planners import default_registry
    from ..planners.request import COMMAND_LINE, resolve

    registry = default_registry()
    sources = dataclasses.replace(COMMAND_LINE, planner=flag)
    params = parse_params(items)
    out: dict[str, dict[str, str]] = {}
    known: set[str] = set()
    try:
        for name in names:
            spec = resolve(None, name, sources=sources, registry=registry)
            known.update(spec.param_names())
            out[name] = {k: v for k, v in params.items() if spec.takes(k)}
            resolve(None, name, params=out[name], sources=sources, registry=registry)
    except (ParameterError, UnknownPlannerError) as exc:
        raise UsageError(str(exc)) from None
    for key in params:
        if not any(key in p for p in out.values()):
            raise UsageError(f"--param {shown(key)}: none of the planners "
                             f"{shown(', '.join(names), 3 * MAX_SHOWN)} has it"
                             f"{did_you_mean(key, sorted(known))}")  # fmt: skip
    return out
