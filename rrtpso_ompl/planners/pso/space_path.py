"""The swarm over a path's waypoints in R^n, SE(2), Dubins and Reeds-Shepp spaces.

The plane has an exact vectorised world (:mod:`.path_optimizer`); these spaces have only the
space information: the user's validity checker, and ``si.checkMotion`` along the space's own
interpolation (a straight line in R^n, OMPL's SE(2) interpolation, the Dubins or Reeds-Shepp
curve). That check is exact in the sense the space defines (the one OMPL's planners use) but it
is a Python callback per state, far too slow for every particle of every iteration. So:

* a particle is every interior waypoint's row (:mod:`rrtpso_ompl.ompl_setup.spaces`: the
  coordinates, or ``x, y, yaw``), the end points fixed; the cost is the path's length, the sum of
  the space's distances, computed for the whole swarm in numpy (Reeds-Shepp: a loop over
  ``space.distance``);
* a candidate is *unknown* until checked, and unknown counts as ``inf``: only candidates that
  would lower their particle's best are checked, the shortest first, at most
  :data:`CHECKED_PER_EVALUATION` of them per evaluation (each costs one ``checkMotion`` per
  segment, stopping at the first blocked one), so ``checkMotion`` runs a bounded number of
  times per iteration; a blocked candidate is ``inf`` too. Every particle's best and the swarm's
  best are therefore checked paths (the seed, particle 0, is the input). A candidate that
  would become the swarm's best is also checked between ``checkMotion``'s states
  (:class:`MotionChecker`: a shortened path hugs obstacles, in the gaps of a coarse check);
  a particle's own best only guides the swarm, ``checkMotion`` suffices for it;
* the result is checked once more, segment by segment, and returned only when strictly shorter
  than the input; else the input comes back unchanged.

Rounds: a greedy shortcut first (``prune``: drop a waypoint whenever the motion past it is free;
the triangle inequality holds in all four spaces, and a result is kept only when shorter), the
swarm around the path, then ``refine_rounds`` rounds that first insert the mid-state of the
longest segments (``space.interpolate(a, b, 0.5)``: on the space's own curve, so the length is
unchanged and the new waypoints are free), up to ``max_waypoints``, and with a deadline up to
``polish_rounds`` rounds re-centred on the best path while each still shortens it by more than
``polish_tolerance``. ``smoothness_weight``, ``violation_weight``, ``window`` and the inflation
cost are the plane's (see docs/spaces.md); here the swarm lowers the length alone.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from ompl import base as ob

from ...ompl_setup.spaces import SpaceAdapter
from . import swarm as pso
from .path_optimizer import PathOptimizerOptions
from .swarm import PSOOptions

__all__ = [
    "CHECKED_PER_EVALUATION",
    "FINAL_FINER",
    "FINER",
    "MotionChecker",
    "SpacePathResult",
    "optimize_ompl_path",
    "optimize_space_path",
]

#: Motions are checked at this many times the space's validity-checking resolution.
FINER = 10
#: ... and a path that is returned, at this many times (once per path: a swarm's shortened path
#: hugs the obstacles, and a check ten times finer still let 2 of 10 Dubins paths cut into an
#: obstacle between its samples, found by 4,000 states along the path; docs/spaces.md).
FINAL_FINER = 100
#: Candidates checked with ``checkMotion`` per evaluation of the swarm, at most (the shortest of
#: those that would improve their particle's best).
CHECKED_PER_EVALUATION = 8
#: A candidate must be this much shorter (relative) than what it replaces to count.
_RELATIVE_GAIN = 1e-12


@dataclass(frozen=True)
class SpacePathResult:
    """Outcome of :func:`optimize_space_path`.

    Attributes
    ----------
    path : ndarray, shape (k, dim)
        The returned waypoints (the input itself when nothing shorter was found).
    length, input_length : float
        Lengths by the space's distance (the sum over segments).
    improved : bool
        Whether ``path`` differs from the input and is shorter.
    history : ndarray
        Best length after each swarm iteration, over all rounds.
    n_iterations, n_evaluations, rounds : int
        Swarm iterations, particle evaluations and rounds over the whole call.
    motion_checks : int
        ``si.checkMotion`` calls (each one segment).
    time : float
        Wall-clock seconds.
    """

    path: np.ndarray
    length: float
    input_length: float
    improved: bool
    history: np.ndarray = field(repr=False)
    n_iterations: int
    n_evaluations: int
    rounds: int
    motion_checks: int
    time: float

    @property
    def cost(self) -> float:
        """The length (the swarm's only cost in these spaces)."""
        return self.length

    @property
    def input_cost(self) -> float:
        return self.input_length


class MotionChecker:
    """A motion of rows checked by ``si.checkMotion`` (the space's interpolation and the user's
    checker, or the user's motion validator), then at :data:`FINER` times its resolution.

    OMPL's discrete check samples a motion at the space's resolution; a swarm that shortens a
    path looks for exactly the gaps between those samples (a tight motion past an obstacle
    cuts its corner between two of them), so the states in between are checked too, as the
    plane's :class:`~rrtpso_ompl.planners.base.SpaceInformationCollisionModel` does. Not exact
    (nothing is with a point checker): a motion may still cut into an obstacle between the
    finer samples, by at most ``(h / FINER)^2 / (8 r)`` for a disc of radius ``r`` and a
    resolution ``h``.

    Parameters
    ----------
    si : ob.SpaceInformation
    adapter : SpaceAdapter
        Writes rows into states (angles as given: the caller normalises).

    Attributes
    ----------
    calls : int
        Motions checked (one ``checkMotion`` each).
    fine_seconds, fine_motions : float, int
        Time spent in the finer checks and how many motions it checked (the checker's measured
        cost, which sizes the time kept back for the last check).
    """

    def __init__(self, si: ob.SpaceInformation, adapter: SpaceAdapter) -> None:
        self.si = si
        self.adapter = adapter
        self.space = si.getStateSpace()
        self.calls = 0
        self.fine_seconds = 0.0
        self.fine_motions = 0
        #: A motion validator that says it is exact (``exact = True``, as
        #: :class:`~rrtpso_ompl.ompl_setup.car.CurveMotionValidator`) needs no finer samples.
        self.exact = bool(getattr(si.getMotionValidator(), "exact", False))
        self._a = si.allocState()  # Python's to free (never freeState)
        self._b = si.allocState()
        self._s = si.allocState()

    def motion_free(self, a: np.ndarray, b: np.ndarray, fine: bool = True,
                    factor: int = FINER) -> bool:  # fmt: skip
        """Whether the motion from row ``a`` to row ``b`` is valid (``fine``: also at
        ``factor`` times the resolution; the time of checks at :data:`FINER` is measured)."""
        sa, sb, s = self._a, self._b, self._s
        self.adapter.assign(sa, a)
        self.adapter.assign(sb, b)
        self.calls += 1
        if self.exact:  # the check is the whole check: it is timed as the finer one is
            t0 = time.perf_counter()
            free = bool(self.si.checkMotion(sa, sb))
            self.fine_seconds += time.perf_counter() - t0
            self.fine_motions += 1
            return free
        if not self.si.checkMotion(sa, sb):
            return False
        if not fine:
            return True
        t0 = time.perf_counter()
        try:
            return self._between(sa, sb, s, factor)
        finally:
            if factor == FINER:
                self.fine_seconds += time.perf_counter() - t0
                self.fine_motions += 1

    def _between(self, sa, sb, s, factor: int) -> bool:
        n = factor * max(int(self.space.validSegmentCount(sa, sb)), 1)
        interpolate, valid = self.space.interpolate, self.si.isValid
        for k in range(1, n):
            if k % factor == 0:
                continue  # a state checkMotion looked at
            interpolate(sa, sb, k / n, s)
            if not valid(s):
                return False
        return True

    def fine_mean(self) -> float:
        """Measured seconds of the finer check per motion (0 before any)."""
        return self.fine_seconds / self.fine_motions if self.fine_motions else 0.0

    def final_check_seconds(self, motions: int) -> float:
        """The measured time a check of ``motions`` motions at :data:`FINAL_FINER` takes (the
        finer checks' cost per motion, scaled: the states checked grow with the factor)."""
        return self.fine_mean() * motions * (1 if self.exact else FINAL_FINER / FINER)

    def path_free(self, rows: np.ndarray, stop: Callable[[], bool] | None = None,
                  fine: bool = True, factor: int = FINER) -> bool | None:  # fmt: skip
        """Whether every motion of the path is valid; None when ``stop`` fired first."""
        for k in range(len(rows) - 1):
            if stop is not None and stop():
                return None
            if not self.motion_free(rows[k], rows[k + 1], fine, factor):
                return False
        return True


def optimize_space_path(
    rows: np.ndarray,
    adapter: SpaceAdapter,
    si: ob.SpaceInformation,
    options: PathOptimizerOptions,
    rng: np.random.Generator,
    terminate: Callable[[], bool] | None = None,
    deadline: float | None = None,
) -> SpacePathResult:
    """Shorten a valid path of a supported space with the swarm; never longer, never invalid.

    Parameters
    ----------
    rows : ndarray, shape (k, dim)
        The path's states as rows (:meth:`SpaceAdapter.path_to_array`); not modified.
    adapter : SpaceAdapter
        The space's adapter (:func:`~rrtpso_ompl.ompl_setup.spaces.space_adapter`).
    si : ob.SpaceInformation
        Checks motions (``si.checkMotion``).
    options : PathOptimizerOptions
        The swarm's and the optimiser's parameters (those this module reads: see its docstring).
    rng : numpy.random.Generator
        The only source of randomness.
    terminate, deadline : callable, float, optional
        A stop test and a ``time.perf_counter()`` time (which also enables the polish rounds),
        looked at between evaluations and motion checks: the best checked path so far is kept.

    Returns
    -------
    SpacePathResult
    """
    t0 = time.perf_counter()
    seed = np.array(rows, dtype=float).reshape(-1, adapter.dim)
    checker = MotionChecker(si, adapter)
    input_length = adapter.length(seed)
    stop = _Stop(terminate, deadline, checker, len(seed) - 1)
    history: list[float] = []
    counts = [0, 0, 0]  # iterations, evaluations, rounds
    best = seed  # no time to check a result: the input comes back as it is
    if stop.room_for_a_check(seed):
        best = _improve(seed, adapter, checker, options, rng, stop, deadline, history, counts)
    best = _final(seed, best, adapter, checker, input_length)
    length = adapter.length(best)
    return SpacePathResult(path=best, length=length, input_length=input_length,
                           improved=best is not seed, history=np.asarray(history),
                           n_iterations=counts[0], n_evaluations=counts[1], rounds=counts[2],
                           motion_checks=checker.calls, time=time.perf_counter() - t0)  # fmt: skip


def _improve(seed, adapter, checker, options, rng, stop, deadline, history, counts):
    """The greedy shortcut, then the rounds: the best path found (``seed`` itself when none)."""
    best = seed
    if options.prune and len(best) > 2:
        best = _prune(best, adapter, checker, stop)
    plan = ["swarm"] + ["refine"] * options.refine_rounds
    for kind in plan + (["polish"] * options.polish_rounds if deadline is not None else []):
        if stop() or len(best) <= 2:  # out of time, or a single motion: nothing to move
            break
        before = adapter.length(best)
        best = _round(kind, best, adapter, checker, options, rng, stop, deadline, history, counts)
        stop.motions = len(best) - 1
        if kind == "polish" and before - adapter.length(best) <= options.polish_tolerance * before:
            break
    return best


#: The time kept back for the last check of the path is this many times its measured cost.
FINAL_CHECK_MARGIN = 1.5


class _Stop:
    """When the work stops: the caller's condition, or ``deadline`` less the time the last check
    of a path of ``motions`` motions needs (:data:`FINAL_CHECK_MARGIN` times its measured cost,
    :meth:`MotionChecker.final_check_seconds`: a user's checker may take a millisecond a state)."""

    def __init__(self, terminate, deadline: float | None, checker: MotionChecker,
                 motions: int) -> None:  # fmt: skip
        self.terminate, self.deadline, self.checker = terminate, deadline, checker
        self.motions = motions

    def __call__(self) -> bool:
        if self.terminate is not None and self.terminate():
            return True
        if self.deadline is None:
            return False
        reserve = FINAL_CHECK_MARGIN * self.checker.final_check_seconds(self.motions)
        return time.perf_counter() >= self.deadline - reserve

    def room_for_a_check(self, rows: np.ndarray) -> bool:
        """With a deadline: time one finer check of the first motion; False when checking the
        whole path that way would not fit twice in the time left."""
        if self.deadline is None or len(rows) <= 2:
            return True
        self.checker.motion_free(rows[0], rows[1])
        need = 2.0 * self.checker.final_check_seconds(len(rows) - 1)
        return time.perf_counter() + need <= self.deadline


def _round(kind, rows, adapter, checker, options, rng, stop, deadline, history, counts):
    """One round: a swarm around ``rows``, after inserting mid-states for a ``"refine"``
    round. Mid-states keep the length (up to rounding; a symmetric Dubins space may split a
    motion the other way round): a finer path that came out longer is not used."""
    if kind == "refine":
        finer = _refine(rows, adapter, options.max_waypoints)
        if adapter.length(finer) <= adapter.length(rows):
            rows = finer
    return _swarm_round(rows, adapter, checker, options, rng, stop, deadline, history, counts)


def _final(seed: np.ndarray, best: np.ndarray, adapter: SpaceAdapter, checker: MotionChecker,
           input_length: float) -> np.ndarray:  # fmt: skip
    """``best`` once checked again along every motion (at :data:`FINAL_FINER` times the
    resolution) and strictly shorter; else ``seed``."""
    if best is seed or not adapter.length(best) < input_length * (1.0 - _RELATIVE_GAIN):
        return seed
    return best if checker.path_free(best, factor=FINAL_FINER) else seed


def _prune(rows: np.ndarray, adapter: SpaceAdapter, checker: MotionChecker, stop) -> np.ndarray:
    """Greedy shortcut: from each kept waypoint, the farthest later one reachable by a valid
    motion (one ``checkMotion`` per try, at most ``k^2 / 2`` on ``k`` waypoints; the input's
    own motions are never re-checked). Kept only when shorter."""
    keep = [0]
    i, last = 0, len(rows) - 1
    while i < last:
        j = last
        while j > i + 1:
            if stop():
                return rows
            if checker.motion_free(rows[i], rows[j]):
                break
            j -= 1
        keep.append(j)
        i = j
    pruned = rows[keep]
    return pruned if adapter.length(pruned) < adapter.length(rows) else rows


def _refine(rows: np.ndarray, adapter: SpaceAdapter, max_waypoints: int) -> np.ndarray:
    """The mid-states of the longest segments inserted (the space's own interpolation, so the
    length and the validity stay as they were), up to ``max_waypoints`` waypoints."""
    room = min(max_waypoints - len(rows), len(rows) - 1)
    if room <= 0:
        return rows
    seg = adapter.distances(rows[:-1], rows[1:])
    split = np.sort(np.argsort(-seg, kind="stable")[:room])
    space = adapter.space
    a, b, mid = space.allocState(), space.allocState(), space.allocState()
    mids = []
    for k in split.tolist():
        adapter.assign(a, rows[k])
        adapter.assign(b, rows[k + 1])
        space.interpolate(a, b, 0.5, mid)
        mids.append(adapter.row(mid))
    return np.insert(rows, split + 1, np.array(mids), axis=0)


def _boxes(rows: np.ndarray, adapter: SpaceAdapter, fraction: float):
    """Each interior waypoint's search box (positions: ``fraction`` of its longer neighbouring
    step, within the space's bounds; angles: a whole turn around the seed), the spread of its
    initial cloud, and the mean step (the velocity clamp's scale)."""
    lin = ~adapter.angular
    step = np.linalg.norm(np.diff(rows[:, lin], axis=0), axis=1)
    step = np.maximum(step, 1e-9)
    half = fraction * np.maximum(step[:-1], step[1:])
    interior = rows[1:-1]
    low, high = adapter.bounds()
    lo = np.where(lin, np.maximum(interior - half[:, None], low), interior - np.pi)
    hi = np.where(lin, np.minimum(interior + half[:, None], high), interior + np.pi)
    local = np.minimum(step[:-1], step[1:])
    sigma = np.where(lin, local[:, None], np.pi)
    return lo, hi, sigma, float(step.mean())


def _swarm_round(rows, adapter, checker, options, rng, stop, deadline, history, counts):
    """One swarm over the interior waypoints of ``rows``; the best checked path (``rows`` when
    no candidate beat it)."""
    interior = rows[1:-1]
    k, dim = interior.shape
    lo, hi, sigma, mean_step = _boxes(rows, adapter, options.box_fraction)
    n = options.swarm_size
    x0 = interior.reshape(-1)
    init = x0 + rng.standard_normal((n, k * dim)) * (options.init_spread * sigma.reshape(-1))
    init[0] = x0  # the seed is a particle: the swarm's best starts as a valid path
    cost = _CheckedLength(rows, adapter, checker, n, stop)
    swarm = PSOOptions.from_values(asdict(options))
    res = pso.minimize(cost, lo.reshape(-1), hi.reshape(-1), swarm, rng, init=init,
                       v_max=options.v_max_fraction * mean_step, terminate=stop,
                       deadline=deadline)  # fmt: skip
    history.extend(res.history.tolist())
    counts[0] += res.n_iterations
    counts[1] += res.n_evaluations
    counts[2] += 1
    if not np.isfinite(res.cost) or not res.cost < cost.seed_length:
        return rows
    return cost.path_of(res.position)


class _CheckedLength:
    """The swarm's cost: a particle's path length when the path was checked valid, else ``inf``.

    ``minimize`` evaluates the first swarm in chunks (in order) and then the whole swarm each
    iteration; the rows seen so far tell which particles a call holds, so that each particle's
    best checked length is known here and only candidates that would lower it are checked.
    (Were that bookkeeping off, only the choice of candidates would suffer: every finite cost
    returned is the length of a path checked valid.)
    """

    def __init__(self, rows, adapter: SpaceAdapter, checker: MotionChecker, n: int, stop) -> None:
        self.start, self.goal = rows[:1], rows[-1:]
        self.adapter, self.checker, self.n, self.stop = adapter, checker, n, stop
        self.k = len(rows) - 2
        self.seed_length = adapter.length(rows)
        self.seed = np.vstack([rows[:1], adapter.normalised(rows[1:-1]), rows[-1:]])
        self.known = np.full(n, np.inf)  # each particle's best checked length
        self.best = self.seed_length  # the swarm's best (checked finely)
        self.seen = 0  # rows of the first evaluation seen so far

    def path_of(self, x: np.ndarray) -> np.ndarray:
        """The waypoints of one particle, interior angles wrapped (as they are checked)."""
        mid = self.adapter.normalised(np.asarray(x, dtype=float).reshape(self.k, -1))
        return np.vstack([self.start, mid, self.goal])

    def __call__(self, x: np.ndarray) -> np.ndarray:
        p = len(x)
        first = self.seen < self.n
        base = self.seen if first else 0
        if first:
            self.seen += p
        mid = self.adapter.normalised(x.reshape(p, self.k, -1))
        dim = mid.shape[-1]
        paths = np.concatenate([np.broadcast_to(self.start, (p, 1, dim)), mid,
                                np.broadcast_to(self.goal, (p, 1, dim))], axis=1)  # fmt: skip
        length = self.adapter.lengths(paths)
        out = np.full(p, np.inf)
        idx = base + np.arange(p)
        if first and base == 0 and np.array_equal(paths[0], self.seed):
            out[0] = length[0]  # the seed: the input path, not re-checked
            self.known[0] = length[0]
        target = np.minimum(self.known[idx % self.n], self.seed_length)
        if first:
            target = np.full(p, self.seed_length)
        hopeful = np.flatnonzero(length < target * (1.0 - _RELATIVE_GAIN))
        for j in hopeful[np.argsort(length[hopeful], kind="stable")][:CHECKED_PER_EVALUATION]:
            fine = bool(length[j] < self.best * (1.0 - _RELATIVE_GAIN))
            free = self.checker.path_free(paths[j], self.stop, fine)
            if free is None:
                break  # out of time: the rest stay unknown
            if free:
                out[j] = length[j]
                i = idx[j] % self.n
                self.known[i] = min(self.known[i], length[j])
                if fine:
                    self.best = float(length[j])
        return out


def optimize_ompl_path(
    si: ob.SpaceInformation,
    adapter: SpaceAdapter,
    path: Any,
    options: PathOptimizerOptions,
    rng: np.random.Generator,
    terminate: Callable[[], bool] | None = None,
    deadline: float | None = None,
) -> SpacePathResult:
    """:func:`optimize_space_path` on an ``og.PathGeometric``, replacing its states in place
    when (and only when) the result is shorter; the end states are written back as they were
    read, so the path still starts and ends exactly where it did."""
    result = optimize_space_path(adapter.path_to_array(path), adapter, si, options, rng,
                                 terminate, deadline)  # fmt: skip
    if result.improved:
        path.clear()
        state = si.allocState()  # Python's to free; append copies it
        for r in result.path:
            adapter.assign(state, r)
            path.append(state)
    return result
