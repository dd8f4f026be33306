"""What every Python planner of this project shares on top of ``ob.Planner``.

* Parameters by name from its declared :class:`~rrtpso_ompl.params.ParamTable`
  (scikit-learn's ``get_params()`` and ``set_params(**params)``), because ``Planner.params()``
  is unusable from Python.
* Typed statistics of the last solve (:class:`PlannerStats`), which know their own part in OMPL's
  benchmark terms: planning time, simplification, planner-specific run properties and progress.
* ``solve`` never raises: an exception inside is logged and reported as ``PlannerStatus.CRASH``
  (an exception escaping a Python planner would abort a whole OMPL Benchmark).
* The collision model: the vectorised :class:`~rrtpso_ompl.model.World` when the space
  information's validity checker carries one (as :mod:`rrtpso_ompl.ompl_setup` builds it), else a
  slower adapter over ``si.checkMotion`` so the planner works in any ``SimpleSetup``.
* A numpy ``Generator`` seeded either by the ``seed`` parameter or from OMPL's own RNG, so that
  ``ompl.util.RNG.setSeed`` alone makes a whole run reproducible.
* The plane only, for now: in any state space but ``ob.RealVectorStateSpace(2)`` the planner
  refuses (the reason in ``planner.unsupported``, logged at ``setup()`` and at each ``solve()``,
  which returns ``ABORT`` and adds no path), never reading a state as two coordinates
  (:mod:`rrtpso_ompl.ompl_setup.space`).
"""

from __future__ import annotations

import contextlib
import logging
import math
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import util as ou

from ..errors import UnsupportedSpaceError
from ..model.problem_types import touch_tolerance
from ..model.raster import Lattice
from ..model.world import MarkingStopped
from ..ompl_setup.space import plane_space_problem, require_plane_space
from ..params import ParamSpec, ParamTable
from ..validation import MAX_SECONDS, SEED_MAX
from .result import BenchmarkRun

__all__ = [
    "BUDGET",
    "SEED",
    "PlannerStats",
    "PythonPlanner",
    "SpaceInformationCollisionModel",
    "collision_model_for",
    "refusing_motions_after",
]

log = logging.getLogger(__name__)


#: The time a planner may split between its stages (OMPL's termination condition does not say how
#: much is left, so planners that split their time are told the whole of it).
BUDGET = ParamSpec(
    "budget",
    float,
    0.0,
    "Total time the caller gives solve(); 0 = unknown: the planner then runs until the "
    "termination condition and bounds its later stages by their iterations only.",
    unit="s",
    low=0.0,
    high=MAX_SECONDS,
)
#: The seed of a planner's own numpy Generator.
SEED = ParamSpec(
    "seed",
    int,
    -1,
    "Seed of the planner's numpy Generator; -1 draws it from OMPL's RNG "
    "(so ompl.util.RNG.setSeed makes the whole run reproducible).",
    low=-1,
    high=SEED_MAX,
)


@dataclass
class PlannerStats:
    """The figures of one solve; the base class holds none.

    Each planner's stats subclass this dataclass with their own fields and say, in
    :meth:`benchmark_run`, which part of the run OMPL's Benchmark would call planning and which
    simplification, and which planner-specific run properties they add. The harness (``solve``,
    ``batch``, ``bench``) asks the stats instead of guessing from their keys.
    """

    def benchmark_run(self, elapsed: float, length: float | None) -> BenchmarkRun:
        """The run in OMPL's terms.

        Parameters
        ----------
        elapsed : float
            Seconds the whole solve took.
        length : float or None
            Length of the path the planner returned (None without one).
        """
        return BenchmarkRun(time=elapsed, solution_length=length, progress=self.progress())

    def progress(self) -> list[tuple[float, float]]:
        """``(time s, best cost)`` samples the planner took itself (none by default)."""
        return []

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary of the figures (the ``stages`` of a solve result)."""
        return asdict(self)


#: A user's checker is sampled this much finer than the space's validity-checking resolution
#: when the swarm checks its candidates: an optimiser searches for exactly the gaps a coarse
#: discrete check leaves, so it must look closer than the planner did.
FINE_RESOLUTION = 0.1
#: A lattice marking through a user's checker looks at its stop condition every this many cells.
_MARK_STOP_EVERY = 64


class SpaceInformationCollisionModel:
    """The :class:`~rrtpso_ompl.model.World` interface the path optimiser needs, answered through
    the space information's own validity checker.

    Used when a planner or :class:`~rrtpso_ompl.planners.PSOPathOptimizer` runs in a
    ``SimpleSetup`` that was not built by this package. A segment is free when every state along
    it, ``fine`` times the space's validity-checking resolution apart (a tenth by default), is
    valid (after the space information's own ``checkMotion``, so a user's motion validator is
    honoured too): not exact (nothing is, with a user's point checker), but ten times
    finer than the discrete motion check a planner used, so the swarm cannot hide a shortcut in
    the gaps of that check. The violation of a colliding segment is its length (there is no
    distance to measure).

    Parameters
    ----------
    si : ompl.base.SpaceInformation
    fine : float
        Sampling step as a share of the space's resolution
        (``si.getStateValidityCheckingResolution() * si.getMaximumExtent()``).

    Attributes
    ----------
    step : float
        Distance between checked states, units.
    stop : callable or None
        Set by the optimiser: once it returns True, the swarm's evaluations count segments as
        blocked without checking them, so a slow checker cannot hold the swarm past its deadline
        (validation, :meth:`segments_free` and :meth:`path_valid`, always checks).
    length_checked, check_time : float
        Segment length checked (units) and the seconds it took: the checker's measured cost.
    """

    def __init__(self, si: ob.SpaceInformation, fine: float = FINE_RESOLUTION) -> None:
        require_plane_space(si, "SpaceInformationCollisionModel")  # it writes st[0], st[1]
        self.si = si
        bounds = si.getStateSpace().getBounds()
        self.bounds = ((bounds.low[0], bounds.low[1]), (bounds.high[0], bounds.high[1]))
        self.tol = touch_tolerance(self.bounds)
        self.robot_radius = 0.0
        resolution = si.getStateValidityCheckingResolution() * si.getMaximumExtent()
        self.step = max(fine * resolution, 1e-12)
        self.stop: Any = None
        #: Looked at every few cells of a lattice marking; see :meth:`marking_stops`.
        self.mark_stop: Any = None
        self.length_checked = 0.0
        self.check_time = 0.0
        self._state = si.allocState()
        self._end = si.allocState()

    def seconds_per_length(self) -> float:
        """Measured checking time per unit of segment length, s (0 before any check)."""
        return self.check_time / self.length_checked if self.length_checked > 0 else 0.0

    def probe(self, point: np.ndarray, n: int = 8) -> float:
        """Time ``n`` checks of ``point`` and return the estimated seconds per unit length at
        this model's step (the user's checker may be slow: a millisecond per state is common
        with a physics engine behind it)."""
        st = self._state
        st[0], st[1] = float(point[0]), float(point[1])
        t0 = time.perf_counter()
        for _ in range(n):
            self.si.isValid(st)
        return (time.perf_counter() - t0) / n / self.step

    def _free(self, a: np.ndarray, b: np.ndarray) -> bool:
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        n = max(1, math.ceil(length / self.step))
        st, sb, valid = self._state, self._end, self.si.isValid
        t0 = time.perf_counter()
        try:
            st[0], st[1], sb[0], sb[1] = float(a[0]), float(a[1]), float(b[0]), float(b[1])
            # The user's own motion validator first (it may be exact, or cheaper), then the
            # states in between, ten times finer than it looked.
            if not self.si.checkMotion(st, sb):
                return False
            for k in range(1, n):
                u = k / n
                st[0] = float(a[0] + u * (b[0] - a[0]))
                st[1] = float(a[1] + u * (b[1] - a[1]))
                if not valid(st):
                    return False
            return True
        finally:
            self.length_checked += max(length, self.step)
            self.check_time += time.perf_counter() - t0

    def segments_free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        flat = [self._free(p, q) for p, q in zip(a.reshape(-1, 2), b.reshape(-1, 2), strict=True)]
        return np.array(flat, dtype=bool).reshape(a.shape[:-1])

    def segment_violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The swarm's cost term: a blocked segment's length. Once :attr:`stop` fires, segments
        count as blocked unchecked (a candidate is only ever accepted after ``path_valid``)."""
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        if self.stop is not None and self.stop():
            return np.linalg.norm(b - a, axis=-1) + self.tol
        free = self.segments_free(a, b)
        return np.where(free, 0.0, np.linalg.norm(b - a, axis=-1) + self.tol)

    def segment_distance(
        self, a: np.ndarray, b: np.ndarray, cap: float | None = None
    ) -> np.ndarray:
        # Unknown distances: report "far" so that refinement never triggers (``cap`` as World's).
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        return np.full(a.shape[:-1], np.inf)

    def path_valid(self, path: np.ndarray) -> bool:
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(p) < 2:
            return len(p) == 1 and bool(self.segments_free(p, p)[0])
        return bool(self.segments_free(p[:-1], p[1:]).all())

    def lattice(self, max_cells: int, split: int = 4) -> Lattice:
        """Square cells centred in the space's bounds, about ``max_cells`` of them."""
        (xmin, ymin), (xmax, ymax) = self.bounds
        h = math.sqrt((xmax - xmin) * (ymax - ymin) / max(max_cells, 1))
        return Lattice.over(self.bounds, h)

    def free_cells(self, lat: Lattice, within: np.ndarray | None = None) -> np.ndarray:
        """Cells whose centre the checker accepts. Not conservative (a point checker says
        nothing about the rest of the cell): paths through them are checked before use."""
        return self.centres_free(lat, within)

    def centres_free(self, lat: Lattice, within: np.ndarray | None = None) -> np.ndarray:
        """Cells whose centre the checker accepts (only those in ``within``, when given).

        Raises
        ------
        MarkingStopped
            When the condition of :meth:`marking_stops` fires first.
        """
        st, valid, stop = self._state, self.si.isValid, self.mark_stop
        asked = np.ones(lat.n_cells, dtype=bool) if within is None else within.ravel()
        free = np.zeros(lat.n_cells, dtype=bool)
        centres = lat.centres()
        for n, k in enumerate(np.flatnonzero(asked).tolist()):
            if stop is not None and n % _MARK_STOP_EVERY == 0 and stop():
                raise MarkingStopped
            st[0], st[1] = float(centres[k, 0]), float(centres[k, 1])
            free[k] = valid(st)
        return free.reshape(lat.nx, lat.ny)

    @contextlib.contextmanager
    def marking_stops(self, stop: Any) -> Iterator[None]:
        """As :meth:`World.marking_stops <rrtpso_ompl.model.World.marking_stops>`: within the
        block a lattice marking raises :class:`~rrtpso_ompl.model.world.MarkingStopped` once
        ``stop()`` is true (the user's checker may take a millisecond a state)."""
        saved, self.mark_stop = self.mark_stop, stop
        try:
            yield
        finally:
            self.mark_stop = saved


def collision_model_for(si: ob.SpaceInformation) -> Any:
    """The World behind ``si``'s validity checker, or a :class:`SpaceInformationCollisionModel`."""
    world = getattr(si.getStateValidityChecker(), "world", None)
    return world if world is not None else SpaceInformationCollisionModel(si)


@contextlib.contextmanager
def refusing_motions_after(model: Any, deadline: float | None) -> Iterator[None]:
    """A context for OMPL's path simplifier in which motion checks through ``model`` (a World)
    are refused after ``deadline`` (:meth:`~rrtpso_ompl.model.World.refusing_motions_after`); no
    change for a user's checker, whose motions OMPL checks itself.

    OMPL's warnings are muted meanwhile: after a refused motion the simplifier's final check
    warns that the path "may slightly touch on an invalid region", which it does not (every
    change it kept passed the exact check)."""
    if not hasattr(model, "refusing_motions_after"):
        yield
        return
    level = ou.getLogLevel()
    if level.value < ou.LOG_ERROR.value:
        ou.setLogLevel(ou.LOG_ERROR)
    try:
        with model.refusing_motions_after(deadline):
            yield
    finally:
        ou.setLogLevel(level)


class PythonPlanner(ob.Planner):
    """Base class: declared parameters, crash-safe ``solve`` and per-solve statistics.

    Subclasses define ``PARAMS`` (a :class:`~rrtpso_ompl.params.ParamTable`) and
    implement ``_solve(ptc)`` returning an ``ob.PlannerStatus``; the statistics of the last solve
    (a :class:`PlannerStats`) go to ``self.last_stats``. ``_solve`` is only called where
    :attr:`unsupported` is None: the plane (``ob.RealVectorStateSpace(2)``), unless a subclass's
    constructor accepts more spaces and resets it (RRTstarPSO does for R^n, SE(2), Dubins and
    Reeds-Shepp); a subclass's ``setup`` does nothing of its own when it is set.

    Attributes
    ----------
    unsupported : str or None
        Why the planner does not plan in the space information's state space (one sentence
        naming the space), or None in the plane. Then ``setup()`` logs it as an error and every
        ``solve()`` logs it and returns ``ob.PlannerStatus.ABORT`` ("the planner did not find a
        solution for some other reason": nothing crashed, and the problem is not infeasible),
        without adding a path to the problem definition. No exception: one raised in ``setup``
        or ``solve`` would escape ``ss.solve()`` and end a whole OMPL Benchmark of several
        planners.
    """

    PARAMS: ParamTable = ParamTable()

    def __init__(self, si: ob.SpaceInformation, name: str, **params: Any) -> None:
        super().__init__(si, name)
        self._values: dict[str, Any] = self.PARAMS.defaults()
        self.set_params(**params)
        self._ompl_rng: ou.RNG | None = None
        self.last_stats: PlannerStats | None = None
        problem = plane_space_problem(si)
        self.unsupported: str | None = None if problem is None else (
            f"{name} refuses to plan: {problem}; OMPL's own planners (e.g. og.RRTstar) plan "
            f"in it")  # fmt: skip
        self._refusal_told = False  # setup() has just logged it (solve() does not repeat it)

    # -- parameters (scikit-learn's get_params / set_params) -----------------------------------
    def get_params(self) -> dict[str, Any]:
        """Every parameter and its current value, as set (a value the planner chooses itself,
        such as RRTstarPSO's automatic ``range``, is reported in its stats instead)."""
        return dict(self._values)

    def set_params(self, **params: Any) -> PythonPlanner:
        """Set parameters by name, validated together over the current values (rules such as
        ``c1 + c2 < 4`` apply to the new values jointly, not one by one); returns the planner.

        Raises
        ------
        ParameterError
            For an unknown name or a value its declaration refuses; nothing is changed then.
        """
        converted = self.PARAMS.validate({**self._values, **params}, owner=self.getName())
        for name in params:
            self._apply(name, converted[name])
        return self

    def _apply(self, name: str, value: Any) -> None:
        """Store a validated value (subclasses may forward it, e.g. to an inner OMPL planner)."""
        self._values[name] = value

    # -- lifecycle -----------------------------------------------------------------------------
    def setup(self) -> None:
        """OMPL's set-up; in a space the planner does not plan in, one error line saying why
        (:attr:`unsupported`). Subclasses call it first and return when :attr:`unsupported` is
        set."""
        super().setup()
        if self.unsupported is not None:
            log.error("%s", self.unsupported)
            self._refusal_told = True

    def clear(self) -> None:
        super().clear()
        self.last_stats = None

    def solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        """Run the planner; exceptions become ``PlannerStatus.CRASH`` (logged), never propagate.

        Without a problem definition (``setProblemDefinition`` never called) there is nothing to
        solve: one error line and ``ABORT``, as OMPL's planners refuse it (they raise "Problem
        definition not specified")."""
        if self.getProblemDefinition() is None:
            log.error("%s: no problem definition: call setProblemDefinition() (or use "
                      "og.SimpleSetup) before solve()", self.getName())  # fmt: skip
            return ob.PlannerStatus(ob.PlannerStatus.ABORT)
        if self.unsupported is not None:
            if not self._refusal_told:  # said once per solve, not twice after ss.solve's setup
                log.error("%s", self.unsupported)
            self._refusal_told = False
            return ob.PlannerStatus(ob.PlannerStatus.ABORT)
        try:
            return self._solve(ptc)
        except Exception:
            log.exception("%s: solve failed", self.getName())
            return ob.PlannerStatus(ob.PlannerStatus.CRASH)

    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        raise NotImplementedError

    # -- helpers for subclasses ----------------------------------------------------------------
    def _start_and_goal(self, ptc: ob.PlannerTerminationCondition) -> tuple[Any, Any]:
        """Start and goal states as ``(x, y)`` tuples, or None.

        Uses the PlannerInputStates (never ``pdef.getStartState``, which frees OMPL's own state
        when the Python wrapper dies) and restarts it, since OMPL consumes starts between solves.

        Raises
        ------
        UnsupportedSpaceError
            Outside the plane (:attr:`unsupported`; ``solve`` refuses before this is reached):
            a state is never read as two coordinates of something else.
        """
        if self.unsupported is not None:
            raise UnsupportedSpaceError(self.unsupported)
        pis = self.getPlannerInputStates()
        pis.restart()
        s = pis.nextStart()
        g = pis.nextGoal(ptc)
        for state in (s, g):
            if state is not None and not isinstance(state, ob.RealVectorStateType):
                raise UnsupportedSpaceError(
                    f"{self.getName()}: a state of type {type(state).__name__}, not a 2-D real "
                    f"vector: this package's planners plan only in ob.RealVectorStateSpace(2)"
                )
        start = None if s is None else (s[0], s[1])
        goal = None if g is None else (g[0], g[1])
        return start, goal

    def _rng(self) -> np.random.Generator:
        """A numpy Generator for one solve: from the ``seed`` parameter when it is >= 0, else
        drawn from an OMPL RNG (itself seeded by ``ompl.util.RNG.setSeed``)."""
        seed = self._values.get("seed", -1)
        if seed is not None and seed >= 0:
            return np.random.default_rng(seed)
        if self._ompl_rng is None:
            self._ompl_rng = ou.RNG()
        return np.random.default_rng(self._ompl_rng.uniformInt(0, 2**31 - 2))
