"""Writing problem files: a problem dictionary as YAML in the format's documented key order.

The inverse of :func:`~rrtpso_ompl.model.problem.load_problem`: keys in the order of
``docs/problem-format.md``, points and obstacles on one line each in YAML flow style (like the
hand-written files in ``problems/``), floats rounded to a given number of decimals, and the
rounded problem validated again before anything is written.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..errors import ProblemError
from ..outputs import write_text_atomic
from ..validation import check_integer
from .format import MOVING, OBSTACLES, PLANNER, ROBOT, TOP
from .problem import Problem, problem_from_dict

__all__ = ["default_decimals", "round_floats", "write_problem"]


def write_problem(
    data: Mapping[str, Any],
    path: str | Path,
    *,
    header: str | None = None,
    decimals: int | None = None,
) -> Path:
    """Write a problem dictionary as a problem file.

    Keys are written in the format's documented order (top level, ``robot``, ``planner``, each
    obstacle, each moving obstacle), points and obstacles on one line each in YAML flow style,
    like the hand-written files in ``problems/``. Every float is rounded to ``decimals`` places
    first, and the rounded problem is validated again: rounding may move an obstacle onto the
    start or make a thin polygon degenerate, and such a file is refused rather than written.

    Parameters
    ----------
    data : mapping
        A problem in the file format (as from :func:`generate` or ``yaml.safe_load``).
    path : str or Path
        Where to write; the folder is created if needed, the file replaced atomically.
    header : str, optional
        Comment lines written first (each line gets a ``# `` prefix).
    decimals : int, optional
        Decimal places for floats, 0..12; default :func:`default_decimals` of the bounds.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ProblemError
        When ``data`` is not a valid problem.
    ValueError
        When it is no longer valid after rounding (the message says which key and suggests more
        decimals), or ``decimals`` is out of range.
    """
    path = Path(path)
    problem = problem_from_dict(data, source=str(path))
    rounded = _rounded_valid(data, path, _decimals(problem, decimals))
    text = _format_problem(rounded, header)
    # The text must read back as exactly the validated dictionary: a formatting slip (a string
    # that YAML would read as a number, say) must not reach the file.
    if yaml.safe_load(text) != _plain(rounded):
        raise AssertionError("internal error: the formatted YAML does not read back as written")

    return write_text_atomic(text, path)


def _decimals(problem: Problem, decimals: int | None) -> int:
    """``decimals`` checked (0..12), or :func:`default_decimals` of the problem's bounds."""
    if decimals is None:
        (xmin, ymin), (xmax, ymax) = problem.bounds
        return default_decimals(max(xmax - xmin, ymax - ymin))
    try:
        return check_integer(decimals, low=0, high=12)
    except ValueError as exc:
        raise ValueError(f"decimals {exc}") from None


def _rounded_valid(data: Mapping[str, Any], path: Path, decimals: int) -> dict[str, Any]:
    """``data`` with every float rounded to ``decimals`` places, validated again: rounding may
    move an obstacle onto the start or make a thin polygon degenerate (a ValueError then)."""
    rounded = round_floats(data, decimals)
    try:
        problem_from_dict(rounded, source=str(path))
    except ProblemError as exc:
        raise ValueError(
            f"{path}: after rounding to {decimals} decimals the problem is no longer valid: "
            f"{exc.key + ': ' if exc.key else ''}{exc.message}; write more decimals"
        ) from None
    return rounded


def default_decimals(size: float) -> int:
    """Decimal places that keep coordinates to about ``1e-5`` of a workspace of side ``size``.

    3 for a side of 100 to 999, 2 for 1000 to 9999, 4 for 10 to 99, and so on (between 0 and 12).
    """
    if not (size > 0 and math.isfinite(size)):
        raise ValueError(f"size must be a positive finite number, got {size!r}")
    return int(min(12, max(0, 5 - math.floor(math.log10(size)))))


def _format_problem(data: Mapping[str, Any], header: str | None) -> str:
    lines = [f"# {line}".rstrip() for line in header.splitlines()] if header else []
    # The format's key order, declared once in format.py (the loader reads the same tables).
    nested = {"robot": ROBOT.names(), "planner": PLANNER.names()}
    for key in _ordered(data, TOP.names()):
        value = data[key]
        if value is None:
            continue
        if key in nested and isinstance(value, Mapping):
            lines.append(f"{key}:")
            lines += [f"  {k}: {_flow(value[k])}" for k in _ordered(value, nested[key])]
        elif key in ("obstacles", "moving_obstacles") and isinstance(value, list | tuple):
            if not value:
                lines.append(f"{key}: []")
                continue
            lines.append(f"{key}:")
            for item in value:
                order = _obstacle_keys(item.get("type")) if key == "obstacles" else MOVING.names()
                lines.append(f"  - {_flow({k: item[k] for k in _ordered(item, order)})}")
        elif key == "description" and isinstance(value, str):
            lines.append(_folded(key, value))
        else:
            lines.append(f"{key}: {_flow(value)}")
    return "\n".join(lines) + "\n"


def _folded(key: str, text: str) -> str:
    """``key: >-`` and the text folded at 100 columns, like the hand-written files.

    Folding is exact only for plain one-line prose (no line breaks, no runs of spaces, no
    leading or trailing space); anything else is left to PyYAML's own quoting.
    """
    if text and text == " ".join(text.split()) and text.isprintable():
        body = textwrap.wrap(text, width=98, break_long_words=False, break_on_hyphens=False)
        block = f"{key}: >-\n" + "\n".join(f"  {line}" for line in body)
        if yaml.safe_load(block) == {key: text}:
            return block
    return yaml.safe_dump({key: text}, width=80, sort_keys=False, allow_unicode=True).rstrip("\n")


def _ordered(mapping: Mapping[str, Any], order: Sequence[str]) -> list[str]:
    """Keys of ``mapping`` in the documented ``order`` (any others, which validation has already
    refused at the top levels, after them in their own order)."""
    return [k for k in order if k in mapping] + [k for k in mapping if k not in order]


def _flow(value: Any) -> str:
    """One value as single-line YAML flow text (``[1.5, 2.0]``, ``{type: circle, ...}``)."""
    text = yaml.safe_dump(
        _plain(value),
        default_flow_style=True,
        width=math.inf,
        sort_keys=False,
        allow_unicode=True,
    ).strip()
    # A lone scalar is dumped as a document with an explicit end marker.
    if text.endswith("\n..."):
        text = text[: -len("\n...")].rstrip()
    return text


def _plain(value: Any) -> Any:
    """Mappings as dicts, sequences as lists, numpy scalars as Python numbers (for PyYAML)."""
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def round_floats(value: Any, decimals: int) -> Any:
    """A deep copy with every float rounded (ints, bools and strings untouched, -0.0 made 0.0)."""
    if isinstance(value, Mapping):
        return {k: round_floats(v, decimals) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [round_floats(v, decimals) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and math.isfinite(value):
        return round(value, decimals) + 0.0
    return value


def _obstacle_keys(kind: Any) -> tuple[str, ...]:
    """The declared keys of an obstacle of ``kind``, in order (none for an unknown kind)."""
    section = OBSTACLES.get(kind) if isinstance(kind, str) else None
    return tuple(section.names()) if section is not None else ()
