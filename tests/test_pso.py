"""The particle swarm (paper eqs. 4-5): convergence, the update rule itself, bounds, seeding."""

from __future__ import annotations

import numpy as np
import pytest

from rrtpso_ompl.pso import PSOOptions, minimize


def sphere(x):
    return np.sum((x - 1.5) ** 2, axis=1)


def test_converges_on_a_shifted_sphere():
    res = minimize(
        sphere,
        -5 * np.ones(5),
        5 * np.ones(5),
        PSOOptions(iterations=300),
        np.random.default_rng(0),
    )
    assert np.allclose(res.position, 1.5, atol=1e-3)
    assert res.cost < 1e-5
    assert res.n_iterations == 300 and len(res.history) == 301
    assert np.all(np.diff(res.history) <= 0)  # the global best never gets worse
    assert res.n_evaluations == 30 * 301


def test_cost_gets_the_whole_swarm_and_positions_stay_in_the_box():
    seen = []

    def cost(x):
        seen.append(x.copy())
        return sphere(x) + 10 * x[:, 0]  # pushes x0 against its lower bound

    lo, hi = np.array([-1.0, 0.0, 0.0]), np.array([1.0, 2.0, 3.0])
    minimize(cost, lo, hi, PSOOptions(swarm_size=12, iterations=40), np.random.default_rng(1))
    assert all(x.shape == (12, 3) for x in seen)
    stacked = np.concatenate(seen)
    assert np.all(stacked >= lo) and np.all(stacked <= hi)
    assert stacked[:, 0].min() == -1.0  # reached the wall, was clipped to it


def test_same_seed_same_result_and_different_seed_differs():
    opts = PSOOptions(iterations=5)  # not converged yet, so different seeds must differ
    lo, hi = -3 * np.ones(4), 3 * np.ones(4)
    a = minimize(sphere, lo, hi, opts, np.random.default_rng(5))
    b = minimize(sphere, lo, hi, opts, np.random.default_rng(5))
    c = minimize(sphere, lo, hi, opts, np.random.default_rng(6))
    assert np.array_equal(a.position, b.position) and np.array_equal(a.history, b.history)
    assert not np.array_equal(a.position, c.position)


def test_terminate_is_polled_every_iteration():
    calls = {"n": 0}

    def stop_after_three():
        calls["n"] += 1
        return calls["n"] > 3

    res = minimize(
        sphere,
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=100),
        np.random.default_rng(0),
        terminate=stop_after_three,
    )
    assert res.n_iterations == 3 and res.stopped_by == "terminate"
    res = minimize(
        sphere,
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=100),
        np.random.default_rng(0),
        terminate=lambda: True,
    )
    assert res.n_iterations == 0 and len(res.history) == 1


def test_early_stop_on_tolerance():
    res = minimize(
        lambda x: np.zeros(len(x)),
        -np.ones(2),
        np.ones(2),
        PSOOptions(iterations=500, tolerance=1e-9, patience=10),
        np.random.default_rng(0),
    )
    assert res.stopped_by == "tolerance" and res.n_iterations == 10


class HalfRNG:
    """A stand-in generator whose r1 = r2 = 0.5, to check the update rule by hand."""

    def random(self, shape):
        return np.full(shape, 0.5)


def test_one_iteration_is_eqs_4_and_5():
    x0 = np.array([[0.0, 0.0], [2.0, 1.0], [-1.0, 3.0]])
    v0 = np.array([[0.1, -0.2], [0.0, 0.3], [0.2, 0.2]])
    opts = PSOOptions(swarm_size=3, iterations=1, w=0.6, c1=1.2, c2=1.8)
    seen = []

    def cost(x):
        seen.append(x.copy())
        return np.sum(x**2, axis=1)

    minimize(cost, -10 * np.ones(2), 10 * np.ones(2), opts, HalfRNG(), init=x0, init_velocity=v0)
    pbest = x0  # after initialisation every particle's best is where it is
    gbest = x0[0]  # cost 0: the best of the three
    v1 = 0.6 * v0 + 1.2 * 0.5 * (pbest - x0) + 1.8 * 0.5 * (gbest - x0)  # eq. 4
    assert np.allclose(seen[1], x0 + v1)  # eq. 5


def test_velocity_clamp():
    seen = []

    def cost(x):
        seen.append(x.copy())
        return -x[:, 0]  # run to the right as fast as allowed

    minimize(
        cost,
        np.zeros(1),
        np.full(1, 100.0),
        PSOOptions(swarm_size=4, iterations=5, v_max=0.5),
        np.random.default_rng(0),
        init=np.zeros((4, 1)),
    )
    steps = np.abs(np.diff(np.stack(seen), axis=0))
    assert steps.max() <= 0.5 + 1e-12


@pytest.mark.parametrize(
    "kwargs",
    [
        {"swarm_size": 1},
        {"iterations": -1},
        {"w": 2.0},
        {"c1": 2.0, "c2": 2.0},
        {"c1": -0.1},
        {"w_damping": 0.0},
        {"v_max": 0.0},
        {"patience": 0},
    ],
    ids=lambda k: ",".join(k),
)
def test_options_are_validated(kwargs):
    with pytest.raises(ValueError):
        PSOOptions(**kwargs)
