"""Exact geometry: the closed forms against independent references (shapely for polygons, an
analytic point-segment distance written here for circles), against dense sampling, and against each
other (the scalar checks OMPL calls and the vectorised checks the swarm calls)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from rrtpso_ompl.model.world import World

BOUNDS = ((0.0, 0.0), (100.0, 100.0))
#: A fixed non-convex polygon (its re-entrant corner is at (50, 50)).
L_SHAPE = np.array([[40, 40], [70, 40], [70, 50], [50, 50], [50, 75], [40, 75]], dtype=float)
#: Comparisons of a distance with the free threshold skip this window around the threshold, where
#: either answer is right (touching is allowed up to round-off).
BOUNDARY_WINDOW = 5e-8

coord = st.floats(-10, 110, allow_nan=False, allow_infinity=False)
point = st.tuples(coord, coord)


# ----------------------------------------------------------------------------------------------
# Independent references
# ----------------------------------------------------------------------------------------------
def point_segment_distance(p, a, b) -> float:
    """Distance from point p to the closed segment a-b (a == b allowed), written from scratch."""
    px, py = p
    ax, ay = a
    bx, by = b
    ux, uy = bx - ax, by - ay
    den = ux * ux + uy * uy
    if den == 0.0:
        return math.hypot(px - ax, py - ay)
    t = min(1.0, max(0.0, ((px - ax) * ux + (py - ay) * uy) / den))
    return math.hypot(px - (ax + t * ux), py - (ay + t * uy))


def reference_distance(world: World, a, b) -> float:
    """Exact distance from segment a-b to the nearest obstacle: analytic for circles (clamped at
    0 inside), shapely for polygons."""
    d = math.inf
    for cx, cy, r in world.circles:
        d = min(d, max(0.0, point_segment_distance((cx, cy), a, b) - r))
    geom = shapely.Point(a) if tuple(a) == tuple(b) else shapely.LineString([a, b])
    for p in world.polygons:
        d = min(d, geom.distance(shapely.Polygon(p)))
    return d


def reference_point_distances(world: World, pts: np.ndarray) -> np.ndarray:
    """Exact distance from each point to the nearest obstacle (0 inside), vectorised."""
    d = np.full(len(pts), np.inf)
    for cx, cy, r in world.circles:
        d = np.minimum(d, np.maximum(0.0, np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) - r))
    geoms = shapely.points(pts)
    for p in world.polygons:
        d = np.minimum(d, shapely.distance(geoms, shapely.Polygon(p)))
    return d


# ----------------------------------------------------------------------------------------------
# Strategies
# ----------------------------------------------------------------------------------------------
@st.composite
def convex_polygons(draw):
    """A random convex polygon: vertices on a circle at sorted random angles."""
    cx, cy = draw(st.floats(15, 85)), draw(st.floats(15, 85))
    n = draw(st.integers(3, 7))
    angles = sorted(draw(st.lists(st.floats(0, 2 * math.pi), min_size=n, max_size=n, unique=True)))
    assume(min(np.diff([*angles, angles[0] + 2 * math.pi])) > 1e-2)
    r = draw(st.floats(2, 15))
    pts = np.array([[cx + r * math.cos(a), cy + r * math.sin(a)] for a in angles])
    poly = shapely.Polygon(pts)
    assume(poly.is_valid and poly.area > 1.0)
    return pts


@st.composite
def rectangles(draw):
    x0, y0 = draw(st.floats(5, 80)), draw(st.floats(5, 80))
    w, h = draw(st.floats(0.5, 20)), draw(st.floats(0.5, 20))
    return np.array([[x0, y0], [x0 + w, y0], [x0 + w, y0 + h], [x0, y0 + h]])


@st.composite
def worlds(draw):
    circles = draw(
        st.lists(st.tuples(st.floats(5, 95), st.floats(5, 95), st.floats(0.5, 15)), max_size=3)
    )
    polys = draw(st.lists(st.one_of(convex_polygons(), rectangles()), max_size=2))
    if draw(st.booleans()):
        polys.append(L_SHAPE)
    radius = draw(st.one_of(st.just(0.0), st.floats(0, 8)))
    return World(BOUNDS, circles, polys, radius)


@st.composite
def segments(draw, world: World):
    """A segment of one of several kinds that stress the exact formulas."""
    kinds = ["random", "degenerate"]
    if world.polygons:
        kinds += ["from_vertex", "through_vertex", "inside", "collinear", "vertex_to_vertex"]
    if len(world.circles):
        kinds += ["near_circle"]
    kind = draw(st.sampled_from(kinds))
    a = draw(point)
    if kind == "random":
        return a, draw(point)
    if kind == "degenerate":
        return a, a
    if kind == "near_circle":
        cx, cy, r = world.circles[draw(st.integers(0, len(world.circles) - 1))]
        ang = draw(st.floats(0, 2 * math.pi))
        off = draw(st.floats(-2, 2)) + r + world.robot_radius
        m = (cx + off * math.cos(ang), cy + off * math.sin(ang))
        t = (-math.sin(ang), math.cos(ang))
        s0, s1 = draw(st.floats(-30, 30)), draw(st.floats(-30, 30))
        return (m[0] + s0 * t[0], m[1] + s0 * t[1]), (m[0] + s1 * t[0], m[1] + s1 * t[1])
    poly = world.polygons[draw(st.integers(0, len(world.polygons) - 1))]
    n = len(poly)
    i = draw(st.integers(0, n - 1))
    v = tuple(float(c) for c in poly[i])
    if kind == "from_vertex":
        return v, a
    if kind == "vertex_to_vertex":
        return v, tuple(float(c) for c in poly[draw(st.integers(0, n - 1))])
    if kind == "through_vertex":
        # From a through the vertex and beyond it.
        s = draw(st.floats(1.0, 3.0))
        return a, (a[0] + s * (v[0] - a[0]), a[1] + s * (v[1] - a[1]))
    if kind == "collinear":
        q = poly[(i + 1) % n]
        s, t = draw(st.floats(-1, 2)), draw(st.floats(-1, 2))
        return (
            (v[0] + s * (q[0] - v[0]), v[1] + s * (q[1] - v[1])),
            (v[0] + t * (q[0] - v[0]), v[1] + t * (q[1] - v[1])),
        )
    # "inside": convex combinations of vertices of a convex piece of the polygon.
    # The L's first four vertices are a convex quadrilateral inside it.
    piece = poly[:4] if np.array_equal(poly, L_SHAPE) else poly
    w1 = np.array(draw(st.lists(st.floats(0.05, 1), min_size=len(piece), max_size=len(piece))))
    w2 = np.array(draw(st.lists(st.floats(0.05, 1), min_size=len(piece), max_size=len(piece))))
    p1, p2 = (w1 / w1.sum()) @ piece, (w2 / w2.sum()) @ piece
    return tuple(float(c) for c in p1), tuple(float(c) for c in p2)


def far_from_threshold(world: World, d: float) -> bool:
    return abs(d - world.threshold) > BOUNDARY_WINDOW


# ----------------------------------------------------------------------------------------------
# Property tests
# ----------------------------------------------------------------------------------------------
@settings(max_examples=250, deadline=None)
@given(data=st.data(), world=worlds())
def test_segment_distance_equals_the_exact_reference(data, world):
    a, b = data.draw(segments(world))
    d = float(world.segment_distance(np.array(a), np.array(b)))
    ref = reference_distance(world, a, b)
    if math.isinf(ref):
        assert math.isinf(d)
    else:
        assert d == pytest.approx(ref, abs=1e-7)
    # The same segment among others in a batch gives the same answer.
    batch = world.segment_distance(np.array([a, b, a]), np.array([b, a, a]))
    assert batch[0] == pytest.approx(d, abs=1e-12) and batch[1] == pytest.approx(d, abs=1e-7)
    assert batch[2] == pytest.approx(reference_distance(world, a, a), abs=1e-7)


@settings(max_examples=150, deadline=None)
@given(data=st.data(), world=worlds())
def test_segment_distance_against_dense_sampling(data, world):
    a, b = data.draw(segments(world))
    assume(world.n_obstacles > 0)
    d = float(world.segment_distance(np.array(a), np.array(b)))
    n = 2000
    t = np.linspace(0.0, 1.0, n)[:, None]
    pts = (1 - t) * np.asarray(a) + t * np.asarray(b)
    exact = reference_point_distances(world, pts)
    sampled = float(exact.min())
    length = math.dist(a, b)
    # Sampling can only overestimate the minimum over the segment ...
    assert sampled >= d - 1e-9
    # ... and by at most the distance to the nearest sample (the distance is 1-Lipschitz).
    assert sampled <= d + length / n + 1e-9
    # point_clearance is the exact point distance too.
    assert np.allclose(world.point_clearance(pts), exact, atol=1e-7, rtol=0)


@settings(max_examples=250, deadline=None)
@given(data=st.data(), world=worlds())
def test_scalar_and_vectorised_motion_checks_agree(data, world):
    a, b = data.draw(segments(world))
    d = float(world.segment_distance(np.array(a), np.array(b)))
    ref = reference_distance(world, a, b)
    assume(far_from_threshold(world, d) and far_from_threshold(world, ref))
    expected = d >= world.threshold
    assert expected == (ref >= world.threshold)
    assert world.motion_free(*a, *b) == expected
    assert world.motion_free(*b, *a) == expected  # direction does not matter
    assert bool(world.segments_free(np.array([a]), np.array([b]))[0]) == expected
    violation = float(world.segment_violation(np.array(a), np.array(b)))
    assert violation >= 0.0
    assert (violation == 0.0) == expected


@settings(max_examples=250, deadline=None)
@given(world=worlds(), p=point)
def test_point_free_agrees_with_point_clearance(world, p):
    dp = float(world.point_clearance(np.array([p]))[0])
    ref = float(reference_point_distances(world, np.array([p]))[0])
    if math.isinf(ref):
        assert math.isinf(dp) and world.point_free(*p)
        return
    assert dp == pytest.approx(ref, abs=1e-7)
    assume(far_from_threshold(world, dp))
    expected = dp >= world.threshold
    assert world.point_free(*p) == expected
    assert world.motion_free(*p, *p) == expected  # a zero-length motion is its point
    assert world.path_valid(np.array([p])) == (expected and world.in_bounds(*p))


# ----------------------------------------------------------------------------------------------
# Hand-made exact cases
# ----------------------------------------------------------------------------------------------
def test_tangent_to_a_circle_is_free_and_a_hair_closer_is_not():
    world = World(BOUNDS, [(50, 50, 10)], [], robot_radius=5)
    # Distance exactly 15 = r + R: touching is allowed.
    assert world.motion_free(0, 65, 100, 65)
    assert world.segments_free(np.array([[0, 65.0]]), np.array([[100, 65.0]]))[0]
    assert float(world.segment_violation(np.array([0, 65.0]), np.array([100, 65.0]))) == 0.0
    # 1e-6 closer (10x the round-off tolerance of this 100-wide world): a collision.
    y = 65 - 1e-6
    assert not world.motion_free(0, y, 100, y)
    assert not world.segments_free(np.array([[0, y]]), np.array([[100, y]]))[0]
    assert float(world.segment_violation(np.array([0, y]), np.array([100, y]))) > 0.0
    # The same for a point, from every side.
    for ang in np.linspace(0, 2 * np.pi, 8, endpoint=False):
        on = 50 + 15 * np.array([math.cos(ang), math.sin(ang)])
        inside = 50 + (15 - 1e-6) * np.array([math.cos(ang), math.sin(ang)])
        assert world.point_free(*on) and not world.point_free(*inside)


def test_touching_a_polygon_edge_at_the_radius_is_free():
    square = np.array([[40, 40], [60, 40], [60, 60], [40, 60]], dtype=float)
    world = World(BOUNDS, [], [square], robot_radius=4)
    assert world.motion_free(0, 36, 100, 36)  # 4 below the bottom edge
    assert world.segments_free(np.array([0, 36.0]), np.array([100, 36.0]))
    assert not world.motion_free(0, 36 + 1e-6, 100, 36 + 1e-6)
    assert not world.segments_free(np.array([0, 36 + 1e-6]), np.array([100, 36 + 1e-6]))
    # Near a corner the safety zone is round: at 45 degrees it reaches 4 / sqrt(2) per axis.
    c = 60 + 4 / math.sqrt(2)
    assert world.point_free(c + 1e-6, c + 1e-6) and not world.point_free(c - 1e-6, c - 1e-6)
    assert world.point_free(62.9, 62.9)  # inside the bounding box grown by R, but free


def test_point_robot_cannot_touch_or_enter():
    """With radius 0 the threshold is +tol, so touching an obstacle counts as a collision."""
    tri = np.array([[50, 50], [60, 40], [60, 60]], dtype=float)
    world = World(BOUNDS, [(20, 20, 5)], [tri], robot_radius=0.0)
    assert not world.motion_free(0, 50, 50, 50)  # ends on a vertex
    assert not world.motion_free(50, 50, 70, 50)  # starts on a vertex and crosses
    assert not world.motion_free(60, 0, 60, 100)  # runs along an edge
    assert not world.motion_free(0, 20, 15, 20)  # ends on a circle
    assert world.motion_free(0, 50 + 1e-3, 49.99, 50 + 1e-3)
    assert float(world.segment_distance(np.array([0, 50.0]), np.array([50, 50.0]))) == 0.0


def test_thin_spike_between_samples_is_caught():
    """A needle 0.002 wide at its base, half-way between two sample columns, crossed near its
    tip: every sample of a discretised check at resolution 1 is free (the whole robot disc of
    radius 0.4 around it), the exact check is not."""
    spike = np.array([[50.499, 10.0], [50.5, 80.0], [50.501, 10.0]])
    world = World(BOUNDS, [], [spike], robot_radius=0.4)
    a, b = (0.0, 79.0), (100.0, 79.0)
    samples = np.stack([np.arange(0.0, 101.0), np.full(101, 79.0)], axis=1)
    assert all(world.point_free(*s) for s in samples)  # every sample is free ...
    assert world.segments_free(samples, samples).all()
    assert not world.motion_free(*a, *b)  # ... the segment is not
    assert not world.segments_free(np.array(a), np.array(b))
    assert float(world.segment_distance(np.array(a), np.array(b))) == 0.0


def test_clipping_a_corner_by_a_hair_is_caught():
    """A segment that clips a polygon corner by 1e-6: a discretised check at resolution 1 misses
    it, the exact check does not."""
    tri = np.array([[50, 50], [60, 40], [60, 60]], dtype=float)
    world = World(BOUNDS, [], [tri], robot_radius=0)
    a, b = (50 + 1e-6, 0.0), (50 + 1e-6, 100.0)
    samples = np.stack([np.full(100, a[0]), np.linspace(0.5, 99.5, 100)], axis=1)
    assert all(world.point_free(*s) for s in samples)
    assert not world.motion_free(*a, *b)
    assert not world.segments_free(np.array(a), np.array(b))
    # With a radius the same holds for a segment clipping the grown corner by 1e-6.
    world = World(BOUNDS, [], [tri], robot_radius=3.0)
    x = 50 - 3 + 1e-6
    assert not world.motion_free(x, 0, x, 100)
    assert world.motion_free(x - 2e-6, 0, x - 2e-6, 100)


def test_circles_are_circles_not_polygons():
    """A 32-gon is no substitute for a circle of radius 10 (robot radius 2, grown radius 12).

    * Inscribed 32-gon (vertices on the grown circle): half-way between two vertices the circle
      bulges 0.058 beyond it; a segment cutting the circle there by 0.01 is missed by the polygon
      and caught exactly.
    * Circumscribed 32-gon (edges tangent to the grown circle): at a vertex it sticks out 0.058
      beyond the circle; a segment 1e-4 outside the circle there collides with the polygon and
      is free exactly.
    """
    r, big_r = 10.0, 2.0
    grown = r + big_r
    world = World(BOUNDS, [(50, 50, r)], [], robot_radius=big_r)
    c = np.array([50.0, 50.0])
    ang = np.arange(32) * 2 * math.pi / 32
    inscribed = shapely.Polygon(c + grown * np.column_stack([np.cos(ang), np.sin(ang)]))
    circumscribed = shapely.Polygon(
        c + grown / math.cos(math.pi / 32) * np.column_stack([np.cos(ang), np.sin(ang)])
    )

    def chord(direction: float, dist: float):
        n = np.array([math.cos(direction), math.sin(direction)])
        t = np.array([-n[1], n[0]])
        m = c + dist * n
        return m - 2 * t, m + 2 * t

    a, b = chord(math.pi / 32, grown - 0.01)  # between vertices 0 and 1
    assert not inscribed.intersects(shapely.LineString([a, b]))
    assert not world.motion_free(*a, *b)
    assert not world.segments_free(a, b)

    a, b = chord(2 * math.pi / 32, grown + 1e-4)  # at vertex 1
    assert circumscribed.intersects(shapely.LineString([a, b]))
    assert world.motion_free(*a, *b)
    assert world.segments_free(a, b)
    assert float(world.segment_distance(a, b)) == pytest.approx(big_r + 1e-4, abs=1e-9)


def test_segment_inside_a_polygon_collides():
    world = World(BOUNDS, [], [np.array([[10, 10], [90, 10], [90, 90], [10, 90]], float)], 0.0)
    assert not world.motion_free(20, 20, 30, 30)
    assert not world.point_free(50, 50)
    assert float(world.segment_distance(np.array([20, 20]), np.array([30, 30]))) == 0.0
    assert float(world.point_clearance(np.array([[50, 50]]))[0]) == 0.0


def test_inside_the_notch_of_the_l_shape_is_outside():
    """The re-entrant corner of a non-convex polygon: the notch is free space."""
    world = World(BOUNDS, [], [L_SHAPE], robot_radius=2.0)
    assert world.point_free(60, 60)  # in the notch, 10 from both inner edges
    assert world.motion_free(55, 70, 68, 55)
    assert float(world.point_clearance(np.array([[52.0, 52.0]]))[0]) == pytest.approx(2.0)
    assert world.point_free(52, 52)  # touches both inner edges at exactly the radius
    assert not world.point_free(52 - 1e-6, 52)
    # Beyond the convex vertex (70, 50) the nearest point is the vertex itself.
    assert float(world.point_clearance(np.array([[72.0, 52.0]]))[0]) == pytest.approx(
        2 * math.sqrt(2)
    )
    assert not world.motion_free(45, 60, 60, 45)  # starts inside the L's upright arm


def test_segment_distance_broadcasts():
    world = World(BOUNDS, [(50, 50, 10)], [L_SHAPE], robot_radius=1.0)
    rng = np.random.default_rng(0)
    a = rng.uniform(0, 100, (3, 4, 2))
    b = rng.uniform(0, 100, 2)
    d = world.segment_distance(a, b)
    assert d.shape == (3, 4)
    for idx in np.ndindex(3, 4):
        assert d[idx] == pytest.approx(reference_distance(world, tuple(a[idx]), tuple(b)), abs=1e-9)
    assert world.segment_violation(a, b).shape == (3, 4)
    assert world.segments_free(a, b).shape == (3, 4)


def test_no_obstacles():
    world = World(BOUNDS, [], [], robot_radius=3.0)
    assert np.isinf(world.segment_distance(np.array([0, 0.0]), np.array([100, 100.0])))
    assert world.motion_free(0, 0, 100, 100) and world.point_free(50, 50)
    assert float(world.segment_violation(np.array([0, 0.0]), np.array([1, 1.0]))) == 0.0
    assert world.path_valid(np.array([[0, 0], [100, 100]]))


# ----------------------------------------------------------------------------------------------
# Paths and violation
# ----------------------------------------------------------------------------------------------
def test_path_valid():
    world = World(BOUNDS, [(50, 50, 10)], [], robot_radius=2)
    assert world.path_valid(np.array([[5, 5], [5, 95], [95, 95]]))
    assert not world.path_valid(np.array([[5, 5], [95, 95]]))  # through the circle
    assert not world.path_valid(np.array([[5, 5], [5, 101]]))  # a waypoint leaves the bounds
    assert not world.path_valid(np.array([[-0.5, 5], [5, 5]]))
    assert world.path_valid(np.array([[0, 0], [0, 100 + 1e-8]]))  # on the bounds (with tol)
    assert not world.path_valid(np.array([[5, 5], [np.nan, 5]]))
    assert not world.path_valid(np.array([[5, 5], [np.inf, 5]]))
    assert world.path_valid(np.array([[5, 5]]))  # a single valid point
    assert not world.path_valid(np.array([[50, 45]]))  # a single point in collision
    assert not world.path_valid(np.array([[150, 5]]))  # a single point out of bounds
    assert not world.path_valid(np.empty((0, 2)))


def test_violation_is_zero_exactly_when_free():
    world = World(BOUNDS, [(30, 30, 8), (70, 70, 5)], [L_SHAPE], robot_radius=3.0)
    rng = np.random.default_rng(11)
    a = rng.uniform(0, 100, (4000, 2))
    b = a + rng.normal(0, 15, (4000, 2))
    v = world.segment_violation(a, b)
    free = world.segments_free(a, b)
    assert free.any() and (~free).any()  # both kinds occur
    assert np.all(v[free] == 0.0) and np.all(v[~free] > 0.0)


def test_violation_sums_over_circles():
    one = World(BOUNDS, [(50, 50, 10)], [], 1.0)
    two = World(BOUNDS, [(50, 50, 10), (50, 52, 10)], [], 1.0)
    a, b = np.array([0.0, 50.0]), np.array([100.0, 50.0])
    v1, v2 = float(one.segment_violation(a, b)), float(two.segment_violation(a, b))
    assert v2 > v1 > 0
    # Through both centres the distance to each is 0, so each contributes the full threshold.
    assert v1 == pytest.approx(one.threshold)
    assert v2 == pytest.approx(2 * two.threshold)
    # Partial intrusion: the segment at y = 60.5 is 0.5 into the grown circle (radius 11).
    a, b = np.array([0.0, 60.5]), np.array([100.0, 60.5])
    assert float(one.segment_violation(a, b)) == pytest.approx(0.5 - one.tol)


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


def test_local_model_box_wholly_inside_a_polygon():
    big = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], dtype=float)
    world = World(((0, 0), (200, 200)), [], [big], robot_radius=1.0)
    model = world.local_model(np.array([[40.0, 40.0]]), np.array([[60.0, 60.0]]))
    a, b = np.array([[[45.0, 45.0]]]), np.array([[[55.0, 55.0]]])
    assert float(world.segment_violation(a, b)[0, 0]) > 0
    assert float(model.violation(a, b)[0, 0]) == pytest.approx(
        float(world.segment_violation(a, b)[0, 0])
    )


# ----------------------------------------------------------------------------------------------
# The spatial index: the same answers as measuring every obstacle
# ----------------------------------------------------------------------------------------------
def _crowded_world(seed: int, radius: float) -> World:
    """Many circles, boxes (map-like: some share edges) and a few polygons."""
    rng = np.random.default_rng(seed)
    circles = np.column_stack([rng.uniform(0, 100, (60, 2)), rng.uniform(0.2, 3, 60)])
    x = rng.integers(0, 40, 80) * 2.5
    y = rng.integers(0, 40, 80) * 2.5
    boxes = np.column_stack([x, y, x + 2.5 * rng.integers(1, 4, 80), y + 2.5])
    polygons = [c + rng.uniform(1, 4) * np.array([[0, 0], [1, 0], [0.5, 0.9]]) for c in
                rng.uniform(5, 95, (6, 2))]  # fmt: skip
    return World(BOUNDS, circles, polygons, radius, boxes)


def _brute(world: World) -> World:
    """The same world checked without its index (every world counts as small)."""
    from unittest import mock

    from rrtpso_ompl.model import obstacle_index

    with mock.patch.object(obstacle_index, "SMALL_WORLD", math.inf):
        twin = World(world.bounds, world.circles, world.polygons, world.robot_radius, world.boxes)
    assert not twin.index.indexed
    return twin


@pytest.mark.parametrize("radius", [0.0, 0.7, 3.0])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_index_gives_the_same_answers_as_brute_force(seed, radius):
    world = _crowded_world(seed, radius)
    brute = _brute(world)
    assert world.index.indexed and world.n_obstacles > 100
    rng = np.random.default_rng(seed + 10)
    a = rng.uniform(-2, 102, (3000, 2))
    # Short, long and zero-length segments, and some along the box grid lines.
    b = a + rng.normal(0, 1, (3000, 2)) * rng.choice([0.0, 1.0, 8.0, 60.0], (3000, 1))
    b[:200, 1] = a[:200, 1] = np.round(a[:200, 1] / 2.5) * 2.5
    free = world.segments_free(a, b)
    np.testing.assert_array_equal(free, brute.segments_free(a, b))
    d = brute.segment_distance(a, b)
    np.testing.assert_array_equal(free, d >= world.threshold)
    scalar = [world.motion_free(*p, *q) for p, q in zip(a, b, strict=True)]
    np.testing.assert_array_equal(scalar, free)
    np.testing.assert_allclose(world.segment_violation(a, b), brute.segment_violation(a, b),
                               rtol=0, atol=1e-12)  # fmt: skip
    cap = world.threshold + 2.0
    capped = world.segment_distance(a, b, cap=cap)
    near = d <= cap
    np.testing.assert_allclose(capped[near], d[near], rtol=0, atol=1e-12)
    assert np.all(capped[~near] > cap)
    pts = a[:500]
    np.testing.assert_array_equal([world.point_free(*p) for p in pts],
                                  brute.point_clearance(pts) >= world.threshold)  # fmt: skip


def test_the_local_model_of_the_index_matches_the_full_check():
    world = _crowded_world(4, 1.0)
    rng = np.random.default_rng(4)
    seg_lo = rng.uniform(0, 90, (12, 2))
    seg_hi = seg_lo + rng.uniform(0.5, 10, (12, 2))
    a = seg_lo + rng.uniform(0, 1, (40, 12, 2)) * (seg_hi - seg_lo)
    b = seg_lo + rng.uniform(0, 1, (40, 12, 2)) * (seg_hi - seg_lo)
    local = world.local_model(seg_lo, seg_hi).violation(a, b)
    np.testing.assert_allclose(local, _brute(world).segment_violation(a, b), rtol=0, atol=1e-12)


@settings(max_examples=150, deadline=None)
@given(
    cells=st.lists(st.tuples(st.integers(0, 19), st.integers(0, 19)), min_size=1, max_size=60,
                   unique=True),
    seg=st.tuples(point, point),
    radius=st.sampled_from([0.0, 1.3, 5.0]),
)  # fmt: skip
def test_map_cells_are_exact_squares(cells, seg, radius):
    """A segment is free of blocked 5 x 5 squares exactly when shapely's distance to their union
    is at least the radius (away from the round-off band)."""
    boxes = np.array([[5 * i, 5 * j, 5 * i + 5, 5 * j + 5] for i, j in cells], dtype=float)
    world = World(BOUNDS, boxes=boxes, robot_radius=radius)
    union = shapely.union_all([shapely.box(*b) for b in boxes])
    a, b = seg
    geom = shapely.Point(a) if a == b else shapely.LineString([a, b])
    d = geom.distance(union)
    assume(abs(d - world.threshold) > BOUNDARY_WINDOW)
    assert world.motion_free(*a, *b) == (d >= world.threshold)
    assert bool(world.segments_free(np.array([a]), np.array([b]))[0]) == (d >= world.threshold)


def _gear(n: int, centre=(50.0, 50.0), r=(20.0, 23.0)) -> np.ndarray:
    """A star-shaped polygon of ``n`` vertices alternating between two radii."""
    k = np.arange(n)
    rad = np.where(k % 2, r[1], r[0])
    ang = 2 * np.pi * k / n
    return np.column_stack([centre[0] + rad * np.cos(ang), centre[1] + rad * np.sin(ang)])


@pytest.mark.parametrize(
    ("radius", "crowded"),
    # 3 s each, most of it the brute-force reference: the quick run keeps one.
    [pytest.param(0.0, 256, marks=pytest.mark.slow), pytest.param(1.0, 256, marks=pytest.mark.slow),
     (1.0, 8)],
)  # fmt: skip
def test_a_polygon_of_thousands_of_vertices_is_checked_edge_by_edge(radius, crowded, monkeypatch):
    """A detailed polygon is indexed as its edges and its interior: a check looks at the edges
    near it only, and the answers are those of brute force and of shapely, also for segments
    wholly inside it (far from every edge) and crossing its crowded boundary. The scalar checks
    go through numpy in cells holding more than ``crowded`` items."""
    import rrtpso_ompl.model.scalar_checks as scalar_checks

    monkeypatch.setattr(scalar_checks, "_CROWDED", crowded)
    gear = _gear(2000)
    world = World(BOUNDS, [(90.0, 10.0, 3.0)], [gear, L_SHAPE * 0.2], radius)
    brute = _brute(world)
    assert world.index.indexed and world.index.grid.max_items < 2000  # no cell holds the whole ring
    rng = np.random.default_rng(7)
    a = rng.uniform(0, 100, (2000, 2))
    b = a + rng.normal(0, 1, (2000, 2)) * rng.choice([0.0, 1.0, 10.0, 40.0], (2000, 1))
    a[:100] = rng.uniform(40, 60, (100, 2))  # wholly inside the gear, far from its edges
    b[:100] = rng.uniform(40, 60, (100, 2))
    d = brute.segment_distance(a, b)
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    lines[np.all(a == b, axis=1)] = shapely.points(a[np.all(a == b, axis=1)])
    ref = np.minimum.reduce(
        [shapely.distance(lines, shapely.Polygon(p)) for p in world.polygons]
        + [np.maximum(0.0, shapely.distance(lines, shapely.Point(90, 10)) - 3)]
    )
    np.testing.assert_allclose(d, ref, rtol=0, atol=1e-9)  # fmt: skip
    assert np.all(d[:100] == 0.0)
    free = world.segments_free(a, b)
    keep = np.abs(d - world.threshold) > BOUNDARY_WINDOW
    np.testing.assert_array_equal(free[keep], (d >= world.threshold)[keep])
    scalar = np.array([world.motion_free(*p, *q) for p, q in zip(a, b, strict=True)])
    np.testing.assert_array_equal(scalar, free)
    np.testing.assert_array_equal([world.point_free(*p) for p in a],
                                  brute.point_clearance(a) >= world.threshold)  # fmt: skip
    np.testing.assert_allclose(world.segment_violation(a, b), brute.segment_violation(a, b),
                               rtol=0, atol=1e-12)  # fmt: skip
    cap = world.threshold + 2.0
    capped = world.segment_distance(a, b, cap=cap)
    near = d <= cap
    np.testing.assert_allclose(capped[near], d[near], rtol=0, atol=1e-12)
    assert np.all(capped[~near] > cap)
    # The swarm's culled model: segments confined to boxes over the crowded ring.
    seg_lo = rng.uniform(20, 70, (6, 2))
    seg_hi = seg_lo + rng.uniform(1, 15, (6, 2))
    pa = seg_lo + rng.uniform(0, 1, (30, 6, 2)) * (seg_hi - seg_lo)
    pb = seg_lo + rng.uniform(0, 1, (30, 6, 2)) * (seg_hi - seg_lo)
    np.testing.assert_allclose(world.local_model(seg_lo, seg_hi).violation(pa, pb),
                               brute.segment_violation(pa, pb), rtol=0, atol=1e-12)  # fmt: skip


def test_after_its_deadline_the_world_refuses_motions_unchecked():
    world = World(BOUNDS, [(50.0, 50.0, 5.0)], [], 1.0)
    a, b = np.array([[10.0, 10.0]]), np.array([[20.0, 10.0]])
    assert world.motion_free(10, 10, 20, 10) and world.segments_free(a, b)[0]
    with world.refusing_motions_after(0.0):  # long past
        assert not world.motion_free(10, 10, 20, 10)
        assert not world.segments_free(a, b)[0] and not world.path_valid([[10, 10], [20, 10]])
        assert world.segment_distance(a, b)[0] > 0  # distances are still measured
    assert world.motion_free(10, 10, 20, 10) and world.refuse_after is None


def _counting_stop(fire_at: int):
    """A stop condition that fires at its ``fire_at``-th look (and counts them)."""
    looks = []

    def stop() -> bool:
        looks.append(1)
        return len(looks) >= fire_at

    return stop, looks


def test_a_lattice_marking_stops_when_its_condition_fires():
    """Marking a lattice among the 20,000 edges of a gear looks at its stop condition between
    chunks and raises MarkingStopped when it fires; outside the block nothing stops it."""
    from rrtpso_ompl.model.raster import Lattice
    from rrtpso_ompl.model.world import MarkingStopped

    world = World(BOUNDS, [], [_gear(20_000)], 1.0)
    lat = Lattice.over(world.bounds, 0.25)  # 160,000 cells, millions of (cell, edge) pairs
    stop, looks = _counting_stop(3)
    with world.marking_stops(stop), pytest.raises(MarkingStopped):
        world.centres_free(lat)
    assert len(looks) == 3 and world.mark_stop is None
    small = Lattice.over(world.bounds, 5.0)
    with world.marking_stops(lambda: False):
        np.testing.assert_array_equal(world.centres_free(small), _brute(world).centres_free(small))


def test_the_culled_model_is_not_built_when_it_would_end_after_the_deadline():
    """Its cost is known before it is built (the index's registrations in the boxes): with a
    deadline already past, None; with time, the model (whatever the machine's speed)."""
    import time

    world = World(BOUNDS, [], [_gear(20_000)], 1.0)
    seg_lo, seg_hi = np.array([[25.0, 25.0]]), np.array([[75.0, 75.0]])
    assert world.local_model(seg_lo, seg_hi, deadline=time.perf_counter() - 1.0) is None
    assert world.local_model(seg_lo, seg_hi, deadline=time.perf_counter() + 1e6) is not None


@pytest.mark.parametrize("seed", [1, 2])
def test_registrations_in_boxes_count_what_the_index_holds_there(seed):
    """The summed-area count equals the registrations of the cells each box meets, and bounds
    the unique pairs ``pairs_in_boxes`` returns."""
    world = _crowded_world(seed, 1.0)
    grid = world.index.grid
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-10, 100, (50, 2))
    hi = lo + rng.uniform(0, 60, (50, 2))
    counts = grid.registrations_in_boxes(lo, hi)
    per_cell = np.diff(grid.offsets).reshape(grid.ny, grid.nx)
    i0, i1, j0, j1 = grid._ranges(np.hstack([lo, hi]))
    brute = [per_cell[j0[q] : j1[q] + 1, i0[q] : i1[q] + 1].sum() for q in range(50)]
    np.testing.assert_array_equal(counts, brute)
    query, _ = grid.pairs_in_boxes(lo, hi)
    assert np.all(np.bincount(query, minlength=50) <= counts)


def test_the_round_off_allowance_is_relative_at_every_scale():
    tiny = ((0.0, 0.0), (1e-6, 1e-6))
    assert World(tiny, [], [], 0.0).tol == pytest.approx(1e-15)
    assert World(BOUNDS, [], [], 0.0).tol == pytest.approx(1e-7)
    # A disc 1e-9 into a circle's safety zone is a collision in a micrometre-wide world (the
    # old absolute allowance of 1e-9 let it through).
    world = World(tiny, [(5e-7, 5e-7, 1e-7)], [], 5e-8)
    x = 5e-7 + 1.5e-7 - 1e-9
    assert not world.point_free(x, 5e-7) and world.point_free(x + 2e-9, 5e-7)
