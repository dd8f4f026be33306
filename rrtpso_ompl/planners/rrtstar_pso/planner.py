"""RRTstarPSO: OMPL's RRT* followed by the particle swarm over its waypoints (the paper's RRT*PSO).

0. The corridor stage (:mod:`.corridor`) looks at every way round the
   obstacles at once, on a lattice of the free space, and pulls the best route taut: a first
   path in milliseconds, in the right corridor, also through mazes that RRT*'s tree would not
   cross in time.
1. OMPL's C++ ``og.RRTstar`` shares this planner's ProblemDefinition and grows its tree for
   ``rrt_time_fraction`` of the time left (always also stopped by the outer termination
   condition). Its best path's waypoints are the paper's "candidate nodes".
2. The candidates, RRT*'s path and the corridor's, each shortened (OMPL's simplifier), are
   ranked by length: a jagged path in the best corridor must not lose to a smooth one in a
   worse corridor.
3. :class:`rrtpso_ompl.planners.PSOPathOptimizer` (the post-pass any planner gets with
   ``+pso``) shortens (and optionally smooths) the winner with the PSO of eqs. 4-5, checking
   every candidate segment exactly.
4. The result replaces RRT*'s path in the ProblemDefinition (``clearSolutionPaths`` then
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
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ...model.geometry import path_length, shortcut
from ...model.world import World
from ...ompl_setup import array_to_path, path_to_array
from ...params import ParamSpec, ParamTable
from ..base import (
    BUDGET,
    SEED,
    PlannerStats,
    PythonPlanner,
    SpaceInformationCollisionModel,
    collision_model_for,
    refusing_motions_after,
)
from ..baselines.ompl_planners import RRTSTAR_PARAMS
from ..post import PSOPathOptimizer, inflation_of, simplify_until
from ..pso.path_optimizer import OPTIMIZER_PARAMS, PathOptimizerOptions
from ..pso.swarm import SWARM_PARAMS
from .corridor import REPRODUCIBLE_CORRIDOR_CELLS, find_corridor_path
from .costroute import cost_route
from .general import solve_in_space, space_of_planner
from .rrtstar_stage import INFLATION_RRT_MIN, INFLATION_RRT_SHARE, RRTstarStatsMixin, grow_rrtstar

#: The RRT* parameters RRTstarPSO passes on to its inner og.RRTstar.
_INNER = ("range", "goal_bias", "rewire_factor", "informed_sampling", "tree_pruning")

__all__ = [
    "RANGE_PER_CLEARANCE",
    "RRTSTAR_PSO_PARAMS",
    "SIMPLIFIER_PASS_LENGTHS",
    "RRTstarPSO",
    "RRTstarPSOStats",
    "clutter_range",
]

#: RRTstarPSO's own parameters (besides its inner RRT*'s, the swarm's and the path optimiser's).
_OWN = ParamTable(
        BUDGET,
        ParamSpec("corridor_cells", int, 4_194_304,
                  "Most cells of the corridor stage's fine lattice (0 = no corridor stage); "
                  "within this, the lattice is as fine as its time share allows.",
                  low=0, high=16_777_216),
        ParamSpec("corridor_fraction", float, 0.25,
                  "Most share of the budget the corridor stage may take (it usually needs far "
                  "less; a smaller lattice is used when the time would not do).",
                  low=0.0, high=1.0),
        ParamSpec("corridor_alternatives", int, 3,
                  "Routes through other corridors the corridor stage tries besides the "
                  "shortest one on its lattice.", low=0, high=32),
        ParamSpec("rrt_time_fraction", float, 0.9,
                  "Share of the budget (after the corridor stage) given to RRT*; the PSO gets "
                  "the rest.", low=1e-3, high=1.0),
        ParamSpec("stall_fraction", float, 0.25,
                  "Hand over to the swarm before RRT*'s share is used up once RRT*'s best cost "
                  "has fallen by less than 0.1 % over this share of the budget (0 = never).",
                  low=0.0, high=1.0),
        ParamSpec("connect_after", float, 0.2,
                  "With no RRT* path after this share of RRT*'s time, RRT* stops: the swarm "
                  "takes over the corridor stage's path, or, without one, OMPL's BIT* looks for "
                  "a first path (narrow passages) whose waypoints become the candidate nodes "
                  "(1 = never).", low=0.0, high=1.0),
        ParamSpec("rrt_max_iterations", int, 0,
                  "Stop RRT* after this many iterations (0 = no limit); with a bounded PSO this "
                  "makes runs reproducible regardless of machine speed.", low=0),
        ParamSpec("simplify", bool, True,
                  "Run OMPL's path simplifier (simplifyMax: vertex reduction and shortcutting "
                  "through the exact motion validator, about a millisecond) on RRT*'s path before "
                  "the swarm."),
        SEED,
)  # fmt: skip

#: RRTstarPSO's parameters by stage, as listings show them (``rrtpso planners RRTstarPSO``): its
#: run, the corridor stage, its inner RRT* (OMPL's own declarations, passed on through their
#: setters) and OMPL's simplifier, the swarm, and the swarm's rounds over the path; the few worth
#: tuning first marked.
RRTSTAR_PSO_PARAMS = (
    _OWN.subset("budget", "seed").grouped("the run", key=("budget",))
    + _OWN.subset("corridor_cells", "corridor_fraction", "corridor_alternatives").grouped(
        "the corridor stage", key=("corridor_fraction",))
    + (ParamTable(*(RRTSTAR_PARAMS[n] for n in _INNER))
       + _OWN.subset("rrt_time_fraction", "stall_fraction", "connect_after",
                     "rrt_max_iterations", "simplify")).grouped(
        "RRT* and OMPL's simplifier", key=("rrt_time_fraction", "rrt_max_iterations"))
    + SWARM_PARAMS.grouped("the swarm (eqs. 4-5)", key=("swarm_size", "iterations"))
    + OPTIMIZER_PARAMS.grouped("the swarm over the path: rounds, polish, costs",
                               key=("smoothness_weight",))
)  # fmt: skip


@dataclass
class RRTstarPSOStats(RRTstarStatsMixin, PlannerStats):
    """Per-stage figures of one RRTstarPSO solve (the ``stages`` of a solve result).

    Lengths are in problem units, times in seconds; ``*_cost`` are the problem's objective (the
    length plus the inflation cost, :mod:`rrtpso_ompl.model.objective`; the length without
    one). In OMPL's benchmark terms the corridor stage,
    the RRT* stage and OMPL's simplifier are the planning, the swarm is the simplification.
    ``rrt_path`` is RRT*'s first path, ``seed_path`` the path the returned one was made from
    (``seed_source`` says whose: ``"corridor"``, ``"RRTstar"``, ``"BITstar"`` or
    ``"costroute"``; a later RRT* path when the anytime loop found a shorter). ``corridor_*``
    describe the corridor stage (``corridor_cells``: its lattice's cells; ``corridor_reason``:
    why it has no path);
    ``costroute_time`` the re-routing of the best candidate through the cheapest cells under an
    inflation cost (:mod:`~rrtpso_ompl.planners.rrtstar_pso.costroute`; its path is a candidate,
    ``"costroute"``).
    ``range_used`` is the inner RRT*'s range, the one chosen for the world when the ``range``
    parameter is 0 (the parameter itself stays as the user set it).
    """

    range_used: float = 0.0
    corridor_length: float | None = None
    corridor_time: float = 0.0
    corridor_cells: int = 0
    corridor_routes: int = 0
    corridor_reason: str = ""
    seed_source: str = ""
    seed_length: float | None = None
    seed_cost: float | None = None
    rrt_length: float | None = None
    first_solution: str = "RRTstar"
    rrt_time: float = 0.0
    rrt_iterations: int = 0
    rrt_waypoints: int = 0
    rrt_path: list[list[float]] = field(default_factory=list)
    seed_path: list[list[float]] = field(default_factory=list)
    rrt_progress: list[tuple[float, float]] = field(default_factory=list)
    simplified_length: float | None = None
    simplify_time: float = 0.0
    costroute_time: float = 0.0
    pso_length: float | None = None
    pso_cost: float | None = None
    pso_time: float = 0.0
    pso_iterations: int = 0
    pso_evaluations: int = 0
    pso_rounds: int = 0
    pso_waypoints: int = 0
    pso_improved: bool = False
    pso_history: list[float] = field(default_factory=list)

    def log_properties(self) -> dict[str, tuple[str, Any]]:
        """The corridor stage's and the cost route's figures first, then RRT*'s and the swarm's."""
        return {
            "corridor time": ("REAL", self.corridor_time),
            "corridor length": ("REAL", self.corridor_length),
            "costroute time": ("REAL", self.costroute_time),
            **super().log_properties(),
        }


#: How many times over OMPL's simplifier checks the path's length in one pass (vertex reduction,
#: shortcuts, collapsing), for sizing it to a user's slow checker: an estimate on the safe side.
SIMPLIFIER_PASS_LENGTHS = 20

#: With no route through the lattice yet, a finer lattice may be tried until this share of the
#: budget (there is nothing for the other stages to refine meanwhile).
_CORRIDOR_NO_ROUTE_SHARE = 0.7

#: Share of the budget kept back for handing the path over (the last checks, OMPL's path): the
#: stages aim to be done by the rest.
FINISH_RESERVE = 0.03

#: RRT*'s automatic range is at most this many times the median clearance of free points.
RANGE_PER_CLEARANCE = 10.0


def clutter_range(world: World, default: float, n_points: int = 1024) -> float:
    """RRT*'s range for a world: OMPL's ``default``, or less where the world is cluttered.

    The median distance to the nearest obstacle over free points spread evenly over the bounds
    (a fixed pseudo-random set: the same world always gets the same range) measures how wide the
    free space is; a motion much longer than that is rarely free. The range is at most
    :data:`RANGE_PER_CLEARANCE` times it: unchanged for the problems of ``problems/static``
    (their median clearance is a sizeable share of the workspace), 18 instead of 283 among
    10,000 circles in 1000 x 1000.
    """
    (xmin, ymin), (xmax, ymax) = world.bounds
    pts = np.random.default_rng(0).uniform((xmin, ymin), (xmax, ymax), size=(n_points, 2))
    cap = default / RANGE_PER_CLEARANCE
    d = world.point_clearance(pts, cap=cap)
    free = d >= world.threshold
    if not free.any():
        return default
    return float(min(default, RANGE_PER_CLEARANCE * np.median(d[free])))


class RRTstarPSO(PythonPlanner):
    """RRT* then PSO over its waypoints (Rasheed, Al-Araji, Abdullah: "Static and Dynamic Path
    Planning Algorithms Design for a Wheeled Mobile Robot Based on a Hybrid Technique").

    Parameters
    ----------
    si : ompl.base.SpaceInformation
        A 2-D real vector space (``ob.RealVectorStateSpace(2)``); or R^n, SE(2), Dubins or
        Reeds-Shepp, where RRT*, OMPL's simplifier and the swarm run through the space
        information (:mod:`.general`, docs/spaces.md). In any other space the planner
        refuses, saying why (``planner.unsupported``, logged; ``solve`` returns ``ABORT``). When
        its validity checker carries a ``world`` (as built by
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
        # Outside the plane: R^n, SE(2), Dubins and Reeds-Shepp through the space information
        # (:mod:`.general`); any other space is refused, naming it.
        self._space = None
        if self.unsupported is not None:
            self._space, self.unsupported = space_of_planner(si, name)
        self.inner = og.RRTstar(si)
        self._inner_ready = False
        self._inflation = None  # the problem's inflation cost, read from the objective in solve

    def setup(self) -> None:
        super().setup()
        if self.unsupported is not None:
            return  # not the plane: solve() refuses (logged), nothing to set up
        self.inner.setProblemDefinition(self.getProblemDefinition())
        for name in _INNER:
            getattr(self.inner, self.PARAMS[name].setter)(self._values[name])
        self.inner.setup()
        if self._space is not None:
            self._inner_ready = True
            return  # no world, no plane stages: the space information does every check
        # Our exact world, or the user's checker behind a fine-sampling model whose measured
        # cost sizes the swarm (one model per planner, so the measurements carry over).
        self._model = collision_model_for(self.getSpaceInformation())
        if self._values["range"] == 0.0:
            # OMPL's default (a fifth of the space's extent) is right for a few obstacles; among
            # thousands almost every motion that long is blocked and the tree barely grows.
            world = self._model
            if isinstance(world, World):
                self.inner.setRange(clutter_range(world, self.inner.getRange()))
        self._inner_ready = True

    def clear(self) -> None:
        super().clear()
        self.inner.clear()

    def _apply(self, name: str, value: Any) -> None:
        super()._apply(name, value)
        if getattr(self, "_inner_ready", False) and name in _INNER:
            # Keep the inner RRT* in step when a parameter changes after setup().
            getattr(self.inner, self.PARAMS[name].setter)(value)

    # ------------------------------------------------------------------------------------------
    def _solve(self, ptc: ob.PlannerTerminationCondition) -> ob.PlannerStatus:
        t0 = time.perf_counter()
        if not self._inner_ready:
            self.setup()
        if self._space is not None:
            return solve_in_space(self, self._space, ptc, t0, self._rng())
        pdef = self.getProblemDefinition()
        stats = RRTstarPSOStats(range_used=self.inner.getRange())  # the one chosen when 0
        self.last_stats = stats

        # The problem's inflation cost, when it has one (the swarm and the ranking lower it).
        self._inflation = inflation_of(pdef.getOptimizationObjective())
        if not isinstance(self._model, World):
            self._inflation = None  # it needs our world's distances; the length then
        corridor = self._corridor(ptc, t0, stats)  # stage 0
        if not self._rrt_futile(corridor):
            self._run_rrtstar(ptc, t0, stats, fallback=corridor is None)  # stage 1
        candidates = self._candidates(corridor, ptc, t0, stats)  # stage 2
        if not candidates:
            if pdef.hasSolution():  # RRT*'s tree never reached the goal
                return ob.PlannerStatus(ob.PlannerStatus.APPROXIMATE_SOLUTION)
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        source, seed, xy = min(candidates, key=lambda c: self._cost(c[2]))
        stats.seed_source, stats.seed_path = source, seed.tolist()
        stats.seed_length = stats.simplified_length = path_length(xy)
        stats.seed_cost = self._cost(xy)
        best = self._swarm(xy, stats, t0, ptc).path  # stage 3
        best = self._anytime(best, stats, t0, ptc)
        stats.pso_length = path_length(best)
        stats.pso_cost = self._cost(best)
        stats.pso_waypoints = len(best)

        # Replace RRT*'s entry either way, so the solution is reported under this planner's name.
        path = array_to_path(self.getSpaceInformation(), best)
        pdef.clearSolutionPaths()
        pdef.addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)

    def _corridor(self, ptc, t0: float, stats: RRTstarPSOStats) -> np.ndarray | None:
        """Stage 0: the corridor stage's path (:func:`.corridor.find_corridor_path`
        within ``corridor_fraction`` of the budget; with no route at all, up to
        :data:`_CORRIDOR_NO_ROUTE_SHARE` of it), or None."""
        params = self._values
        if params["corridor_cells"] <= 0:
            stats.corridor_reason = "off"
            return None
        start, goal = self._start_and_goal(ptc)
        if start is None or goal is None:
            stats.corridor_reason = "no start or goal state"
            return None
        budget = params["budget"]
        cells = params["corridor_cells"]
        seconds = params["corridor_fraction"] * budget if budget > 0 else None
        if params["rrt_max_iterations"] > 0:
            # Iteration-bounded (reproducible) runs: a lattice sized by the clock would differ
            # from run to run; a fixed one does not.
            seconds, cells = None, min(cells, REPRODUCIBLE_CORRIDOR_CELLS)
        if isinstance(self._model, SpaceInformationCollisionModel):
            # The user's checker answers the lattice one state at a time: size it to its cost.
            per_check = self._model.probe(np.asarray(start)) * self._model.step
            if seconds is not None:
                cells = min(cells, int(0.4 * seconds / max(per_check, 1e-9)))
            if cells < 1024:
                stats.corridor_reason = "the validity checker is too slow for a lattice"
                return None
        t1 = time.perf_counter()
        more = None if seconds is None else t0 + _CORRIDOR_NO_ROUTE_SHARE * budget - t1
        result = find_corridor_path(
            self._model,
            start,
            goal,
            seconds,
            cells,
            ptc,
            params["corridor_alternatives"],
            no_route_seconds=more,
        )
        stats.corridor_time = time.perf_counter() - t1
        stats.corridor_cells = result.lattice.n_cells if result.lattice else 0
        stats.corridor_routes = result.routes
        stats.corridor_reason = result.reason
        if result.path is None:
            return None
        stats.corridor_length = result.length
        return result.path

    def _candidates(self, corridor, ptc, t0: float, stats: RRTstarPSOStats):
        """Stage 2: ``(source, raw waypoints, shortened waypoints)`` of every candidate path:
        RRT*'s (or BIT*'s) after OMPL's simplifier, and the corridor stage's (already taut in
        its corridor) after a greedy shortcut."""
        pdef = self.getProblemDefinition()
        out = []
        if pdef.hasSolution():
            raw = pdef.getSolutionPath()  # shared ownership: stays valid after clearSolutionPaths
            xy = path_to_array(raw)
            stats.rrt_length = path_length(xy)
            stats.rrt_waypoints = len(xy)
            stats.rrt_path = xy.tolist()
            if not pdef.hasApproximateSolution():
                short = self._simplify(raw, xy, stats, ptc, t0) if self._values["simplify"] else xy
                out.append((stats.first_solution, xy, short))
        if corridor is not None:
            # Taut within its corridor already: a short look-ahead suffices. (Counted with the
            # simplification: on a maze path of hundreds of waypoints it takes a while.)
            t1 = time.perf_counter()
            short = shortcut(corridor, self._model.segments_free, self._stop(ptc, t0), window=8)
            stats.simplify_time += time.perf_counter() - t1
            out.append(("corridor", corridor, short))
        if self._inflation is not None and out:
            # The shortest path hugs the walls: re-routed through the cheapest cells of a band
            # round it (the costmap's way), it is a far better seed for the inflation cost.
            t1 = time.perf_counter()
            around = min(out, key=lambda c: self._cost(c[2]))[2]
            end = self._finish_by(t0)  # half of what is left, the swarm gets the rest
            routed = cost_route(self._model, self._inflation, around,
                                None if end is None else t1 + 0.5 * max(end - t1, 0.0))  # fmt: skip
            stats.costroute_time = time.perf_counter() - t1
            if routed is not None:
                out.append(("costroute", routed, routed))
        return out

    def _cost(self, xy: np.ndarray) -> float:
        """The problem's objective of waypoints ``xy``: the length, plus the inflation cost when
        the problem has one."""
        if self._inflation is None:
            return path_length(xy)
        return self._inflation.path_cost(self._model, xy)

    def _finish_by(self, t0: float) -> float | None:
        """When the stages must be done (``time.perf_counter()`` s): the end of the budget, less
        :data:`FINISH_RESERVE` of it for handing the path over; None without a budget."""
        budget = self._values["budget"]
        return t0 + (1.0 - FINISH_RESERVE) * budget if budget > 0 else None

    def _stop(self, ptc, t0: float):
        """The outer condition or :meth:`_finish_by`."""
        deadline = self._finish_by(t0)
        if deadline is None:
            return lambda: bool(ptc())
        return lambda: bool(ptc()) or time.perf_counter() >= deadline

    def _anytime(self, best: np.ndarray, stats: RRTstarPSOStats, t0: float, ptc) -> np.ndarray:
        """RRT* stalled and the swarm converged with time left: grow the same tree on, and run
        the swarm again whenever RRT* finds a path that, shortened, beats the seed so far."""
        pdef = self.getProblemDefinition()
        while self._resumable(t0, ptc):
            seed_cost = self.inner.bestCost().value()
            self._run_rrtstar(ptc, t0, stats, resume=True)
            if not self.inner.bestCost().value() < seed_cost * (1.0 - 1e-9):
                break
            if pdef.hasApproximateSolution() or not pdef.hasSolution():
                break
            raw = pdef.getSolutionPath()
            xy = path_to_array(raw)
            seed = xy
            if self._values["simplify"] and not ptc():
                xy = self._simplify(raw, xy, stats, ptc, t0)
            if self._cost(xy) >= stats.seed_cost:
                continue  # still no better start than the one the swarm had
            again = self._swarm(xy, stats, t0, ptc)
            if again.cost < self._cost(best):
                best, stats.seed_path, stats.seed_source = again.path, seed.tolist(), "RRTstar"
                stats.seed_length, stats.seed_cost = path_length(xy), self._cost(xy)
        return best

    def _simplify(self, raw: og.PathGeometric, xy: np.ndarray, stats: RRTstarPSOStats, ptc, t0):
        """OMPL's simplifier on a copy of RRT*'s path; the shorter of the two waypoints.

        ``simplifyMax`` (about a millisecond on a typical path) without a budget; with one, its
        steps in small batches for at most half of what is left (:func:`simplify_until`), so a
        path of hundreds of waypoints through a maze cannot eat the swarm's share or the budget.
        """
        t1 = time.perf_counter()
        budget = self._values["budget"]
        if budget > 0 and not self._simplifier_fits(xy, 0.5 * (t0 + budget - t1)):
            return xy
        simplified = og.PathGeometric(raw)  # a copy: RRT*'s own path stays as it was
        if budget > 0:
            left = max(0.5 * (t0 + budget - t1), 1e-4)
            with refusing_motions_after(self._model, t1 + left):
                simplify_until(self.getSpaceInformation(), simplified, t1 + left,
                               self.getProblemDefinition().getOptimizationObjective())  # fmt: skip
        else:
            og.PathSimplifier(self.getSpaceInformation()).simplifyMax(simplified)
        candidate = path_to_array(simplified)
        better = self._cost(candidate) < self._cost(xy) and self._fine_valid(candidate, t0)
        stats.simplify_time += time.perf_counter() - t1
        return candidate if better else xy

    def _simplifier_fits(self, xy: np.ndarray, left: float) -> bool:
        """Whether OMPL's simplifier can be trusted to stop within ``left`` seconds.

        It polls its termination condition only between whole passes, each of which checks
        motions along the path many times over (:data:`SIMPLIFIER_PASS_LENGTHS`). Our world
        refuses the motions it is asked for after the time is up, which ends a pass at once
        (:meth:`~rrtpso_ompl.model.World.refusing_motions_after`); with a user's checker of a
        millisecond per state a single pass can take a second, so it only runs when a pass
        fits."""
        model = self._model
        if not isinstance(model, SpaceInformationCollisionModel):
            return True
        si = self.getSpaceInformation()
        per_state = model.probe(xy[0]) * model.step
        states = path_length(xy) / (si.getStateValidityCheckingResolution() * si.getMaximumExtent())
        return SIMPLIFIER_PASS_LENGTHS * per_state * states <= left

    def _fine_valid(self, xy: np.ndarray, t0: float) -> bool:
        """Whether ``xy`` passes our exact world's check, or the user's checker sampled finer
        than the space's resolution.

        OMPL's simplifier checks motions at the space's resolution, and a shortcut into the gap
        between two checked states is exactly what it finds; it may also repair a state it
        finds invalid by moving it without checking the motions to it. Its path is only kept
        when the check passes (with a user's checker: when that check fits in what is left of
        the budget)."""
        model = self._model
        if not isinstance(model, SpaceInformationCollisionModel):
            return bool(model.path_valid(xy))
        budget = self._values["budget"]
        if budget > 0:
            rate = model.seconds_per_length() or model.probe(xy[0])
            if rate * path_length(xy) > 0.5 * (t0 + budget - time.perf_counter()):
                return False
        return model.path_valid(xy)

    def _swarm(
        self, xy: np.ndarray, stats: RRTstarPSOStats, t0: float, ptc: ob.PlannerTerminationCondition
    ):
        """The path optimiser over the candidate nodes, until the budget's end."""
        # With a known budget the PSO stops at its end (and at the outer condition); without one
        # the outer condition has already fired, so the swarm is bounded by its iterations only.
        terminate = None
        deadline = self._finish_by(t0)
        if deadline is not None:

            def terminate() -> bool:
                return ptc() or time.perf_counter() >= deadline

        # The same post-pass any planner gets with "+pso" (one optimiser, not two).
        si = self.getSpaceInformation()
        options = PathOptimizerOptions.from_values(self._values)
        objective = self.getProblemDefinition().getOptimizationObjective()
        if self._inflation is None or getattr(objective, "inflation", None) != self._inflation:
            objective = self._inflation  # the swarm's own distances (or the length)
        optimizer = PSOPathOptimizer(si, options=options, world=self._model, rng=self._rng(),
                                     objective=objective)  # fmt: skip
        result = optimizer.optimize_array(xy, terminate, deadline)
        # Summed over the swarm runs of one solve (one, unless the anytime loop ran more).
        stats.pso_time += result.time
        stats.pso_iterations += result.n_iterations
        stats.pso_evaluations += result.n_evaluations
        stats.pso_rounds += result.rounds
        stats.pso_history.extend(result.history.tolist())
        stats.pso_length = result.length
        stats.pso_waypoints = len(result.path)
        stats.pso_improved = stats.pso_improved or result.improved
        return result

    def _resumable(self, t0: float, ptc) -> bool:
        """Whether the anytime loop may grow RRT* again: a time budget with time left that the
        swarm did not use, and no iteration cap (which keeps runs reproducible)."""
        budget = self._values["budget"]
        if budget <= 0 or self._values["stall_fraction"] <= 0:
            return False
        if self._values["rrt_max_iterations"] > 0:
            return False
        if self._inflation is not None and INFLATION_RRT_SHARE * budget < INFLATION_RRT_MIN:
            return False  # RRT* cannot help in what is left (:meth:`_rrt_futile`)
        return not ptc() and time.perf_counter() < t0 + 0.98 * budget

    def _rrt_futile(self, corridor) -> bool:
        """Under an inflation cost with the corridor stage's path in hand, RRT* is left out when
        its share of the budget is under :data:`INFLATION_RRT_MIN` seconds: each of its motion
        costs is a Python call that may first measure new distances, so in so little time it
        adds a few vertices and overruns its share."""
        budget = self._values["budget"]
        return (self._inflation is not None and corridor is not None and budget > 0
                and INFLATION_RRT_SHARE * budget < INFLATION_RRT_MIN)  # fmt: skip

    def _run_rrtstar(
        self,
        ptc: ob.PlannerTerminationCondition,
        t0: float,
        stats: RRTstarPSOStats,
        resume: bool = False,
        fallback: bool = True,
    ) -> None:
        """Stage 1: :func:`.rrtstar_stage.grow_rrtstar` on this planner's inner RRT*."""
        grow_rrtstar(
            self.inner, self.getProblemDefinition(), self._values, ptc, t0, stats,
            inflation=self._inflation is not None, resume=resume, fallback=fallback,
        )  # fmt: skip
