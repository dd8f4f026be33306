"""The ``rrtpso`` command line: one module per subcommand over the package's public API.

Exit status: 0 success, 1 no valid path (or the subcommand's own "not achieved"), 2 bad input or
usage (one message on stderr, no traceback, nothing written), 130 interrupted.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from ..errors import RrtpsoError
from . import batch, bench, generate, optimum, planners, simulate, solve
from .common import EXIT_BAD_INPUT, EXIT_INTERRUPTED

__all__ = ["main"]

#: The subcommands, in the order ``rrtpso --help`` lists them.
COMMANDS = (solve, simulate, batch, generate, optimum, bench, planners)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rrtpso",
        description="Plan 2-D paths for wheeled robots with RRT*PSO and OMPL's planners.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    args = build_parser().parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    logging.basicConfig(
        level=logging.INFO if getattr(args, "verbose", 0) else logging.WARNING,
        format="%(levelname)s: %(name)s: %(message)s",
    )
    try:
        return args.func(args)
    except RrtpsoError as exc:  # bad input of any kind: its message names where it came from
        print(f"rrtpso: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("rrtpso: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _version() -> str:
    from .. import __version__

    return __version__


if __name__ == "__main__":
    sys.exit(main())
