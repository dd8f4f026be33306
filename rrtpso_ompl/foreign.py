"""Running code that is not ours (a plugin's import, a plugin planner's ``solve``) so that it
cannot stop the tool.

Such code may raise anything, ``SystemExit`` (``sys.exit(3)``) and ``KeyboardInterrupt``
included; none of them must end a command that was not asked to end. But a real Ctrl-C (or
SIGTERM, SIGHUP) that arrives while the code runs must still stop the command, as everywhere
else. The two look alike from the outside (a ``KeyboardInterrupt`` raised by the plugin's own
code is no Ctrl-C), so :func:`contained` watches the stop signals while the code runs: the
exception is kept for the caller to report, unless a stop signal was received, which goes on.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from .errors import MAX_SHOWN, shown

__all__ = [
    "STOP_SIGNALS",
    "Contained",
    "StopWatch",
    "contained",
    "describe_failure",
    "noting_stop_signals",
]

#: The signals that stop a command: Ctrl-C, and SIGTERM and SIGHUP (``rrtpso_ompl.cli.main``).
STOP_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)


class StopWatch:
    """The stop signals received while :func:`noting_stop_signals` watched, and how each was
    handled before."""

    def __init__(self) -> None:
        #: The signals received, in order.
        self.received: list[int] = []
        self._previous: dict[int, Any] = {}

    def handle(self, signum: int, frame: Any = None) -> None:
        """Handle ``signum`` as the previous handler would: run it (``KeyboardInterrupt`` for
        Ctrl-C, the command line's ``Terminated``), or, where the default held, end the
        process as the signal does."""
        previous = self._previous.get(signum, signal.SIG_DFL)
        if callable(previous):
            previous(signum, frame)
        elif previous == signal.SIG_DFL:
            if signum == getattr(signal, "SIGINT", None):
                raise KeyboardInterrupt
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)


@contextlib.contextmanager
def noting_stop_signals() -> Iterator[StopWatch]:
    """While the block runs, note every stop signal received (``watch.received``), and handle
    it as before, at once (:meth:`StopWatch.handle`).

    Signals that were ignored stay ignored. Outside the main thread (where Python runs no signal
    handler, so no ``KeyboardInterrupt`` there is a real one) nothing is changed and nothing
    noted.
    """
    watch = StopWatch()

    def note(signum: int, frame: Any) -> None:
        watch.received.append(signum)
        watch.handle(signum, frame)

    if threading.current_thread() is threading.main_thread():
        for sig in STOP_SIGNALS:
            previous = signal.getsignal(sig)
            if previous in (signal.SIG_IGN, None):  # ignored, or not set from Python
                continue
            watch._previous[sig] = previous
            signal.signal(sig, note)
    try:
        yield watch
    finally:
        for sig, previous in watch._previous.items():
            # A handler that changed it meanwhile (the command line ignores a second signal
            # while it cleans up) has the last word.
            if signal.getsignal(sig) is note:
                signal.signal(sig, previous)


@dataclass
class Contained:
    """What :func:`contained` caught: ``error`` is None when the block ended normally."""

    error: BaseException | None = None

    @property
    def message(self) -> str:
        """The error in one bounded line (:func:`describe_failure`); empty without one."""
        return describe_failure(self.error) if self.error is not None else ""


@contextlib.contextmanager
def contained(passthrough: tuple[type[BaseException], ...] = ()) -> Iterator[Contained]:
    """Run foreign code: whatever it raises is caught and kept (``box.error``), ``SystemExit``
    and ``KeyboardInterrupt`` included, unless a stop signal was received meanwhile
    (:func:`noting_stop_signals`): that one goes on, as it would anywhere else.

    Parameters
    ----------
    passthrough : tuple of exception types
        Raised on unchanged: the caller's own errors (bad input, out of memory).

    Examples
    --------
    >>> with contained() as box:
    ...     raise SystemExit(3)
    >>> box.message
    'SystemExit: sys.exit(3) was called'
    """
    box = Contained()
    with noting_stop_signals() as watch:
        try:
            yield box
        except passthrough:
            raise
        except BaseException as exc:
            if watch.received:  # a real Ctrl-C, SIGTERM or SIGHUP: stop as asked
                if isinstance(exc, KeyboardInterrupt):
                    raise  # the signal's own (or as good as)
                watch.handle(watch.received[0])  # the code raised something else instead
                raise
            box.error = exc
        if watch.received:
            # The code swallowed the exception the signal raised: the stop was still asked for.
            watch.handle(watch.received[0])


def describe_failure(exc: BaseException) -> str:
    """What went wrong, in one line of bounded length: ``ValueError: boom``, ``SystemExit:
    sys.exit(3) was called``."""
    if isinstance(exc, SystemExit):
        return f"SystemExit: sys.exit({shown(repr(exc.code))}) was called"
    try:
        text = " ".join(str(exc).split())
    except Exception:  # a __str__ that raises: the type still says something
        text = ""
    name = type(exc).__name__
    return f"{name}: {shown(text, 3 * MAX_SHOWN)}" if text else name
