"""Exact geometry: the closed forms against shapely, against dense sampling, and against each
other (the scalar checks OMPL calls and the vectorised checks the swarm calls)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rrtpso_ompl.world import World

BOUNDS = ((0.0, 0.0), (100.0, 100.0))
L_SHAPE = np.array([[40, 40], [70, 40], [70, 50], [50, 50], [50, 75], [40, 75]], dtype=float)

coord = st.floats(-10, 110, allow_nan=False)
point = st.tuples(coord, coord)


@st.composite
def convex_polygon(draw):
    cx, cy = draw(st.floats(15, 85)), draw(st.floats(15, 85))
    n = draw(st.integers(3, 7))
    angles = sorted(draw(st.lists(st.floats(0, 2 * math.pi), min_size=n, max_size=n, unique=True)))
    r = draw(st.floats(2, 15))
    pts = np.array([[cx + r * math.cos(a), cy + r * math.sin(a)] for a in angles])
    poly = shapely.Polygon(pts)
    assume(poly.is_valid and poly.area > 1.0)
    return pts


@st.composite
def worlds(draw):
    circles = draw(
        st.lists(st.tuples(st.floats(5, 95), st.floats(5, 95), st.floats(0.5, 15)), max_size=4)
    )
    polys = draw(st.lists(convex_polygon(), max_size=2))
    if draw(st.booleans()):
        polys.append(L_SHAPE)
    radius = draw(st.floats(0, 8))
    return World(BOUNDS, circles, polys, radius)


def reference_distance(world: World, a, b) -> float:
    """Independent exact reference: shapely for polygons, analytic for circles."""
    geom = shapely.LineString([a, b]) if a != b else shapely.Point(a)
    d = math.inf
    for cx, cy, r in world.circles:
        d = min(d, max(0.0, geom.distance(shapely.Point(cx, cy)) - r))
    for p in world.polygons:
        d = min(d, geom.distance(shapely.Polygon(p)))
    return d


def sampled_distance(world: World, a, b, n: int = 2000) -> float:
    t = np.linspace(0.0, 1.0, n)[:, None]
    pts = (1 - t) * np.asarray(a) + t * np.asarray(b)
    return float(world.point_clearance(pts).min())


@settings(max_examples=150, deadline=None)
@given(world=worlds(), a=point, b=point)
def test_segment_distance_is_exact(world, a, b):
    d = float(world.segment_distance(np.array(a), np.array(b)))
    ref = reference_distance(world, a, b)
    if math.isinf(ref):
        assert math.isinf(d)
        return
    assert d == pytest.approx(ref, abs=1e-7)
    # Dense sampling can only overestimate the minimum, by at most half a sample step.
    sampled = sampled_distance(world, a, b)
    step = math.dist(a, b) / 1999
    assert d <= sampled + 1e-9
    assert sampled <= d + step + 1e-9


@settings(max_examples=150, deadline=None)
@given(world=worlds(), a=point, b=point)
def test_scalar_and_vectorised_checks_agree(world, a, b):
    d = float(world.segment_distance(np.array(a), np.array(b)))
    assume(abs(d - world.robot_radius) > 1e-7)  # either answer is right on the boundary itself
    expected = d >= world.robot_radius
    assert world.motion_free(*a, *b) == expected
    assert bool(world.segments_free(np.array([a]), np.array([b]))[0]) == expected
    assert (float(world.segment_violation(np.array(a), np.array(b))) == 0.0) == expected
    dp = float(world.point_clearance(np.array([a]))[0])
    assume(abs(dp - world.robot_radius) > 1e-7)
    assert world.point_free(*a) == (dp >= world.robot_radius)


def test_tangent_segment_is_free_and_a_hair_closer_is_not():
    world = World(BOUNDS, [(50, 50, 10)], [], robot_radius=5)
    assert world.motion_free(0, 65, 100, 65)  # distance exactly 15 = r + R: touching is allowed
    assert not world.motion_free(0, 65 - 1e-6, 100, 65 - 1e-6)
    assert world.segments_free(np.array([[0, 65.0]]), np.array([[100, 65.0]]))[0]


def test_circles_are_circles_not_polygons():
    """Half-way between two vertices of a 32-gon the circle bulges 0.048 beyond the polygon
    (radius 10): a segment cutting the circle there by 0.01 is missed by the polygon and caught
    exactly, and one passing 1e-4 outside the circle is free."""
    world = World(BOUNDS, [(50, 50, 10)], [], robot_radius=0)
    angle = math.pi / 32  # half-way between vertices 0 and 1 of a 32-gon starting at angle 0
    n = np.array([math.cos(angle), math.sin(angle)])
    tangent = np.array([-n[1], n[0]])
    polygon = shapely.Point(50, 50).buffer(10, quad_segs=8)  # 32 vertices on the circle

    cut = np.array([50.0, 50.0]) + (10 - 0.01) * n
    a, b = cut - 2 * tangent, cut + 2 * tangent
    assert not polygon.intersects(shapely.LineString([a, b]))  # the approximation misses it
    assert not world.motion_free(*a, *b)
    assert not world.segments_free(a, b)

    outside = np.array([50.0, 50.0]) + (10 + 1e-4) * n
    assert world.motion_free(*(outside - 2 * tangent), *(outside + 2 * tangent))


def test_thin_corner_between_samples_is_caught():
    """A segment that clips a polygon corner by 1e-6: a discretised check at resolution 1 misses
    it, the exact check does not."""
    tri = np.array([[50, 50], [60, 40], [60, 60]], dtype=float)
    world = World(BOUNDS, [], [tri], robot_radius=0)
    a, b = (50 + 1e-6, 0.0), (50 + 1e-6, 100.0)
    samples = np.stack([np.full(100, a[0]), np.linspace(0.5, 99.5, 100)], axis=1)
    assert all(world.point_free(*s) for s in samples)  # every sample is free...
    assert not world.motion_free(*a, *b)  # ...the segment is not
    assert not world.segments_free(np.array(a), np.array(b))


def test_segment_inside_polygon_collides():
    world = World(BOUNDS, [], [np.array([[10, 10], [90, 10], [90, 90], [10, 90]], float)], 0.0)
    assert not world.motion_free(20, 20, 30, 30)
    assert float(world.segment_distance(np.array([20, 20]), np.array([30, 30]))) == 0.0


def test_path_valid():
    world = World(BOUNDS, [(50, 50, 10)], [], robot_radius=2)
    assert world.path_valid(np.array([[5, 5], [5, 95], [95, 95]]))
    assert not world.path_valid(np.array([[5, 5], [95, 95]]))  # through the circle
    assert not world.path_valid(np.array([[5, 5], [5, 101]]))  # leaves the bounds
    assert not world.path_valid(np.array([[5, 5], [np.nan, 5]]))
    assert world.path_valid(np.array([[5, 5]]))
    assert not world.path_valid(np.empty((0, 2)))


def test_violation_sums_over_circles():
    one = World(BOUNDS, [(50, 50, 10)], [], 1.0)
    two = World(BOUNDS, [(50, 50, 10), (50, 52, 10)], [], 1.0)
    a, b = np.array([0.0, 50.0]), np.array([100.0, 50.0])
    assert float(two.segment_violation(a, b)) > float(one.segment_violation(a, b)) > 0


def test_local_model_matches_full_check():
    """The culled model the swarm uses equals the full check for segments inside their boxes."""
    rng = np.random.default_rng(3)
    world = World(BOUNDS, rng.uniform([0, 0, 1], [100, 100, 8], (12, 3)), [L_SHAPE], 3.0)
    lo = rng.uniform(0, 60, (5, 2))
    hi = lo + rng.uniform(5, 40, (5, 2))
    model = world.local_model(lo, hi)
    a = rng.uniform(lo, hi, (200, 5, 2))
    b = rng.uniform(lo, hi, (200, 5, 2))
    assert np.allclose(model.violation(a, b), world.segment_violation(a, b))
