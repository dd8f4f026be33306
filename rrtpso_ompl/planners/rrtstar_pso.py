"""RRTstarPSO: OMPL's RRT* followed by the particle swarm over its waypoints (the paper's RRT*PSO).

1. OMPL's C++ ``og.RRTstar`` shares this planner's ProblemDefinition and grows its tree for
   ``rrt_time_fraction`` of the time budget (always also stopped by the outer termination
   condition). Its best path's waypoints are the paper's "candidate nodes".
2. :func:`rrtpso_ompl.path_optimizer.optimize_path` shortens (and optionally smooths) them with the
   PSO of eqs. 4-5, checking every candidate segment exactly.
3. The result replaces RRT*'s path in the ProblemDefinition (``clearSolutionPaths`` then
   ``addSolutionPath``), so ``ss.getSolutionPath()`` returns it like any planner's path.

Use it like any OMPL planner::

    planner = RRTstarPSO(ss.getSpaceInformation(), budget=1.0)
    ss.setPlanner(planner)
    ss.solve(1.0)

Set ``budget`` to the time you give ``solve`` (the command-line tools do) so that the planner can
split it; the termination condition itself does not tell how much time is left.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..ompl_setup.context import array_to_path, path_to_array
from . import swarm as pso
from .base import PythonPlanner, collision_model_for
from .path_optimizer import PathOptimizerOptions, optimize_path, path_length
from .registry import ParamSpec

__all__ = ["RRTSTAR_PSO_PARAMS", "SWARM_PARAMS", "RRTstarPSO", "RRTstarPSOStats"]

#: Parameters of the swarm and of the path optimiser, shared with the PSO baseline planner.
SWARM_PARAMS: tuple[ParamSpec, ...] = (
    ParamSpec(
        "swarm_size",
        int,
        30,
        "Number of particles (candidate paths) in the swarm.",
        low=2,
        high=10000,
    ),
    ParamSpec(
        "iterations",
        int,
        100,
        "PSO iterations per optimisation round (eqs. 4-5).",
        low=0,
        high=1_000_000,
    ),
    ParamSpec(
        "w", float, 0.7298, "Inertia weight of the particle velocity (eq. 4).", low=0.0, high=1.5
    ),
    ParamSpec(
        "c1",
        float,
        1.49618,
        "Cognitive coefficient: pull to the particle's best (eq. 4); c1 + c2 < 4.",
        low=0.0,
        high=4.0,
    ),
    ParamSpec(
        "c2",
        float,
        1.49618,
        "Social coefficient: pull to the swarm's best (eq. 4); c1 + c2 < 4.",
        low=0.0,
        high=4.0,
    ),
    ParamSpec(
        "tolerance",
        float,
        1e-6,
        "End a PSO round early when the best cost improved by less "
        "than this (relative) over `patience` iterations; 0 = always run all iterations.",
        low=0.0,
        high=1.0,
    ),
    ParamSpec(
        "patience", int, 15, "Window of the early stop, in iterations.", low=1, high=1_000_000
    ),
    ParamSpec(
        "w_damping",
        float,
        1.0,
        "Factor applied to w after every iteration (1 = constant).",
        low=1e-6,
        high=1.0,
    ),
    ParamSpec(
        "v_max_fraction",
        float,
        0.1,
        "Velocity clamp per coordinate, as a fraction of the mean segment length of the seed path.",
        low=1e-6,
        high=10.0,
    ),
    ParamSpec(
        "smoothness_weight",
        float,
        0.0,
        "Cost per squared radian of turning at a waypoint (0 = shortest path only).",
        unit="length/rad^2",
        low=0.0,
    ),
    ParamSpec(
        "violation_weight",
        float,
        10.0,
        "Penalty per unit of intrusion of a candidate segment into an obstacle's safety zone.",
        low=1e-9,
    ),
    ParamSpec(
        "seed",
        int,
        -1,
        "Seed of the PSO's numpy Generator; -1 draws it from OMPL's RNG "
        "(so ompl.util.RNG.setSeed makes the whole run reproducible).",
        low=-1,
        high=2**32 - 1,
    ),
)

RRTSTAR_PSO_PARAMS: tuple[ParamSpec, ...] = (
    ParamSpec(
        "range",
        float,
        0.0,
        "RRT*: longest motion added to the tree; 0 lets OMPL choose (20% of the space's extent).",
        unit="length",
        low=0.0,
    ),
    ParamSpec(
        "goal_bias", float, 0.05, "RRT*: probability of sampling the goal.", low=0.0, high=1.0
    ),
    ParamSpec(
        "rewire_factor",
        float,
        1.1,
        "RRT*: scale of the rewiring radius (>= 1 keeps asymptotic optimality).",
        low=1.0,
        high=10.0,
    ),
    ParamSpec(
        "informed_sampling",
        bool,
        False,
        "RRT*: once a path exists, sample only where a shorter one can be (OMPL's informed "
        "sampling, as in InformedRRTstar); off = the paper's plain RRT*.",
    ),
    ParamSpec(
        "tree_pruning",
        bool,
        False,
        "RRT*: prune tree vertices that cannot lead to a shorter path (with informed_sampling "
        "this is OMPL's InformedRRTstar).",
    ),
    ParamSpec(
        "budget",
        float,
        0.0,
        "Total time the caller gives solve(); 0 = unknown: RRT* then "
        "runs until the termination condition and the PSO runs its iterations after it.",
        unit="s",
        low=0.0,
    ),
    ParamSpec(
        "rrt_time_fraction",
        float,
        0.9,
        "Share of the budget given to RRT*; the PSO gets the rest.",
        low=1e-3,
        high=1.0,
    ),
    ParamSpec(
        "rrt_max_iterations",
        int,
        0,
        "Stop RRT* after this many iterations (0 = no limit); "
        "with a bounded PSO this makes runs reproducible regardless of machine speed.",
        low=0,
    ),
    *SWARM_PARAMS,
    ParamSpec(
        "init_spread",
        float,
        0.05,
        "Spread of the initial swarm around the RRT* path, as a "
        "fraction of the shorter segment next to each waypoint.",
        low=0.0,
        high=10.0,
    ),
    ParamSpec(
        "box_fraction",
        float,
        0.5,
        "Each PSO round keeps every waypoint within this "
        "fraction of its longer segment from its seed position (exact obstacle culling).",
        low=1e-3,
        high=100.0,
    ),
    ParamSpec(
        "simplify",
        bool,
        True,
        "Run OMPL's path simplifier (simplifyMax: vertex reduction and shortcutting through the "
        "exact motion validator, about a millisecond) on RRT*'s path before the swarm.",
    ),
    ParamSpec("prune", bool, True, "Shortcut RRT*'s waypoints (exactly) before the swarm runs."),
    ParamSpec(
        "refine_rounds",
        int,
        4,
        "Extra PSO rounds with mid-points inserted on segments that run along an obstacle.",
        low=0,
        high=20,
    ),
    ParamSpec("max_waypoints", int, 48, "Most waypoints refinement may create.", low=2, high=10000),
)


@dataclass
class RRTstarPSOStats:
    """Per-stage figures of one RRTstarPSO solve (the ``stages`` of a solve result).

    Lengths are in problem units, times in seconds.
    """

    rrt_length: float | None = None
    rrt_time: float = 0.0
    rrt_iterations: int = 0
    rrt_waypoints: int = 0
    rrt_path: list[list[float]] = field(default_factory=list)
    rrt_progress: list[tuple[float, float]] = field(default_factory=list)
    simplified_length: float | None = None
    simplify_time: float = 0.0
    pso_length: float | None = None
    pso_time: float = 0.0
    pso_iterations: int = 0
    pso_evaluations: int = 0
    pso_rounds: int = 0
    pso_waypoints: int = 0
    pso_improved: bool = False
    pso_history: list[float] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        d = asdict(self)
        d["rrt_progress"] = [list(p) for p in self.rrt_progress]
        return d


def swarm_options(values: dict[str, Any], v_max: float | None = None) -> pso.PSOOptions:
    """The :class:`~rrtpso_ompl.pso.PSOOptions` named by the :data:`SWARM_PARAMS` values."""
    names = ("swarm_size", "iterations", "w", "c1", "c2", "w_damping", "tolerance", "patience")
    return pso.PSOOptions(**{n: values[n] for n in names}, v_max=v_max)


#: Our parameters that belong to the inner og.RRTstar, with its setter.
_INNER_SETTERS = {
    "range": "setRange",
    "goal_bias": "setGoalBias",
    "rewire_factor": "setRewireFactor",
    "informed_sampling": "setInformedSampling",
    "tree_pruning": "setTreePruning",
}


def check_swarm_values(values: dict[str, Any]) -> None:
    """Constraints between swarm parameters (one value alone cannot break them)."""
    if values["c1"] + values["c2"] >= 4.0:
        raise ValueError(
            f"parameters 'c1' + 'c2' must be < 4 (paper Table 2), got {values['c1']} + "
            f"{values['c2']}"
        )


class RRTstarPSO(PythonPlanner):
    """RRT* then PSO over its waypoints (Rasheed, Al-Araji, Abdullah: "Static and Dynamic Path
    Planning Algorithms Design for a Wheeled Mobile Robot Based on a Hybrid Technique").

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        A 2-D real vector space. When its validity checker carries a ``world`` (as built by
        :func:`rrtpso_ompl.ompl_setup.make_context`), candidate paths are checked in vectorised
        form; otherwise each segment goes through ``si.checkMotion``.
    name : str
        Planner name for OMPL's logs and benchmarks.
    **params
        Any of :data:`RRTSTAR_PSO_PARAMS` by name (see ``docs/planners.md``).
    """

    PARAMS = RRTSTAR_PSO_PARAMS

    def __init__(self, si: ob.SpaceInformation, name: str = "RRTstarPSO", **params: Any) -> None:
        super().__init__(si, name, **params)
        self.inner = og.RRTstar(si)
        self._inner_ready = False

    def setup(self) -> None:
        super().setup()
        self.inner.setProblemDefinition(self.getProblemDefinition())
        for name, setter in _INNER_SETTERS.items():
            getattr(self.inner, setter)(self._values[name])
        self.inner.setup()
        if self._values["range"] == 0.0:
            self._values["range"] = self.inner.getRange()  # report what OMPL chose
        self._inner_ready = True

    def clear(self) -> None:
        super().clear()
        self.inner.clear()

    def set_param(self, name: str, value: Any) -> None:
        super().set_param(name, value)
        if getattr(self, "_inner_ready", False) and name in _INNER_SETTERS:
            # Keep the inner RRT* in step when a parameter changes after setup().
            getattr(self.inner, _INNER_SETTERS[name])(self._values[name])

    # ------------------------------------------------------------------------------------------
    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        if not self._inner_ready:
            self.setup()
        pdef = self.getProblemDefinition()
        values = self._values
        stats = RRTstarPSOStats()
        self.last_stats = stats

        # --- stage 1: RRT* ------------------------------------------------------------------
        self._run_rrtstar(ptc, t0, stats)
        if not pdef.hasSolution():
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        raw = pdef.getSolutionPath()  # shared ownership: stays valid after clearSolutionPaths
        xy = path_to_array(raw)
        stats.rrt_length = path_length(xy)
        stats.rrt_waypoints = len(xy)
        stats.rrt_path = xy.tolist()
        if pdef.hasApproximateSolution():
            # The tree never reached the goal: nothing to optimise between fixed end points.
            return ob.PlannerStatus(ob.PlannerStatus.APPROXIMATE_SOLUTION)

        # --- stage 2: OMPL's simplifier, so the swarm starts from a locally shortened path ------
        if values["simplify"] and not ptc():
            t1 = time.perf_counter()
            simplified = og.PathGeometric(raw)  # a copy: RRT*'s own path stays as it was
            og.PathSimplifier(self.getSpaceInformation()).simplifyMax(simplified)
            candidate = path_to_array(simplified)
            if path_length(candidate) < path_length(xy):
                xy = candidate
            stats.simplify_time = time.perf_counter() - t1
        stats.simplified_length = path_length(xy)

        # --- stage 3: PSO over the candidate nodes --------------------------------------------
        model = collision_model_for(self.getSpaceInformation())
        options = PathOptimizerOptions(
            pso=swarm_options(values),
            smoothness_weight=values["smoothness_weight"],
            violation_weight=values["violation_weight"],
            init_spread=values["init_spread"],
            v_max_fraction=values["v_max_fraction"],
            box_fraction=values["box_fraction"],
            prune=values["prune"],
            refine_rounds=values["refine_rounds"],
            max_waypoints=values["max_waypoints"],
        )
        budget = values["budget"]
        # With a known budget the PSO stops at its end (and at the outer condition); without one
        # the outer condition has already fired, so the swarm is bounded by its iterations only.
        if budget > 0:
            deadline = t0 + budget

            def terminate() -> bool:
                return ptc() or time.perf_counter() >= deadline
        else:
            terminate = None
        result = optimize_path(xy, model, options, self._rng(), terminate)
        stats.pso_time = result.time
        stats.pso_iterations = result.n_iterations
        stats.pso_evaluations = result.n_evaluations
        stats.pso_rounds = result.rounds
        stats.pso_history = result.history.tolist()
        stats.pso_length = result.length
        stats.pso_waypoints = len(result.path)
        stats.pso_improved = result.improved

        # Replace RRT*'s entry either way, so the solution is reported under this planner's name.
        path = array_to_path(self.getSpaceInformation(), result.path)
        pdef.clearSolutionPaths()
        pdef.addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)

    def _run_rrtstar(
        self, ptc: ob.PlannerTerminationCondition, t0: float, stats: RRTstarPSOStats
    ) -> None:
        """Grow RRT* until its share of the budget, its iteration cap or the outer condition.

        The tree is grown in short slices (repeated ``solve`` calls continue the same tree) so that
        the best cost can be sampled over time: OMPL's progress properties are not reachable from
        Python.
        """
        values = self._values
        budget = values["budget"]
        rrt_end = t0 + values["rrt_time_fraction"] * budget if budget > 0 else None
        max_iter = values["rrt_max_iterations"]
        start_iter = self.inner.numIterations()
        inner_cost = self.inner.bestCost

        if max_iter > 0:
            # Iteration-bounded: one call with a Python condition that RRT* polls once per
            # iteration (no period, so no checker thread and no GIL deadlock).
            def stop() -> bool:
                return (
                    self.inner.numIterations() - start_iter >= max_iter
                    or ptc()
                    or (rrt_end is not None and time.perf_counter() >= rrt_end)
                )

            self.inner.solve(ob.PlannerTerminationCondition(stop))
        else:
            slice_s = 0.05 if budget <= 0 else max(0.01, values["rrt_time_fraction"] * budget / 20)
            while not ptc():
                now = time.perf_counter()
                if rrt_end is not None and now >= rrt_end:
                    break
                step = slice_s if rrt_end is None else min(slice_s, rrt_end - now)
                sub = ob.plannerOrTerminationCondition(
                    ptc, ob.timedPlannerTerminationCondition(max(step, 1e-4))
                )
                self.inner.solve(sub)
                cost = inner_cost().value()
                if np.isfinite(cost):
                    stats.rrt_progress.append((time.perf_counter() - t0, float(cost)))
        stats.rrt_time = time.perf_counter() - t0
        stats.rrt_iterations = self.inner.numIterations() - start_iter
