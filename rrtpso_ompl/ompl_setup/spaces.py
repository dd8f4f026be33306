"""OMPL state spaces beyond the plane as numpy rows: R^n, SE(2), Dubins and Reeds-Shepp.

The swarm moves waypoints as real vectors; this module is the one place that says how a state of
a supported space is such a vector, and how far apart two of them are, for a whole batch at once:

========================  ===========  ===============================================  ==========
space                     row          distance of a segment ``a -> b``                 how
========================  ===========  ===============================================  ==========
``RealVectorStateSpace``  ``s[0..n)``  Euclidean                                        numpy
``SE2StateSpace``         x, y, yaw    ``w0 * |dxy| + w1 * |wrap(dyaw)|`` (OMPL's       numpy
                                       subspace weights, 1 and 0.5 by default)
``DubinsStateSpace``      x, y, yaw    shortest forward path of turning radius rho      numpy
                                       (OMPL's own six words; ``isSymmetric``: the
                                       shorter of both directions)
``ReedsSheppStateSpace``  x, y, yaw    shortest path forwards and backwards             a loop over
                                                                                        ``distance``
========================  ===========  ===============================================  ==========

(The closed forms are in :mod:`.curves`; Reeds-Shepp's 48 words there are exact but slower in
numpy than OMPL's C++ called once a segment, so the adapter loops.)

Every distance equals ``space.distance`` (tested to 1e-9 on thousands of random pairs); a user's
Python subclass of one of these spaces may override ``distance``, so there the adapter asks the
space itself, one segment at a time. Anything else (SE(3), SO(2) alone, a compound space of the
user's, ...) is refused with :class:`~rrtpso_ompl.errors.UnsupportedSpaceError`, naming the space.

The Python bindings do not expose OMPL's space-type enum, so spaces are told apart by their
Python classes (``DubinsStateSpace`` and ``ReedsSheppStateSpace`` subclass ``SE2StateSpace``),
and the turning radius, which has no getter, is read back from one distance (``getPath`` gives
the length in turning radii).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..errors import UnsupportedSpaceError
from .curves import dubins_lengths, reeds_shepp_lengths
from .space import describe_space

__all__ = [
    "MAX_DIMENSION",
    "SUPPORTED_SPACES",
    "DubinsAdapter",
    "RealVectorAdapter",
    "ReedsSheppAdapter",
    "SE2Adapter",
    "SpaceAdapter",
    "space_adapter",
    "unsupported_space",
    "wrap_angle",
]

#: The spaces the adapter reads, as a user writes them (for messages and docs).
SUPPORTED_SPACES = ("ob.RealVectorStateSpace(n)", "ob.SE2StateSpace", "ob.DubinsStateSpace",
                    "ob.ReedsSheppStateSpace")  # fmt: skip
#: Most coordinates of a real vector space the swarm is offered (a particle holds every interior
#: waypoint's coordinates: beyond this the swarm is the wrong tool).
MAX_DIMENSION = 64

_TWO_PI = 2.0 * math.pi


def wrap_angle(yaw: np.ndarray) -> np.ndarray:
    """Angles in ``[-pi, pi)`` as OMPL's ``SO2StateSpace.enforceBounds`` puts them, rad."""
    v = np.fmod(np.asarray(yaw, dtype=float), _TWO_PI)
    v = np.where(v < -math.pi, v + _TWO_PI, v)
    return np.where(v >= math.pi, v - _TWO_PI, v)


def _space_of(si_or_space: Any) -> Any:
    getter = getattr(si_or_space, "getStateSpace", None)
    return getter() if callable(getter) else si_or_space


class SpaceAdapter:
    """States of one OMPL state space as rows of ``dim`` floats, and their distances.

    Parameters
    ----------
    space : ob.StateSpace
        A space of the adapter's kind (use :func:`space_adapter` to pick the kind).

    Attributes
    ----------
    kind : str
        ``"R^n"``, ``"SE(2)"``, ``"Dubins"`` or ``"Reeds-Shepp"``.
    dim : int
        Floats per state.
    angular : ndarray of bool, shape (dim,)
        Which coordinates are angles (they wrap; the swarm moves them within +-pi).
    vectorised : bool
        Whether :meth:`distances` is numpy (False: a loop over ``space.distance``).
    """

    kind = ""
    dim = 0

    def __init__(self, space: Any) -> None:
        self.space = space
        self.angular = np.zeros(self.dim, dtype=bool)
        self.vectorised = True
        self._a = space.allocState()
        self._b = space.allocState()

    # -- states <-> rows -----------------------------------------------------------------------
    def row(self, state: Any) -> np.ndarray:
        """The state's coordinates (copied: OMPL's states are borrowed)."""
        raise NotImplementedError

    def assign(self, state: Any, row: Sequence[float]) -> None:
        """Write ``row`` into ``state`` as it is (angles unwrapped: :meth:`normalised` first)."""
        raise NotImplementedError

    def to_array(self, states: Sequence[Any]) -> np.ndarray:
        """``(k, dim)`` rows of the states."""
        return np.array([self.row(s) for s in states], dtype=float).reshape(-1, self.dim)

    def path_to_array(self, path: og.PathGeometric) -> np.ndarray:
        """The states of an ``og.PathGeometric`` as ``(k, dim)`` rows."""
        return self.to_array(path.getStates())

    def array_to_path(self, si: ob.SpaceInformation, rows: np.ndarray) -> og.PathGeometric:
        """A new ``og.PathGeometric`` with one state per row, in order (the rows as they are)."""
        path = og.PathGeometric(si)
        state = self.space.allocState()
        for r in np.asarray(rows, dtype=float).reshape(-1, self.dim):
            self.assign(state, r)
            path.append(state)  # appends a copy
        # The binding hands an allocated state to Python, which frees it (never freeState).
        return path

    def normalised(self, rows: np.ndarray) -> np.ndarray:
        """``rows`` with angles wrapped into ``[-pi, pi)`` (a copy)."""
        out = np.array(rows, dtype=float)
        if self.angular.any():
            out[..., self.angular] = wrap_angle(out[..., self.angular])
        return out

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper limits of each coordinate (angles: ``-pi``, ``pi``)."""
        b = self.space.getBounds()
        n = self.dim - int(self.angular.sum())
        low = np.full(self.dim, -math.pi)
        high = np.full(self.dim, math.pi)
        low[:n] = [b.low[i] for i in range(n)]
        high[:n] = [b.high[i] for i in range(n)]
        return low, high

    # -- distances -----------------------------------------------------------------------------
    def distances(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``space.distance`` from each row of ``a`` to the matching row of ``b``.

        Parameters
        ----------
        a, b : array_like, shape (..., dim)
            Broadcast against each other.

        Returns
        -------
        ndarray, shape (...)
            In the space's unit (problem units; SE(2) adds weighted radians).
        """
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        return self._looped(a, b)

    def _looped(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The space's own ``distance``, one pair at a time (about a microsecond each)."""
        sa, sb, dist = self._a, self._b, self.space.distance
        flat_a = a.reshape(-1, self.dim)
        flat_b = b.reshape(-1, self.dim)
        out = np.empty(len(flat_a))
        for k in range(len(flat_a)):
            self.assign(sa, flat_a[k])
            self.assign(sb, flat_b[k])
            out[k] = dist(sa, sb)
        return out.reshape(a.shape[:-1])

    def length(self, rows: np.ndarray) -> float:
        """A path's length: the sum of the space's distances between consecutive rows."""
        rows = np.asarray(rows, dtype=float).reshape(-1, self.dim)
        if len(rows) < 2:
            return 0.0
        return float(self.distances(rows[:-1], rows[1:]).sum())

    def lengths(self, paths: np.ndarray) -> np.ndarray:
        """Lengths of a batch of paths, shape ``(P, k, dim) -> (P,)``."""
        paths = np.asarray(paths, dtype=float)
        return self.distances(paths[:, :-1], paths[:, 1:]).sum(axis=-1)

    def describe(self) -> str:
        """The space in words (its OMPL name and class)."""
        return describe_space(self.space)


class RealVectorAdapter(SpaceAdapter):
    """``ob.RealVectorStateSpace(n)``: the row is the state; Euclidean distance."""

    kind = "R^n"

    def __init__(self, space: Any) -> None:
        self.dim = int(space.getDimension())
        super().__init__(space)
        self.vectorised = type(space) is ob.RealVectorStateSpace

    def row(self, state: Any) -> np.ndarray:
        return np.array([state[i] for i in range(self.dim)], dtype=float)

    def assign(self, state: Any, row: Sequence[float]) -> None:
        for i in range(self.dim):
            state[i] = float(row[i])

    def distances(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        if not self.vectorised:
            return self._looped(a, b)
        return np.sqrt(((b - a) ** 2).sum(axis=-1))


class SE2Adapter(SpaceAdapter):
    """``ob.SE2StateSpace``: rows ``(x, y, yaw)``; OMPL's weighted distance
    ``w0 * |dxy| + w1 * |wrap(dyaw)|`` with the space's own subspace weights."""

    kind = "SE(2)"
    dim = 3

    def __init__(self, space: Any) -> None:
        super().__init__(space)
        self.angular = np.array([False, False, True])
        self.weights = tuple(float(w) for w in space.getSubspaceWeights())
        self.vectorised = type(space) is ob.SE2StateSpace

    def row(self, state: Any) -> np.ndarray:
        return np.array([state.getX(), state.getY(), state.getYaw()], dtype=float)

    def assign(self, state: Any, row: Sequence[float]) -> None:
        state.setXY(float(row[0]), float(row[1]))
        state.setYaw(float(row[2]))

    def distances(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        if not self.vectorised:
            return self._looped(a, b)
        xy = np.sqrt((b[..., 0] - a[..., 0]) ** 2 + (b[..., 1] - a[..., 1]) ** 2)
        # OMPL's SO2 distance: |a - b|, or 2 pi minus it beyond pi (for angles in [-pi, pi]).
        d = np.abs(a[..., 2] - b[..., 2])
        yaw = np.where(d > math.pi, _TWO_PI - d, d)
        return self.weights[0] * xy + self.weights[1] * yaw


def _turning_radius(space: Any) -> float:
    """A Dubins or Reeds-Shepp space's turning radius: ``getPath`` measures in turning radii,
    ``distance`` in units, and there is no getter."""
    a, b = space.allocState(), space.allocState()  # Python's to free
    a.setXY(0.0, 0.0)
    a.setYaw(0.0)
    b.setXY(1.0, 0.0)
    b.setYaw(0.0)
    return float(space.distance(a, b) / space.getPath(a, b).length())


class DubinsAdapter(SE2Adapter):
    """``ob.DubinsStateSpace(rho, isSymmetric)``: rows ``(x, y, yaw)``; the Dubins distance in
    numpy (:func:`dubins_lengths`, OMPL's own words and tolerances)."""

    kind = "Dubins"

    def __init__(self, space: Any) -> None:
        super().__init__(space)
        self.turning_radius = _turning_radius(space)
        self.symmetric = bool(space.hasSymmetricDistance())
        self.vectorised = type(space) is ob.DubinsStateSpace

    def distances(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        if not self.vectorised:
            return self._looped(a, b)
        rho = self.turning_radius
        forward = dubins_lengths(a, b, rho)  # in turning radii
        if self.symmetric:
            forward = np.minimum(forward, dubins_lengths(b, a, rho))
        return rho * forward


class ReedsSheppAdapter(SE2Adapter):
    """``ob.ReedsSheppStateSpace(rho)``: rows ``(x, y, yaw)``; the distance from the space itself,
    one segment at a time.

    OMPL's 48 words in numpy (:func:`~rrtpso_ompl.ompl_setup.curves.reeds_shepp_lengths`, equal
    to ``space.distance`` to 1e-14) are slower than this loop: measured 14 us a segment in the
    swarm's batches of 210 (6 us in batches of 20,000) against 4.4 us for the loop, on a loaded
    2-core VM (docs/spaces.md). Set ``vectorised = True`` to use them all the same."""

    kind = "Reeds-Shepp"

    def __init__(self, space: Any) -> None:
        super().__init__(space)
        self.turning_radius = _turning_radius(space)
        self.vectorised = False

    def distances(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
        if not self.vectorised or type(self.space) is not ob.ReedsSheppStateSpace:
            return self._looped(a, b)
        return self.turning_radius * reeds_shepp_lengths(a, b, self.turning_radius)


# -- choosing an adapter ---------------------------------------------------------------------------
def unsupported_space(si_or_space: Any) -> str | None:
    """Why the swarm cannot read a space's states as rows, or None when it can.

    Parameters
    ----------
    si_or_space : ob.SpaceInformation or ob.StateSpace

    Returns
    -------
    str or None
        One sentence naming the space and what is supported.
    """
    space = _space_of(si_or_space)
    if isinstance(space, ob.SE2StateSpace):
        return None
    if isinstance(space, ob.RealVectorStateSpace) and 1 <= space.getDimension() <= MAX_DIMENSION:
        return None
    return (f"the state space {describe_space(space)} is none of those this package's planners "
            f"plan in: ob.RealVectorStateSpace(n) for n = 1..{MAX_DIMENSION}, "
            f"{', '.join(SUPPORTED_SPACES[1:])}")  # fmt: skip


def space_adapter(si_or_space: Any, who: str = "") -> SpaceAdapter:
    """The adapter of a supported space.

    Parameters
    ----------
    si_or_space : ob.SpaceInformation or ob.StateSpace
    who : str
        What asks, for the message (``"RRTstarPSO"``).

    Raises
    ------
    UnsupportedSpaceError
        For any other space (SE(3), SO(2) alone, a compound space of the user's, ...), naming it.
    """
    problem = unsupported_space(si_or_space)
    if problem is not None:
        raise UnsupportedSpaceError(f"{who}: {problem}" if who else problem)
    space = _space_of(si_or_space)
    if isinstance(space, ob.DubinsStateSpace):
        return DubinsAdapter(space)
    if isinstance(space, ob.ReedsSheppStateSpace):
        return ReedsSheppAdapter(space)
    if isinstance(space, ob.SE2StateSpace):
        return SE2Adapter(space)
    return RealVectorAdapter(space)
