"""States of R^n, SE(2), Dubins and Reeds-Shepp as numpy rows, and their distances in numpy:
equal to OMPL's own ``space.distance`` on thousands of random pairs (issue 35)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.errors import PlannerError, UnsupportedSpaceError
from rrtpso_ompl.ompl_setup.curves import reeds_shepp_lengths
from rrtpso_ompl.ompl_setup.spaces import (
    MAX_DIMENSION,
    DubinsAdapter,
    RealVectorAdapter,
    ReedsSheppAdapter,
    SE2Adapter,
    space_adapter,
    unsupported_space,
    wrap_angle,
)

PAIRS = 4000


def _bounded(space, n: int = 2, high: float = 10.0):
    bounds = ob.RealVectorBounds(n)
    bounds.setLow(0.0)
    bounds.setHigh(high)
    space.setBounds(bounds)
    return space


def _poses(rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Random pose pairs at every scale: far apart, within a turning radius, a hair apart, the
    same position, the same pose; yaws anywhere, some outside [-pi, pi)."""
    a = np.c_[rng.uniform(0, 10, (n, 2)), rng.uniform(-4, 4, n)]
    scale = rng.choice([1e-7, 0.01, 0.3, 1.0, 5.0], n)[:, None]
    b = np.c_[a[:, :2] + rng.normal(0, 1, (n, 2)) * scale, rng.uniform(-4, 4, n)]
    b[:40] = a[:40]  # the same pose
    b[40:80, :2] = a[40:80, :2]  # turning on the spot
    b[80:120, 2] = a[80:120, 2]  # the same heading
    return a, b


def _ompl_distances(adapter, a, b) -> np.ndarray:
    space = adapter.space
    sa, sb = space.allocState(), space.allocState()
    out = []
    for ra, rb in zip(a, b, strict=True):
        adapter.assign(sa, ra)
        adapter.assign(sb, rb)
        out.append(space.distance(sa, sb))
    return np.array(out)


SE2_LIKE = {
    "SE(2)": lambda: ob.SE2StateSpace(),
    "Dubins 0.3": lambda: ob.DubinsStateSpace(0.3),
    "Dubins 1.7": lambda: ob.DubinsStateSpace(1.7),
    "Dubins symmetric": lambda: ob.DubinsStateSpace(0.8, True),
    "Reeds-Shepp": lambda: ob.ReedsSheppStateSpace(0.6),
}


@pytest.mark.parametrize("kind", list(SE2_LIKE))
def test_se2_like_distances_equal_ompl_s(kind):
    adapter = space_adapter(_bounded(SE2_LIKE[kind]()))
    a, b = _poses(np.random.default_rng(7), PAIRS)
    mine = adapter.distances(a, b)
    theirs = _ompl_distances(adapter, a, b)
    assert np.all(np.isfinite(mine))
    np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-9)
    # Broadcasting: one pose against many, and (P, k) batches of paths.
    np.testing.assert_allclose(adapter.distances(a[0], b[:50]), _ompl_distances(
        adapter, np.broadcast_to(a[0], (50, 3)), b[:50]), rtol=0, atol=1e-9)  # fmt: skip
    paths = np.stack([a[:30], b[:30], a[30:60]], axis=1)  # (30, 3, 3)
    expected = theirs[:30] + _ompl_distances(adapter, b[:30], a[30:60])
    np.testing.assert_allclose(adapter.lengths(paths), expected, rtol=0, atol=1e-9)


def test_reeds_shepp_s_48_words_in_numpy_equal_ompl_s():
    """Not what the adapter uses (OMPL's loop is faster), but exact all the same."""
    adapter = space_adapter(_bounded(ob.ReedsSheppStateSpace(0.6)))
    a, b = _poses(np.random.default_rng(11), PAIRS)
    theirs = _ompl_distances(adapter, a, b)
    np.testing.assert_allclose(0.6 * reeds_shepp_lengths(a, b, 0.6), theirs, rtol=0, atol=1e-9)
    adapter.vectorised = True
    np.testing.assert_allclose(adapter.distances(a, b), theirs, rtol=0, atol=1e-9)


def test_the_kinds_and_what_is_numpy():
    assert type(space_adapter(_bounded(ob.SE2StateSpace()))) is SE2Adapter
    dubins = space_adapter(_bounded(ob.DubinsStateSpace(0.4, True)))
    assert type(dubins) is DubinsAdapter and dubins.vectorised and dubins.symmetric
    assert math.isclose(dubins.turning_radius, 0.4, rel_tol=1e-12)
    rs = space_adapter(_bounded(ob.ReedsSheppStateSpace(0.6)))
    assert type(rs) is ReedsSheppAdapter and not rs.vectorised
    assert math.isclose(rs.turning_radius, 0.6, rel_tol=1e-12)
    assert not space_adapter(_bounded(ob.DubinsStateSpace(0.4))).symmetric


def test_se2_honours_the_space_s_own_weights():
    space = _bounded(ob.SE2StateSpace())
    space.setSubspaceWeight(1, 2.5)
    adapter = space_adapter(space)
    assert adapter.weights == (1.0, 2.5)
    a, b = _poses(np.random.default_rng(3), 500)
    np.testing.assert_allclose(adapter.distances(a, b), _ompl_distances(adapter, a, b),
                               rtol=0, atol=1e-9)  # fmt: skip


@pytest.mark.parametrize("n", range(2, 11))
def test_real_vector_distances_and_rows(n):
    space = _bounded(ob.RealVectorStateSpace(n), n)
    adapter = space_adapter(space)
    assert type(adapter) is RealVectorAdapter and adapter.dim == n and adapter.vectorised
    rng = np.random.default_rng(n)
    a, b = rng.uniform(0, 10, (500, n)), rng.uniform(0, 10, (500, n))
    np.testing.assert_allclose(adapter.distances(a, b), _ompl_distances(adapter, a, b),
                               rtol=0, atol=1e-9)  # fmt: skip
    low, high = adapter.bounds()
    assert low.tolist() == [0.0] * n and high.tolist() == [10.0] * n


def test_rows_round_trip_exactly_through_a_path():
    spaces = ((_bounded(ob.DubinsStateSpace(1.0)), 3), (_bounded(ob.RealVectorStateSpace(4), 4), 4))
    for space, dim in spaces:
        si = ob.SpaceInformation(space)
        adapter = space_adapter(si)
        rows = np.random.default_rng(0).uniform(0, 3, (6, dim))
        path = adapter.array_to_path(si, rows)
        assert isinstance(path, og.PathGeometric) and path.getStateCount() == 6
        assert np.array_equal(adapter.path_to_array(path), rows)  # bit for bit
        assert math.isclose(adapter.length(rows), path.length(), rel_tol=1e-12)


def test_angles_wrap_as_ompl_wraps_them():
    so2 = ob.SO2StateSpace()
    s = so2.allocState()
    yaws = np.array([-7.0, -math.pi, -3.0, 0.0, 3.0, math.pi, 4.0, 9.5, 13.0])
    wrapped = []
    for y in yaws:
        s.value = float(y)
        so2.enforceBounds(s)
        wrapped.append(s.value)
    np.testing.assert_allclose(wrap_angle(yaws), wrapped, rtol=0, atol=1e-12)
    assert np.all((wrap_angle(yaws) >= -math.pi) & (wrap_angle(yaws) < math.pi))


def test_a_python_subclass_is_asked_for_its_own_distance():
    """A user's subclass may override ``distance``: the adapter then loops over it."""

    class Manhattan(ob.RealVectorStateSpace):
        def distance(self, a, b):
            return abs(a[0] - b[0]) + abs(a[1] - b[1]) + abs(a[2] - b[2])

    space = _bounded(Manhattan(3), 3)
    adapter = space_adapter(space)
    assert not adapter.vectorised
    assert adapter.distances(np.zeros(3), np.array([1.0, 2.0, 3.0])) == pytest.approx(6.0)


def _compound():
    space = ob.CompoundStateSpace()
    space.addSubspace(_bounded(ob.RealVectorStateSpace(2)), 1.0)
    space.addSubspace(ob.SO2StateSpace(), 0.5)
    return space


REFUSED = {
    "SE(3)": (lambda: _bounded(ob.SE3StateSpace(), 3), r"\(ob\.SE3StateSpace, 6 dimensions\)"),
    "SO(2)": (ob.SO2StateSpace, r"\(ob\.SO2StateSpace, 1 dimension\)"),
    "compound": (_compound, r"\(ob\.CompoundStateSpace, 3 dimensions\)"),
    "R^65": (lambda: ob.RealVectorStateSpace(MAX_DIMENSION + 1), r"RealVectorStateSpace\(65\)"),
}


@pytest.mark.parametrize("kind", list(REFUSED))
def test_other_spaces_are_refused_naming_them(kind):
    make, named = REFUSED[kind]
    space = make()
    said = unsupported_space(space)
    assert said is not None and space.getName() in said
    assert "ob.DubinsStateSpace" in said and "ob.ReedsSheppStateSpace" in said
    with pytest.raises(UnsupportedSpaceError, match=rf"^Thing: the state space .*{named}") as exc:
        space_adapter(ob.SpaceInformation(space), "Thing")
    assert isinstance(exc.value, PlannerError)
