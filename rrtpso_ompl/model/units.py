"""Length units of a problem and their size in metres (ROS uses SI units, REP 103; Nav2's
defaults are in metres)."""

from __future__ import annotations

import contextlib

from ..errors import ProblemError, shown

__all__ = ["METRES_PER_UNIT", "metres_per_unit", "units_fields"]

#: Metres in one problem unit, for every spelling a problem's ``units`` key accepts.
METRES_PER_UNIT: dict[str, float] = {
    "mm": 1e-3,
    "millimetre": 1e-3,
    "millimeter": 1e-3,
    "cm": 1e-2,
    "centimetre": 1e-2,
    "centimeter": 1e-2,
    "dm": 0.1,
    "m": 1.0,
    "metre": 1.0,
    "meter": 1.0,
    "km": 1e3,
    "in": 0.0254,
    "inch": 0.0254,
    "ft": 0.3048,
    "foot": 0.3048,
    "feet": 0.3048,
}


def metres_per_unit(units: str, source: str = "<dict>") -> float:
    """Metres in one unit of ``units``, for outputs that must be in metres.

    Parameters
    ----------
    units : str
        The problem's ``units`` key (case and surrounding blanks ignored; plural ``s`` too).
        Empty (the key absent) means metres, the unit of ROS and of map problems.
    source : str
        The problem file, named in the error.

    Raises
    ------
    ProblemError
        ``units`` is not a length unit this table knows: a ROS output cannot be converted.
    """
    key = units.strip().lower()
    if not key:
        return 1.0
    if key not in METRES_PER_UNIT and key.endswith("s") and key[:-1] in METRES_PER_UNIT:
        key = key[:-1]
    try:
        return METRES_PER_UNIT[key]
    except KeyError:
        known = ", ".join(sorted({"mm", "cm", "m", "km", "in", "ft"}))
        raise ProblemError(
            source,
            "units",
            f"unknown length unit '{shown(units)}' for a ROS output (known: {known})",
        ) from None


def units_fields(units: str) -> dict[str, str | float]:
    """What a JSON output says about its lengths: ``{"units": units}``, and
    ``"metres_per_unit"`` when :func:`metres_per_unit` knows the unit (an unknown unit is no
    error here: JSON and CSV outputs keep the problem's units, whatever they are).

    Parameters
    ----------
    units : str
        The problem's ``units`` key (empty: metres, as for the ROS outputs).
    """
    out: dict[str, str | float] = {"units": units}
    with contextlib.suppress(ProblemError):
        out["metres_per_unit"] = metres_per_unit(units)
    return out
