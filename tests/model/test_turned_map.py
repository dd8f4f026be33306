"""Turned maps (a map YAML whose origin yaw is not 0, issue 26 item 3): map_server's placement,
exact checks against shapely, the bounds and the unknown space around the map, and start and
goal errors that name the cell."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import shapely
from helpers import _map, _pgm, map_shapes, turned_copy

from rrtpso_ompl.errors import ProblemError
from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.model.occupancy import load_map

#: Distances this close to the clearance threshold may go either way (round-off of the turn,
#: far below the touch tolerance of 1e-9 of the workspace).
BAND = 1e-10


def _problem(tmp_path, img, origin, radius=0.3, **problem):
    """A problem on a map of ``img`` (0.5 m cells) with the given origin ``[x, y, yaw]``."""
    _map(tmp_path, img, origin=list(origin))
    doc = {"map": "m.yaml", "start": [1e-3, 1e-3], "goal": [1e-3, 1e-3],
           "robot": {"radius": radius}, **problem}  # fmt: skip
    path = tmp_path / "p.yaml"
    path.write_text(json.dumps(doc))
    return path


def _random_map(seed: int, shape=(24, 32)) -> np.ndarray:
    """Occupied (0), free (254) and unknown (205) cells at random, in blobs and speckle."""
    rng = np.random.default_rng(seed)
    img = np.full(shape, 254, dtype=np.uint8)
    img[rng.random(shape) < 0.12] = 0
    img[rng.random(shape) < 0.04] = 205
    for _ in range(6):  # a few walls, so that merged boxes are long and thin
        i, j = rng.integers(0, shape[0]), rng.integers(0, shape[1] - 8)
        img[i, j : j + 8] = 0
    return img


# ----------------------------------------------------------------------------------------------
# Where the cells are
# ----------------------------------------------------------------------------------------------
def test_yaw_turns_the_image_about_the_lower_left_corner_of_its_lower_left_cell(tmp_path):
    # 3 rows x 4 columns of 0.5 m; origin (1, 2), yaw 90 degrees. nav_msgs/MapMetaData: the
    # origin is the pose of the bottom-left corner of cell (0, 0), the image's lower-left cell;
    # cell (mx, my) (my counted from the bottom row) has its centre at
    # origin + R(yaw) ((mx + 0.5) res, (my + 0.5) res).
    img = np.full((3, 4), 254, dtype=np.uint8)
    img[2, 0] = 0  # the lower-left cell
    img[0, 3] = 0  # the upper-right one
    m = load_map(_map(tmp_path, img, origin=[1.0, 2.0, math.pi / 2]))
    assert m.yaw == math.pi / 2 and m.origin == (1.0, 2.0)
    # Lower-left cell: grid square [1, 1.5] x [2, 2.5], turned about (1, 2): [0.5, 1] x [2, 2.5].
    assert m.cell_centre(2, 0) == pytest.approx((0.75, 2.25), abs=1e-12)
    # Upper-right cell: grid [2.5, 3] x [3, 3.5] -> [-0.5, 0] x [3.5, 4].
    assert m.cell_centre(0, 3) == pytest.approx((-0.25, 3.75), abs=1e-12)
    for my in range(3):
        for mx in range(4):
            want = (1.0 - (my + 0.5) * 0.5, 2.0 + (mx + 0.5) * 0.5)  # R(90) (a, b) = (-b, a)
            assert m.cell_centre(2 - my, mx) == pytest.approx(want, abs=1e-12)
    assert m.corners == pytest.approx(np.array([[1, 2], [1, 4], [-0.5, 4], [-0.5, 2]]), abs=1e-12)
    assert np.ravel(m.bounding_box) == pytest.approx([-0.5, 2.0, 1.0, 4.0], abs=1e-12)
    # The world blocks the turned squares, not the unturned ones.
    world = World(m.bounding_box, boxes=m.boxes, box_frame=m.frame)
    assert not world.point_free(0.75, 2.25) and not world.point_free(-0.25, 3.75)
    assert world.point_free(0.25, 2.25)  # the unturned lower-left cell's neighbour, free
    assert world.point_free(0.75, 3.75)


def test_a_map_that_is_not_turned_has_no_frame_and_reads_as_before(tmp_path):
    img = np.full((3, 4), 254, dtype=np.uint8)
    m = load_map(_map(tmp_path, img, origin=[1.0, 2.0]))
    assert m.yaw == 0.0 and m.frame is None
    assert m.bounding_box == m.extent == ((1.0, 2.0), (3.0, 3.5))


@pytest.mark.parametrize(("origin", "key", "words"), [
    ([5e8, 0.0, -math.pi / 4], "origin[2]", "corners reach"),
    ([0.0, 0.0, "a"], "origin[2]", "must be a number"),
    ([0.0, 0.0, math.inf], "origin[2]", "finite"),
])  # fmt: skip
def test_bad_yaws_are_refused_naming_the_key(tmp_path, origin, key, words):
    # 4.9e8 m cells from x = 5e8 stay under 1e9 unturned; turned by -45 degrees the far corner
    # reaches x = 5e8 + 4.9e8 sqrt(2).
    img = np.full((1, 1), 254, dtype=np.uint8)
    _pgm(tmp_path / "m.pgm", img)
    path = tmp_path / "m.yaml"
    path.write_text(json.dumps({"image": "m.pgm", "resolution": 4.9e8, "origin": origin})
                    .replace("Infinity", ".inf"))  # fmt: skip
    with pytest.raises(ProblemError) as err:
        load_map(path)
    assert key in str(err.value) and words in str(err.value)


# ----------------------------------------------------------------------------------------------
# Bounds and the unknown space around a turned map
# ----------------------------------------------------------------------------------------------
def test_default_bounds_box_the_turned_map_and_its_corners_are_unknown(tmp_path):
    img = np.full((10, 20), 254, dtype=np.uint8)
    p = load_problem(_problem(tmp_path, img, [0.0, 0.0, 0.3], start=[5.0, 3.0], goal=[6, 3]))
    assert p.bounds == p.map.bounding_box
    # The four corner triangles of the box: its area less the map's (10 m x 5 m).
    (x0, y0), (x1, y1) = p.bounds
    outside = p.map_outside
    assert len(outside) == 4
    area = sum(shapely.Polygon(o.points).area for o in outside)
    assert area == pytest.approx((x1 - x0) * (y1 - y0) - 50.0, rel=1e-12)
    assert all(shapely.Polygon(o.points).is_valid for o in outside)
    assert p.map_frame.confined == (0.0, 0.0, 10.0, 5.0)  # all free space lies in the map
    # Turned a quarter: the box is the map itself (up to round-off): no unknown slivers.
    p = load_problem(_problem(tmp_path, img, [0.0, 0.0, math.pi / 2], start=[-3, 5], goal=[-3, 6]))
    assert p.map_outside == () and p.map_frame.confined is not None
    # unknown: free: nothing outside blocks, and free space is not confined to the map.
    p = load_problem(_problem(tmp_path, img, [0.0, 0.0, 0.3], start=[5.0, 3.0], goal=[6, 3],
                              map={"file": "m.yaml", "unknown": "free"}))  # fmt: skip
    assert p.map_outside == () and p.map_frame.confined is None


def test_bounds_that_cut_the_turned_map_leave_it_unconfined(tmp_path):
    img = np.full((10, 20), 254, dtype=np.uint8)
    p = load_problem(_problem(tmp_path, img, [0.0, 0.0, 0.3], start=[5.0, 3.0], goal=[6, 3],
                              bounds=[[0, 0], [12, 12]]))  # fmt: skip
    assert p.map_frame.confined is None  # the map's lower-left corner region is cut away
    union = shapely.union_all([shapely.Polygon(o.points) for o in p.map_outside])
    rect = shapely.Polygon(p.map.corners)
    want = shapely.box(0, 0, 12, 12).difference(rect)
    assert union.symmetric_difference(want).area < 1e-9


def test_the_unknown_space_around_a_turned_map_is_valid_convex_pieces_for_any_turn():
    """Turns, pivots and bounds at random (bounds that hold the map, cut it, or touch its
    corners): the pieces are valid convex polygons that cover exactly the bounds outside the
    map, up to slivers of the round-off allowance."""
    from rrtpso_ompl.model.geometry import GridFrame
    from rrtpso_ompl.model.problem_types import outside_polygons

    rng = np.random.default_rng(7)
    for k in range(300):
        yaw = rng.choice([rng.uniform(-4, 4), rng.integers(-4, 5) * math.pi / 2, 1e-12])
        pivot = rng.uniform(-50, 50, 2)
        w, h = rng.uniform(1, 40, 2)
        corners = GridFrame(pivot, yaw).to_world(
            pivot + np.array([[0, 0], [w, 0], [w, h], [0, h]]))
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        if k % 3 == 1:  # bounds that cut the map
            span = hi - lo
            lo, hi = lo + rng.uniform(0, 0.4, 2) * span, hi - rng.uniform(0, 0.4, 2) * span
        elif k % 3 == 2:  # bounds wider than the map's box
            lo, hi = lo - rng.uniform(0, 5, 2), hi + rng.uniform(0, 5, 2)
        tol = 1e-9 * max(np.abs(lo).max(), np.abs(hi).max(), *(hi - lo))
        pieces = outside_polygons(((lo[0], lo[1]), (hi[0], hi[1])), corners, tol)
        shapes = [shapely.Polygon(p.points) for p in pieces]
        assert all(g.is_valid and g.area > 0 and g.convex_hull.area - g.area < 1e-9 * g.area
                   for g in shapes)  # fmt: skip
        want = shapely.box(*lo, *hi).difference(shapely.Polygon(corners))
        got = shapely.union_all(shapes) if shapes else shapely.Polygon()
        assert got.symmetric_difference(want).area <= 1e-6 * (1.0 + want.area)
        assert sum(g.area for g in shapes) == pytest.approx(got.area, rel=1e-9, abs=1e-9)


# ----------------------------------------------------------------------------------------------
# Exact checks against shapely
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("yaw", "radius", "seed"), [
    (0.3, 0.3, 0), (math.pi / 2, 0.3, 1), (-2.5, 0.0, 2), (1.0, 0.7, 3), (0.3, 0.0, 4),
])  # fmt: skip
def test_every_check_agrees_with_shapely_on_turned_cells(tmp_path, yaw, radius, seed):
    """Random segments near the turned squares: the world's answers equal shapely's exact
    distances from the segment to the union of the turned cell squares (and the unknown space
    around the map), away from a band of 1e-7 around the threshold."""
    img = _random_map(seed)
    # Bounds wider than the map on two sides: unknown space both beside the map and in the
    # corners of its turned rectangle.
    path = _problem(tmp_path, img, [3.0, -2.0, yaw], radius=radius, start=[1e6, 1e6])
    doc = json.loads(path.read_text())
    m = load_map(tmp_path / "m.yaml")
    (bx0, by0), (bx1, by1) = m.bounding_box
    doc["bounds"] = [[bx0 - 1.0, by0], [bx1, by1 + 1.5]]
    # A start and goal that the loader accepts (the freest lattice points), and a rectangle and
    # a circle of the problem file in free space away from them (a rectangle stays axis-aligned
    # in the world: a polygon there, beside the turned boxes).
    free = _free_points(m, doc["bounds"], radius)
    start, goal = free[0], free[1]
    far = free[(np.hypot(*(free - start).T) > 3.0) & (np.hypot(*(free - goal).T) > 3.0)]
    (rx, ry), (cx, cy) = far[0], far[np.hypot(*(far - far[0]).T) > 2.0][0]
    doc.update(start=start.tolist(), goal=goal.tolist(), obstacles=[
        {"type": "rectangle", "min": [rx - 0.4, ry - 0.25], "max": [rx + 0.4, ry + 0.25]},
        {"type": "circle", "center": [cx, cy], "radius": 0.35},
    ])  # fmt: skip
    path.write_text(json.dumps(doc))
    problem = load_problem(path)
    world = World.from_problem(problem)
    assert world.box_frame is not None and world.raster is None and len(world.circles) == 1
    shapes = map_shapes(problem, cells=True).union(
        shapely.box(rx - 0.4, ry - 0.25, rx + 0.4, ry + 0.25))
    rng = np.random.default_rng(seed)
    (bx0, by0), (bx1, by1) = problem.bounds
    n = 3000
    a = rng.uniform([bx0, by0], [bx1, by1], (n, 2))
    b = a + rng.normal(0.0, 1.2, (n, 2))
    b[: n // 10] = a[: n // 10]  # some points
    segments = shapely.linestrings(np.stack([a, b], axis=1))
    ref = np.minimum(shapely.distance(shapes, segments),
                     np.maximum(shapely.distance(shapely.Point(cx, cy), segments) - 0.35, 0.0))
    thr = world.threshold
    sure = np.abs(ref - thr) > BAND
    want = ref >= thr
    assert sure.mean() > 0.99 and want[sure].any() and not want[sure].all()
    free_v = world.segments_free(a, b)
    assert np.array_equal(free_v[sure], want[sure])
    free_s = np.array([world.motion_free(*a[i], *b[i]) for i in range(n)])
    assert np.array_equal(free_s[sure], want[sure])
    point = np.array([world.point_free(*a[i]) for i in range(n)])
    ref_p = np.minimum(shapely.distance(shapes, shapely.points(a)),
                       np.maximum(np.hypot(a[:, 0] - cx, a[:, 1] - cy) - 0.35, 0.0))
    sure_p = np.abs(ref_p - thr) > BAND
    assert np.array_equal(point[sure_p], (ref_p >= thr)[sure_p])
    np.testing.assert_allclose(world.segment_distance(a, b), ref, atol=1e-9)
    assert np.array_equal((world.segment_violation(a, b) == 0.0)[sure], want[sure])
    # in_polygons: boxes and polygons, not circles.
    inside = world.in_polygons(a[:, 0], a[:, 1])
    ref_in = shapely.distance(shapes, shapely.points(a))
    assert not inside[ref_in > BAND].any() and inside[ref_in == 0.0].all()


def _free_points(m, bounds, radius) -> np.ndarray:
    """Lattice points inside ``bounds`` that keep ``radius`` (plus a margin) from the map, as
    shapely sees it, farthest first."""
    (bx0, by0), (bx1, by1) = bounds
    blocked = shapely.union_all(shapely.polygons(m.frame.box_corners(m.boxes)))
    rect = shapely.Polygon(m.corners)
    x, y = np.meshgrid(np.linspace(bx0, bx1, 40), np.linspace(by0, by1, 40))
    p = np.column_stack([x.ravel(), y.ravel()])
    d = shapely.distance(blocked, shapely.points(p))
    d = np.minimum(d, shapely.distance(rect.exterior, shapely.points(p)))
    d[~shapely.contains_xy(rect, p[:, 0], p[:, 1])] = 0.0
    assert (d > radius + 0.05).sum() >= 2
    return p[np.argsort(-d)]


@pytest.mark.parametrize("yaw", [0.3, math.pi / 2])
def test_the_swarm_model_and_the_lattice_are_exact_and_conservative_on_turned_cells(
    tmp_path, yaw
):
    """The swarm's local violation model equals the world's own; lattice cells reported free
    keep the clearance everywhere (shapely's distance from the whole cell square)."""
    problem = load_problem(turned_copy(tmp_path, "lab_clutter", yaw, pivot=(1.0, -2.0))[0])
    world = World.from_problem(problem)
    rng = np.random.default_rng(5)
    (x0, y0), (x1, y1) = problem.bounds
    a = rng.uniform([x0, y0], [x1, y1], (40, 6, 2))
    b = a + rng.normal(0.0, 0.4, a.shape)
    lo, hi = np.minimum(a, b).min(axis=0) - 0.05, np.maximum(a, b).max(axis=0) + 0.05
    local = world.local_model(lo, hi).violation(a, b)
    np.testing.assert_allclose(local, world.segment_violation(a, b), atol=1e-12)
    assert (local > 0).any() and (local == 0).any()
    lat = world.lattice(20_000)
    free = world.free_cells(lat)
    assert free.any()
    i, j = np.nonzero(free)
    ox, oy = lat.origin
    h = lat.h
    squares = shapely.box(ox + h * i, oy + h * j, ox + h * (i + 1), oy + h * (j + 1))
    d = shapely.distance(map_shapes(problem), squares)
    assert d.min() >= world.threshold - 1e-9


# ----------------------------------------------------------------------------------------------
# Start and goal
# ----------------------------------------------------------------------------------------------
def test_a_start_in_a_turned_cell_is_refused_naming_its_row_and_column(tmp_path):
    img = np.full((10, 20), 254, dtype=np.uint8)
    img[4, 7] = 0  # grid square [3.5, 4] x [2.5, 3]
    m = load_map(_map(tmp_path, img, origin=[1.0, 2.0, 0.3]))
    cx, cy = m.cell_centre(4, 7)
    # Where the cell would be unturned is free; the turned square holds the start.
    path = _problem(tmp_path, img, [1.0, 2.0, 0.3], radius=0.0, start=[cx + 0.2, cy - 0.1],
                    goal=[cx + 2.0, cy + 1.0])  # fmt: skip
    with pytest.raises(ProblemError) as err:
        load_problem(path)
    msg = str(err.value)
    assert "start" in msg and "occupied map cell at image row 4, column 7" in msg
    assert f"centred at ({cx:g}, {cy:g}), turned 0.3 rad" in msg and "m.yaml" in msg
    # With a radius, a start beside the turned square is refused as overlapping it.
    doc = json.loads(path.read_text())
    doc["robot"]["radius"] = 0.3
    doc["start"] = (np.array([cx, cy]) + 0.45 * np.array([math.cos(0.3), math.sin(0.3)])).tolist()
    path.write_text(json.dumps(doc))
    with pytest.raises(ProblemError, match=r"overlaps the occupied map cell at image row 4"):
        load_problem(path)


def test_a_goal_whose_disc_reaches_the_unknown_corner_of_a_turned_map_is_refused(tmp_path):
    img = np.full((10, 20), 254, dtype=np.uint8)
    m = load_map(_map(tmp_path, img, origin=[0.0, 0.0, 0.3]))
    corner = m.corners[0]  # the origin: beyond it, toward the box's corner, is unknown space
    inward = np.array([math.cos(0.3 + math.pi / 4), math.sin(0.3 + math.pi / 4)])
    goal = (corner + 0.3 * inward).tolist()  # 0.21 m from both sides of the map
    path = _problem(tmp_path, img, [0.0, 0.0, 0.3], radius=0.25, start=[5.0, 3.0], goal=goal)
    with pytest.raises(ProblemError, match=r"goal: .* reaches beyond the map"):
        load_problem(path)
    doc = json.loads(path.read_text())
    doc["map"] = {"file": "m.yaml", "unknown": "free"}
    path.write_text(json.dumps(doc))
    assert load_problem(path).goal == pytest.approx(goal)
