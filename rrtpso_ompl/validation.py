"""Checks of single values, shared by the problem loader, the parameter tables and the generator.

Each check returns the converted value or raises ``ValueError`` with a message that starts with
"must", so that every caller can put its own subject in front of it (``obstacles[2].radius``,
``parameter 'swarm_size'``, ``--n``) and report it in its own error type.
"""

from __future__ import annotations

import math
import numbers
import reprlib
from typing import Any

__all__ = [
    "MAX_COORDINATE",
    "MAX_SECONDS",
    "MIN_EXTENT",
    "SEED_MAX",
    "check_integer",
    "check_number",
    "check_seconds",
    "check_seed",
    "describe",
    "short_repr",
]

#: The largest seed: OMPL's ``RNG::setSeed`` takes a 32-bit unsigned integer on every platform
#: (``std::uint_fast32_t``, which is 32 bits on some), and numpy accepts any non-negative one.
SEED_MAX = 2**32 - 1

#: Largest coordinate or length, in any unit. Exact checks allow for round-off of 1e-9 of the
#: workspace's scale (:func:`~rrtpso_ompl.model.problem.touch_tolerance`); beyond 1e9 that
#: allowance would exceed a unit, and at 1e160 squared distances overflow.
MAX_COORDINATE = 1e9
#: Smallest side of the workspace: well above the absolute round-off allowance of 1e-9.
MIN_EXTENT = 1e-6
#: Longest time budget, seconds (about 11.6 days). OMPL's timed termination condition holds its
#: deadline in integer nanoseconds, and a budget near 1e10 s overflows it: the planner then
#: returns at once with no solution.
MAX_SECONDS = 1e6

#: Short, bounded reprs: a value may be a huge or self-referencing structure (YAML anchors).
_REPR = reprlib.Repr()
_REPR.maxlevel = 3
_REPR.maxstring = _REPR.maxother = _REPR.maxlong = 40
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = _REPR.maxset = _REPR.maxfrozenset = 4


#: Longest repr a message shows, characters.
_MAX_REPR = 100


def short_repr(value: Any) -> str:
    """A repr of at most :data:`_MAX_REPR` characters, however large or nested the value."""
    try:
        text = _REPR.repr(value)
    except ValueError:  # an int with more digits than Python will convert to text
        return "(too long to show)"
    return text if len(text) <= _MAX_REPR else text[: _MAX_REPR - 3] + "..."


def describe(value: Any) -> str:
    """A short description of a wrong value for error messages (type and bounded repr)."""
    if value is None:
        return "nothing (null)"
    return f"{type(value).__name__} {short_repr(value)}"


def _bound_text(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def check_number(
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    strict_low: bool = False,
) -> float:
    """A finite real number (not a bool) in ``[low, high]`` (``(low, high]`` with ``strict_low``).

    Raises
    ------
    ValueError
        ``"must be a number, got str 'x'"`` and the like.
    """
    # bool is an int subclass, but `radius: yes` is a mistake, not the number 1.
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"must be a number, got {describe(value)}")
    try:
        x = float(value)
    except OverflowError:
        raise ValueError("is too large for a floating-point number") from None
    if not math.isfinite(x):
        raise ValueError(f"must be a finite number, got {x}")
    if low is not None and (x <= low if strict_low else x < low):
        raise ValueError(f"must be {'>' if strict_low else '>='} {_bound_text(low)}, got {x:g}")
    if high is not None and x > high:
        raise ValueError(f"must be <= {_bound_text(high)}, got {x:g}")
    return x


def check_integer(value: Any, *, low: int | None = None, high: int | None = None) -> int:
    """An integer (not a bool; a float with an integral value is accepted) in ``[low, high]``.

    Raises
    ------
    ValueError
        ``"must be an integer, got float 2.5"`` and the like.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"must be an integer, got {describe(value)}")
    if not isinstance(value, numbers.Integral):
        if not math.isfinite(value) or value != int(value):
            raise ValueError(f"must be an integer, got {describe(value)}")
        value = int(value)
    value = int(value)
    if low is not None and value < low:
        raise ValueError(f"must be >= {low}, got {value}")
    if high is not None and value > high:
        raise ValueError(f"must be <= {high}, got {value}")
    return value


def check_seconds(value: Any) -> float:
    """A time budget: a positive number of seconds, at most :data:`MAX_SECONDS`."""
    x = check_number(value, low=0.0, strict_low=True)
    if x > MAX_SECONDS:
        raise ValueError(
            f"must be at most {MAX_SECONDS:g} s (about 11.6 days; OMPL's deadline overflows "
            f"beyond about 1e10 s), got {x:g}"
        )
    return x


def check_seed(value: Any) -> int:
    """A random seed: an integer in ``[0, SEED_MAX]`` (the range OMPL's RNG takes)."""
    try:
        return check_integer(value, low=0, high=SEED_MAX)
    except ValueError as exc:
        raise ValueError(f"{exc} (seeds are integers from 0 to 2**32 - 1)") from None
