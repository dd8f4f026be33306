"""The reference curve: the paper's polynomial and the certified spline or its polyline fallback."""

from __future__ import annotations

import numpy as np
from helpers import BOUNDS

from rrtpso_ompl.kinematics import reference_curve, reference_polynomial
from rrtpso_ompl.model.world import World


def test_reference_polynomial_recovers_a_cubic_and_refuses_non_functions():
    x = np.linspace(20, 450, 12)
    coef = [3.352e-06, -0.00284, 1.472, -15.67]  # the paper's eq. 6
    path = np.column_stack([x, np.polyval(coef, x)])
    assert np.allclose(reference_polynomial(path), coef, rtol=1e-6)
    assert reference_polynomial(np.array([[0, 0], [10, 5], [5, 10]])) is None


def test_reference_curve_is_certified_and_tightens_or_falls_back():
    world = World(BOUNDS, [(250, 250, 80)], [], robot_radius=28.5)
    path = np.array([[20, 20], [150, 330], [300, 420], [450, 450]], dtype=float)
    assert world.path_valid(path)
    curve = reference_curve(path, world)
    pts = np.column_stack([curve.x, curve.y])
    if curve.kind == "spline":
        assert world.segments_free(pts[:-1], pts[1:]).all()
        assert np.allclose(pts[0], path[0]) and np.allclose(pts[-1], path[-1])
    else:
        assert np.array_equal(pts, path)
    poly = reference_curve(path, world, smooth=False)  # the fallback
    assert poly.kind == "polyline" and np.count_nonzero(poly.turns) == 2
