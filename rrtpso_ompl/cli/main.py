"""The ``rrtpso`` command line: one module per subcommand over the package's public API.

Exit status: 0 success, 1 no valid path (or the subcommand's own "not achieved"), 2 bad input or
usage (one message on stderr, no traceback, nothing written) or an output that could not be
written (the disk is full, standard output was closed when the command started: one message
naming the output and the reason; the old file is intact), 128 + the signal when stopped by a
signal: 130 Ctrl-C (SIGINT), 129 SIGHUP, 143 SIGTERM. The three end alike: workers stopped,
temporary files removed, a results file left valid (continue it with ``--resume``). A pipe whose
reader went away (``rrtpso planners | head -1``) is not an error: nothing is said and the status
is 0, or the command's own when it had finished its work (``solve --json -``).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import signal
import sys
from collections.abc import Iterator, Sequence
from typing import Any, NoReturn

from .._version import __version__
from ..errors import OutputError, RrtpsoError, shown
from ..outputs import (
    STDOUT,
    guard_standard_streams,
    os_reason,
    results_only_on_stdout,
    silence_stdout,
    stdout_closed,
)
from .common import EXIT_BAD_INPUT, EXIT_INTERRUPTED, EXIT_OK, add_shared_flags, set_quiet

__all__ = ["Terminated", "main"]

#: The subcommands, in the order ``rrtpso --help`` lists them: each a module of this package with
#: ``HELP`` (its line in ``rrtpso --help``), ``add_parser`` and ``run``. A module imports what
#: its command needs in ``add_parser`` and ``run``, not at its top, so that importing all of them
#: costs nothing (docs/design.md, "Start-up").
COMMANDS = ("solve", "simulate", "batch", "generate", "optimum", "bench", "planners")


class _WholeWords(argparse.HelpFormatter):
    """argparse's help, its lines broken between words only (argparse's own breaks a long
    name such as ``omega_left`` or a path in two)."""

    def _split_lines(self, text: str, width: int) -> list[str]:
        import textwrap

        return textwrap.wrap(" ".join(text.split()), width, break_long_words=False,
                             break_on_hyphens=False)  # fmt: skip


class _Parser(argparse.ArgumentParser):
    """argparse's parser, its usage errors bounded: argparse quotes a bad value whole
    (``--runs 1000...``), and a command-line argument may hold 128 KiB; its help breaks lines
    between words only."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", _WholeWords)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        super().error(shown(message, MAX_USAGE_MESSAGE))


#: Most characters of a usage error of argparse.
MAX_USAGE_MESSAGE = 500


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The parser of ``rrtpso``: every subcommand's, or with ``only``, that subcommand's in
    full and the others as their line in ``rrtpso --help`` alone. A subcommand's flags may need
    its modules (``generate``'s kinds, ``simulate``'s strategies), which a command that does not
    run it should not import (:func:`command_of`)."""
    parser = _Parser(
        prog="rrtpso",
        description="Plan 2-D paths for wheeled robots with RRT*PSO and OMPL's planners.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    shared = _Parser(add_help=False)
    add_shared_flags(shared)
    for name in COMMANDS:
        module = importlib.import_module(f"{__package__}.{name}")
        if only is None or name == only:
            module.add_parser(sub, [shared])
        else:
            sub.add_parser(name, help=module.HELP)
    return parser


def command_of(argv: Sequence[str]) -> str:
    """The subcommand ``argv`` runs: its first argument that is not an option, as argparse
    reads it (``rrtpso`` itself takes no option with a value); "" when there is none."""
    for i, arg in enumerate(argv):
        if arg == "--":
            return argv[i + 1] if i + 1 < len(argv) else ""
        if not arg.startswith("-") or arg == "-":
            return arg
    return ""


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where Ctrl-C raises ``KeyboardInterrupt`` and handled alike:
    every ``finally`` and ``except BaseException`` on the way runs (workers are stopped, the
    temporary files of unfinished outputs removed, the results file released).

    Parameters
    ----------
    signum : int
        The signal; the exit status is ``128 + signum``.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


#: The signals that stop a command as Ctrl-C does (SIGHUP: the terminal went away).
STOP_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
)


def _raise_terminated(signum: int, frame: object) -> None:
    # A second signal must not cut the cleanup of the first short (kill -9 still can).
    for sig in STOP_SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    raise Terminated(signum)


@contextlib.contextmanager
def _stop_signals_as_interrupts() -> Iterator[None]:
    """SIGTERM and SIGHUP raise :class:`Terminated` while the block runs (main thread only:
    Python runs signal handlers there), then the previous handlers are back."""
    try:
        saved = {sig: signal.signal(sig, _raise_terminated) for sig in STOP_SIGNALS}
    except ValueError:  # not the main thread: leave the signals alone
        saved = {}
    try:
        yield
    finally:
        for sig, handler in saved.items():
            signal.signal(sig, handler)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    guard_standard_streams()  # before any file is opened: `rrtpso ... >&-`
    with results_only_on_stdout():  # OMPL's own lines go to stderr, results to stdout
        return _run(argv)


def _run(argv: Sequence[str] | None) -> int:
    try:
        with _stop_signals_as_interrupts():
            # Building simulate's parser loads the strategies (its choices), plugins included:
            # a Ctrl-C then ends as anywhere else, and their warnings wait for -q and -v.
            # Only the parser of the command run is built (build_parser).
            words = sys.argv[1:] if argv is None else list(argv)
            try:
                with _held_log_records() as held:
                    args = build_parser(command_of(words)).parse_args(words)
            except SystemExit:  # --help, --version, a usage error: nothing asked for quiet
                _show(held, logging.WARNING)
                raise
            _configure(args, argv, held)
            status = args.func(args)
            _flush_stdout()
        return status
    except RrtpsoError as exc:  # bad input of any kind: its message names where it came from
        if isinstance(exc, OutputError) and exc.path == STDOUT:
            silence_stdout()  # what is still buffered for it cannot be written either
        return _fail(f"rrtpso: error: {exc}", EXIT_BAD_INPUT)
    except Terminated as exc:
        return _fail(f"rrtpso: terminated by {signal.Signals(exc.signum).name}", 128 + exc.signum)
    except KeyboardInterrupt:
        return _fail("rrtpso: interrupted", EXIT_INTERRUPTED)
    except BrokenPipeError:
        # The reader of standard output went away (`rrtpso planners | head -1`, a batch's
        # `--out - | head -3`): it chose to stop reading, which is no error of ours. Like other
        # command-line tools, stop quietly; 0, so that the status does not depend on whether
        # the reader left before or after the last write. (A single result written to `-`, as
        # `solve --json -` does, is finished first and keeps its own status: outputs.publish.)
        silence_stdout()
        return EXIT_OK
    except MemoryError:
        return _fail(
            "rrtpso: error: out of memory: the input is too large for this machine (see the "
            "limits in docs/problem-format.md)",
            EXIT_BAD_INPUT,
        )


def _configure(
    args: argparse.Namespace, argv: Sequence[str] | None, held: list[logging.LogRecord]
) -> None:
    """Quiet, verbose and Python's logging from the flags; then the records held while the
    parser was built, those the level lets through."""
    args.argv = list(sys.argv[1:] if argv is None else argv)
    set_quiet(args.quiet)
    if args.quiet:
        args.verbose = -1  # -q wins over -v: only errors, from Python's logging and from OMPL
    _show(held, {-1: logging.ERROR, 0: logging.WARNING}.get(args.verbose, logging.INFO))


def _show(held: list[logging.LogRecord], level: int) -> None:
    """Python's logging at ``level`` (on stderr), and the ``held`` records it lets through."""
    logging.basicConfig(level=level, format="%(levelname)s: %(name)s: %(message)s")
    for record in held:
        if record.levelno >= level:
            logging.getLogger(record.name).handle(record)


class _Holder(logging.Handler):
    """A logging handler that keeps the records it is given, in ``records``."""

    def __init__(self, records: list[logging.LogRecord]) -> None:
        super().__init__()
        self.records = records

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@contextlib.contextmanager
def _held_log_records() -> Iterator[list[logging.LogRecord]]:
    """Hold the log records of the block (warnings and above) instead of printing them: the
    flags that say whether to print them (-q, -v) are not parsed yet."""
    records: list[logging.LogRecord] = []
    root = logging.getLogger()
    handler = _Holder(records)
    handler.setLevel(logging.WARNING)
    root.addHandler(handler)
    try:
        yield records
    finally:
        root.removeHandler(handler)


def _fail(message: str, status: int) -> int:
    with contextlib.suppress(OSError):
        print(message, file=sys.stderr)
    return status


def _flush_stdout() -> None:
    """Flush standard output now, so that a failure is one message, not Python's at exit."""
    if stdout_closed():
        return
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        raise  # the reader went away: quiet (main)
    except OSError as exc:
        raise OutputError(STDOUT, os_reason(exc)) from None


if __name__ == "__main__":
    sys.exit(main())
