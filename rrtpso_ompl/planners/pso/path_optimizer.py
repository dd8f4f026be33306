"""Post-optimisation of a polyline path with the particle swarm (the "PSO" half of RRT*PSO).

The paper hands the waypoints ("candidate nodes") of an RRT* path to a PSO that makes the path
shorter and smoother. Here a particle is the vector of all *interior* waypoints of the path (end
points fixed), so a swarm of ``P`` particles is ``P`` candidate paths, evaluated in one broadcast.

Cost of a candidate path ``q_0 .. q_n`` (``q_0`` = start and ``q_n`` = goal fixed):

.. math::

    J = \\sum_j \\lVert q_{j+1} - q_j \\rVert + \\lambda_s \\sum_j \\alpha_j^2
        + [V > 0] \\, (J_0 + \\lambda_v V)

plus, when the robot has an inflation cost, ``w`` times its integral along the path (the
problem's objective ``J``, :mod:`rrtpso_ompl.model.objective`), where ``alpha_j`` is the turning
angle at interior waypoint ``j`` (radians), ``V`` the total
intrusion of the path's segments into the robot's safety zone (exact, see
:meth:`rrtpso_ompl.model.World.segment_violation`) and ``J_0`` the cost of the path the swarm was
seeded with. The ``J_0`` offset makes every colliding candidate worse than the seed, so the global
best is always collision-free (Deb's feasibility rule folded into one number), while ``lambda_v V``
still tells colliding particles which way is out.

Guarantees of :func:`optimize_path`: the result is valid (every segment checked exactly) and never
costlier than the input (longer, without an inflation cost); when it cannot improve, it returns
the input unchanged.

Stages, each optional:

1. *prune*: greedy exact shortcutting (keep a waypoint only when the next ones are not directly
   visible), so the swarm searches the few dimensions that matter;
2. *PSO* over the interior waypoints, seeded around the current path: one swarm over all of
   them (the paper's), or, on longer paths, one small swarm per window of ``window``
   consecutive waypoints (a fixed waypoint between two windows makes their costs independent,
   so every window keeps a best of its own, :func:`~rrtpso_ompl.planners.pso.swarm.minimize` with
   ``blocks``); the windows shift from round to round so that every waypoint moves;
3. *refine*: where a segment runs along an obstacle (a polyline can only approximate an arc by its
   chords' tangents), insert mid-points and run the swarm again, up to ``max_waypoints``;
4. *polish* (only with a deadline): more rounds re-centred on the best path while each still
   pays, so the caller's budget is used while the cost falls.

With an inflation cost a path must bend away from walls, which a taut path's few waypoints
cannot: before the first round, segments that pass within the inflation radius of an obstacle
are cut into pieces no longer than the inflation radius (up to ``max_cost_waypoints``), and
waypoints are only dropped (prune, the last shortcut) where that does not raise ``J``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from ...model.geometry import path_length, shortcut, turning_angles
from ...model.objective import ClearanceField, InflationCost
from ...model.world import World
from ...params import declared, param
from . import swarm as pso
from .swarm import SWARM_PARAMS, PSOOptions

__all__ = [
    "OPTIMIZER_PARAMS",
    "PathCost",
    "PathOptimizationResult",
    "PathOptimizerOptions",
    "optimize_path",
]


#: Validations of the whole path that follow the swarm's last iteration: the time kept back for
#: them, measured on the input (a world refusing motions after the deadline fails them late).
CHECKS_AFTER_SWARM = 4
#: ... and this share of the time left besides (the last iteration's overrun, the final costs).
CHECKS_SHARE = 0.03


@declared
class PathOptimizerOptions(PSOOptions):
    """Settings of the PSO path optimiser: the swarm's (eqs. 4-5) and the optimiser's own.

    Each round confines every waypoint to a square around its seed position, of half-width
    ``box_fraction`` times the longer of its two segments (and the workspace bounds). Only
    obstacles that can reach such a box are checked, which keeps the check exact and makes it
    several times cheaper in clutter; later rounds re-centre the boxes."""

    smoothness_weight: float = param(
        0.0,
        "Cost per squared radian of turning at a waypoint (0 = shortest path only).",
        unit="length/rad^2",
        low=0.0,
    )
    violation_weight: float = param(
        10.0,
        "Penalty per unit of intrusion of a candidate segment into an obstacle's safety zone.",
        low=1e-9,
    )
    init_spread: float = param(
        0.05,
        "Spread of the initial swarm around the seed path, as a fraction of the shorter segment "
        "next to each waypoint.",
        low=0.0,
        high=10.0,
    )
    v_max_fraction: float = param(
        0.1,
        "Velocity clamp per coordinate, as a fraction of the mean segment length of the seed path.",
        low=1e-6,
        high=10.0,
    )
    box_fraction: float = param(
        0.5,
        "Each PSO round keeps every waypoint within this fraction of its longer segment from its "
        "seed position (exact obstacle culling).",
        low=1e-3,
        high=100.0,
    )
    prune: bool = param(True, "Shortcut the seed path's waypoints (exactly) before the swarm runs.")
    refine_rounds: int = param(
        4,
        "Extra PSO rounds with mid-points inserted on segments that run along an obstacle.",
        low=0,
        high=20,
    )
    refine_margin: float = param(
        0.05,
        "A segment runs along an obstacle when its clearance is below robot radius + "
        "refine_margin x max(robot radius, segment length): scale-free, and it fires for a "
        "point robot too.",
        low=0.0,
        high=10.0,
    )
    max_waypoints: int = param(48, "Most waypoints refinement may create.", low=2, high=10_000)
    max_cost_waypoints: int = param(
        400,
        "With an inflation cost: most waypoints the path may be cut into so that it can bend "
        "away from walls (segments near obstacles get one waypoint per inflation radius).",
        low=2,
        high=100_000,
    )
    window: int = param(
        4,
        "Waypoints each sub-swarm moves: the path's waypoints are cut into windows of this many, "
        "a fixed waypoint between two windows, and every window gets a swarm of its own (all in "
        "one array operation; the windows shift every round). 0 = one swarm over all the "
        "waypoints, as in the paper.",
        low=0,
        high=10_000,
    )
    polish_rounds: int = param(
        20,
        "With a deadline, further rounds re-centred on the best path while each still shortens "
        "it by more than `polish_tolerance` and time remains (0 = none).",
        low=0,
        high=10_000,
    )
    polish_tolerance: float = param(
        1e-5,
        "Relative shortening a polish round must achieve for the next one to run.",
        low=0.0,
        high=1.0,
    )


#: The path optimiser's own parameters (:class:`PathOptimizerOptions` without the swarm's).
OPTIMIZER_PARAMS = PathOptimizerOptions.PARAMS.without(*SWARM_PARAMS.names())


@dataclass(frozen=True)
class PathOptimizationResult:
    """Outcome of :func:`optimize_path`.

    Attributes
    ----------
    path : (n, 2) ndarray
        The returned path (the input itself when nothing better was found).
    length, input_length : float
        Euclidean lengths of the returned and of the input path.
    improved : bool
        Whether ``path`` differs from (and is shorter than) the input.
    history : ndarray
        The path's best cost after each PSO iteration, over all rounds (the paper's best-cost
        curve): a round whose best was not kept (refused by the exact check, or costlier) is
        flat at the cost it started from, and a round of windows (whose swarms see their
        window's cost only) steps from the cost before it to the cost after it.
    n_iterations, n_evaluations : int
        PSO iterations and particle evaluations over all rounds.
    rounds : int
        Optimisation rounds run (1 + refinements).
    time : float
        Wall-clock seconds.
    """

    path: np.ndarray
    length: float
    input_length: float
    improved: bool
    cost: float
    input_cost: float
    history: np.ndarray = field(repr=False)
    n_iterations: int
    n_evaluations: int
    rounds: int
    time: float


class PathCost:
    """Vectorised length, smoothness and collision terms of candidate paths.

    Parameters
    ----------
    start, goal : (2,) array_like
        Fixed end points.
    world : World
        Exact collision model.
    smoothness_weight : float
        ``lambda_s`` (see the module docstring).
    violation : callable, optional
        ``violation(a, b)`` of segments; the world's when omitted.
    objective : InflationCost, optional
        Adds ``w`` times the inflation cost's integral (nothing when inactive or omitted),
        measured on a :class:`~rrtpso_ompl.model.objective.ClearanceField` (interpolated
        distances: the swarm's evaluations are many; the final comparison is exact).
    field : ClearanceField, optional
        The field to share (rounds of one optimisation share their measurements).
    """

    def __init__(
        self,
        start,
        goal,
        world: World,
        smoothness_weight: float = 0.0,
        violation: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
        objective: InflationCost | None = None,
        field: ClearanceField | None = None,
    ) -> None:
        self.start = np.asarray(start, dtype=float)
        self.goal = np.asarray(goal, dtype=float)
        self.world = world
        self.smoothness_weight = float(smoothness_weight)
        #: ``violation(a, b)`` for segments ``(P, S, 2)``; a culled model when the caller knows the
        #: candidates stay in boxes, else the world's full check.
        self.violation = violation or world.segment_violation
        self.objective = objective if objective is not None and objective.active else None
        if self.objective is not None and field is None:
            step = self.objective.step
            field = ClearanceField(world, step, self.objective.inflation_radius + 2.0 * step)
        self.field = field

    def inflation(self, a: np.ndarray, b: np.ndarray) -> np.ndarray | float:
        """``w`` times the inflation cost's integral along segments ``a[..]-b[..]`` (0 without
        one)."""
        if self.objective is None:
            return 0.0
        return self.objective.weight * self.objective.segment_integrals(self.world, a, b,
                                                                        self.field)  # fmt: skip

    def full_paths(self, x: np.ndarray) -> np.ndarray:
        """Particles ``(P, 2k)`` to paths ``(P, k + 2, 2)`` with the fixed end points."""
        p = x.shape[0]
        mid = x.reshape(p, -1, 2)
        s = np.broadcast_to(self.start, (p, 1, 2))
        g = np.broadcast_to(self.goal, (p, 1, 2))
        return np.concatenate([s, mid, g], axis=1)

    def terms(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(length + lambda_s * smoothness, violation)``, each of shape ``(P,)``."""
        paths = self.full_paths(x)
        seg = np.diff(paths, axis=1)
        seg_len = np.sqrt(np.einsum("pki,pki->pk", seg, seg))
        cost = seg_len.sum(axis=1)
        if self.smoothness_weight > 0 and seg.shape[1] > 1:
            cost = cost + self.smoothness_weight * turning_angles(paths).__pow__(2).sum(axis=1)
        if self.objective is not None:
            cost = cost + self.inflation(paths[:, :-1], paths[:, 1:]).sum(axis=1)
        violation = self.violation(paths[:, :-1], paths[:, 1:]).sum(axis=1)
        return cost, violation


def _refine(path: np.ndarray, world: World, margin: float, max_waypoints: int) -> np.ndarray:
    """Insert the mid-point of every segment that runs along an obstacle (clearance tight).

    Tight means a clearance below ``r + margin * max(r, l)`` for a segment of length ``l``: the
    same share of the robot for a disc robot, and of the segment for a point robot (whose
    clearance along a chord that should bend round a circle grows with the chord's length).
    """
    r = world.robot_radius
    seg = np.hypot(*np.diff(path, axis=0).T)
    d = world.segment_distance(path[:-1], path[1:], cap=r + margin * max(r, float(seg.max())))
    tight = np.flatnonzero(d < r + margin * np.maximum(r, seg) + world.tol)
    room = max_waypoints - len(path)
    if room <= 0 or len(tight) == 0:
        return path
    tight = tight[:room]
    mids = 0.5 * (path[tight] + path[tight + 1])
    return np.insert(path, tight + 1, mids, axis=0)


def _search_boxes(path: np.ndarray, world: World, fraction: float):
    """Per interior waypoint, the box it may move in this round: ``fraction`` of its longer
    segment around it, clipped to the bounds; and the lengths of the path's segments."""
    seg_len = np.linalg.norm(np.diff(path, axis=0), axis=1)
    (xmin, ymin), (xmax, ymax) = world.bounds
    half = fraction * np.maximum(seg_len[:-1], seg_len[1:])
    interior = path[1:-1]
    lo = np.maximum(interior - half[:, None], [xmin, ymin])
    hi = np.minimum(interior + half[:, None], [xmax, ymax])
    return lo, hi, seg_len


def _violation_within(world: World, seg_lo: np.ndarray, seg_hi: np.ndarray,
                      deadline: float | None):  # fmt: skip
    """The world's violation for segments that stay in the boxes ``seg_lo[s]..seg_hi[s]``:
    culled to the obstacles near each box when the world can (exact for such segments), else
    the full check. None when building the culled model would end after ``deadline``
    (:meth:`~rrtpso_ompl.model.World.local_model`): no time for a swarm round."""
    if not hasattr(world, "local_model"):
        return world.segment_violation
    local = world.local_model(seg_lo, seg_hi, deadline)
    return None if local is None else local.violation


def _pso_round(
    seed_path: np.ndarray,
    cost_model: PathCost,
    options: PathOptimizerOptions,
    rng: np.random.Generator,
    terminate: Callable[[], bool] | None,
    deadline: float | None = None,
) -> tuple[np.ndarray, pso.PSOResult]:
    """One swarm run over every interior waypoint, seeded around ``seed_path``; returns the best
    path and the PSO result (the seed path itself, with no iterations, when even one evaluation
    would end after ``deadline``)."""
    world = cost_model.world
    interior = seed_path[1:-1]
    k = len(interior)
    lo, hi, seg_len = _search_boxes(seed_path, world, options.box_fraction)
    # Spread each waypoint's initial cloud by the shorter of its two segments: a waypoint between
    # close neighbours must not be thrown across them.
    local = np.minimum(seg_len[:-1], seg_len[1:])
    sigma = np.repeat(options.init_spread * np.maximum(local, world.tol), 2)
    pt_lo = np.vstack([seed_path[:1], lo, seed_path[-1:]])
    pt_hi = np.vstack([seed_path[:1], hi, seed_path[-1:]])
    violation = _violation_within(world, np.minimum(pt_lo[:-1], pt_lo[1:]),
                                  np.maximum(pt_hi[:-1], pt_hi[1:]), deadline)  # fmt: skip
    if violation is None:
        return seed_path, _unstarted(interior.reshape(-1), _cost_of(cost_model, seed_path),
                                     time.perf_counter())  # fmt: skip
    round_cost = PathCost(cost_model.start, cost_model.goal, world, cost_model.smoothness_weight,
                          violation, cost_model.objective, cost_model.field)  # fmt: skip

    n = options.swarm_size
    x0 = interior.reshape(-1)
    init = x0 + rng.standard_normal((n, 2 * k)) * sigma
    init[0] = x0  # the seed path itself is a particle, so G_best starts valid
    t_one = time.perf_counter()
    offset = float(round_cost.terms(x0[None, :])[0][0])
    if _no_time_for_a_swarm(t_one, deadline):
        return seed_path, _unstarted(x0, offset, t_one)

    res = _swarm(round_cost.terms, offset, lo, hi, options, rng, init, seg_len, terminate,
                 deadline)  # fmt: skip
    best = np.vstack([seed_path[:1], res.position.reshape(k, 2), seed_path[-1:]])
    return best, res


def _windows(n_interior: int, width: int, offset: int) -> np.ndarray:
    """(K, width) indices into the path of the waypoints each window moves, -1 for the empty
    slots of a short window. Interior waypoints are 1..n_interior; every ``width + 1``-th one
    (shifted by ``offset``) stays fixed, so no two windows share a segment."""
    idx = np.arange(1, n_interior + 1)
    fixed = (idx - 1 + offset) % (width + 1) == width
    moving = idx[~fixed]
    if not len(moving):
        return np.empty((0, width), dtype=np.int64)
    # A new window starts after a fixed waypoint (a gap in the moving indices) or when full.
    gap = np.ones(len(moving), dtype=bool)
    gap[1:] = np.diff(moving) > 1
    group = np.cumsum(gap) - 1
    slot = np.arange(len(moving)) - np.flatnonzero(gap)[group]
    out = np.full((group[-1] + 1, width), -1, dtype=np.int64)
    out[group, slot] = moving
    return out


def _no_time_for_a_swarm(t_one: float, deadline: float | None) -> bool:
    """Whether the swarm's first chunk of evaluations (:data:`swarm._FIRST_CHUNK` particles, each
    about as long as the one evaluation that started at ``t_one`` and ends now) would end after
    ``deadline``: on a path of hundreds of waypoints that chunk alone can outlast a budget's
    end, and an evaluation cannot be interrupted."""
    now = time.perf_counter()
    return deadline is not None and now + pso._FIRST_CHUNK * (now - t_one) > deadline


def _unstarted(x0: np.ndarray, cost: float, t_one: float) -> pso.PSOResult:
    """The result of a swarm round that did not start (no time): the seed."""
    return pso.PSOResult(position=x0, cost=cost, history=np.array([cost]), n_iterations=0,
                         n_evaluations=1, time=time.perf_counter() - t_one,
                         stopped_by="deadline")  # fmt: skip


def _swarm(terms, offset, lo, hi, options, rng, init, seg_len, terminate, deadline, blocks=1):
    """The swarm of one round: cost = length (and smoothness) from ``terms``, and where a
    segment intrudes, ``offset`` (the seed's cost) plus the weighted violation, so no colliding
    particle ranks before the seed; velocities clamped to ``v_max_fraction`` of the mean seed
    segment."""

    def cost(x: np.ndarray) -> np.ndarray:
        c, v = terms(x)
        return np.where(v > 0.0, c + offset + options.violation_weight * v, c)

    return pso.minimize(
        cost,
        lo.reshape(-1),
        hi.reshape(-1),
        PSOOptions.from_values(asdict(options)),
        rng,
        init=init,
        v_max=options.v_max_fraction * float(seg_len.mean()),
        terminate=terminate,
        blocks=blocks,
        deadline=deadline,
    )


def _window_boxes(seed_path: np.ndarray, world, options: PathOptimizerOptions, offset: int,
                  deadline: float | None = None):  # fmt: skip
    """The windows of one round (:func:`_windows`, ``-1`` for an empty slot) and what their
    swarm needs: each slot's waypoint index (an empty slot's: its window's closing fixed
    waypoint), the search box of each slot ``(K, W, 2)`` (an empty slot's is that waypoint),
    the fixed waypoints before and after each window, the seed's segment lengths and the
    violation measure, culled to the boxes of the windows' segments."""
    width = options.window
    win = _windows(len(seed_path) - 2, width, offset)
    real = win >= 0
    # Each window's closing fixed waypoint: after its last real slot.
    last = win.max(axis=1)
    first = win[:, 0]
    slot_idx = np.where(real, win, last[:, None] + 1)  # empty slots sit on the closing point
    lo_all, hi_all, seg_len = _search_boxes(seed_path, world, options.box_fraction)
    lo_pts = np.vstack([seed_path[:1], lo_all, seed_path[-1:]])
    hi_pts = np.vstack([seed_path[:1], hi_all, seed_path[-1:]])
    lo = np.where(real[..., None], lo_pts[slot_idx], seed_path[slot_idx])  # (K, W, 2)
    hi = np.where(real[..., None], hi_pts[slot_idx], seed_path[slot_idx])
    before, after = seed_path[first - 1], seed_path[last + 1]  # (K, 2)
    chain_lo = np.concatenate([before[:, None], lo, after[:, None]], axis=1)  # (K, W + 2, 2)
    chain_hi = np.concatenate([before[:, None], hi, after[:, None]], axis=1)
    # Segment boxes of every chain, for the culled exact check.
    seg_lo = np.minimum(chain_lo[:, :-1], chain_lo[:, 1:]).reshape(-1, 2)
    seg_hi = np.maximum(chain_hi[:, :-1], chain_hi[:, 1:]).reshape(-1, 2)
    violation = _violation_within(world, seg_lo, seg_hi, deadline)
    return win, slot_idx, lo, hi, before, after, seg_len, violation


def _window_terms(cost_model: PathCost, before, after, violation, n_win: int, width: int):
    """The swarm's cost terms of :func:`_window_round`: ``terms(x)`` gives, per particle and
    window, the chain's length (plus smoothness and inflation) and its collision violation.

    Window ``k`` is the chain ``before[k], q_1 .. q_W, after[k]`` (``x`` holds the ``q``)."""

    def chains(x: np.ndarray) -> np.ndarray:
        n = x.shape[0]
        mid = x.reshape(n, n_win, width, 2)
        a = np.broadcast_to(before[None, :, None], (n, n_win, 1, 2))
        b = np.broadcast_to(after[None, :, None], (n, n_win, 1, 2))
        return np.concatenate([a, mid, b], axis=2)

    def terms(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ch = chains(x)
        seg = np.diff(ch, axis=2)
        length = np.sqrt(np.einsum("pksi,pksi->pks", seg, seg)).sum(axis=2)
        if cost_model.smoothness_weight > 0:
            # Turning at the moving waypoints; the turn at a fixed waypoint depends on two
            # windows and is left out, so that the windows' costs stay independent.
            length = length + cost_model.smoothness_weight * (
                turning_angles(ch) ** 2).sum(axis=2)  # fmt: skip
        if cost_model.objective is not None:
            length = length + cost_model.inflation(ch[:, :, :-1], ch[:, :, 1:]).sum(axis=2)
        n = ch.shape[0]
        v = violation(ch[:, :, :-1].reshape(n, -1, 2), ch[:, :, 1:].reshape(n, -1, 2))
        return length, v.reshape(n, n_win, width + 1).sum(axis=2)

    return terms


def _window_round(
    seed_path: np.ndarray,
    cost_model: PathCost,
    options: PathOptimizerOptions,
    rng: np.random.Generator,
    terminate: Callable[[], bool] | None,
    offset: int,
    deadline: float | None = None,
) -> tuple[np.ndarray, pso.PSOResult]:
    """One round of a small swarm per window of ``options.window`` waypoints, all windows in one
    array operation (:func:`~rrtpso_ompl.planners.pso.swarm.minimize` with ``blocks``).

    Window ``k`` is the chain ``fixed, q_1 .. q_W, fixed``; a short window's empty slots are
    pinned to its closing fixed waypoint (zero-length segments, no cost). Its cost is the
    chain's length (and smoothness), and, when a segment intrudes, the seed chain's cost plus
    the penalty: no window's best is ever worse or colliding. Returns the path with every
    window's best in place, and the swarm's result.
    """
    world = cost_model.world
    width = options.window
    win, slot_idx, lo, hi, before, after, seg_len, violation = _window_boxes(
        seed_path, world, options, offset, deadline
    )
    if violation is None:  # no time to build the culled check: the seed as it is
        x0 = seed_path[1:-1].reshape(-1)
        return seed_path, _unstarted(x0, _cost_of(cost_model, seed_path), time.perf_counter())
    real = win >= 0
    n_win = len(win)
    terms = _window_terms(cost_model, before, after, violation, n_win, width)
    x0 = seed_path[slot_idx].reshape(-1)
    local = np.minimum(seg_len[:-1], seg_len[1:])
    spread = np.where(real, options.init_spread * np.maximum(local[np.maximum(win - 1, 0)],
                                                             world.tol), 0.0)  # fmt: skip
    n = options.swarm_size
    init = x0 + rng.standard_normal((n, n_win * width * 2)) * np.repeat(spread.reshape(-1), 2)
    init[0] = x0
    t_one = time.perf_counter()
    offset_cost = terms(x0[None])[0][0]  # (K,)
    if _no_time_for_a_swarm(t_one, deadline):
        return seed_path, _unstarted(x0, float(offset_cost.sum()), t_one)

    res = _swarm(terms, offset_cost, lo, hi, options, rng, init, seg_len, terminate, deadline,
                 blocks=n_win)  # fmt: skip
    best = seed_path.copy()
    pos = res.position.reshape(n_win, width, 2)
    best[win[real]] = pos[real]
    return best, res


def optimize_path(
    path: np.ndarray,
    world: World,
    options: PathOptimizerOptions | None = None,
    rng: np.random.Generator | None = None,
    terminate: Callable[[], bool] | None = None,
    deadline: float | None = None,
    objective: InflationCost | None = None,
    field: ClearanceField | None = None,
) -> PathOptimizationResult:
    """Shorten (and optionally smooth) a valid path with the particle swarm, end points fixed.

    Parameters
    ----------
    path : (n, 2) array_like
        Waypoints of any planner's path (e.g. RRT*'s candidate nodes).
    world : World
        Exact collision model (obstacles, bounds, robot radius).
    options : PathOptimizerOptions, optional
        Defaults when omitted.
    rng : numpy.random.Generator, optional
        Source of all randomness; ``numpy.random.default_rng()`` (unseeded) when omitted.
    terminate : callable, optional
        Polled once per PSO iteration; stops the optimisation early when it returns True. With
        it, rounds go on (up to ``polish_rounds`` more) while they still pay.
    deadline : float, optional
        ``time.perf_counter()`` seconds by which the swarm must be done: no PSO iteration starts
        that would end after it (their cost is measured as they run).
    objective : InflationCost, optional
        The problem's inflation cost: the swarm lowers ``J`` instead of the length.
    field : ClearanceField, optional
        Interpolated distances to share (the OMPL objective's: measured once for both).

    Returns
    -------
    PathOptimizationResult
        Its ``path`` is valid and no costlier than the input (``J``; the length without an
        objective); it equals the input when the input was invalid or nothing better was found.
    """
    t0 = time.perf_counter()
    options = options or PathOptimizerOptions()
    rng = rng if rng is not None else np.random.default_rng()
    original = np.array(path, dtype=float).reshape(-1, 2)
    t_check = time.perf_counter()
    valid = len(original) >= 2 and world.path_valid(original)
    if deadline is not None:
        # The swarm ends early enough for the checks after it (a round's, the last shortcut's
        # and the result's), which a world refusing motions after the deadline would fail.
        now = time.perf_counter()
        deadline -= CHECKS_AFTER_SWARM * (now - t_check) + CHECKS_SHARE * max(deadline - now, 0.0)
        stop = terminate
        terminate = lambda: time.perf_counter() >= deadline or bool(stop and stop())  # noqa: E731
    run = _Rounds(original, world, options, rng, terminate, deadline, objective, field)
    if valid and not run.stopped():
        run.optimise()
    return run.result(t0)


class _Rounds:
    """The rounds of one :func:`optimize_path` call and their bookkeeping."""

    def __init__(self, original, world, options, rng, terminate, deadline=None, objective=None,
                 field=None):  # fmt: skip
        self.deadline = deadline
        self.original = original
        self.world = world
        self.options = options
        self.rng = rng
        self.terminate = terminate
        self.cost_model = PathCost(original[0], original[-1], world, options.smoothness_weight,
                                   objective=objective, field=field)  # fmt: skip
        self.current = original
        self.history: list[np.ndarray] = []
        self.iterations = self.evaluations = self.rounds = 0

    def stopped(self) -> bool:
        return self.terminate is not None and self.terminate()

    def optimise(self) -> None:
        """Prune, then rounds (refining where segments run along obstacles) while they pay."""
        opts, world = self.options, self.world
        field = self.cost_model.field
        # With an inflation cost, the distances along the path are measured first and in time
        # (a measurement cannot be cut short): no time for them, no swarm.
        if field is not None and not field.prefill(self.original, 0.0, self.deadline):
            return
        if opts.prune:
            self.current = self._no_costlier(
                shortcut(self.original, world.segments_free, self.terminate), self.original
            )
        if self.cost_model.objective is not None:
            self.current = _densify(self.current, world, self.cost_model.objective,
                                    opts.max_cost_waypoints)  # fmt: skip
            # ... and round it, where the rounds' candidates will lie.
            seg = np.hypot(*np.diff(self.current, axis=0).T)
            reach = opts.box_fraction * float(seg.max(initial=0.0))
            if not field.prefill(self.current, reach, self.deadline):
                return
        # Without a deadline the work is bounded by the refinement rounds (reproducible); with
        # one, polish rounds follow while a round still shortens the path.
        limit = 1 + opts.refine_rounds + (opts.polish_rounds if self.terminate else 0)
        still = 0
        for r in range(limit):
            if self.stopped() or len(self.current) <= 2:
                break
            seed = self.current
            if r > 0:
                seed = _refine(seed, world, opts.refine_margin, opts.max_waypoints)
            refined = len(seed) > len(self.current)
            before = _cost_of(self.cost_model, seed)
            after = self._round(seed, r)
            # Rounds that neither refine nor pay (both window offsets, with windows): converged.
            still = 0 if refined or before - after > opts.polish_tolerance * before else still + 1
            if still >= (2 if opts.window and len(seed) - 2 > opts.window else 1):
                break
        if self.rounds:
            # Drop waypoints that ended up collinear or redundant (where that costs nothing).
            self.current = self._no_costlier(
                shortcut(self.current, world.segments_free, self.terminate), self.current
            )
            if self.history and len(self.history[-1]):
                # The last point of the curve is the path this pass leaves (it costs no more).
                last = np.array(self.history[-1], dtype=float)
                last[-1] = min(last[-1], _cost_of(self.cost_model, self.current))
                self.history[-1] = last

    def _no_costlier(self, candidate: np.ndarray, fallback: np.ndarray) -> np.ndarray:
        """``candidate`` unless it costs more than ``fallback`` (a shortcut never lengthens a
        path, but with an inflation cost it may run it along a wall)."""
        if self.cost_model.objective is None:
            return candidate
        worse = _cost_of(self.cost_model, candidate) > _cost_of(self.cost_model, fallback)
        return fallback if worse else candidate

    def _round(self, seed: np.ndarray, r: int) -> float:
        """One swarm round from ``seed``; keeps its path when valid and no worse. Returns the
        cost after the round."""
        opts = self.options
        windowed = bool(opts.window and len(seed) - 2 > opts.window)
        if windowed:
            candidate, res = _window_round(seed, self.cost_model, opts, self.rng, self.terminate,
                                           r * (opts.window // 2 + 1), self.deadline)  # fmt: skip
        else:
            candidate, res = _pso_round(seed, self.cost_model, opts, self.rng, self.terminate,
                                        self.deadline)  # fmt: skip
        self.iterations += res.n_iterations
        self.evaluations += res.n_evaluations
        self.rounds += 1
        before = _cost_of(self.cost_model, seed)
        if self.world.path_valid(candidate):
            cost = _cost_of(self.cost_model, candidate)
            if cost <= before:
                # The path's cost as the round went: a window's swarm reports its window's own
                # cost, so that round shows the path's cost before it and after it only.
                steps = np.full(len(res.history), before) if windowed else res.history
                self.history.append(np.clip(steps, cost, before))
                if len(steps):
                    self.history[-1][-1] = cost
                self.current = candidate
                return cost
        # The round's best was not kept (the exact check refused it, or it cost more): its
        # history would show a gain the path never had, so the round counts as flat.
        self.history.append(np.full(len(res.history), before))
        self.current = seed
        return before

    def result(self, t0: float) -> PathOptimizationResult:
        """Keep the contract: valid and never costlier than the input, else the input itself."""
        p = self.current
        input_cost = self.cost(self.original)
        ok = p is not self.original and self.world.path_valid(p)
        history = np.concatenate(self.history) if self.history else np.empty(0)
        if not (ok and self.cost(p) < input_cost):
            p = self.original
            history = np.full(len(history), input_cost)  # nothing the swarm found was kept
        return PathOptimizationResult(
            path=p,
            length=path_length(p),
            input_length=path_length(self.original),
            improved=p is not self.original,
            cost=self.cost(p),
            input_cost=input_cost,
            history=history,
            n_iterations=self.iterations,
            n_evaluations=self.evaluations,
            rounds=self.rounds,
            time=time.perf_counter() - t0,
        )

    def cost(self, path: np.ndarray) -> float:
        """The objective ``J`` of a path (its length without an inflation cost)."""
        objective = self.cost_model.objective
        if objective is None:
            return path_length(path)
        return objective.path_cost(self.world, path)


def _densify(path: np.ndarray, world: World, objective: InflationCost, limit: int) -> np.ndarray:
    """Cut every segment that passes within the inflation radius of an obstacle into equal pieces
    no longer than that radius, so that the swarm can bend the path away from the wall; at most
    ``limit`` waypoints in all (the pieces are made longer to fit)."""
    seg = np.diff(path, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    near = world.segment_distance(path[:-1], path[1:], cap=objective.inflation_radius)
    near = near < objective.inflation_radius
    spacing = objective.inflation_radius
    room = limit - len(path)
    if room <= 0 or not near.any():
        return path
    pieces = np.where(near, np.ceil(length / spacing), 1.0)
    extra = pieces.sum() - len(pieces)
    if extra > room:  # longer pieces, so the waypoints fit the limit
        pieces = np.where(near, np.maximum(1.0, np.floor(pieces * room / extra)), 1.0)
    pieces = pieces.astype(np.int64)
    seg_of = np.repeat(np.arange(len(seg)), pieces)
    first = np.cumsum(pieces) - pieces
    t = (np.arange(int(pieces.sum())) - first[seg_of]) / pieces[seg_of]
    out = path[:-1][seg_of] + t[:, None] * seg[seg_of]
    return np.vstack([out, path[-1:]])


def _cost_of(cost_model: PathCost, path: np.ndarray) -> float:
    c, _ = cost_model.terms(path[1:-1].reshape(1, -1))
    return float(c[0])
