"""Post-passes after any planner: OMPL's simplifier and the swarm as an OMPL path optimiser.

:class:`PSOPathOptimizer` is shaped like OMPL's ``og.PathSimplifier``: it is made from a
``SpaceInformation`` (and the swarm's declared parameters) and ``optimize(path, ptc_or_seconds)``
improves an ``og.PathGeometric`` in place, returning whether it changed it. It never makes a path
longer or invalid. It checks candidates through the space information's own validity checker and
motion validator (:class:`~rrtpso_ompl.planners.base.SpaceInformationCollisionModel`), so it
works in any OMPL setup; when the setup is ours (the validity checker carries a
:class:`~rrtpso_ompl.model.World`), it uses the exact vectorised world instead.

A *planner spec* names a planner and the post-passes that follow it, in order:
``"BITstar+simplify+pso"``. :func:`run_post` runs such steps on a solution path within a deadline;
:func:`~rrtpso_ompl.planners.solve` gives them :data:`POST_PARAMS`' ``post_fraction`` of the
time budget.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

from ..model.geometry import path_length as path_length_of
from ..model.objective import InflationCost
from ..ompl_setup import InflationObjective, assign_path, path_to_array
from ..ompl_setup.objective import path_cost
from ..ompl_setup.space import require_plane_space
from .base import SpaceInformationCollisionModel, collision_model_for, refusing_motions_after
from .pso.path_optimizer import PathOptimizationResult, PathOptimizerOptions, optimize_path
from .request import POST_PARAMS, POST_STEPS, parse_steps, split_spec

__all__ = [
    "ITERATIONS_NEEDED",
    "MIN_SWARM",
    "POST_PARAMS",
    "POST_STEPS",
    "VALIDATIONS_NEEDED",
    "PSOPathOptimizer",
    "PostStep",
    "parse_steps",
    "run_post",
    "simplify_until",
    "split_spec",
]

#: With a user's checker, the time left must hold this many validations of the path (the input's,
#: the final one, and room for the swarm), or the swarm does not run.
VALIDATIONS_NEEDED = 4
#: ... and the swarm is shrunk so that this many iterations fit (a particle costs about one
#: validation per iteration).
ITERATIONS_NEEDED = 3
#: The smallest swarm worth running.
MIN_SWARM = 4


@dataclass(frozen=True)
class PostStep:
    """One post-pass on one path: lengths and objective costs before and after (units; the costs
    equal the lengths without an inflation cost) and its time (s)."""

    step: str
    length_before: float
    length_after: float
    time: float
    cost_before: float | None = None
    cost_after: float | None = None

    def to_dict(self) -> dict[str, Any]:
        out = {"step": self.step, "length_before": self.length_before,
               "length_after": self.length_after, "time": self.time}  # fmt: skip
        if self.cost_before is not None:
            out |= {"cost_before": self.cost_before, "cost_after": self.cost_after}
        return out


class PSOPathOptimizer:
    """The particle swarm (paper eqs. 4-5) as an OMPL path optimiser, like ``og.PathSimplifier``.

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        A 2-D real vector space (``ob.RealVectorStateSpace(2)``) with the user's validity checker
        (and motion validator).
    options : PathOptimizerOptions, optional
        The swarm's and the optimiser's parameters (defaults when omitted); or pass them by name
        in ``params``.
    world : World, optional
        An exact collision model to use instead of the space information's checks (found on the
        validity checker when the setup is ours).
    rng : numpy.random.Generator, optional
        Drawn from OMPL's RNG when omitted, so ``ompl.util.RNG.setSeed`` makes runs reproducible.
    objective : ompl.base.OptimizationObjective or InflationCost, optional
        What the swarm lowers: the problem's inflation cost when it is ours
        (:class:`~rrtpso_ompl.ompl_setup.InflationObjective`, or the
        :class:`~rrtpso_ompl.model.objective.InflationCost` itself), else the length.
    **params
        Parameters by name (``swarm_size=40, ...``), as :data:`PathOptimizerOptions` declares.

    Raises
    ------
    UnsupportedSpaceError
        When ``si``'s space is not ``ob.RealVectorStateSpace(2)`` (SE(2), Dubins, ``R^3``, ...):
        the swarm moves waypoints in the plane, so it refuses here, at construction, rather than
        hand back a path of the wrong space. OMPL's ``og.PathSimplifier`` works in any space.

    Examples
    --------
    >>> optimizer = PSOPathOptimizer(ss.getSpaceInformation())      # doctest: +SKIP
    >>> optimizer.optimize(ss.getSolutionPath(), 0.2)                # doctest: +SKIP
    True
    """

    def __init__(
        self,
        si: ob.SpaceInformation,
        *,
        options: PathOptimizerOptions | None = None,
        world: Any = None,
        rng: np.random.Generator | None = None,
        objective: Any = None,
        **params: Any,
    ) -> None:
        if options is not None and params:
            raise TypeError("give the options or parameters by name, not both")
        require_plane_space(si, "PSOPathOptimizer")
        self.si = si
        self.options = options or PathOptimizerOptions()
        self.set_params(**params)
        self.model = world if world is not None else collision_model_for(si)
        if rng is None:
            rng = np.random.default_rng(ou.RNG().uniformInt(0, 2**31 - 2))
        self.rng = rng
        # The inflation cost needs our world's distances; with a user's checker, the length.
        self.inflation = inflation_of(objective) if hasattr(self.model, "point_clearance") else None
        # The OMPL objective's measured distances, shared (none to share for a bare cost).
        self.field = getattr(objective, "field", None) if self.inflation is not None else None
        #: The :class:`PathOptimizationResult` of the last call.
        self.last_result: PathOptimizationResult | None = None
        #: Why the last call left the path alone without running the swarm ("" when it ran).
        self.skipped = ""

    def get_params(self) -> dict[str, Any]:
        """Every parameter and its current value (as scikit-learn's ``get_params``)."""
        return dataclasses.asdict(self.options)

    def set_params(self, **params: Any) -> PSOPathOptimizer:
        """Set parameters by name, validated together over the current values (rules such as
        ``c1 + c2 < 4`` apply to the new values jointly); returns the optimiser.

        Raises
        ------
        ParameterError
            For an unknown name or a value its declaration refuses; nothing is changed then.
        """
        table = PathOptimizerOptions.PARAMS
        for name in params:
            if name not in table:
                table[name]  # raises, naming the known parameters
        converted = table.validate({**self.get_params(), **params}, owner="PSOPathOptimizer")
        self.options = dataclasses.replace(self.options, **{k: converted[k] for k in params})
        return self

    def optimize(self, path: og.PathGeometric, ptc_or_seconds: Any = None) -> bool:
        """Shorten ``path`` in place; True when it changed it (then shorter and valid).

        Parameters
        ----------
        path : og.PathGeometric
        ptc_or_seconds : ob.PlannerTerminationCondition, float or None
            When to stop: a termination condition, a time in seconds (which also sizes the work
            to a slow checker, see :meth:`optimize_array`), or None (the swarm's iteration and
            round limits only).
        """
        deadline = None
        if isinstance(ptc_or_seconds, int | float):
            deadline = time.perf_counter() + float(ptc_or_seconds)
        result = self.optimize_array(
            path_to_array(path), _terminator(ptc_or_seconds, deadline), deadline
        )
        if not result.improved:
            return False
        assign_path(self.si, path, result.path)
        return True

    def optimize_array(
        self,
        xy: np.ndarray,
        terminate: Callable[[], bool] | None = None,
        deadline: float | None = None,
    ) -> PathOptimizationResult:
        """The same on an ``(n, 2)`` array of waypoints; the input is never modified.

        With the user's checker (not our exact world) and a ``deadline``
        (``time.perf_counter()`` seconds), the work is sized to the checker's measured cost:
        validating the path once must fit :data:`VALIDATIONS_NEEDED` times in the time left, or
        the input comes back untouched; the swarm is shrunk so that
        :data:`ITERATIONS_NEEDED` iterations fit; and its evaluations stop (count as blocked) a
        validation's time before the deadline, so that the final check still fits.
        """
        model, options = self.model, self.options
        self.skipped = ""
        if isinstance(model, SpaceInformationCollisionModel) and deadline is not None:
            options, reserve = self._size(xy, deadline)
            if options is None:
                self.last_result = _unchanged(xy, self.inflation, model)
                return self.last_result
            model.stop = lambda: time.perf_counter() >= deadline - reserve
        try:
            # Our world answers "blocked" after the deadline: the swarm's shortcuts test whole
            # views at once, and one view near a detailed polygon can outlast the time left.
            with refusing_motions_after(model, deadline):
                self.last_result = optimize_path(xy, model, options, self.rng, terminate, deadline,
                                                 self.inflation, self.field)  # fmt: skip
        finally:
            if isinstance(model, SpaceInformationCollisionModel):
                model.stop = None
        return self.last_result

    def _size(self, xy: np.ndarray, deadline: float) -> tuple[PathOptimizerOptions | None, float]:
        """The swarm sized to a user's checker and the time left, and the time kept back for
        the final validation; None when even validating the path does not fit."""
        model = self.model
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        rate = model.seconds_per_length() or model.probe(xy[0])
        validate = rate * max(path_length_of(xy), model.step)
        left = deadline - time.perf_counter()
        if left < VALIDATIONS_NEEDED * validate:
            self.skipped = (f"the checker needs {validate:.3g} s to validate the path once, "
                            f"{left:.3g} s are left")  # fmt: skip
            return None, 0.0
        # One particle costs about one validation per iteration.
        spare = left - (VALIDATIONS_NEEDED - 1) * validate
        particles = int(spare / (ITERATIONS_NEEDED * validate))
        size = min(self.options.swarm_size, particles)
        if size < MIN_SWARM:
            self.skipped = f"room for {particles} particles only"
            return None, 0.0
        return dataclasses.replace(self.options, swarm_size=size), 1.5 * validate


#: Attempts each call of one of OMPL's simplifier steps makes, at least (a quarter of the path's
#: states when that is more): few enough that the deadline is checked often.
SIMPLIFY_ATTEMPTS = 16
#: Sweeps in a row that change nothing before the simplifier counts as converged.
SIMPLIFY_PATIENCE = 3


def simplify_until(
    si: ob.SpaceInformation, path: og.PathGeometric, deadline: float, objective: Any = None
) -> None:
    """OMPL's path simplifier on ``path``, in place, a few attempts at a time until ``deadline``
    (``time.perf_counter()`` seconds) or until it stops changing the path.

    OMPL's own ``simplify(path, ptc)`` polls its termination condition only between whole
    passes, and a pass over a path of hundreds of waypoints checks motions along it so often
    that it took seconds (21 s past a 5 s budget on a 128 x 128 maze map). Its steps (vertex
    reduction, partial shortcuts, collapsing close vertices) take a number of attempts, so they
    run here in small batches with the deadline checked in between. B-spline smoothing, the last
    step of ``simplifyMax``, is left out: it adds states and cannot stop early. With an
    ``objective`` its shortcuts weigh that objective's costs (a step may still raise them:
    :func:`run_post` undoes a step that did).
    """
    simplifier = og.PathSimplifier(si, None, objective) if objective is not None else (
        og.PathSimplifier(si))  # fmt: skip
    steps = (simplifier.reduceVertices, simplifier.partialShortcutPath,
             simplifier.collapseCloseVertices)  # fmt: skip
    still = 0
    while still < SIMPLIFY_PATIENCE:
        changed = False
        for step in steps:
            if time.perf_counter() >= deadline:
                return
            attempts = max(SIMPLIFY_ATTEMPTS, path.getStateCount() // 4)
            changed = step(path, attempts, attempts) or changed
        still = 0 if changed else still + 1


def run_post(
    si: ob.SpaceInformation,
    path: og.PathGeometric,
    steps: Iterable[str],
    deadline: float,
    *,
    values: Mapping[str, Any] | None = None,
    world: Any = None,
    rng: np.random.Generator | None = None,
    objective: Any = None,
) -> list[PostStep]:
    """Run the post-passes ``steps`` on ``path`` in place, in order, until ``deadline``
    (``time.perf_counter()`` seconds).

    OMPL's simplifier gets at most ``simplify_share`` of what is left when the swarm follows it;
    the swarm gets the rest. ``values`` holds the swarm's and :data:`POST_PARAMS`' parameters by
    name (defaults for the missing ones). With the problem's ``objective`` (an OMPL objective)
    no step raises its cost: a step that did is undone. ``simplify`` works in any state space;
    ``pso`` only in the plane (:class:`PSOPathOptimizer` raises ``UnsupportedSpaceError``).
    """
    steps = tuple(steps)
    values = dict(values or {})
    post = POST_PARAMS.defaults() | {k: v for k, v in values.items() if k in POST_PARAMS}
    out: list[PostStep] = []
    for i, step in enumerate(steps):
        t0 = time.perf_counter()
        before = float(path.length())
        saved = og.PathGeometric(path)  # a copy, of whatever space (not read as coordinates)
        cost_before = path_cost(objective, path) if objective is not None else None
        left = max(deadline - t0, 0.0)
        if step == "simplify":
            share = post["simplify_share"] if "pso" in steps[i + 1 :] else 1.0
            if left > 0:
                seconds = max(share * left, 1e-4)
                # Our world also cuts a long batch short (it refuses motions after the time);
                # a user's checker, in any space, is OMPL's to call.
                ours = world or getattr(si.getStateValidityChecker(), "world", None)
                with refusing_motions_after(ours, t0 + seconds):
                    simplify_until(si, path, t0 + seconds, objective)
        else:
            options = PathOptimizerOptions.from_values(values)
            optimizer = PSOPathOptimizer(si, options=options, world=world, rng=rng,
                                         objective=objective)  # fmt: skip
            optimizer.optimize(path, left if left > 0 else 0.0)
        cost_after = path_cost(objective, path) if objective is not None else None
        if cost_after is not None and cost_after > cost_before:
            _restore(path, saved)  # the step raised the objective: undone
            cost_after = cost_before
        out.append(PostStep(step, before, float(path.length()), time.perf_counter() - t0,
                            cost_before, cost_after))  # fmt: skip
    return out


def _restore(path: og.PathGeometric, saved: og.PathGeometric) -> None:
    """Put the states of ``saved`` back into ``path``, in place (``append`` copies each)."""
    path.clear()
    for state in saved.getStates():
        path.append(state)


def inflation_of(objective: Any) -> InflationCost | None:
    """The :class:`~rrtpso_ompl.model.objective.InflationCost` behind an objective (ours, or the
    cost itself), or None: the swarm then lowers the length."""
    if isinstance(objective, InflationCost):
        return objective if objective.active else None
    if isinstance(objective, InflationObjective):
        return objective.inflation
    return None


def _terminator(ptc_or_seconds: Any, deadline: float | None = None) -> Callable[[], bool] | None:
    """A zero-argument stop test from a termination condition or a number of seconds."""
    if ptc_or_seconds is None:
        return None
    if deadline is not None:
        return lambda: time.perf_counter() >= deadline
    ptc = ptc_or_seconds
    return lambda: bool(ptc())


def _unchanged(xy: np.ndarray, inflation: InflationCost | None, world) -> PathOptimizationResult:
    """The result that hands the input back (the swarm did not run)."""
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    length = path_length_of(p)
    cost = inflation.path_cost(world, p) if inflation is not None else length
    return PathOptimizationResult(path=p, length=length, input_length=length, improved=False,
                                  cost=cost, input_cost=cost, history=np.empty(0), n_iterations=0,
                                  n_evaluations=0, rounds=0, time=0.0)  # fmt: skip
