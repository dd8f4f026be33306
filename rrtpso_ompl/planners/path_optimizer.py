"""Post-optimisation of a polyline path with the particle swarm (the "PSO" half of RRT*PSO).

The paper hands the waypoints ("candidate nodes") of an RRT* path to a PSO that makes the path
shorter and smoother. Here a particle is the vector of all *interior* waypoints of the path (end
points fixed), so a swarm of ``P`` particles is ``P`` candidate paths, evaluated in one broadcast.

Cost of a candidate path ``q_0 .. q_n`` (``q_0`` = start and ``q_n`` = goal fixed):

.. math::

    J = \\sum_j \\lVert q_{j+1} - q_j \\rVert + \\lambda_s \\sum_j \\alpha_j^2
        + [V > 0] \\, (J_0 + \\lambda_v V)

where ``alpha_j`` is the turning angle at interior waypoint ``j`` (radians), ``V`` the total
intrusion of the path's segments into the robot's safety zone (exact, see
:meth:`rrtpso_ompl.model.World.segment_violation`) and ``J_0`` the cost of the path the swarm was
seeded with. The ``J_0`` offset makes every colliding candidate worse than the seed, so the global
best is always collision-free (Deb's feasibility rule folded into one number), while ``lambda_v V``
still tells colliding particles which way is out.

Guarantees of :func:`optimize_path`: the result is valid (every segment checked exactly) and never
longer than the input; when it cannot improve, it returns the input unchanged.

Stages, each optional:

1. *prune*: greedy exact shortcutting (keep a waypoint only when the next ones are not directly
   visible), so the swarm searches the few dimensions that matter;
2. *PSO* over the interior waypoints, seeded around the current path;
3. *refine*: where a segment runs along an obstacle (a polyline can only approximate an arc by its
   chords' tangents), insert mid-points and run the swarm again, up to ``max_waypoints``;
4. *polish* (only with a deadline): more rounds re-centred on the best path while each still
   pays, so the caller's budget is used while the cost falls.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

import numpy as np

from ..model.geometry import path_length, shortcut, turning_angles
from ..model.world import World
from . import swarm as pso
from .params import declared, param
from .swarm import SWARM_PARAMS, PSOOptions

__all__ = [
    "OPTIMIZER_PARAMS",
    "PathCost",
    "PathOptimizationResult",
    "PathOptimizerOptions",
    "optimize_path",
]


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
        Best cost after each PSO iteration, over all rounds (the paper's best-cost curve).
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
    """

    def __init__(
        self,
        start,
        goal,
        world: World,
        smoothness_weight: float = 0.0,
        violation: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
    ) -> None:
        self.start = np.asarray(start, dtype=float)
        self.goal = np.asarray(goal, dtype=float)
        self.world = world
        self.smoothness_weight = float(smoothness_weight)
        #: ``violation(a, b)`` for segments ``(P, S, 2)``; a culled model when the caller knows the
        #: candidates stay in boxes, else the world's full check.
        self.violation = violation or world.segment_violation

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


def _pso_round(
    seed_path: np.ndarray,
    cost_model: PathCost,
    options: PathOptimizerOptions,
    rng: np.random.Generator,
    terminate: Callable[[], bool] | None,
    deadline: float | None = None,
) -> tuple[np.ndarray, pso.PSOResult]:
    """One swarm run seeded around ``seed_path``; returns the best path and the PSO result
    (the seed path itself, with no iterations, when even one evaluation would end after
    ``deadline``)."""
    world = cost_model.world
    interior = seed_path[1:-1]
    k = len(interior)
    seg_len = np.linalg.norm(np.diff(seed_path, axis=0), axis=1)
    # Spread each waypoint's initial cloud by the shorter of its two segments: a waypoint between
    # close neighbours must not be thrown across them.
    local = np.minimum(seg_len[:-1], seg_len[1:])
    sigma = np.repeat(options.init_spread * np.maximum(local, world.tol), 2)

    # Search boxes per waypoint (end points: zero-size boxes), clipped to the workspace.
    (xmin, ymin), (xmax, ymax) = world.bounds
    half = options.box_fraction * np.maximum(seg_len[:-1], seg_len[1:])
    lo = np.maximum(interior - half[:, None], [xmin, ymin])
    hi = np.minimum(interior + half[:, None], [xmax, ymax])
    violation = None
    if hasattr(world, "local_model"):
        pt_lo = np.vstack([seed_path[:1], lo, seed_path[-1:]])
        pt_hi = np.vstack([seed_path[:1], hi, seed_path[-1:]])
        seg_lo = np.minimum(pt_lo[:-1], pt_lo[1:])
        seg_hi = np.maximum(pt_hi[:-1], pt_hi[1:])
        local_model = world.local_model(seg_lo, seg_hi)
        violation = local_model.violation
    round_cost = PathCost(
        cost_model.start, cost_model.goal, world, cost_model.smoothness_weight, violation
    )

    n = options.swarm_size
    x0 = interior.reshape(-1)
    init = x0 + rng.standard_normal((n, 2 * k)) * sigma
    init[0] = x0  # the seed path itself is a particle, so G_best starts valid
    t_one = time.perf_counter()
    offset = float(round_cost.terms(x0[None, :])[0][0])
    now = time.perf_counter()
    if deadline is not None and now + (now - t_one) > deadline:
        # The swarm's first evaluation (of n particles) would not end in time either.
        return seed_path, pso.PSOResult(position=x0, cost=offset, history=np.array([offset]),
                                        n_iterations=0, n_evaluations=1, time=now - t_one,
                                        stopped_by="deadline")  # fmt: skip

    def cost(x: np.ndarray) -> np.ndarray:
        c, v = round_cost.terms(x)
        return np.where(v > 0.0, c + offset + options.violation_weight * v, c)

    res = pso.minimize(
        cost,
        lo.reshape(-1),
        hi.reshape(-1),
        PSOOptions.from_values(asdict(options)),
        rng,
        init=init,
        v_max=options.v_max_fraction * float(seg_len.mean()),
        terminate=terminate,
        deadline=deadline,
    )
    best = np.vstack([seed_path[:1], res.position.reshape(k, 2), seed_path[-1:]])
    return best, res


def optimize_path(
    path: np.ndarray,
    world: World,
    options: PathOptimizerOptions | None = None,
    rng: np.random.Generator | None = None,
    terminate: Callable[[], bool] | None = None,
    deadline: float | None = None,
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
        Polled once per PSO iteration; stops the optimisation early when it returns True.
    deadline : float, optional
        ``time.perf_counter()`` seconds; no swarm evaluation is started that would, judging by
        the last one, end after it (:func:`~rrtpso_ompl.planners.swarm.minimize`).

    Returns
    -------
    PathOptimizationResult
        Its ``path`` is valid and no longer than the input; it equals the input when the input was
        invalid or nothing shorter was found.
    """
    t0 = time.perf_counter()
    options = options or PathOptimizerOptions()
    rng = rng if rng is not None else np.random.default_rng()
    original = np.array(path, dtype=float).reshape(-1, 2)
    input_length = path_length(original)

    def result(p: np.ndarray, hist: list[np.ndarray], iters: int, evals: int, rounds: int):
        improved = p is not original
        return PathOptimizationResult(
            path=p,
            length=path_length(p),
            input_length=input_length,
            improved=improved,
            history=np.concatenate(hist) if hist else np.empty(0),
            n_iterations=iters,
            n_evaluations=evals,
            rounds=rounds,
            time=time.perf_counter() - t0,
        )

    if len(original) < 2 or not world.path_valid(original):
        return result(original, [], 0, 0, 0)

    if terminate is not None and terminate():
        return result(original, [], 0, 0, 0)  # no time left: the input, as promised
    cost_model = PathCost(original[0], original[-1], world, options.smoothness_weight)
    current = shortcut(original, world.segments_free, terminate) if options.prune else original
    history: list[np.ndarray] = []
    iters = evals = rounds = 0
    for r in range(1 + options.refine_rounds):
        if terminate is not None and terminate():
            break
        if r > 0:
            refined = _refine(current, world, options.refine_margin, options.max_waypoints)
            if len(refined) == len(current):
                break
            current = refined
        if len(current) <= 2:
            break  # a straight segment: nothing left to optimise
        candidate, res = _pso_round(current, cost_model, options, rng, terminate, deadline)
        history.append(res.history)
        iters += res.n_iterations
        evals += res.n_evaluations
        rounds += 1
        if world.path_valid(candidate) and res.cost <= _cost_of(cost_model, current):
            current = candidate

    # Anytime: with a deadline, keep polishing (boxes re-centred on the best path) while rounds
    # still pay; the budget is the caller's, so none of it is left unused while the cost falls.
    polish = options.polish_rounds if terminate is not None else 0
    for _ in range(polish):
        if terminate() or len(current) <= 2:
            break
        before = _cost_of(cost_model, current)
        candidate, res = _pso_round(current, cost_model, options, rng, terminate, deadline)
        history.append(res.history)
        iters += res.n_iterations
        evals += res.n_evaluations
        rounds += 1
        if not (world.path_valid(candidate) and res.cost <= before):
            break
        current = candidate
        if before - res.cost <= options.polish_tolerance * before:
            break

    # Drop waypoints that ended up collinear or redundant, then keep the contract: valid and never
    # longer than the input, else the input itself.
    if rounds:
        current = shortcut(current, world.segments_free, terminate)
    if world.path_valid(current) and path_length(current) < input_length:
        return result(current, history, iters, evals, rounds)
    return result(original, history, iters, evals, rounds)


def _cost_of(cost_model: PathCost, path: np.ndarray) -> float:
    c, _ = cost_model.terms(path[1:-1].reshape(1, -1))
    return float(c[0])
