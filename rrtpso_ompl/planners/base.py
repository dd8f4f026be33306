"""What every Python planner of this project shares on top of ``ob.Planner``.

* Parameters by name from a :class:`~rrtpso_ompl.registry.ParamSpec` table (``set_param``,
  ``get_param``, ``param_values``), because ``Planner.params()`` is unusable from Python.
* ``solve`` never raises: an exception inside is logged and reported as ``PlannerStatus.CRASH``
  (an exception escaping a Python planner would abort a whole OMPL Benchmark).
* The collision model: the vectorised :class:`~rrtpso_ompl.world.World` when the space
  information's validity checker carries one (as :mod:`rrtpso_ompl.ompl_setup` builds it), else a
  slower adapter over ``si.checkMotion`` so the planner works in any ``SimpleSetup``.
* A numpy ``Generator`` seeded either by the ``seed`` parameter or from OMPL's own RNG, so that
  ``ompl.util.RNG.setSeed`` alone makes a whole run reproducible.
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import util as ou

from ..model.problem import touch_tolerance
from .registry import ParamSpec

__all__ = ["PythonPlanner", "SpaceInformationCollisionModel", "collision_model_for"]

log = logging.getLogger(__name__)


class SpaceInformationCollisionModel:
    """The :class:`~rrtpso_ompl.world.World` interface the path optimiser needs, answered one
    segment at a time by ``si.checkMotion``.

    Used when a planner runs in a ``SimpleSetup`` that was not built by this package. Exact only as
    far as the space information's motion validator is; slower than the vectorised World. The
    violation of a colliding segment is its length (there is no distance to measure).
    """

    def __init__(self, si: ob.SpaceInformation) -> None:
        self.si = si
        bounds = si.getStateSpace().getBounds()
        self.bounds = ((bounds.low[0], bounds.low[1]), (bounds.high[0], bounds.high[1]))
        self.tol = touch_tolerance(
            max(bounds.high[0] - bounds.low[0], bounds.high[1] - bounds.low[1])
        )
        self.robot_radius = 0.0
        self._a = si.allocState()
        self._b = si.allocState()

    def _free(self, a: np.ndarray, b: np.ndarray) -> bool:
        self._a[0], self._a[1] = float(a[0]), float(a[1])
        self._b[0], self._b[1] = float(b[0]), float(b[1])
        if not self.si.isValid(self._a) or not self.si.isValid(self._b):
            return False
        return bool(self.si.checkMotion(self._a, self._b))

    def segments_free(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        flat = [self._free(p, q) for p, q in zip(a.reshape(-1, 2), b.reshape(-1, 2), strict=True)]
        return np.array(flat, dtype=bool).reshape(a.shape[:-1])

    def segment_violation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        free = self.segments_free(a, b)
        return np.where(free, 0.0, np.linalg.norm(b - a, axis=-1) + self.tol)

    def segment_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        # Unknown distances: report "far" so that refinement never triggers.
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        return np.full(a.shape[:-1], np.inf)

    def path_valid(self, path: np.ndarray) -> bool:
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(p) < 2:
            return len(p) == 1 and bool(self.segments_free(p, p)[0])
        return bool(self.segments_free(p[:-1], p[1:]).all())


def collision_model_for(si: ob.SpaceInformation) -> Any:
    """The World behind ``si``'s validity checker, or a :class:`SpaceInformationCollisionModel`."""
    world = getattr(si.getStateValidityChecker(), "world", None)
    return world if world is not None else SpaceInformationCollisionModel(si)


class PythonPlanner(ob.Planner):
    """Base class: a parameter table, crash-safe ``solve`` and per-solve statistics.

    Subclasses define ``PARAMS`` (a tuple of ParamSpec) and implement ``_solve(ptc)`` returning an
    ``ob.PlannerStatus``; the statistics of the last solve go to ``self.last_stats``.
    """

    PARAMS: tuple[ParamSpec, ...] = ()

    def __init__(self, si: ob.SpaceInformation, name: str, **params: Any) -> None:
        super().__init__(si, name)
        self._values: dict[str, Any] = {p.name: p.default for p in self.PARAMS}
        for key, value in params.items():
            self.set_param(key, value)
        self._ompl_rng: ou.RNG | None = None
        self.last_stats: Any = None

    # -- parameters ----------------------------------------------------------------------------
    @classmethod
    def param_spec(cls, name: str) -> ParamSpec:
        """The spec of parameter ``name`` (``KeyError`` listing the known names otherwise)."""
        for p in cls.PARAMS:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in cls.PARAMS)
        raise KeyError(f"{cls.__name__} has no parameter '{name}' (known: {known})")

    def set_param(self, name: str, value: Any) -> None:
        """Set a parameter by name; the value is validated against its spec."""
        self._values[name] = self.param_spec(name).convert(value)

    def get_param(self, name: str) -> Any:
        """Current value of parameter ``name``."""
        self.param_spec(name)
        return self._values[name]

    def param_values(self) -> dict[str, Any]:
        """All parameters and their current values."""
        return dict(self._values)

    # -- lifecycle -----------------------------------------------------------------------------
    def clear(self) -> None:
        super().clear()
        self.last_stats = None

    def solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        """Run the planner; exceptions become ``PlannerStatus.CRASH`` (logged), never propagate."""
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
        """
        pis = self.getPlannerInputStates()
        pis.restart()
        s = pis.nextStart()
        g = pis.nextGoal(ptc)
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

    @staticmethod
    def _finite_or_none(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None
