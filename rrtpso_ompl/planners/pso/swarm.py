"""A vectorised global-best particle swarm optimiser (paper eqs. 4-5).

Each particle ``i`` has a position ``X_i`` and a velocity ``V_i`` in ``R^dims``. One iteration is

.. math::

    V_i(k+1) = w V_i(k) + c_1 r_1 (P_{i,best}(k) - X_i(k)) + c_2 r_2 (G_{best}(k) - X_i(k))   (4)

    X_i(k+1) = X_i(k) + V_i(k+1)                                                         (5)

with ``r_1, r_2 ~ U[0, 1]`` drawn per particle and per dimension. Two standard options the paper
does not need but long runs do: an inertia damping factor (``w`` is multiplied by ``w_damping``
after each iteration) and a velocity clamp (``|V| <= v_max`` per dimension). Positions are clipped
to the box ``[lower, upper]`` and the velocity component that pushed a particle out is zeroed.

The whole swarm is updated with array operations; the cost function receives the whole swarm,
``(n_particles, dims) -> (n_particles,)``, so it can be vectorised too.

**Blocks.** When the cost is a sum of terms over disjoint groups of coordinates (a long path cut
into windows of waypoints separated by fixed ones), each group can have a best of its own:
``minimize(..., blocks=K)`` splits the coordinates into ``K`` equal blocks, the cost returns
``(n_particles, K)`` and eqs. 4-5 run with ``P_best`` and ``G_best`` per block. That is ``K``
independent swarms of low dimension updated in one array operation, which converge far faster
than one swarm over all the coordinates (cooperative PSO; van den Bergh and Engelbrecht, IEEE
TEC 2004). ``blocks=1`` is the ordinary swarm, draw for draw.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...params import Rule, declared, param

__all__ = ["SWARM_PARAMS", "PSOOptions", "PSOResult", "minimize"]

CostFunction = Callable[[np.ndarray], np.ndarray]


@declared(rules=[Rule(("c1", "c2"), lambda c1, c2: c1 + c2 < 4.0, "c1 + c2 < 4 (paper Table 2)")])
class PSOOptions:
    """Settings of the particle swarm (paper Table 2, plus early stopping and inertia damping)."""

    swarm_size: int = param(
        30, "Number of particles (candidate paths) in the swarm.", low=2, high=10_000
    )
    iterations: int = param(
        100, "PSO iterations per optimisation round (eqs. 4-5).", low=0, high=1_000_000
    )
    w: float = param(0.7298, "Inertia weight of the particle velocity (eq. 4).", low=0.0, high=1.5)
    c1: float = param(
        1.49618,
        "Cognitive coefficient: pull to the particle's best (eq. 4); c1 + c2 < 4.",
        low=0.0,
        high=4.0,
    )
    c2: float = param(
        1.49618,
        "Social coefficient: pull to the swarm's best (eq. 4); c1 + c2 < 4.",
        low=0.0,
        high=4.0,
    )
    tolerance: float = param(
        1e-6,
        "End a PSO round early when the best cost improved by less than this (relative) over "
        "`patience` iterations; 0 = always run all iterations.",
        low=0.0,
        high=1.0,
    )
    patience: int = param(15, "Window of the early stop, in iterations.", low=1, high=1_000_000)
    w_damping: float = param(
        1.0, "Factor applied to w after every iteration (1 = constant).", low=1e-6, high=1.0
    )


#: The swarm's parameters, as :class:`PSOOptions` declares them.
SWARM_PARAMS = PSOOptions.PARAMS


@dataclass(frozen=True)
class PSOResult:
    """Outcome of :func:`minimize`.

    Attributes
    ----------
    position : ndarray, shape (dims,)
        The global best position ``G_best`` (with blocks: each block's best, side by side).
    cost : float
        Its cost (with blocks: the sum of the blocks' best costs).
    history : ndarray, shape (n_iterations + 1,)
        Best cost after initialisation and after each iteration (never increasing).
    n_iterations : int
        Iterations performed.
    n_evaluations : int
        Particle evaluations (swarm size times the number of cost calls).
    time : float
        Wall-clock seconds.
    stopped_by : str
        ``"iterations"``, ``"tolerance"``, ``"terminate"`` or ``"deadline"``.
    """

    position: np.ndarray
    cost: float
    history: np.ndarray = field(repr=False)
    n_iterations: int
    n_evaluations: int
    time: float
    stopped_by: str


def minimize(
    cost: CostFunction,
    lower: np.ndarray,
    upper: np.ndarray,
    options: PSOOptions,
    rng: np.random.Generator,
    *,
    init: np.ndarray | None = None,
    init_velocity: np.ndarray | None = None,
    v_max: float | None = None,
    terminate: Callable[[], bool] | None = None,
    blocks: int = 1,
    deadline: float | None = None,
) -> PSOResult:
    """Minimise ``cost`` over the box ``[lower, upper]`` with a global-best PSO.

    Parameters
    ----------
    cost : callable
        ``cost(X)`` with ``X`` of shape ``(n_particles, dims)`` returns ``(n_particles,)`` costs.
    lower, upper : (dims,) array_like
        Box bounds of the positions.
    options : PSOOptions
        Swarm settings.
    rng : numpy.random.Generator
        The only source of randomness (``r_1``, ``r_2`` and the initial swarm).
    init : (n_particles, dims) array_like, optional
        Initial positions; uniform in the box when omitted. Its rows are clipped to the box.
    init_velocity : (n_particles, dims) array_like, optional
        Initial velocities; zero when omitted (the paper's step 1 draws them; zero is standard
        when the swarm is seeded around a known solution, as RRT*PSO's is).
    v_max : float, optional
        Velocity clamp per dimension (``|V| <= v_max``), in the unit of the positions, derived
        by the caller from the problem's scale; None for no clamp.
    terminate : callable, optional
        Polled once per iteration; the run stops when it returns True (e.g. OMPL's
        ``PlannerTerminationCondition``).
    blocks : int
        Independent blocks of ``dims / blocks`` coordinates (see the module docstring); the cost
        then returns ``(n_particles, blocks)``.
    deadline : float, optional
        ``time.perf_counter()`` seconds: the run stops before an iteration whose evaluation, as
        long as the last one, would end after it; the first evaluation, and those near the end,
        go a few particles at a time and stop between them (an evaluation cannot be
        interrupted, and its cost varies with where the particles went).

    Returns
    -------
    PSOResult
    """
    t0 = time.perf_counter()
    lower, upper = _checked_box(lower, upper, blocks, v_max)
    x, v = _initial_swarm(lower, upper, options.swarm_size, rng, init, init_velocity)

    def evaluate(pos: np.ndarray) -> np.ndarray:
        return np.asarray(cost(pos), dtype=float).reshape(len(pos), blocks)

    f, cut, t_eval = _first_evaluation(evaluate, x, deadline)
    best = _Bests.start(x, f, blocks)
    history = [best.cost]
    stopped_by = "deadline"
    if not cut:
        stopped_by = _iterate(evaluate, x, v, best, history, options, rng, (lower, upper, v_max),
                              (terminate, deadline, t_eval))  # fmt: skip
    return PSOResult(
        position=best.gbest_x,
        cost=best.cost,
        history=np.asarray(history),
        n_iterations=len(history) - 1,
        n_evaluations=len(x) * len(history),  # the first swarm, then one per iteration
        time=time.perf_counter() - t0,
        stopped_by=stopped_by,
    )


def _checked_box(lower, upper, blocks: int, v_max: float | None):
    """``(lower, upper)`` as float arrays, once ``blocks`` and ``v_max`` are checked."""
    lower = np.asarray(lower, dtype=float)
    upper = np.asarray(upper, dtype=float)
    dims = lower.shape[0]
    if blocks < 1 or dims % blocks:
        raise ValueError(f"blocks must divide the {dims} dimensions, got {blocks}")
    if v_max is not None and not v_max > 0:
        raise ValueError(f"v_max must be > 0 or None, got {v_max}")
    return lower, upper


def _first_evaluation(evaluate, x: np.ndarray, deadline: float | None):
    """The first swarm's costs, whether the deadline cut it short, and its seconds."""
    t_eval = time.perf_counter()
    cut = False
    if deadline is None:
        f = evaluate(x)
    else:
        f, cut = _costs(evaluate, x, deadline)
    return f, cut, time.perf_counter() - t_eval


def _iterate(evaluate, x, v, best: _Bests, history: list, options: PSOOptions, rng, box,
             stop) -> str:  # fmt: skip
    """The iterations of eqs. 4-5 after the first evaluation, appending each iteration's best
    cost to ``history``; returns why they stopped. ``box = (lower, upper, v_max)``, ``stop =
    (terminate, deadline, seconds the last evaluation took)``."""
    lower, upper, v_max = box
    terminate, deadline, t_eval = stop
    w = options.w
    for k in range(1, options.iterations + 1):
        if terminate is not None and terminate():
            return "terminate"
        now = time.perf_counter()
        if deadline is not None and now + t_eval > deadline:
            return "deadline"
        x, v = _move(x, v, best, w, options, rng, lower, upper, v_max)
        # Near the end, in chunks: an evaluation's cost varies with where the particles went
        # (a segment cutting obstacles costs far more to measure), and the last one may be no
        # guide to the next (a swarm over a 1024 x 1024 map's path overran by 0.3 s).
        near_end = deadline is not None and now + NEAR_END_EVALUATIONS * t_eval > deadline
        f, cut = _costs(evaluate, x, deadline) if near_end else (evaluate(x), False)
        t_eval = time.perf_counter() - now
        best.update(x, f)
        history.append(best.cost)
        if cut:
            return "deadline"
        w *= options.w_damping
        if _converged(history, options, k):
            return "tolerance"
    return "iterations"


def _initial_swarm(lower, upper, n: int, rng, init, init_velocity):
    """Positions (``init`` clipped to the box, or uniform in it) and velocities (``init_velocity``
    or zero) of ``n`` particles."""
    dims = lower.shape[0]
    if init is None:
        x = rng.uniform(lower, upper, size=(n, dims))
    else:
        x = np.clip(np.asarray(init, dtype=float).reshape(n, dims), lower, upper)
    v = np.zeros((n, dims)) if init_velocity is None else np.asarray(init_velocity, float).copy()
    return x, v


def _move(x, v, best: _Bests, w: float, options: PSOOptions, rng, lower, upper, v_max):
    """One step of every particle: eqs. 4-5, the velocity clamped to ``v_max``, positions clipped
    to the box (a particle stopped by the wall keeps no momentum into it)."""
    n, dims = x.shape
    r1 = rng.random((n, dims))
    r2 = rng.random((n, dims))
    v = w * v + options.c1 * r1 * (best.pbest_x - x) + options.c2 * r2 * (best.gbest_x - x)  # eq. 4
    if v_max is not None:
        np.clip(v, -v_max, v_max, out=v)
    x = x + v  # eq. 5
    out = (x < lower) | (x > upper)
    if out.any():
        np.clip(x, lower, upper, out=x)
        v[out] = 0.0
    return x, v


def _converged(history: list[float], options: PSOOptions, k: int) -> bool:
    """Whether the best cost fell by at most ``tolerance`` (relative) over ``patience`` steps."""
    if options.tolerance <= 0 or k < options.patience:
        return False
    old = history[-1 - options.patience]
    return old - history[-1] <= options.tolerance * max(abs(old), 1e-300)


@dataclass
class _Bests:
    """Each particle's best position and costs per block, and the swarm's best per block (the
    blocks are independent: each takes its best coordinates from whichever particle has them)."""

    pbest_x: np.ndarray
    pbest_f: np.ndarray
    gbest_x: np.ndarray
    gbest_f: np.ndarray

    @classmethod
    def start(cls, x: np.ndarray, f: np.ndarray, blocks: int) -> _Bests:
        cols = np.arange(blocks)
        g = np.argmin(f, axis=0)
        gbest_x = _by_block(x, blocks)[g, cols].reshape(x.shape[1])  # a copy (fancy indexing)
        return cls(x.copy(), f.copy(), gbest_x, f[g, cols].copy())

    @property
    def cost(self) -> float:
        return float(self.gbest_f.sum())

    def update(self, x: np.ndarray, f: np.ndarray) -> None:
        blocks = f.shape[1]
        cols = np.arange(blocks)
        better = f < self.pbest_f
        self.pbest_f[better] = f[better]
        _by_block(self.pbest_x, blocks)[better] = _by_block(x, blocks)[better]
        g = np.argmin(self.pbest_f, axis=0)
        improved = self.pbest_f[g, cols] < self.gbest_f
        if improved.any():
            gb = self.gbest_x.reshape(blocks, -1)
            gb[improved] = _by_block(self.pbest_x, blocks)[g[improved], cols[improved]]
            self.gbest_f[improved] = self.pbest_f[g[improved], cols[improved]]


def _by_block(a: np.ndarray, blocks: int) -> np.ndarray:
    """``(n, dims)`` viewed as ``(n, blocks, dims / blocks)``."""
    return a.reshape(a.shape[0], blocks, -1)


#: Particles evaluated first when a swarm with a deadline evaluates in chunks (the seed and one
#: drawn particle: a drawn particle's segments may cut obstacles, whose exact violation costs far
#: more than the seed's check); later chunks double, up to :data:`_MAX_CHUNK`.
_FIRST_CHUNK = 2
_MAX_CHUNK = 8

#: An iteration evaluates in chunks (:func:`_costs`) once the deadline is within this many of
#: the last evaluation's durations (an evaluation may cost ten times the last one when the
#: particles move onto obstacles; cheap ones are chunked only in their last milliseconds).
NEAR_END_EVALUATIONS = 20.0


def _costs(cost: CostFunction, x: np.ndarray, deadline: float) -> tuple[np.ndarray, bool]:
    """The swarm's costs, a few particles at a time, and whether they were cut short (``inf``,
    never a best, for the rest) because the next chunk, at the last one's cost per particle,
    would end after ``deadline``: this bounds how far an evaluation can overrun by about one
    particle's evaluation. Particle 0 (the seed, when there is one) comes first. The costs are
    those of one call: each particle's depends on it alone."""
    parts: list[np.ndarray] = []
    c0, size = 0, _FIRST_CHUNK
    while c0 < len(x):  # at most len(x) chunks
        t = time.perf_counter()
        parts.append(cost(x[c0 : c0 + size]))
        now = time.perf_counter()
        per_particle = (now - t) / len(parts[-1])
        c0, size = c0 + size, min(2 * size, _MAX_CHUNK)
        if c0 < len(x) and now + per_particle * min(size, len(x) - c0) > deadline:
            parts.append(np.full((len(x) - c0, parts[0].shape[1]), np.inf))
            return np.concatenate(parts), True
    return np.concatenate(parts), False
