"""The exact optimum: closed forms, an independent brute force, bounds from above and below."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
import shapely
from helpers import PROBLEMS, SINGLE_CIRCLE, rrtpso_exe
from scipy.sparse import csr_array
from scipy.sparse.csgraph import dijkstra

from rrtpso_ompl.groundtruth.generate import generate, grid_path
from rrtpso_ompl.groundtruth.optimum import shortest_path
from rrtpso_ompl.model.geometry import path_length
from rrtpso_ompl.model.problem import Circle, Polygon, load_problem, problem_from_dict
from rrtpso_ompl.model.world import World
from rrtpso_ompl.planners.solve import solve


def _one_circle_length(s, g, c, rho) -> float:
    """Tangent, arc, tangent around one disc that blocks the straight line (closed form)."""
    s, g, c = (np.asarray(v, float) for v in (s, g, c))
    d1, d2 = np.linalg.norm(s - c), np.linalg.norm(g - c)
    cos_t = np.dot(s - c, g - c) / (d1 * d2)
    theta = math.acos(np.clip(cos_t, -1, 1))
    arc = theta - math.acos(rho / d1) - math.acos(rho / d2)
    return math.sqrt(d1**2 - rho**2) + math.sqrt(d2**2 - rho**2) + rho * arc


def _box(lo, hi):
    return {"type": "rectangle", "min": list(lo), "max": list(hi)}


def test_single_circle_is_tangent_arc_tangent():
    problem = problem_from_dict(SINGLE_CIRCLE)
    result = shortest_path(problem)
    rho = 80 + 28.5
    expected = _one_circle_length((20, 20), (450, 450), (250, 250), rho)
    assert expected == pytest.approx(647.4596, abs=1e-4)
    assert result.length == pytest.approx(expected, rel=1e-12)
    assert [p.kind for p in result.pieces] == ["line", "arc", "line"]
    arc = result.pieces[1]
    assert arc.radius == pytest.approx(rho) and arc.center == pytest.approx((250, 250))
    for line in (result.pieces[0], result.pieces[2]):
        # Tangent: the line's distance from the centre equals the grown radius.
        a, b = np.array(line.start), np.array(line.end)
        u, w = b - a, np.array([250.0, 250.0]) - a
        dist = abs(u[0] * w[1] - u[1] * w[0]) / np.linalg.norm(u)
        assert dist == pytest.approx(rho, rel=1e-12)
    assert sum(p.length for p in result.pieces) == pytest.approx(result.length, rel=1e-12)


@pytest.mark.parametrize(
    ("start", "goal"),
    [((10, 40), (90, 55)), ((20, 80), (75, 15)), ((50, 5), (45, 95)), ((5, 50), (95, 50))],
)
def test_one_circle_off_the_diagonal(start, goal):
    doc = {
        "bounds": [[0, 0], [100, 100]],
        "start": list(start),
        "goal": list(goal),
        "robot": {"radius": 3},
        "obstacles": [{"type": "circle", "center": [50, 50], "radius": 15}],
    }
    result = shortest_path(problem_from_dict(doc))
    assert result.length == pytest.approx(_one_circle_length(start, goal, (50, 50), 18), rel=1e-12)


def test_straight_line_when_nothing_is_in_the_way():
    doc = {"bounds": [[0, 0], [10, 10]], "start": [1, 1], "goal": [9, 4], "robot": {"radius": 0.5},
           "obstacles": [{"type": "circle", "center": [5, 8], "radius": 1}]}  # fmt: skip
    result = shortest_path(problem_from_dict(doc))
    assert result.length == pytest.approx(math.hypot(8, 3), rel=1e-12)
    assert result.polyline().tolist() == [[1, 1], [9, 4]]


def test_point_robot_bends_at_the_square_corners():
    doc = {"bounds": [[0, 0], [100, 100]], "start": [10, 50], "goal": [90, 50],
           "robot": {"radius": 0}, "obstacles": [_box((40, 35), (60, 60))]}  # fmt: skip
    result = shortest_path(problem_from_dict(doc))
    # Over the top: (10,50) -> (40,60) -> (60,60) -> (90,50); the bottom is longer.
    expected = 2 * math.hypot(30, 10) + 20
    assert result.length == pytest.approx(expected, abs=1e-6)
    bends = [p.end for p in result.pieces[:-1]]
    assert any(np.allclose(b, (40, 60), atol=1e-6) for b in bends)
    assert any(np.allclose(b, (60, 60), atol=1e-6) for b in bends)


def test_disc_robot_rounds_the_square_corners():
    """Robot radius R: tangent to the corner circles, a straight run along the offset top edge and
    the two corner arcs (closed form for a symmetric set-up)."""
    R = 4.0
    doc = {"bounds": [[0, 0], [100, 100]], "start": [10, 50], "goal": [90, 50],
           "robot": {"radius": R}, "obstacles": [_box((40, 35), (60, 60))]}  # fmt: skip
    result = shortest_path(problem_from_dict(doc))
    v = np.array([40.0, 60.0])
    d = np.linalg.norm(v - (10, 50))
    tangent = math.sqrt(d**2 - R**2)
    # The tangent leaves the corner circle at angle phi; the arc runs from there to straight up.
    direction = math.atan2(10, 30)  # start -> corner
    phi = direction + math.asin(R / d)  # the tangent's heading
    arc = R * phi  # the heading turns from phi to 0 along the arc
    expected = 2 * (tangent + arc) + 20
    assert result.length == pytest.approx(expected, rel=1e-12)
    assert [p.kind for p in result.pieces] == ["line", "arc", "line", "arc", "line"]


def test_no_path_into_a_closed_box(tmp_path):
    walls = [_box((60, 60), (90, 62)), _box((60, 88), (90, 90)), _box((60, 60), (62, 90)),
             _box((88, 60), (90, 90))]  # fmt: skip
    doc = {"name": "boxed", "bounds": [[0, 0], [100, 100]], "start": [10, 10],
           "goal": [75, 75], "robot": {"radius": 1}, "obstacles": walls}  # fmt: skip
    result = shortest_path(problem_from_dict(doc))
    assert result.length is None and not result.found and result.pieces == []
    path = tmp_path / "boxed.yaml"
    path.write_text(json.dumps(doc))
    out = tmp_path / "opt.json"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(path), "--json", str(out)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 1
    assert json.loads(out.read_text())["length"] is None
    assert json.loads(out.read_text())["path"] == []


def test_a_gap_narrower_than_the_robot_is_closed():
    """Two boxes with a 5-wide gap: a robot of radius 2 passes, one of radius 3 must go round."""
    doc = {"bounds": [[0, 0], [100, 100]], "start": [50, 10], "goal": [50, 90],
           "obstacles": [_box((0, 45), (47.5, 55)), _box((52.5, 45), (100, 55))]}  # fmt: skip
    small = shortest_path(problem_from_dict({**doc, "robot": {"radius": 2}}))
    assert small.length == pytest.approx(80.0, rel=1e-12)
    big = shortest_path(problem_from_dict({**doc, "robot": {"radius": 3}}))
    assert big.length is None  # the boxes reach the bounds on both sides


def test_start_equals_goal_and_goal_tolerance():
    doc = {"bounds": [[0, 0], [10, 10]], "start": [2, 2], "goal": [2, 2], "robot": {"radius": 0.5}}
    assert shortest_path(problem_from_dict(doc)).length == 0.0
    doc = {**doc, "goal": [8, 2], "goal_tolerance": 1.5}
    result = shortest_path(problem_from_dict(doc))
    assert result.length == pytest.approx(6.0 - 1.5, rel=1e-12) and result.exact
    # With the tolerance the path around a circle ends where its leg enters the goal disc.
    doc = {"bounds": [[0, 0], [500, 500]], "start": [20, 20], "goal": [450, 450],
           "goal_tolerance": 10, "robot": {"radius": 28.5},
           "obstacles": [{"type": "circle", "center": [250, 250], "radius": 80}]}  # fmt: skip
    result = shortest_path(problem_from_dict(doc))
    full = _one_circle_length((20, 20), (450, 450), (250, 250), 108.5)
    assert result.length == pytest.approx(full - 10, rel=1e-12)


# ----------------------------------------------------------------------------------------------
def _brute_force(problem, quad_segs: int = 16, bound: float = math.inf) -> float | None:
    """An independent check: the visibility graph of the grown obstacles drawn as shapely
    polygons (vertices on the true boundary, so slightly smaller than the grown obstacles: a
    lower bound that tends to the optimum as ``quad_segs`` grows). Only vertices that a path
    no longer than ``bound`` can pass are kept."""
    R = problem.robot.radius
    shapes = []
    for o in problem.obstacles:
        if isinstance(o, Circle):
            shapes.append(shapely.Point(o.center).buffer(o.radius + R, quad_segs=quad_segs))
        elif isinstance(o, Polygon):
            shapes.append(shapely.Polygon(o.points).buffer(R, quad_segs=quad_segs))
    union = shapely.union_all(shapes)
    (x0, y0), (x1, y1) = problem.bounds
    verts = [problem.start[:2], problem.goal[:2]]
    for poly in getattr(union, "geoms", [union]):
        for ring in [poly.exterior, *poly.interiors]:
            verts.extend(ring.coords[:-1])
    v = np.array(verts, float)
    v = v[(v[:, 0] >= x0) & (v[:, 0] <= x1) & (v[:, 1] >= y0) & (v[:, 1] <= y1)]
    reach = np.hypot(*(v - v[0]).T) + np.hypot(*(v - v[1]).T)
    v = v[reach <= bound]
    i, j = np.triu_indices(len(v), k=1)
    lines = shapely.linestrings(np.stack([v[i], v[j]], axis=1))
    ok = ~shapely.relate_pattern(union, lines, "T********")  # no interior in common
    w = np.hypot(*(v[i] - v[j]).T)[ok]
    graph = csr_array((w, (i[ok], j[ok])), shape=(len(v), len(v)))
    d = dijkstra(graph, directed=False, indices=0)[1]
    return float(d) if np.isfinite(d) else None


def _cluttered(seed: int, robot_radius: float, n: int = 9, sizes=(5, 14)) -> dict:
    """Overlapping random circles, boxes and convex polygons across the start-goal line."""
    rng = np.random.default_rng(seed)
    start, goal = np.array([5.0, 50.0]), np.array([95.0, 50.0])
    obstacles = []
    while len(obstacles) < n:
        c = rng.uniform((20, 25), (80, 75))
        size = rng.uniform(*sizes)
        if min(np.linalg.norm(c - start), np.linalg.norm(c - goal)) < size + robot_radius + 3:
            continue
        kind = rng.random()
        if kind < 0.4:
            obstacles.append({"type": "circle", "center": c.round(2).tolist(), "radius": size})
        elif kind < 0.6:
            lo, hi = (c - size * 0.7).round(2), (c + size * rng.uniform(0.3, 0.9)).round(2)
            obstacles.append({"type": "rectangle", "min": lo.tolist(), "max": hi.tolist()})
        else:
            angles = np.sort(rng.uniform(0, 2 * np.pi, rng.integers(3, 7)))
            pts = c + size * np.column_stack([np.cos(angles), np.sin(angles)])
            obstacles.append({"type": "polygon", "points": pts.round(2).tolist()})
    return {"bounds": [[0, 0], [100, 100]], "start": start.tolist(), "goal": goal.tolist(),
            "robot": {"radius": robot_radius}, "obstacles": obstacles}  # fmt: skip


@pytest.mark.parametrize(
    ("seed", "robot_radius", "n"),
    [(1, 0.0, 9), (2, 1.5, 9), (3, 3.0, 9), (4, 0.5, 9), (5, 0.5, 40),
     pytest.param(6, 1.0, 50, marks=pytest.mark.slow)],  # 2.5 s: the quick run has 40 obstacles
)  # fmt: skip
def test_agrees_with_brute_force_and_is_below_a_certified_grid_path(seed, robot_radius, n):
    """Few obstacles, and many (indexed world, tangents pruned by occlusion)."""
    size = (5, 14) if n < 20 else (1.5, 4)
    problem = problem_from_dict(_cluttered(seed, robot_radius, n, size))
    result = shortest_path(problem)
    assert result.found
    lower = _brute_force(problem, bound=result.length * 1.001)
    assert lower is not None
    assert result.length > math.dist(problem.start, problem.goal) + 0.1  # obstacles in the way
    # The inscribed polygons make the brute force slightly shorter, never longer.
    assert lower <= result.length * (1 + 1e-9)
    assert result.length <= lower * (1 + 5e-4)
    grid = grid_path(problem)
    assert grid is not None and result.length <= path_length(grid) + 1e-9


def test_generated_worlds_are_below_their_grid_paths():
    for kind, seed in (("circles", 3), ("polygons", 4)):
        problem = problem_from_dict(generate(kind, seed, robot_radius=1.0))
        result = shortest_path(problem)
        grid = grid_path(problem)
        assert result.found and result.length <= path_length(grid) + 1e-9


def test_pieces_touch_but_never_enter_the_grown_obstacles():
    problem = load_problem(PROBLEMS / "static" / "polygon_map.yaml")
    result = shortest_path(problem)
    world = World.from_problem(problem)
    ends = np.array([p.start for p in result.pieces] + [result.pieces[-1].end])
    assert world.points_in_bounds(ends).all()
    lines = [p for p in result.pieces if p.kind == "line"]
    d = world.segment_distance(np.array([p.start for p in lines]), np.array([p.end for p in lines]))
    assert d.min() >= world.robot_radius - world.tol
    # Arcs, sampled densely: every point is at least R from every obstacle (up to round-off).
    for arc in (p for p in result.pieces if p.kind == "arc"):
        pts = arc.points(math.radians(0.1))
        assert world.point_clearance(pts).min() >= world.robot_radius - 1e-9
    assert d.min() == pytest.approx(world.robot_radius, abs=1e-9)  # it does touch: optimal


@pytest.mark.parametrize("planner", ["RRTstarPSO", "RRTstar", "RRTConnect"])
@pytest.mark.parametrize("name", ["single_circle", "polygon_map"])
def test_planners_never_beat_the_optimum(planner, name):
    problem = load_problem(PROBLEMS / "static" / f"{name}.yaml")
    optimum = shortest_path(problem).length
    result = solve(problem, planner, time_limit=0.3, seed=5)
    assert result.solved
    assert result.length >= optimum - 1e-9
    assert result.length <= 1.5 * optimum  # and they are in the right neighbourhood


def test_library_optima_are_below_their_grid_paths():
    for name in ("paper_static", "narrow_passage", "bug_trap", "maze", "yarpiz_pso", "wall_gap"):
        problem = load_problem(PROBLEMS / "static" / f"{name}.yaml")
        result = shortest_path(problem)
        grid = grid_path(problem)
        assert result.found and grid is not None
        assert result.length <= path_length(grid) + 1e-9, name
        assert result.length >= math.dist(problem.start, problem.goal) - 1e-9


@pytest.mark.parametrize("path", sorted((PROBLEMS / "static").glob("*.yaml")), ids=lambda p: p.stem)
def test_the_json_path_is_a_valid_path_of_nearly_the_exact_length(path):
    """Arcs become circumscribed polygons, not chords: the exact checker accepts the path."""
    problem = load_problem(path)
    world = World.from_problem(problem)
    result = shortest_path(problem, world)
    polyline = np.asarray(result.to_dict(world)["path"])
    assert world.path_valid(polyline)
    assert result.length <= path_length(polyline) <= result.length * (1 + 2e-4)
    # The old chords were not valid wherever the path wraps an obstacle.
    chords = np.vstack([p.points()[[0, -1]] for p in result.pieces])
    assert path_length(chords) <= path_length(polyline)


def _valid_visibility_path(problem, quad_segs: int = 8, bound: float = math.inf):
    """An independent check from above: the shortest path of a visibility graph whose nodes lie
    on the polygons *circumscribed* about the robot's circles at every obstacle vertex (and about
    every grown circle), so that a segment between two neighbours of one ring is tangent to the
    circle; edges are kept when shapely finds them at least the robot radius from every obstacle.
    Its path is valid, so the optimum is never longer; it is longer than the optimum only by the
    rings' corners (``tan(d / 2) / (d / 2)`` on the arcs, about 1 % at 8 segments a quarter).
    Only nodes a path no longer than ``bound`` can pass are kept. Returns ``(length, path)``, or
    ``(None, None)``."""
    R = problem.robot.radius
    n = 4 * quad_segs
    delta = 2.0 * math.pi / n
    ang = delta * (np.arange(n) + 0.5)
    ring = np.column_stack([np.cos(ang), np.sin(ang)]) / math.cos(delta / 2)
    shapes, nodes = [], [np.array([problem.start[:2], problem.goal[:2]], float)]
    for o in problem.obstacles:
        if isinstance(o, Circle):
            shapes.append(shapely.Point(o.center).buffer(o.radius, quad_segs=256))
            nodes.append(np.array(o.center) + (o.radius + R) * ring)
        else:
            shapes.append(shapely.Polygon(o.points))
            nodes.append((np.array(o.points)[:, None, :] + R * ring[None]).reshape(-1, 2))
    v = np.vstack(nodes)
    (x0, y0), (x1, y1) = problem.bounds
    keep = (v[:, 0] >= x0) & (v[:, 0] <= x1) & (v[:, 1] >= y0) & (v[:, 1] <= y1)
    keep &= np.hypot(*(v - v[0]).T) + np.hypot(*(v - v[1]).T) <= bound
    tree = shapely.STRtree(shapes)
    clearance = R * (1 - 1e-9)  # touching is allowed; round-off is not a collision
    keep[tree.query(shapely.points(v), predicate="dwithin", distance=clearance)[0]] = False
    keep[:2] = True
    v = v[keep]
    i, j = np.triu_indices(len(v), k=1)
    lines = shapely.linestrings(np.stack([v[i], v[j]], axis=1))
    ok = np.ones(len(i), dtype=bool)
    ok[tree.query(lines, predicate="dwithin", distance=clearance)[0]] = False
    graph = csr_array((np.hypot(*(v[i] - v[j]).T)[ok], (i[ok], j[ok])), shape=(len(v),) * 2)
    d, pred = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not np.isfinite(d[1]):
        return None, None
    chain = [1]
    while chain[-1] != 0:
        chain.append(pred[chain[-1]])
    return float(d[1]), v[chain[::-1]]


def _clearance_by_shapely(problem, polyline: np.ndarray) -> float:
    """Least distance from a polyline to the obstacles, by shapely (to a circle: to its centre,
    less its radius)."""
    line = shapely.LineString(polyline)
    d = [
        shapely.distance(line, shapely.Point(o.center)) - o.radius
        if isinstance(o, Circle)
        else shapely.distance(line, shapely.Polygon(o.points))
        for o in problem.obstacles
    ]
    return float(min(d, default=math.inf))


def _assert_sandwiched(problem):
    """The optimum is no longer than the valid visibility path, within 1 % of it, and its own
    path is valid (shapely's distances, and the world's exact check)."""
    world = World.from_problem(problem)
    result = shortest_path(problem, world)
    assert result.found
    upper, path = _valid_visibility_path(problem, bound=result.length * 1.02)
    assert upper is not None
    assert world.path_valid(path)  # the independent path is valid by the exact check too
    assert result.length <= upper * (1 + 1e-9)
    assert result.length >= upper * (1 - 1e-2)
    polyline = result.valid_polyline(world)
    assert world.path_valid(polyline)
    assert _clearance_by_shapely(problem, polyline) >= problem.robot.radius - world.tol
    return result


def test_a_path_along_a_polygon_edge_is_found():
    """The shortest path runs along an edge of the octagon (wrapping its two end vertices): the
    tangent between their circles leaves and reaches them exactly at the ends of their cones, and
    round-off put its angle a hair before the cone's start, which a plain ``mod`` turned into a
    whole turn ahead: the edge was refused and the optimum went round the other side (26.79
    instead of 15.91)."""
    octagon = [[88.983, 92.518], [84.848, 91.445], [83.425, 88.422], [84.215, 85.381],
               [87.785, 83.505], [90.865, 84.887], [92.025, 87.045], [91.501, 90.561]]  # fmt: skip
    start, goal = np.array([80.0, 90.0]), np.array([95.0, 95.0])
    doc = {"bounds": [[60, 70], [100, 100]], "start": start.tolist(), "goal": goal.tolist(),
           "robot": {"radius": 1.0},
           "obstacles": [{"type": "polygon", "points": octagon}]}  # fmt: skip
    result = _assert_sandwiched(problem_from_dict(doc))
    # Start -> vertex 1 -> along the edge -> vertex 0 -> goal, clockwise, in closed form.
    v1, v0 = np.array(octagon[1]), np.array(octagon[0])
    edge = (v0 - v1) / np.linalg.norm(v0 - v1)
    normal = np.array([-edge[1], edge[0]])  # outward (the ring is clockwise)
    assert np.dot(normal, v1 - np.mean(octagon, axis=0)) > 0
    d1, d2 = np.linalg.norm(start - v1), np.linalg.norm(goal - v0)
    arrive = math.atan2(*(start - v1)[::-1]) % (2 * math.pi) - math.acos(1 / d1)
    leave = math.atan2(*(goal - v0)[::-1]) + math.acos(1 / d2)
    n = math.atan2(normal[1], normal[0])
    expected = math.sqrt(d1**2 - 1) + (arrive - n) + np.linalg.norm(v0 - v1) + (n - leave)
    expected += math.sqrt(d2**2 - 1)
    assert arrive > n > leave  # both arcs turn clockwise
    assert result.length == pytest.approx(expected, rel=1e-12)
    kinds = [p.kind for p in result.pieces]
    assert kinds == ["line", "arc", "line", "arc", "line"]
    along = result.pieces[2]  # the edge's offset, from vertex 1's circle to vertex 0's
    assert np.allclose(along.start, v1 + normal) and np.allclose(along.end, v0 + normal)


def test_generated_polygons_seed_2_is_below_a_known_valid_path():
    """The exact optimum of ``rrtpso generate polygons --seed 2`` was 131.0472, longer than the
    130.4414 of a path that BIT* and OMPL's simplifier found (valid: 1.00006 from every polygon)."""
    problem = problem_from_dict(generate("polygons", 2))
    bitstar = np.array([[5.0, 5.0], [32.13984523, 42.6771303], [32.32101641, 45.68840498],
                        [51.24694657, 63.15071668], [73.94890126, 83.50871681],
                        [75.17631538, 84.60532107], [83.84530783, 92.22519757],
                        [90.97139258, 94.59365424], [95.0, 95.0]])  # fmt: skip
    assert World.from_problem(problem).path_valid(bitstar)
    assert _clearance_by_shapely(problem, bitstar) >= 1.0
    result = _assert_sandwiched(problem)
    assert result.length <= path_length(bitstar)
    assert result.length == pytest.approx(129.9506, abs=1e-4)


def _overlapping(seed: int, kinds=("convex", "star", "box"), n: int = 8) -> dict:
    """Random obstacles along the diagonal that may overlap: convex polygons, star-shaped
    (non-convex) ones and boxes; robot radius 0.5, 1 or 2."""
    rng = np.random.default_rng(seed)
    radius = (0.5, 1.0, 2.0)[seed % 3]
    start, goal = np.array([5.0, 5.0]), np.array([95.0, 95.0])
    obstacles = []
    while len(obstacles) < n:
        c = start + rng.uniform(0.15, 0.85) * (goal - start) + rng.normal(0.0, 12.0, 2)
        size = rng.uniform(5, 14)
        if min(np.linalg.norm(c - start), np.linalg.norm(c - goal)) < size + radius + 3:
            continue
        kind = kinds[rng.integers(len(kinds))]
        if kind == "box":
            lo, hi = c - size * rng.uniform(0.3, 0.8, 2), c + size * rng.uniform(0.3, 0.8, 2)
            obstacles.append({"type": "rectangle", "min": lo.round(2).tolist(),
                              "max": hi.round(2).tolist()})  # fmt: skip
            continue
        m = rng.integers(3, 8) if kind == "convex" else rng.integers(5, 10)
        angles = np.sort(rng.uniform(0, 2 * np.pi, m))
        r = size if kind == "convex" else size * rng.uniform(0.35, 1.0, m)[:, None]
        pts = (c + r * np.column_stack([np.cos(angles), np.sin(angles)])).round(2)
        if shapely.Polygon(pts).is_valid:
            obstacles.append({"type": "polygon", "points": pts.tolist()})
    return {"bounds": [[0, 0], [100, 100]], "start": start.tolist(), "goal": goal.tolist(),
            "robot": {"radius": radius}, "obstacles": obstacles}  # fmt: skip


@pytest.mark.parametrize(
    ("family", "seed"),
    [("generated", 30), ("generated", 5), ("generated", 7), ("mixed", 16), ("mixed", 3),
     ("convex", 35), ("convex", 38), ("convex", 4), ("star", 28), ("star", 11), ("boxes", 1),
     ("boxes", 2), ("boxes", 6), ("circles", 3), ("cluttered", 4)],
)  # fmt: skip
def test_optima_are_never_longer_than_a_valid_path(family, seed):
    """Random cross-check: generated non-overlapping convex polygons (8 of them), and obstacles
    that overlap (a vertex of one inside another, concave corners of their union), star-shaped
    polygons and boxes. Before the cone fix, the optimum was 0.6-5.5 % too long on generated 30,
    mixed 16, convex 35 and 38, star 28 (boxes never: their angles are exact). Circles, and
    circles, boxes and polygons together, for good measure."""
    if family == "generated":
        doc = generate("polygons", seed, n=8)
    elif family == "circles":
        doc = generate("circles", seed, n=12)
    elif family == "cluttered":
        doc = _cluttered(seed, 1.0)
    else:
        kinds = {"mixed": ("convex", "star", "box"), "convex": ("convex",), "star": ("star",),
                 "boxes": ("box",)}[family]  # fmt: skip
        doc = _overlapping(seed, kinds, n=10 if family == "boxes" else 8)
    _assert_sandwiched(problem_from_dict(doc))


@pytest.mark.parametrize("seed", [0, 1])
def test_the_cheap_filters_never_drop_a_free_tangent(seed):
    """The raster's rejection and the near-obstacle pass only remove tangents the exact check
    would reject, and between them they remove most of the blocked ones."""
    from rrtpso_ompl.groundtruth.free_grid import FreeGrid
    from rrtpso_ompl.groundtruth.optimum.circles import NodeCircles
    from rrtpso_ompl.groundtruth.optimum.graph import TangentGraph
    from rrtpso_ompl.groundtruth.optimum.tangents import tangents_from

    problem = problem_from_dict(_cluttered(seed, 0.8, 40, (1.5, 4)))
    world = World.from_problem(problem)
    start, goal = np.array(problem.start[:2]), np.array(problem.goal[:2])
    grid = FreeGrid.for_world(world, start, goal)
    nodes = NodeCircles.build(world, grid, start, goal, world.robot_radius)
    graph = TangentGraph(world, grid, nodes, 0.0, math.inf)
    n = len(graph.circles)
    i, j = np.nonzero(~np.eye(n, dtype=bool))
    pick = np.random.default_rng(seed).choice(len(i), 2000, replace=False)
    cand = tangents_from(graph.circles, i[pick], j[pick])
    free = world.segments_free(cand.p, cand.q)
    raster = grid.blocked_segments(cand.p, cand.q)
    near = graph.blocked_near(cand)
    assert not (free & (raster | near)).any()
    assert (raster | near).sum() > 0.5 * (~free).sum()


# ----------------------------------------------------------------------------------------------
# Maps: brute force on small random grids, mazes, the lower bounds and the pruning
# ----------------------------------------------------------------------------------------------
def _write_map(folder, blocked: np.ndarray, res: float = 1.0, name: str = "m"):
    """A map_server map (YAML + PGM) of ``blocked`` (image order, row 0 on top)."""
    h, w = blocked.shape
    img = np.where(blocked, 0, 254).astype(np.uint8)
    (folder / f"{name}.pgm").write_bytes(f"P5\n{w} {h}\n255\n".encode() + img.tobytes())
    (folder / f"{name}.yaml").write_text(
        f"image: {name}.pgm\nresolution: {res}\norigin: [0.0, 0.0, 0.0]\n"
    )
    return folder / f"{name}.yaml"


def _map_problem(folder, blocked, start, goal, radius, res=1.0):
    yaml_path = _write_map(folder, blocked, res)
    doc = {"name": "grid", "map": yaml_path.name, "start": list(start), "goal": list(goal),
           "robot": {"radius": radius}}  # fmt: skip
    return problem_from_dict(doc, source=str(folder / "grid.yaml"), base=folder)


def _map_brute_force(blocked, res, radius, start, goal, quad_segs=8,
                     bound=math.inf) -> float | None:  # fmt: skip
    """Visibility graph of the blocked cells grown by the radius, drawn by shapely (vertices on
    the true boundary: a lower bound that tends to the optimum). A point robot's cells are grown
    by a hair with square corners, so that two cells touching at a corner stay closed, as in the
    exact checker. Only vertices a path no longer than ``bound`` can pass are kept."""
    h = blocked.shape[0]
    rows, cols = np.nonzero(blocked)
    cells = shapely.union_all(shapely.box(cols * res, (h - 1 - rows) * res, (cols + 1) * res,
                                          (h - rows) * res))  # fmt: skip
    if radius > 0:
        union = cells.buffer(radius, quad_segs=quad_segs)
    else:
        union = cells.buffer(1e-7, join_style="mitre")
    verts = [start, goal]
    for poly in getattr(union, "geoms", [union]):
        for ring in [poly.exterior, *poly.interiors]:
            verts.extend(ring.coords[:-1])
    v = np.array(verts, float)
    x1, y1 = blocked.shape[1] * res, h * res
    v = v[(v[:, 0] >= 0) & (v[:, 0] <= x1) & (v[:, 1] >= 0) & (v[:, 1] <= y1)]
    v = v[np.hypot(*(v - v[0]).T) + np.hypot(*(v - v[1]).T) <= bound]
    i, j = np.triu_indices(len(v), k=1)
    lines = shapely.linestrings(np.stack([v[i], v[j]], axis=1))
    ok = ~shapely.relate_pattern(union, lines, "T********")
    w = np.hypot(*(v[i] - v[j]).T)[ok]
    graph = csr_array((w, (i[ok], j[ok])), shape=(len(v), len(v)))
    d = dijkstra(graph, directed=False, indices=0)[1]
    return float(d) if np.isfinite(d) else None


def _random_grid(rng, size=12, density=0.3, pinches=2):
    """Random cells, with a few diagonal pinches (two cells touching only at a corner)."""
    g = rng.random((size, size)) < density
    for _ in range(pinches):
        r, c = rng.integers(1, size - 2, 2)
        g[r : r + 2, c : c + 2] = [[True, False], [False, True]]
    g[-1, 0] = g[0, -1] = False  # start and goal cells
    return g


@pytest.mark.parametrize(("seed", "radius"), [(0, 0.0), (1, 0.0), (2, 0.0), (3, 0.25),
                                              pytest.param(4, 0.4, marks=pytest.mark.slow),
                                              (5, 0.7)])  # fmt: skip
def test_grid_maps_agree_with_brute_force(tmp_path, seed, radius):
    rng = np.random.default_rng(seed)
    blocked = _random_grid(rng)
    start, goal = (0.5, 0.5), (11.5, 11.5)
    if radius > 0:  # a disc robot needs room at the ends
        blocked[-2:, :2] = blocked[:2, -2:] = False
        start, goal = (1.0, 1.0), (11.0, 11.0)
    problem = _map_problem(tmp_path, blocked, start, goal, radius)
    result = shortest_path(problem)
    bound = result.length * 1.001 if result.found else math.inf
    brute = _map_brute_force(blocked, 1.0, radius, start, goal, bound=bound)
    if brute is None:
        assert not result.found
        return
    assert result.found
    world = World.from_problem(problem)
    assert world.path_valid(result.valid_polyline(world))
    # The brute force's polygons lie inside the grown cells: a lower bound, close to it.
    assert brute <= result.length * (1 + 1e-9) + 1e-6
    assert result.length <= brute * (1 + 1e-3) + 1e-6
    grid = grid_path(problem)
    if grid is not None:
        assert result.length <= path_length(grid) + 1e-9


def _maze(rng, n=6, corridor=1, wall=1) -> np.ndarray:
    """A perfect maze of n x n rooms (depth-first), corridors and walls in cells."""
    step = corridor + wall
    size = n * step + wall
    g = np.ones((size, size), bool)
    seen = np.zeros((n, n), bool)
    stack = [(0, 0)]
    seen[0, 0] = True
    g[wall : wall + corridor, wall : wall + corridor] = False
    while stack:
        i, j = stack[-1]
        nb = [(i + di, j + dj) for di, dj in ((0, 1), (1, 0), (0, -1), (-1, 0))
              if 0 <= i + di < n and 0 <= j + dj < n and not seen[i + di, j + dj]]  # fmt: skip
        if not nb:
            stack.pop()
            continue
        a, b = nb[rng.integers(len(nb))]
        seen[a, b] = True
        r0, c0 = wall + a * step, wall + b * step
        g[r0 : r0 + corridor, c0 : c0 + corridor] = False
        r, c = wall + min(i, a) * step, wall + min(j, b) * step
        if a != i:
            g[r + corridor : r + step, c : c + corridor] = False
        else:
            g[r : r + corridor, c + corridor : c + step] = False
        stack.append((a, b))
    return g


@pytest.mark.parametrize(("corridor", "radius"), [(1, 0.0), (2, 0.0), (3, 0.5)])
def test_mazes_agree_with_brute_force(tmp_path, corridor, radius):
    blocked = _maze(np.random.default_rng(corridor), 5, corridor)
    size = blocked.shape[0]
    start = (1 + corridor / 2, size - 1 - corridor / 2)  # the top-left room
    goal = (size - 1 - corridor / 2, 1 + corridor / 2)  # the bottom-right room
    problem = _map_problem(tmp_path, blocked, start, goal, radius)
    result = shortest_path(problem)
    brute = _map_brute_force(blocked, 1.0, radius, start, goal, bound=result.length * 1.001)
    assert result.found and brute is not None
    assert result.length > 1.15 * math.dist(start, goal)  # walls in the way
    assert brute <= result.length * (1 + 1e-9) + 1e-6 <= brute * (1 + 1e-3) + 2e-6


def test_the_pinch_between_two_cells_is_closed(tmp_path):
    """Two cells touching only at a corner close the diagonal for a point robot: the path goes
    round (the old formulation's semantics)."""
    blocked = np.zeros((6, 6), bool)
    blocked[1:3, 1:3] = True
    blocked[3:5, 3:5] = True  # touches the first block at (3, 3) only
    blocked[0, 5] = True
    # The squares [1, 3] x [3, 5] and [3, 5] x [1, 3]: from below-left of the pinch to above
    # right of it, the straight line runs through (3, 3).
    problem = _map_problem(tmp_path, blocked, (2.0, 2.0), (4.0, 4.0), 0.0)
    result = shortest_path(problem)
    brute = _map_brute_force(blocked, 1.0, 0.0, (2.0, 2.0), (4.0, 4.0))
    assert result.length > math.dist((2, 2), (4, 4)) + 0.1
    assert result.length == pytest.approx(brute, rel=1e-5)


@pytest.mark.parametrize("radius", [0.0, 0.6])
def test_the_lower_bounds_are_admissible(tmp_path, radius):
    """Against exact optima from random free points: the geodesic bound never exceeds the
    shortest path, and free segments always pass the step-count test."""
    from rrtpso_ompl.groundtruth.free_grid import FreeGrid

    blocked = _maze(np.random.default_rng(7), 5, 2)
    size = blocked.shape[0]
    goal = (size - 2.0, 2.0)
    problem = _map_problem(tmp_path, blocked, (2.0, size - 2.0), goal, radius)
    world = World.from_problem(problem)
    grid = FreeGrid.for_world(world, problem.start, goal)
    rng = np.random.default_rng(0)
    pts = rng.uniform(0, size, (400, 2))
    pts = pts[world.point_clearance(pts) >= world.threshold][:12]
    assert len(pts) >= 8
    lb = grid.lower_bound(1, pts)
    tight = 0
    for p, bound in zip(pts, lb, strict=True):
        doc = {"map": "m.yaml", "start": p.tolist(), "goal": list(goal),
               "robot": {"radius": radius}}  # fmt: skip
        query = problem_from_dict(doc, source=str(tmp_path / "q.yaml"), base=tmp_path)
        exact = shortest_path(query).length
        assert bound <= exact * (1 + 1e-12)
        tight += bound > math.dist(p, goal) + 1.0  # the geodesic part does work
    assert tight >= 3
    a = rng.uniform(0, size, (3000, 2))
    b = np.clip(a + rng.uniform(-5, 5, (3000, 2)), 0, size)  # short: some are free in a maze
    free = world.segments_free(a, b) & (world.point_clearance(a) >= world.threshold)
    assert free.sum() > 20
    ranges = grid.step_ranges(np.column_stack([np.vstack([a, b]), np.zeros(6000)]))
    d = np.abs(b - a)
    ok = grid.visible_pairs(ranges[:3000], ranges[3000:], d[:, 0], d[:, 1])
    assert ok[free].all() and not ok.all()  # never drops a free segment, and does prune


def test_bounded_rounds_find_the_unbounded_optimum(tmp_path):
    """Rounds of growing bounds, and a bound far too loose, give the same optimum."""
    blocked = _maze(np.random.default_rng(3), 5, 2)
    size = blocked.shape[0]
    problem = _map_problem(tmp_path, blocked, (2.0, size - 2.0), (size - 2.0, 2.0), 0.3)
    rounds = shortest_path(problem)
    free = shortest_path(problem, upper_bound=math.inf)
    assert rounds.length == pytest.approx(free.length, rel=1e-12)


def test_stopped_searches_say_so():
    problem = load_problem(PROBLEMS / "static" / "maze.yaml")
    calls = []

    def terminate() -> bool:
        calls.append(1)
        return len(calls) > 3

    result = shortest_path(problem, terminate=terminate)
    assert result.stopped and not result.found and result.length is None
    assert not shortest_path(problem).stopped


@pytest.mark.slow  # seconds of work: the full run only
def test_six_library_maps_keep_their_written_optima():
    """The optima written in the headers of problems/maps (computed by the old formulation)."""
    import re

    for path in sorted((PROBLEMS / "maps").glob("*.yaml")):
        text = path.read_text()
        written = float(re.search(r"Shortest collision-free path: ([0-9.]+)", text).group(1))
        result = shortest_path(load_problem(path))
        assert result.length == pytest.approx(written, abs=6e-5), path.stem


def test_a_search_that_adds_nodes_faster_than_it_expands_them(tmp_path):
    """A warehouse of 1-cell aisles: the first expansions add over 2,048 tangent nodes, and the
    record of expanded nodes once grew by only its own size (an IndexError, issue 37)."""
    from rrtpso_ompl.groundtruth.generate import generate_to_file

    path = generate_to_file("warehouse_map", 2, tmp_path / "w.yaml", cells=128, rack=2,
                            aisle=(1, 1), run=(10, 10), cross=(1, 1), robot_radius=0.0,
                            query=0)  # fmt: skip
    problem = load_problem(path)
    world = World.from_problem(problem)
    result = shortest_path(problem, world)
    assert result.found
    grid = grid_path(problem)
    assert result.length <= path_length(grid) + 1e-9
    assert world.path_valid(np.asarray(result.to_dict(world)["path"]))
    assert result.length == pytest.approx(84.51244267708103, rel=1e-9)
