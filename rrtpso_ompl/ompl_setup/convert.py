"""OMPL geometric paths to numpy arrays and back (2-D real vector states).

Only the plane: a path of any other space is refused (:mod:`.space`) rather than read or written
as two coordinates. A path does not tell its space (``PathGeometric.getSpaceInformation`` is not
bound), so :func:`path_to_array` can refuse only states that are not real vectors (SE(2), ...);
the caller makes sure an ``R^n`` path is ``R^2``, as :func:`assign_path` does from ``si``."""

from __future__ import annotations

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..errors import UnsupportedSpaceError
from .space import require_plane_space

__all__ = ["array_to_path", "assign_path", "path_to_array"]


def path_to_array(path: og.PathGeometric) -> np.ndarray:
    """Waypoints of an OMPL geometric path as an ``(n, 2)`` array (copied).

    Raises
    ------
    UnsupportedSpaceError
        For states that are not real vectors (an SE(2) path, ...).
    """
    states = path.getStates()
    if states and not isinstance(states[0], ob.RealVectorStateType):
        raise UnsupportedSpaceError(
            f"path_to_array: the path's states are {type(states[0]).__name__}, not 2-D real "
            f"vectors: only paths of ob.RealVectorStateSpace(2) convert to (n, 2) arrays"
        )
    return np.array([(s[0], s[1]) for s in states], dtype=float).reshape(-1, 2)


def array_to_path(si: ob.SpaceInformation, xy: np.ndarray) -> og.PathGeometric:
    """An OMPL geometric path through the waypoints ``xy`` ``(n, 2)``."""
    path = og.PathGeometric(si)
    assign_path(si, path, xy)
    return path


def assign_path(si: ob.SpaceInformation, path: og.PathGeometric, xy: np.ndarray) -> None:
    """Replace the states of ``path`` by the waypoints ``xy`` ``(n, 2)``, in place (the caller's
    object changes: e.g. the problem definition's solution path).

    Raises
    ------
    UnsupportedSpaceError
        When ``si``'s space is not ``ob.RealVectorStateSpace(2)`` (the other coordinates of its
        states would be left unset).
    """
    require_plane_space(si, "array_to_path")
    path.clear()
    # The binding hands ownership of an allocated state to Python (freeing it here would free it
    # twice); append copies it into the path.
    state = si.allocState()
    for x, y in np.asarray(xy, dtype=float):
        state[0], state[1] = float(x), float(y)
        path.append(state)
