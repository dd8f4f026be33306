"""Repairing a seed whose motions fail the fine check, outside the plane.

OMPL's RRT* and its simplifier check a motion at the space's validity-checking resolution; the
path RRTstarPSO hands on must also pass :data:`~rrtpso_ompl.planners.pso.space_path.FINAL_FINER`
times that resolution (a motion that grazes an obstacle between OMPL's samples is a collision
the user's dense check finds). Measured before this module: 2 of 10 R^3 seeds, 1 of 10 R^6 and
3 of 10 Reeds-Shepp seeds had no seed passing that check, and RRTstarPSO gave no answer there.

The repair works through the space information alone: a motion ``a -> b`` that fails is replaced
by ``a -> m -> b``, ``m`` the motion's own mid-state (on the space's curve) or one of the states
drawn around it (a Gaussian of growing spread in the position coordinates and the angles, the
shortest detour first), each half checked at the fine factor; when no single state does, the
halves through the first few candidates are repaired in turn. Depth and tries are bounded, and
the whole repair stops after :data:`MAX_CHECKS` motion checks or when ``stop`` fires; the
result's motions have all passed the fine check, or there is no result.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...ompl_setup.spaces import SpaceAdapter
from ..pso.space_path import FINAL_FINER, MotionChecker

__all__ = ["MAX_CHECKS", "repair_path"]

#: Motion checks one repair may spend, at most (each at the fine factor).
MAX_CHECKS = 1000
#: Splits of one motion, at most (a motion becomes at most ``2 ** MAX_DEPTH`` motions).
MAX_DEPTH = 3
#: Spreads of the states drawn around a mid-state, as fractions of the motion's length in the
#: position coordinates (and of a quarter turn in the angles).
SPREADS = (0.02, 0.05, 0.1, 0.2, 0.4)
#: States drawn per spread.
DRAWS = 4
#: Candidate states whose two halves are repaired in turn when no single split does.
DEEPER = 2


class _Budget:
    """The checks left and the caller's stop test."""

    def __init__(self, checker: MotionChecker, stop: Callable[[], bool] | None) -> None:
        self.checker, self.stop = checker, stop
        self.left = MAX_CHECKS
        self._state = checker.si.allocState()  # Python's to free (never freeState)
        self._known: dict[tuple[bytes, bytes], bool] = {}

    def valid(self, row: np.ndarray) -> bool:
        """Whether the state of ``row`` passes the user's checker."""
        self.checker.adapter.assign(self._state, row)
        return bool(self.checker.si.isValid(self._state))

    def free(self, a: np.ndarray, b: np.ndarray) -> bool | None:
        """Whether ``a -> b`` passes the fine check; None when out of checks or time. A motion
        is checked once (the answers are kept)."""
        key = (a.tobytes(), b.tobytes())
        if key in self._known:
            return self._known[key]
        if self.left <= 0 or (self.stop is not None and self.stop()):
            return None
        self.left -= 1
        self._known[key] = self.checker.motion_free(a, b, factor=FINAL_FINER)
        return self._known[key]


def repair_path(rows: np.ndarray, adapter: SpaceAdapter, checker: MotionChecker,
                rng: np.random.Generator,
                stop: Callable[[], bool] | None = None) -> np.ndarray | None:  # fmt: skip
    """``rows`` with every motion that fails the fine check replaced by motions that pass it.

    Parameters
    ----------
    rows : ndarray, shape (k, dim)
        A path whose waypoints are valid states (RRT*'s, or the simplifier's); not modified.
    adapter : SpaceAdapter
        The space's rows (angles, bounds, the space's interpolation).
    checker : MotionChecker
        ``si.checkMotion`` and the finer check through the user's checker.
    rng : numpy.random.Generator
        The states drawn around a mid-state.
    stop : callable, optional
        Looked at before each motion check.

    Returns
    -------
    ndarray or None
        The repaired path (the end states exactly as given, an interior waypoint replaced when
        no motion leaving it could be repaired, each motion checked at
        :data:`~rrtpso_ompl.planners.pso.space_path.FINAL_FINER` times the resolution), or None
        when a motion could not be repaired within the bounds.
    """
    budget = _Budget(checker, stop)
    out = [rows[0]]
    for b in rows[1:]:
        piece = _motion(out[-1], b, adapter, budget, rng, MAX_DEPTH)
        if piece is None and len(out) > 1 and budget.left > 0:
            # The motion's start waypoint may itself be the trouble (every motion leaving it
            # with its heading grazes): a repair from the waypoint before it replaces it.
            out.pop()
            piece = _motion(out[-1], b, adapter, budget, rng, MAX_DEPTH)
        if piece is None:
            return None
        out.extend(piece)
    return np.array(out)


def _motion(a, b, adapter: SpaceAdapter, budget: _Budget, rng, depth: int) -> list | None:
    """The states after ``a`` of a checked replacement of ``a -> b`` (``[b]`` when it passes):
    first one split through any of the candidate states with both halves as they are, then the
    halves through the first :data:`DEEPER` candidates repaired in turn (breadth before depth:
    most grazes need one state beside the motion)."""
    free = budget.free(a, b)
    if free:
        return [b]
    if free is None or depth == 0:
        return None
    candidates = [m for m in _around(_mid_state(a, b, adapter), a, b, adapter, rng)
                  if budget.valid(m)]  # fmt: skip
    for m in candidates:
        left = budget.free(a, m)
        right = budget.free(m, b) if left else False
        if left is None or right is None:
            return None
        if right:
            return [m, b]
    for m in candidates[:DEEPER]:
        left = _motion(a, m, adapter, budget, rng, depth - 1)
        right = _motion(m, b, adapter, budget, rng, depth - 1) if left is not None else None
        if right is not None:
            return left + right
        if budget.left <= 0:
            return None
    return None


def _mid_state(a: np.ndarray, b: np.ndarray, adapter: SpaceAdapter) -> np.ndarray:
    """The state halfway along the space's own curve from ``a`` to ``b``."""
    space = adapter.space
    sa, sb, mid = space.allocState(), space.allocState(), space.allocState()
    adapter.assign(sa, a)
    adapter.assign(sb, b)
    space.interpolate(sa, sb, 0.5, mid)
    return adapter.row(mid)


def _around(mid: np.ndarray, a: np.ndarray, b: np.ndarray, adapter: SpaceAdapter, rng):
    """The mid-state, then :data:`DRAWS` states per spread of :data:`SPREADS` around it, within
    the space's bounds, angles wrapped, each spread's shortest detour first."""
    yield mid
    lin = ~adapter.angular
    # The motion's length by the space's distance: a car's loop is long where its ends are near.
    scale = max(float(np.linalg.norm(b[lin] - a[lin])), float(adapter.distances(a, b)), 1e-9)
    low, high = adapter.bounds()
    sigma = np.where(lin, scale, 0.5 * np.pi)
    for spread in SPREADS:
        drawn = mid + rng.standard_normal((DRAWS, adapter.dim)) * (spread * sigma)
        drawn[:, lin] = np.clip(drawn[:, lin], low[lin], high[lin])
        drawn = adapter.normalised(drawn)
        detour = adapter.distances(a, drawn) + adapter.distances(drawn, b)
        yield from drawn[np.argsort(detour, kind="stable")]
