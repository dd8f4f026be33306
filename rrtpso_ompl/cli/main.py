"""The ``rrtpso`` command line: one module per subcommand over the package's public API.

Exit status: 0 success, 1 no valid path (or the subcommand's own "not achieved"), 2 bad input or
usage (one message on stderr, no traceback, nothing written), 128 + the signal when stopped by a
signal: 130 Ctrl-C (SIGINT), 129 SIGHUP, 143 SIGTERM. The three end alike: workers stopped,
temporary files removed, a results file left valid (continue it with ``--resume``).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
from collections.abc import Iterator, Sequence

from ..errors import RrtpsoError
from . import batch, bench, generate, optimum, planners, simulate, solve
from .common import EXIT_BAD_INPUT, EXIT_INTERRUPTED, add_shared_flags, set_quiet

__all__ = ["Terminated", "main"]

#: The subcommands, in the order ``rrtpso --help`` lists them.
COMMANDS = (solve, simulate, batch, generate, optimum, bench, planners)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rrtpso",
        description="Plan 2-D paths for wheeled robots with RRT*PSO and OMPL's planners.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    shared = argparse.ArgumentParser(add_help=False)
    add_shared_flags(shared)
    for command in COMMANDS:
        command.add_parser(sub, [shared])
    return parser


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
    args = build_parser().parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    set_quiet(args.quiet)
    logging.basicConfig(
        level=logging.INFO if getattr(args, "verbose", 0) else logging.WARNING,
        format="%(levelname)s: %(name)s: %(message)s",
    )
    try:
        with _stop_signals_as_interrupts():
            return args.func(args)
    except RrtpsoError as exc:  # bad input of any kind: its message names where it came from
        return _fail(f"rrtpso: error: {exc}", EXIT_BAD_INPUT)
    except Terminated as exc:
        return _fail(f"rrtpso: terminated by {signal.Signals(exc.signum).name}", 128 + exc.signum)
    except KeyboardInterrupt:
        return _fail("rrtpso: interrupted", EXIT_INTERRUPTED)
    except BrokenPipeError:
        # The reader went away (`rrtpso planners | head -1`): nothing more can be said to it.
        _silence_stdout()
        return _fail("rrtpso: error: the output pipe was closed before everything was written",
                     EXIT_BAD_INPUT)  # fmt: skip
    except MemoryError:
        return _fail(
            "rrtpso: error: out of memory: the input is too large for this machine (see the "
            "limits in docs/problem-format.md)",
            EXIT_BAD_INPUT,
        )


def _fail(message: str, status: int) -> int:
    with contextlib.suppress(OSError):
        print(message, file=sys.stderr)
    return status


def _silence_stdout() -> None:
    """Point stdout at /dev/null, so that Python's final flush does not raise again."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)


def _version() -> str:
    from .. import __version__

    return __version__


if __name__ == "__main__":
    sys.exit(main())
