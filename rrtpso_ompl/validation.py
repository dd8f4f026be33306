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

from .errors import shown

__all__ = [
    "MAX_COORDINATE",
    "MAX_RUNS",
    "MAX_SECONDS",
    "MAX_STEPS",
    "MIN_EXTENT",
    "SEED_MAX",
    "check_integer",
    "check_number",
    "check_run_count",
    "check_seconds",
    "check_seed",
    "describe",
    "number_hint",
    "short_repr",
]

#: The largest seed: OMPL's ``RNG::setSeed`` takes a 32-bit unsigned integer on every platform
#: (``std::uint_fast32_t``, which is 32 bits on some), and numpy accepts any non-negative one.
SEED_MAX = 2**32 - 1

#: Largest coordinate or length, in any unit. Exact checks allow for round-off of 1e-9 of the
#: workspace's scale (:func:`~rrtpso_ompl.model.problem.touch_tolerance`); beyond 1e9 that
#: allowance would exceed a unit, and at 1e160 squared distances overflow.
MAX_COORDINATE = 1e9
#: Smallest side of the workspace, absolute and as a share of its coordinates' magnitude: the
#: round-off allowance, 1e-9 of the workspace's scale (its larger side or coordinate
#: magnitude), then stays at most a thousandth of a side.
MIN_EXTENT = 1e-6
#: Longest time budget, seconds (about 11.6 days). OMPL's timed termination condition holds its
#: deadline in integer nanoseconds, and a budget near 1e10 s overflows it: the planner then
#: returns at once with no solution.
MAX_SECONDS = 1e6
#: Most runs one batch or bench may make (files x planners x runs x budgets): each is a task,
#: and later a row, held in memory (about 0.5 kB a task, a few kB a row with its path).
MAX_RUNS = 100_000
#: Most control steps (one per ``robot.sample_time``) of a simulation or of the wheel-command
#: trajectory of ``rrtpso solve --trajectory``: a million rows take about 10 s and 450 MB to
#: compute and write (docs/problem-format.md).
MAX_STEPS = 1_000_000

#: Short, bounded reprs: a value may be a huge or self-referencing structure (YAML anchors).
_REPR = reprlib.Repr()
_REPR.maxlevel = 3
_REPR.maxstring = _REPR.maxother = _REPR.maxlong = 40
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = _REPR.maxset = _REPR.maxfrozenset = 4


#: Longest repr a message shows, characters.
_MAX_REPR = 100


def short_repr(value: Any) -> str:
    """A repr of at most :data:`_MAX_REPR` characters, however large or nested the value (a
    long string also says how long it is)."""
    try:
        text = _REPR.repr(value)
    except ValueError:  # an int with more digits than Python will convert to text
        return "(too long to show)"
    if len(text) > _MAX_REPR:
        text = text[: _MAX_REPR - 3] + "..."
    if isinstance(value, str) and len(value) > _REPR.maxstring:
        text += f" ({len(value):,} characters)"
    return text


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
        raise ValueError(f"must be >= {low}, got {shown(value)}")
    if high is not None and value > high:
        raise ValueError(f"must be <= {high}, got {shown(value)}")
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


def check_run_count(runs: int, planners: int = 1, files: int = 1, budgets: int = 1) -> int:
    """The number of runs of a batch or bench, ``runs x planners x files x budgets``, at most
    :data:`MAX_RUNS`.

    Raises
    ------
    ValueError
        ``"must be at most 100,000 in one batch or bench, got runs 200,000 x 1 planner x 1
        file = 200,000 (...)"``.
    """
    total = runs * planners * files * budgets
    if total > MAX_RUNS:
        factors = [f"runs {runs:,}", _count(planners, "planner"), _count(files, "file")]
        if budgets != 1:
            factors.append(_count(budgets, "budget"))
        raise ValueError(
            f"must be at most {MAX_RUNS:,} in one batch or bench, got {' x '.join(factors)} = "
            f"{total:,} (fewer runs, or split the files)"
        )
    return total


def _count(n: int, noun: str) -> str:
    return f"{n:,} {noun}{'' if n == 1 else 's'}"


def number_hint(value: Any) -> str:
    """Why a number-like string is not a number, for a message: `` (a number in quotes is text:
    remove the quotes)`` and the like (empty when the value does not look like a number)."""
    if not isinstance(value, str):
        return ""
    try:
        x = float(value)
    except ValueError:
        return ""
    if not math.isfinite(x):
        return ""
    if "e" in value.lower():
        # PyYAML follows YAML 1.1, where a float needs a point: 1e3 and 1.0e3 are text.
        fixed = repr(x)
        mantissa, e, exponent = fixed.partition("e")
        if e and "." not in mantissa:
            fixed = f"{mantissa}.0e{exponent}"
        return f" (YAML reads {shown(value)} as text, not a number: write {fixed})"
    return " (a number in quotes is text: remove the quotes)"
