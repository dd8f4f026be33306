"""Which OMPL state spaces this package's planners plan in: for now, the plane only.

RRTstarPSO, the PSO baseline, Exact and :class:`~rrtpso_ompl.planners.PSOPathOptimizer` read and
write a state as its two coordinates ``(s[0], s[1])``. In any other space that is a wrong answer,
not a slow one: in ``RealVectorStateSpace(3)`` the third coordinate is dropped (a "path" from
``(1, 1, 8.7)`` to ``(9, 9, 8.7)`` for a start at ``(1, 1, 1)``), and an ``SE2StateType`` cannot be
read by index at all. So they refuse every space but ``ob.RealVectorStateSpace(2)``, before they
read a state, with the reason :func:`plane_space_problem` gives: one sentence naming the space.
OMPL's own planners (``og.RRTstar``, ...) plan in all of those spaces.
"""

from __future__ import annotations

from typing import Any

from ompl import base as ob

from ..errors import UnsupportedSpaceError

__all__ = [
    "PLANE_SPACE",
    "centre_bounds",
    "describe_space",
    "plane_space_problem",
    "require_plane_space",
]

#: The one state space this package's planners plan in, as a user writes it.
PLANE_SPACE = "ob.RealVectorStateSpace(2)"


def centre_bounds(bounds: Any) -> ob.RealVectorBounds:
    """A problem's ``bounds`` ``((xmin, ymin), (xmax, ymax))`` (where the robot's centre may
    be) as OMPL's bounds of the plane's two coordinates (also those of an SE(2)-like space)."""
    (xmin, ymin), (xmax, ymax) = bounds
    out = ob.RealVectorBounds(2)
    out.setLow(0, xmin)
    out.setLow(1, ymin)
    out.setHigh(0, xmax)
    out.setHigh(1, ymax)
    return out


def _space_of(si_or_space: Any) -> Any:
    getter = getattr(si_or_space, "getStateSpace", None)
    return getter() if callable(getter) else si_or_space


def _dimension(space: Any) -> int | None:
    try:
        return int(space.getDimension())
    except (AttributeError, TypeError):  # not bound for every space (TimeStateSpace)
        return None


def describe_space(si_or_space: Any) -> str:
    """The space in words, for messages: its OMPL name, its class and its dimension.

    Parameters
    ----------
    si_or_space : ob.SpaceInformation or ob.StateSpace

    Examples
    --------
    >>> describe_space(ob.RealVectorStateSpace(3))  # doctest: +SKIP
    "'RealVectorSpace0' (ob.RealVectorStateSpace(3))"
    >>> describe_space(ob.DubinsStateSpace(1.0))  # doctest: +SKIP
    "'DubinsSE2CompoundSpace1' (ob.DubinsStateSpace, 3 dimensions)"
    """
    space = _space_of(si_or_space)
    cls = type(space)
    kind = f"ob.{cls.__name__}" if cls.__module__.startswith("ompl") else cls.__qualname__
    dim = _dimension(space)
    if isinstance(space, ob.RealVectorStateSpace) and dim is not None:
        kind = f"{kind}({dim})"
    elif dim is not None:
        kind = f"{kind}, {dim} dimension{'s' if dim != 1 else ''}"
    try:
        name = f"{space.getName()!r} "
    except (AttributeError, TypeError):
        name = ""
    return f"{name}({kind})"


def plane_space_problem(si_or_space: Any) -> str | None:
    """Why this package's planners do not plan in a space, or None when they do.

    They plan in a 2-D real vector space (``ob.RealVectorStateSpace(2)``, or a subclass of it);
    anything else (``RealVectorStateSpace(n)`` for n != 2, SE(2), Dubins, Reeds-Shepp, SO(2),
    compound spaces, ...) gets one sentence naming the space.

    Parameters
    ----------
    si_or_space : ob.SpaceInformation or ob.StateSpace

    Returns
    -------
    str or None
    """
    space = _space_of(si_or_space)
    if isinstance(space, ob.RealVectorStateSpace) and _dimension(space) == 2:
        return None
    return (f"the state space {describe_space(space)} is not {PLANE_SPACE}, the only space "
            f"this package's planners plan in for now")  # fmt: skip


def require_plane_space(si_or_space: Any, who: str) -> None:
    """Raise :class:`~rrtpso_ompl.errors.UnsupportedSpaceError` unless the space is the plane.

    Parameters
    ----------
    si_or_space : ob.SpaceInformation or ob.StateSpace
    who : str
        What refuses, for the message (``"PSOPathOptimizer"``).
    """
    problem = plane_space_problem(si_or_space)
    if problem is not None:
        raise UnsupportedSpaceError(f"{who}: {problem}")
