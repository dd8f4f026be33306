"""The particle swarm (paper eqs. 4-5): convergence, the update rule itself, bounds, seeding,
termination and the validation of its options."""

from __future__ import annotations

import numpy as np
import pytest

from rrtpso_ompl.errors import ParameterError
from rrtpso_ompl.planners.pso.swarm import SWARM_PARAMS, PSOOptions, minimize


def sphere(x):
    return np.sum(x**2, axis=1)


SHIFT = np.array([1.5, -2.0, 0.25])
WEIGHTS = np.array([1.0, 4.0, 0.5])


def shifted_quadratic(x):
    """An anisotropic quadratic with its minimum 3.0 at SHIFT."""
    return np.sum(WEIGHTS * (x - SHIFT) ** 2, axis=1) + 3.0


class ConstRNG:
    """A stand-in generator: ``random`` returns a constant (so r1 = r2 = value) and ``uniform``
    the middle of the box, so the update can be replayed by hand."""

    def __init__(self, value: float = 0.5) -> None:
        self.value = value

    def random(self, shape):
        return np.full(shape, self.value)

    def uniform(self, low, high, size):
        return np.broadcast_to(0.5 * (np.asarray(low) + np.asarray(high)), size).copy()


def recording(cost):
    """Wrap ``cost`` to record a copy of every swarm it is called with."""
    seen: list[np.ndarray] = []

    def wrapped(x):
        seen.append(np.array(x, copy=True))
        return cost(x)

    return wrapped, seen


# ----------------------------------------------------------------------------------------------
# Convergence and bookkeeping
# ----------------------------------------------------------------------------------------------
def test_converges_on_the_sphere_in_5d():
    res = minimize(
        sphere,
        -5 * np.ones(5),
        5 * np.ones(5),
        PSOOptions(iterations=300),
        np.random.default_rng(0),
    )
    assert np.allclose(res.position, 0.0, atol=1e-3)
    assert res.cost < 1e-6
    assert res.cost == pytest.approx(float(sphere(res.position[None])[0]))
    assert res.n_iterations == 300 and len(res.history) == 301
    assert res.history[-1] == res.cost
    assert np.all(np.diff(res.history) <= 0)  # the global best never gets worse
    assert res.n_evaluations == 30 * 301
    assert res.stopped_by == "iterations"
    assert res.time >= 0


def test_converges_on_a_shifted_anisotropic_quadratic():
    res = minimize(
        shifted_quadratic,
        -5 * np.ones(3),
        5 * np.ones(3),
        PSOOptions(swarm_size=20, iterations=200),
        np.random.default_rng(1),
    )
    assert np.allclose(res.position, SHIFT, atol=1e-3)
    assert res.cost == pytest.approx(3.0, abs=1e-6)
    assert res.cost >= 3.0
    assert np.all(np.diff(res.history) <= 0) and len(res.history) == res.n_iterations + 1


def test_optimum_on_the_boundary_of_the_box():
    """The unconstrained minimum (1.5, ...) lies outside [-1, 1]: the best is the corner."""
    res = minimize(
        lambda x: np.sum((x - 1.5) ** 2, axis=1),
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=100),
        np.random.default_rng(2),
    )
    assert np.allclose(res.position, 1.0, atol=1e-9)


def test_zero_iterations_returns_the_best_initial_particle():
    init = np.array([[3.0, 3.0], [0.5, -0.5], [-2.0, 1.0]])
    cost, seen = recording(sphere)
    res = minimize(
        cost,
        -5 * np.ones(2),
        5 * np.ones(2),
        PSOOptions(swarm_size=3, iterations=0),
        np.random.default_rng(0),
        init=init,
    )
    assert len(seen) == 1 and np.array_equal(seen[0], init)
    assert np.array_equal(res.position, init[1]) and res.cost == 0.5
    assert res.n_iterations == 0 and len(res.history) == 1 and res.n_evaluations == 3


def test_init_is_clipped_to_the_box():
    cost, seen = recording(sphere)
    init = np.array([[-9.0, 0.0], [0.0, 9.0]])
    minimize(
        cost,
        -np.ones(2),
        np.ones(2),
        PSOOptions(swarm_size=2, iterations=0),
        np.random.default_rng(0),
        init=init,
    )
    assert np.array_equal(seen[0], [[-1.0, 0.0], [0.0, 1.0]])


# ----------------------------------------------------------------------------------------------
# Randomness
# ----------------------------------------------------------------------------------------------
def test_same_seed_same_result_and_different_seed_differs():
    opts = PSOOptions(iterations=5)  # not converged yet, so different seeds must differ
    lo, hi = -3 * np.ones(4), 3 * np.ones(4)
    a = minimize(sphere, lo, hi, opts, np.random.default_rng(7))
    b = minimize(sphere, lo, hi, opts, np.random.default_rng(7))
    c = minimize(sphere, lo, hi, opts, np.random.default_rng(8))
    assert np.array_equal(a.position, b.position) and np.array_equal(a.history, b.history)
    assert a.cost == b.cost
    assert not np.array_equal(a.position, c.position)
    assert not np.array_equal(a.history, c.history)


# ----------------------------------------------------------------------------------------------
# Termination
# ----------------------------------------------------------------------------------------------
def test_terminate_true_at_once_runs_no_iteration():
    cost, seen = recording(sphere)
    res = minimize(
        cost,
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=100),
        np.random.default_rng(0),
        terminate=lambda: True,
    )
    assert res.n_iterations == 0 and len(res.history) == 1 and res.stopped_by == "terminate"
    assert len(seen) == 1  # only the initial swarm was evaluated


@pytest.mark.parametrize("n", [1, 3, 17])
def test_terminate_is_polled_once_per_iteration(n):
    calls = {"n": 0}

    def stop_after_n():
        calls["n"] += 1
        return calls["n"] > n

    cost, seen = recording(sphere)
    res = minimize(
        cost,
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=100),
        np.random.default_rng(0),
        terminate=stop_after_n,
    )
    assert res.n_iterations == n and res.stopped_by == "terminate"
    assert calls["n"] == n + 1
    assert len(seen) == n + 1 and len(res.history) == n + 1
    assert res.n_evaluations == 30 * (n + 1)


def test_terminate_never_true_runs_all_iterations():
    calls = {"n": 0}

    def never():
        calls["n"] += 1
        return False

    res = minimize(
        sphere,
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=12),
        np.random.default_rng(0),
        terminate=never,
    )
    assert res.n_iterations == 12 and calls["n"] == 12 and res.stopped_by == "iterations"


def test_early_stop_on_a_flat_cost():
    res = minimize(
        lambda x: np.zeros(len(x)),
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=500, tolerance=1e-9, patience=10),
        np.random.default_rng(0),
    )
    assert res.stopped_by == "tolerance" and res.n_iterations == 10


def test_early_stop_waits_while_the_cost_still_improves():
    """A cost that improves by a factor of 2 every call never triggers a 1e-3 tolerance."""
    calls = {"n": 0}

    def halving(x):
        calls["n"] += 1
        return np.full(len(x), 2.0 ** -calls["n"])

    res = minimize(
        halving,
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=40, tolerance=1e-3, patience=5),
        np.random.default_rng(0),
    )
    assert res.stopped_by == "iterations" and res.n_iterations == 40


def test_early_stop_on_the_sphere_is_near_the_optimum():
    res = minimize(
        sphere,
        -5 * np.ones(3),
        5 * np.ones(3),
        PSOOptions(iterations=5000, tolerance=1e-6, patience=20),
        np.random.default_rng(3),
    )
    assert res.stopped_by == "tolerance" and res.n_iterations < 5000
    # Stopped because the last `patience` iterations improved by at most the relative tolerance.
    old, new = res.history[-21], res.history[-1]
    assert old - new <= 1e-6 * abs(old)
    assert res.cost < 1e-3


# ----------------------------------------------------------------------------------------------
# Shapes and bounds
# ----------------------------------------------------------------------------------------------
def test_cost_gets_the_whole_swarm_and_positions_stay_in_the_box():
    cost, seen = recording(lambda x: sphere(x - 1.0) + 10 * x[:, 0])  # pushes x0 to its wall
    lo, hi = np.array([-1.0, 0.0, 0.0]), np.array([1.0, 2.0, 3.0])
    res = minimize(cost, lo, hi, PSOOptions(swarm_size=12, iterations=40), np.random.default_rng(1))
    assert len(seen) == 41
    assert all(x.shape == (12, 3) for x in seen)
    stacked = np.concatenate(seen)
    assert np.all(stacked >= lo) and np.all(stacked <= hi)
    assert stacked[:, 0].min() == -1.0  # reached the wall, was clipped to it exactly
    assert np.all(res.position >= lo) and np.all(res.position <= hi)


def test_velocity_clamp():
    cost, seen = recording(lambda x: -x[:, 0])  # run to the right as fast as allowed
    minimize(
        cost,
        np.zeros(1),
        np.full(1, 100.0),
        PSOOptions(swarm_size=4, iterations=5),
        np.random.default_rng(0),
        init=np.array([[0.0], [10.0], [20.0], [30.0]]),  # the best pulls the others hard
        v_max=0.5,
    )
    steps = np.abs(np.diff(np.stack(seen), axis=0))
    assert steps.max() <= 0.5 + 1e-12
    assert steps.max() == pytest.approx(0.5)  # and the clamp is actually reached


# ----------------------------------------------------------------------------------------------
# The update rule
# ----------------------------------------------------------------------------------------------
def test_one_iteration_is_eqs_4_and_5():
    x0 = np.array([[0.0, 0.0], [2.0, 1.0], [-1.0, 3.0]])
    v0 = np.array([[0.1, -0.2], [0.0, 0.3], [0.2, 0.2]])
    opts = PSOOptions(swarm_size=3, iterations=1, w=0.6, c1=1.2, c2=1.8)
    cost, seen = recording(sphere)
    res = minimize(
        cost, -10 * np.ones(2), 10 * np.ones(2), opts, ConstRNG(), init=x0, init_velocity=v0
    )
    pbest = x0  # after initialisation every particle's best is where it is
    gbest = x0[0]  # cost 0: the best of the three
    v1 = 0.6 * v0 + 1.2 * 0.5 * (pbest - x0) + 1.8 * 0.5 * (gbest - x0)  # eq. 4
    assert len(seen) == 2
    assert np.allclose(seen[1], x0 + v1, rtol=0, atol=1e-15)  # eq. 5
    assert res.n_iterations == 1


def test_uniform_initialisation_uses_the_rng():
    cost, seen = recording(sphere)
    lo, hi = np.array([-2.0, 4.0]), np.array([6.0, 8.0])
    minimize(cost, lo, hi, PSOOptions(swarm_size=4, iterations=0), ConstRNG())
    assert np.array_equal(seen[0], np.tile([2.0, 6.0], (4, 1)))


def reference_pso(cost, lo, hi, opts: PSOOptions, v_max, x, v, r: float, iterations: int):
    """Eqs. 4-5 with inertia damping, velocity clamp and walls, replayed by hand with constant
    r1 = r2 = r. Returns the swarm at every evaluation."""
    x, v = x.copy(), v.copy()
    f = cost(x)
    pbest_x, pbest_f = x.copy(), f.copy()
    g = int(np.argmin(f))
    gbest_x, gbest_f = x[g].copy(), f[g]
    w = opts.w
    swarms = [x.copy()]
    for _ in range(iterations):
        v = w * v + opts.c1 * r * (pbest_x - x) + opts.c2 * r * (gbest_x - x)
        if v_max is not None:
            v = np.clip(v, -v_max, v_max)
        x = x + v
        for i in range(x.shape[0]):
            for j in range(x.shape[1]):
                if x[i, j] < lo[j] or x[i, j] > hi[j]:
                    x[i, j] = min(max(x[i, j], lo[j]), hi[j])
                    v[i, j] = 0.0
        f = cost(x)
        for i in range(len(f)):
            if f[i] < pbest_f[i]:
                pbest_x[i], pbest_f[i] = x[i].copy(), f[i]
                if f[i] < gbest_f:
                    gbest_x, gbest_f = x[i].copy(), f[i]
        swarms.append(x.copy())
        w *= opts.w_damping
    return swarms


def test_several_iterations_match_a_hand_written_reference():
    """Damping, velocity clamp and the wall (position clipped, velocity zeroed) over 8 steps."""
    rng = np.random.default_rng(4)
    x0 = rng.uniform(-1, 1, (5, 2))
    v0 = rng.uniform(-0.5, 0.5, (5, 2))
    lo, hi = np.array([-1.0, -1.0]), np.array([1.0, 1.0])
    opts = PSOOptions(swarm_size=5, iterations=8, w=0.9, c1=1.0, c2=2.5, w_damping=0.8, tolerance=0)
    v_max = 0.7

    def cost(x):
        return np.sum((x - np.array([3.0, 0.2])) ** 2, axis=1)  # pulls everyone into the wall

    wrapped, seen = recording(cost)
    minimize(wrapped, lo, hi, opts, ConstRNG(0.37), init=x0, init_velocity=v0, v_max=v_max)
    expected = reference_pso(cost, lo, hi, opts, v_max, x0, v0, 0.37, 8)
    assert len(seen) == len(expected) == 9
    for got, want in zip(seen, expected, strict=True):
        assert np.allclose(got, want, rtol=0, atol=1e-12)
    assert np.any(np.stack(seen)[:, :, 0] == 1.0)  # the wall was actually hit


# ----------------------------------------------------------------------------------------------
# Options
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs",
    [
        {"swarm_size": 1},
        {"swarm_size": 0},
        {"iterations": -1},
        {"w": -0.1},
        {"w": 1.6},
        {"c1": 2.0, "c2": 2.0},
        {"c1": 3.0, "c2": 1.5},
        {"c1": -0.1},
        {"c2": -0.1},
        {"w_damping": 0.0},
        {"w_damping": 1.01},
        {"tolerance": -1e-9},
        {"patience": 0},
    ],
    ids=lambda k: ",".join(f"{key}={val}" for key, val in k.items()),
)
def test_invalid_options_are_rejected(kwargs):
    with pytest.raises(ParameterError):
        PSOOptions(**kwargs)


@pytest.mark.parametrize("v_max", [0.0, -1.0, float("nan")])
def test_invalid_velocity_clamp_is_rejected(v_max):
    with pytest.raises(ValueError, match="v_max"):
        minimize(
            lambda x: x.sum(axis=1),
            np.zeros(1),
            np.ones(1),
            PSOOptions(),
            np.random.default_rng(0),
            v_max=v_max,
        )


def test_options_defaults_are_the_declared_ones():
    """One declaration per parameter: the options class takes its defaults from the table."""
    assert PSOOptions().swarm_size == SWARM_PARAMS["swarm_size"].default
    assert {f: getattr(PSOOptions(), f) for f in SWARM_PARAMS.names()} == SWARM_PARAMS.defaults()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"swarm_size": 2},
        {"iterations": 0},
        {"w": 0.0},
        {"w": 1.5},
        {"c1": 1.99, "c2": 2.0},
        {"c1": 0.0, "c2": 0.0},
        {"w_damping": 1.0},
        {"w_damping": 1e-3},
        {"tolerance": 0.0, "patience": 1},
    ],
    ids=lambda k: ",".join(f"{key}={val}" for key, val in k.items()),
)
def test_valid_edge_options_are_accepted(kwargs):
    opts = PSOOptions(**kwargs)
    for key, val in kwargs.items():
        assert getattr(opts, key) == val


def test_options_are_keyword_only_and_frozen():
    with pytest.raises(TypeError):
        PSOOptions(30)  # type: ignore[misc]
    opts = PSOOptions()
    with pytest.raises(AttributeError):
        opts.w = 0.5  # type: ignore[misc]


def test_a_deadline_stops_the_swarm_before_an_evaluation_that_would_end_after_it():
    """An evaluation cannot be interrupted (near a detailed polygon one can take a sizeable share
    of a short budget): the swarm does not start one that, as long as the last, would end after
    the deadline. Here each evaluation takes 0.2 s and 0.3 s are left after the first."""
    import time

    def slow(x):
        time.sleep(0.2)
        return sphere(x)

    opts = PSOOptions(swarm_size=4, iterations=50, tolerance=0.0)
    lo, hi = -np.ones(2), np.ones(2)
    rng = np.random.default_rng(0)
    res = minimize(slow, lo, hi, opts, rng, deadline=time.perf_counter() + 0.3)
    assert res.stopped_by == "deadline" and res.n_iterations <= 1
    # Without a deadline the same swarm runs its iterations (a cheap cost here).
    full = minimize(sphere, lo, hi, opts, np.random.default_rng(0))
    assert full.n_iterations == 50


def test_the_first_evaluation_of_a_swarm_with_a_deadline_stops_between_particles():
    """Nothing is measured before the first evaluation: it runs a few particles at a time (the
    seed and one drawn particle first) and leaves the rest unevaluated (never the best) when the
    next few would end too late."""
    import time

    calls = []

    def slow(x):
        calls.append(len(x))
        time.sleep(0.2)
        return sphere(x)

    opts = PSOOptions(swarm_size=30, iterations=50)
    lo, hi = -np.ones(2), np.ones(2)
    init = np.zeros((30, 2))
    init[1:] = 0.5
    res = minimize(slow, lo, hi, opts, np.random.default_rng(0), init=init,
                   deadline=time.perf_counter() + 0.3)  # fmt: skip
    assert calls == [2] and res.stopped_by == "deadline" and res.n_iterations == 0
    assert res.cost == 0.0 and np.array_equal(res.position, [0.0, 0.0])  # the seed particle
    # Costs come out the same whether the swarm is evaluated at once or in parts.
    a = minimize(sphere, lo, hi, opts, np.random.default_rng(3), deadline=time.perf_counter() + 60)
    b = minimize(sphere, lo, hi, opts, np.random.default_rng(3))
    assert a.cost == b.cost and np.array_equal(a.history, b.history)


def test_blocks_are_independent_swarms_that_beat_one_swarm_over_everything():
    """A separable cost: 12 blocks of 2 coordinates each with its own minimum. Per-block bests
    reach every minimum; one swarm over all 24 coordinates, same evaluations, does worse."""
    from rrtpso_ompl.planners.pso.swarm import PSOOptions, minimize

    k, d = 12, 2
    target = np.random.default_rng(0).uniform(-5, 5, size=(k, d))

    def per_block(x):
        return ((x.reshape(len(x), k, d) - target) ** 2).sum(axis=2)

    lo, hi = np.full(k * d, -10.0), np.full(k * d, 10.0)
    opts = PSOOptions(swarm_size=20, iterations=150, tolerance=0.0)
    split = minimize(per_block, lo, hi, opts, np.random.default_rng(1), blocks=k)
    whole = minimize(lambda x: per_block(x).sum(axis=1), lo, hi, opts, np.random.default_rng(1))
    assert split.cost < 1e-6
    assert split.cost < whole.cost
    assert np.allclose(split.position.reshape(k, d), target, atol=1e-3)
    assert np.all(np.diff(split.history) <= 0)  # the summed best never rises
    with pytest.raises(ValueError, match="blocks"):
        minimize(per_block, lo, hi, opts, np.random.default_rng(1), blocks=5)


def test_an_iteration_near_the_deadline_stops_between_particles(monkeypatch):
    """An evaluation's cost varies with where the particles went: near the end an iteration
    goes a few particles at a time, so one that turns slow stops between chunks (the costs
    measured count, the rest are never a best) instead of running past the deadline. The clock
    is the cost function's own: no machine's speed decides."""
    from rrtpso_ompl.planners.pso import swarm as swarm_module

    clock = [0.0]
    monkeypatch.setattr(swarm_module.time, "perf_counter", lambda: clock[0])
    calls = []

    def turning_slow(x):  # 0.1 ms a particle, then 10 ms once past 0.25 s
        calls.append(len(x))
        clock[0] += len(x) * (1e-4 if clock[0] < 0.25 else 1e-2)
        return sphere(x)

    opts = PSOOptions(swarm_size=30, iterations=10_000, tolerance=0.0)
    lo, hi = -np.ones(2), np.ones(2)
    res = minimize(turning_slow, lo, hi, opts, np.random.default_rng(0), deadline=0.3)
    assert res.stopped_by == "deadline"
    # Late by at most one chunk (of at most 8 particles) measured at the old speed.
    assert clock[0] <= 0.3 + swarm_module._MAX_CHUNK * 1e-2 + 1e-9
    assert swarm_module._FIRST_CHUNK in calls[1:]  # the iterations near the end went in chunks
    assert np.isfinite(res.cost) and res.n_iterations > 10
