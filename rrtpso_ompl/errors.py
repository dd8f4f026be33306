"""One family of errors: everything rrtpso-ompl raises on purpose derives from RrtpsoError.

An :class:`RrtpsoError` means *the input cannot be honoured* (a problem file, a planner name, a
parameter value, a command-line flag, an output target), never a bug. Its message is written for
the user and names where the input came from; the command line prints it and exits with status 2,
without a traceback. Anything else that escapes is a bug and keeps its traceback.

The subclasses also derive from the built-in exception a Python caller would expect
(``ValueError`` for bad values, ``KeyError`` for an unknown name), so ``except ValueError`` keeps
working for code written before the family existed.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = [
    "ArgumentError",
    "GenerationError",
    "OutputError",
    "ParameterError",
    "PlannerError",
    "ProblemError",
    "RrtpsoError",
    "UnknownPlannerError",
    "UnsupportedSpaceError",
    "UsageError",
    "did_you_mean",
    "shown",
]

#: Most characters a message shows of one value it echoes (a key, a name, a unit, a value).
MAX_SHOWN = 100
#: Most characters a message shows of a file name (names are long more often than values are).
MAX_SHOWN_PATH = 1000
#: Most characters of a whole message: the last guard, for a message that echoes several
#: values or one this module's callers did not shorten.
MAX_MESSAGE = 4000


def shown(text: object, limit: int = MAX_SHOWN) -> str:
    """``text`` as a message echoes it: whole when it has at most ``limit`` characters, else its
    beginning and its end around ``...``, and how long it is.

    Every message echoes what the user wrote through this (or through
    :func:`~rrtpso_ompl.validation.short_repr` for a value of any type), so that a 1 MB
    ``units:`` value or key name gives a message of a line, not of a megabyte.

    Examples
    --------
    >>> shown("x" * 1_000_000, 20)
    'xxxxxxxx...xxxxxxxxx (1,000,000 characters)'
    """
    if not isinstance(text, str):
        try:
            text = str(text)
        except ValueError:  # an int with more digits than Python converts to text
            return "(too long to show)"
    n = len(text)
    if n <= limit:
        return text
    head = max(1, (limit - 3) // 2)
    tail = max(1, limit - 3 - head)
    return f"{text[:head]}...{text[-tail:]} ({n:,} characters)"


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for a misspelt or shortened name among ``choices``, else empty.

    The one suggestion rule for keys and parameters (a problem file's ``robot.raduis``, a
    ``--param swarm_siz=3``).
    """
    choices = list(choices)
    close = difflib.get_close_matches(word, choices, n=1)
    if not close and len(word) >= 3:
        # difflib misses abbreviations such as `time` for `time_limit`.
        close = [c for c in choices if c.startswith(word)][:1]
    return f" (did you mean '{close[0]}'?)" if close else ""


class RrtpsoError(Exception):
    """Base of every deliberate error of rrtpso-ompl: bad input, reported by its message alone."""

    def __str__(self) -> str:
        # KeyError quotes its argument; every error of the family reads as plain text, and is
        # bounded (MAX_MESSAGE) whatever it echoes.
        return shown(self.args[0], MAX_MESSAGE) if self.args else type(self).__name__


class ProblemError(RrtpsoError, ValueError):
    """A problem file (or dictionary) is not a valid problem.

    Parameters
    ----------
    source : str
        The file the problem came from (or a label such as ``"<dict>"``).
    key : str
        The offending key as a dotted path, e.g. ``"obstacles[2].radius"``; empty for the
        whole file.
    message : str
        What is wrong, in words a user can act on.
    """

    def __init__(self, source: str, key: str, message: str) -> None:
        self.source = str(source)
        self.key = key
        self.message = message
        path = shown(self.source, MAX_SHOWN_PATH)
        # A key path joins a few names, each shortened where it is built (an unknown key).
        where = f"{path}: {shown(key, 3 * MAX_SHOWN)}" if key else path
        super().__init__(f"{where}: {message}")

    def __reduce__(self):
        # Picklable, so that a worker process can send it back to its parent.
        return (type(self), (self.source, self.key, self.message))


class ParameterError(RrtpsoError, ValueError):
    """A parameter name or value that its declaration does not allow.

    Parameters
    ----------
    message : str
        The whole message, naming the parameter (and its owner, when known).
    name : str
        The parameter (or ``"a + b"`` for a rule over several).
    origin : str
        Where the value came from, put before the message: ``"p.yaml: --param swarm_size"``,
        ``"params['swarm_size']"`` (empty when not known).
    """

    def __init__(self, message: str, name: str = "", origin: str = "") -> None:
        self.name = name
        self.origin = origin
        #: The message without its origin.
        self.detail = message
        super().__init__(f"{origin}: {message}" if origin else message)

    def __reduce__(self):
        return (type(self), (self.detail, self.name, self.origin))


class PlannerError(RrtpsoError):
    """A planner cannot be selected or configured."""


class UnknownPlannerError(PlannerError, KeyError):
    """No usable planner of that name.

    The message lists the known names, suggests the closest one and, for a planner that exists but
    is excluded, says why. ``origin`` (where the name came from: ``"--planner"``,
    ``"p.yaml: planner.type"``) goes before the message.
    """

    def __init__(self, name: str, known, reason: str = "", origin: str = "") -> None:
        import difflib

        self.name = name
        self.known = sorted(known, key=str.lower)
        self.reason = reason
        self.origin = origin
        listing = ", ".join(self.known)
        if reason:
            text = f"planner '{shown(name)}' is unavailable ({reason}); known planners: {listing}"
        else:
            lower = {k.lower(): k for k in self.known}
            close = difflib.get_close_matches(name.lower(), list(lower), n=1, cutoff=0.6)
            hint = f" (did you mean '{lower[close[0]]}'?)" if close else ""
            text = f"unknown planner '{shown(name)}'{hint}; known planners: {listing}"
        super().__init__(f"{origin}: {text}" if origin else text)

    def __reduce__(self):
        return (type(self), (self.name, self.known, self.reason, self.origin))


class UnsupportedSpaceError(PlannerError, ValueError):
    """A planner or path optimiser of this package was given an OMPL state space it does not plan
    in (for now: anything but ``ob.RealVectorStateSpace(2)``). The message names the space and
    what is supported; OMPL's own planners plan in such spaces."""


class UsageError(RrtpsoError):
    """A command-line flag, argument or output target that cannot be honoured."""


class OutputError(RrtpsoError, OSError):
    """An output could not be written: the disk is full, the pipe was closed, standard output is
    closed, the name is too long, ...

    Raised by the writers of :mod:`rrtpso_ompl.outputs` and the results file after the temporary
    file (or the torn line) has been removed, so the old file is intact and nothing half-written
    is left. Also an ``OSError``, for callers that catch that.

    Parameters
    ----------
    path : str
        The output as it was named (``-`` for standard output).
    reason : str
        Why, as the system says it (``No space left on device``).
    """

    def __init__(self, path: str, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        where = "standard output" if self.path == "-" else self.path
        super().__init__(f"{where}: cannot write: {reason}")

    def __reduce__(self):
        return (type(self), (self.path, self.reason))


class GenerationError(RrtpsoError, ValueError):
    """The generator's options are invalid, or no problem satisfying them was found within the
    allowed attempts (too many or too large obstacles, too large a robot for the workspace)."""


class ArgumentError(RrtpsoError, TypeError):
    """A Python argument of the wrong kind: a file name where a :class:`~rrtpso_ompl.model.Problem`
    goes, a string where a mapping of parameters goes, ``None`` where a path goes."""
