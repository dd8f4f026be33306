"""OMPL geometric paths to numpy arrays and back (2-D real vector states)."""

from __future__ import annotations

import numpy as np
from ompl import base as ob
from ompl import geometric as og

__all__ = ["array_to_path", "assign_path", "path_to_array"]


def path_to_array(path: og.PathGeometric) -> np.ndarray:
    """Waypoints of an OMPL geometric path as an ``(n, 2)`` array (copied)."""
    return np.array([(s[0], s[1]) for s in path.getStates()], dtype=float).reshape(-1, 2)


def array_to_path(si: ob.SpaceInformation, xy: np.ndarray) -> og.PathGeometric:
    """An OMPL geometric path through the waypoints ``xy`` ``(n, 2)``."""
    path = og.PathGeometric(si)
    assign_path(si, path, xy)
    return path


def assign_path(si: ob.SpaceInformation, path: og.PathGeometric, xy: np.ndarray) -> None:
    """Replace the states of ``path`` by the waypoints ``xy`` ``(n, 2)``, in place (the caller's
    object changes: e.g. the problem definition's solution path)."""
    path.clear()
    # The binding hands ownership of an allocated state to Python (freeing it here would free it
    # twice); append copies it into the path.
    state = si.allocState()
    for x, y in np.asarray(xy, dtype=float):
        state[0], state[1] = float(x), float(y)
        path.append(state)
