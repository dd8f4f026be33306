"""Problem files: every shipped file loads, every bad input gets one clear ProblemError."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import yaml
from helpers import PROBLEMS, SINGLE_CIRCLE
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rrtpso_ompl.errors import ArgumentError
from rrtpso_ompl.model.format import TOP
from rrtpso_ompl.model.problem import (
    Circle,
    MovingObstacle,
    Polygon,
    ProblemError,
    load_problem,
    problem_from_dict,
)
from rrtpso_ompl.model.world import World

SHIPPED = sorted(PROBLEMS.glob("*/*.yaml"))


# ----------------------------------------------------------------------------------------------
# The shipped problems
# ----------------------------------------------------------------------------------------------
def test_the_five_problems_are_shipped():
    names = {p.stem for p in SHIPPED}
    assert names >= {
        "paper_static",
        "single_circle",
        "narrow_passage",
        "cluttered_circles",
        "polygon_map",
    }


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_problems_load(path):
    problem = load_problem(path)
    assert problem.name == path.stem
    assert problem.description and problem.robot.radius >= 0
    # Start and goal are free for the planners' own collision checker too.
    world = World.from_problem(problem)
    for x, y in (problem.start, problem.goal):
        assert world.in_bounds(x, y) and world.point_free(x, y)


def test_paper_static_has_the_papers_robot():
    p = load_problem(PROBLEMS / "static" / "paper_static.yaml")
    assert p.bounds == ((0, 0), (500, 500)) and p.start == (20, 20) and p.goal == (450, 450)
    r = p.robot
    assert (r.radius, r.wheel_radius, r.track_width, r.sample_time) == (28.5, 7.6, 38, 0.15)
    assert (r.speed, r.sensor_range) == (20, 100)
    assert r.radius == pytest.approx(1.5 * r.track_width / 2)
    assert "reconstruction" in p.description.lower()


def test_single_circle_is_the_documented_one():
    p = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    assert p.obstacles == (Circle((250.0, 250.0), 80.0),)
    assert p.robot.radius == 28.5 and "647.45" in p.description


# ----------------------------------------------------------------------------------------------
# Bad input: one ProblemError naming the file and the key
# ----------------------------------------------------------------------------------------------
_DELETE = object()


def _with(**changes):
    """SINGLE_CIRCLE with changes at ``a__b__0``-style paths (``_DELETE`` removes the key)."""
    data = copy.deepcopy(SINGLE_CIRCLE)
    for dotted, value in changes.items():
        keys = dotted.split("__")
        node = data
        for k in keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        last = keys[-1]
        if value is _DELETE:
            del node[last]
        elif isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return data


def _obstacle(**fields):
    return _with(obstacles=[fields])


def _moving(**changes):
    mo = {"radius": 1, "start": [0, 0], "speed": 1, "heading_deg": 0, **changes}
    return _with(moving_obstacles=[{k: v for k, v in mo.items() if v is not _DELETE}])


# (id, document, the key the message must name, a fragment of the message)
BAD = [
    # the document and its top-level keys
    ("not-a-mapping", [1, 2], "", "mapping"),
    ("missing-bounds", _with(bounds=_DELETE), "bounds", "missing"),
    ("missing-start", _with(start=_DELETE), "start", "missing"),
    ("missing-goal", _with(goal=_DELETE), "goal", "missing"),
    ("missing-robot", _with(robot=_DELETE), "robot", "missing"),
    ("null-robot", _with(robot=None), "robot", "missing"),
    ("unknown-top-key", _with(obstacle=[]), "obstacle", "did you mean 'obstacles'"),
    ("non-string-top-key", {**SINGLE_CIRCLE, 3: 4}, "3", "unknown key"),
    ("name-empty", _with(name=""), "name", "non-empty"),
    ("name-number", _with(name=7), "name", "string"),
    ("description-list", _with(description=["a"]), "description", "string"),
    ("units-number", _with(units=1), "units", "string"),
    # numbers and points
    ("bounds-inverted", _with(bounds=[[500, 0], [0, 500]]), "bounds", "xmin < xmax"),
    ("bounds-flat", _with(bounds=[[0, 0], [500, 0]]), "bounds", "ymin < ymax"),
    ("bounds-shape", _with(bounds=[0, 0, 500, 500]), "bounds", "[[xmin"),
    ("bounds-string", _with(bounds="0 0 500 500"), "bounds", "[[xmin"),
    ("bounds-nested", _with(bounds=[[[0], 0], [500, 500]]), "bounds[0][0]", "number"),
    ("bounds-huge", _with(bounds=[[-1e308, 0], [1e308, 500]]), "bounds[0][0]", "within +-1e+09"),
    ("point-shape", _with(start=[1, 2, 3]), "start", "[x, y]"),
    ("point-scalar", _with(goal=450), "goal", "[x, y]"),
    ("point-string-coordinate", _with(start=[20, "20"]), "start[1]", "number"),
    ("point-null-coordinate", _with(start=[None, 20]), "start[0]", "number"),
    ("point-bool-coordinate", _with(start=[True, 20]), "start[0]", "number"),
    ("point-inf", _with(goal=[float("inf"), 20]), "goal[0]", "finite"),
    ("point-huge-int", _with(goal=[10**400, 20]), "goal[0]", "too large"),
    ("exponent-as-text", _with(goal=["4.5e2", 450]), "goal[0]", "write 450.0"),
    # start and goal in the workspace
    ("start-outside", _with(start=[-5, 20]), "start", "outside the bounds"),
    ("goal-outside", _with(goal=[450, 501]), "goal", "outside the bounds"),
    ("start-in-obstacle", _with(start=[250, 250]), "start", "overlaps obstacles[0]"),
    ("goal-disc-overlaps", _with(goal=[250, 350]), "goal", "overlaps obstacles[0] (circle)"),
    (
        "start-in-rectangle",
        _with(obstacles=[{"type": "rectangle", "min": [0, 0], "max": [10, 10]}]),
        "start",
        "overlaps obstacles[0] (rectangle)",
    ),
    (
        "point-robot-on-boundary",
        _with(
            robot={"radius": 0}, obstacles=[{"type": "rectangle", "min": [20, 0], "max": [30, 30]}]
        ),
        "start",
        "lies in or on obstacles[0]",
    ),
    ("negative-tolerance", _with(goal_tolerance=-1), "goal_tolerance", ">= 0"),
    ("string-tolerance", _with(goal_tolerance="0"), "goal_tolerance", "remove the quotes"),
    # the robot
    ("robot-not-mapping", _with(robot=28.5), "robot", "mapping"),
    ("missing-robot-radius", _with(robot={}), "robot.radius", "missing"),
    ("unknown-robot-key", _with(robot={"radius": 1, "radus": 2}), "robot.radus", "unknown"),
    ("robot-key-typo-hint", _with(robot={"radius": 1, "sped": 2}), "robot.sped", "'speed'"),
    ("negative-radius", _with(robot={"radius": -1}), "robot.radius", ">= 0"),
    ("string-radius", _with(robot={"radius": "big"}), "robot.radius", "number"),
    ("bool-radius", _with(robot={"radius": True}), "robot.radius", "number"),
    ("nan-radius", _with(robot={"radius": float("nan")}), "robot.radius", "finite"),
    ("list-radius", _with(robot={"radius": [28.5]}), "robot.radius", "number"),
    ("zero-speed", _with(robot={"radius": 1, "speed": 0}), "robot.speed", "> 0"),
    (
        "negative-wheel",
        _with(robot={"radius": 1, "wheel_radius": -7.6}),
        "robot.wheel_radius",
        "> 0",
    ),
    (
        "inf-track",
        _with(robot={"radius": 1, "track_width": float("inf")}),
        "robot.track_width",
        "finite",
    ),
    ("zero-sample-time", _with(robot={"radius": 1, "sample_time": 0}), "robot.sample_time", "> 0"),
    (
        "string-sensor",
        _with(robot={"radius": 1, "sensor_range": "far"}),
        "robot.sensor_range",
        "number",
    ),
    # obstacles
    ("obstacles-not-list", _with(obstacles={"type": "circle"}), "obstacles", "list"),
    ("obstacle-not-mapping", _with(obstacles=[[1, 2]]), "obstacles[0]", "mapping"),
    ("obstacle-no-type", _obstacle(center=[1, 1], radius=1), "obstacles[0].type", "missing"),
    (
        "obstacle-unknown-type",
        _obstacle(type="hexagon"),
        "obstacles[0].type",
        "circle, rectangle, polygon",
    ),
    ("obstacle-type-typo", _obstacle(type="circel"), "obstacles[0].type", "did you mean 'circle'"),
    ("obstacle-type-number", _obstacle(type=3), "obstacles[0].type", "unknown obstacle type"),
    ("circle-negative", _with(obstacles__0__radius=-3), "obstacles[0].radius", "> 0"),
    ("circle-zero", _with(obstacles__0__radius=0), "obstacles[0].radius", "> 0"),
    ("circle-no-center", _obstacle(type="circle", radius=3), "obstacles[0].center", "missing"),
    (
        "circle-key-typo",
        _obstacle(type="circle", centre=[1, 1], radius=1),
        "obstacles[0].centre",
        "did you mean 'center'",
    ),
    (
        "circle-with-rectangle-key",
        _obstacle(type="circle", center=[1, 1], radius=1, min=[0, 0]),
        "obstacles[0].min",
        "unknown key for a circle",
    ),
    (
        "circle-bad-center",
        _obstacle(type="circle", center=[1], radius=1),
        "obstacles[0].center",
        "[x, y]",
    ),
    (
        "rectangle-inverted",
        _obstacle(type="rectangle", min=[10, 10], max=[5, 20]),
        "obstacles[0]",
        "min < max",
    ),
    (
        "rectangle-flat",
        _obstacle(type="rectangle", min=[10, 10], max=[20, 10]),
        "obstacles[0]",
        "min < max",
    ),
    ("rectangle-no-max", _obstacle(type="rectangle", min=[10, 10]), "obstacles[0].max", "missing"),
    (
        "rectangle-with-radius",
        _obstacle(type="rectangle", min=[10, 10], max=[20, 20], radius=1),
        "obstacles[0].radius",
        "unknown key for a rectangle",
    ),
    ("polygon-no-points", _obstacle(type="polygon"), "obstacles[0].points", "missing"),
    (
        "polygon-points-mapping",
        _obstacle(type="polygon", points={"a": 1}),
        "obstacles[0].points",
        "list",
    ),
    (
        "polygon-two-points",
        _obstacle(type="polygon", points=[[0, 0], [1, 1]]),
        "obstacles[0].points",
        "at least 3",
    ),
    (
        "polygon-repeated-vertices",
        _obstacle(type="polygon", points=[[0, 0], [1, 1], [1, 1], [0, 0]]),
        "obstacles[0].points",
        "at least 3 distinct",
    ),
    (
        "polygon-collinear",
        _obstacle(type="polygon", points=[[0, 0], [1, 1], [2, 2]]),
        "obstacles[0].points",
        "collinear",
    ),
    (
        "polygon-bowtie",
        _obstacle(type="polygon", points=[[0, 0], [10, 10], [0, 10], [10, 0]]),
        "obstacles[0].points",
        "not a simple polygon",
    ),
    (
        "polygon-spike",
        _obstacle(
            type="polygon", points=[[100, 100], [200, 100], [300, 100], [200, 100], [200, 200]]
        ),
        "obstacles[0].points",
        "not a simple polygon",
    ),
    (
        "polygon-bad-vertex",
        _obstacle(type="polygon", points=[[0, 0], [1, 0], [1, "x"]]),
        "obstacles[0].points[2][1]",
        "number",
    ),
    (
        "polygon-huge",
        _obstacle(type="polygon", points=[[-1e308, -1e308], [1e308, -1e308], [1e308, 1e308]]),
        "obstacles[0].points[0][0]",
        "within +-1e+09",
    ),
    (
        "second-obstacle-named",
        _with(obstacles=[SINGLE_CIRCLE["obstacles"][0], {"type": "circle", "center": [1, 1]}]),
        "obstacles[1].radius",
        "missing",
    ),
    # moving obstacles
    ("moving-not-list", _with(moving_obstacles={"radius": 1}), "moving_obstacles", "list"),
    ("moving-missing-speed", _moving(speed=_DELETE), "moving_obstacles[0].speed", "missing"),
    ("moving-negative-speed", _moving(speed=-1), "moving_obstacles[0].speed", ">= 0"),
    ("moving-zero-radius", _moving(radius=0), "moving_obstacles[0].radius", "> 0"),
    (
        "moving-nan-heading",
        _moving(heading_deg=float("nan")),
        "moving_obstacles[0].heading_deg",
        "finite",
    ),
    (
        "moving-unknown-key",
        _moving(heading=3),
        "moving_obstacles[0].heading",
        "did you mean 'heading_deg'",
    ),
    # the goal heading: a number of degrees, as heading_deg
    ("goal-yaw-string", _with(goal_yaw="north"), "goal_yaw", "number"),
    ("goal-yaw-quoted", _with(goal_yaw="90"), "goal_yaw", "remove the quotes"),
    ("goal-yaw-nan", _with(goal_yaw=float("nan")), "goal_yaw", "finite"),
    ("goal-yaw-inf", _with(goal_yaw=float("-inf")), "goal_yaw", "finite"),
    ("goal-yaw-bool", _with(goal_yaw=True), "goal_yaw", "number"),
    ("goal-yaw-list", _with(goal_yaw=[0, 90]), "goal_yaw", "number"),
    # planner defaults
    ("planner-not-mapping", _with(planner="RRTstar"), "planner", "mapping"),
    (
        "planner-unknown-key",
        _with(planner={"time": 1}),
        "planner.time",
        "did you mean 'time_limit'",
    ),
    ("time-limit-zero", _with(planner={"time_limit": 0}), "planner.time_limit", "> 0"),
    ("time-limit-negative", _with(planner={"time_limit": -2}), "planner.time_limit", "> 0"),
    ("time-limit-inf", _with(planner={"time_limit": float("inf")}), "planner.time_limit", "finite"),
    ("time-limit-string", _with(planner={"time_limit": "1s"}), "planner.time_limit", "number"),
    ("seed-negative", _with(planner={"seed": -1}), "planner.seed", "must be >= 0"),
    ("seed-float", _with(planner={"seed": 1.5}), "planner.seed", "integer"),
    ("seed-bool", _with(planner={"seed": True}), "planner.seed", "integer"),
    ("seed-too-large", _with(planner={"seed": 2**32}), "planner.seed", "2**32 - 1"),
    ("planner-type-empty", _with(planner={"type": ""}), "planner.type", "non-empty"),
    ("planner-type-list", _with(planner={"type": ["RRTstar"]}), "planner.type", "string"),
    ("params-not-mapping", _with(planner={"params": [1]}), "planner.params", "mapping"),
    ("params-empty-list", _with(planner={"params": []}), "planner.params", "mapping"),
    ("params-int-keys", _with(planner={"params": {1: 2}}), "planner.params", "mapping"),
]


@pytest.mark.parametrize("doc,key,fragment", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_names_file_and_key(tmp_path, doc, key, fragment):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ProblemError) as info:
        load_problem(path)
    err = info.value
    assert err.key == key
    assert str(err).startswith(f"{path}: {key}: " if key else f"{path}: ")
    assert fragment in err.message
    assert "\n" not in str(err)  # one line on stderr


@pytest.mark.parametrize("doc,key,fragment", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_dict_input_is_checked_the_same_way(doc, key, fragment):
    with pytest.raises(ProblemError) as info:
        problem_from_dict(doc, source="mem")
    assert info.value.key == key and fragment in info.value.message
    assert str(info.value).startswith("mem: ")


# ----------------------------------------------------------------------------------------------
# What valid input becomes
# ----------------------------------------------------------------------------------------------
def _signed_area(pts):
    return 0.5 * sum(
        x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True)
    )


def test_rectangles_become_counter_clockwise_4_gons():
    doc = _with(obstacles=[{"type": "rectangle", "min": [10, 300], "max": [60, 350]}])
    (rect,) = problem_from_dict(doc).obstacles
    assert isinstance(rect, Polygon) and rect.kind == "rectangle"
    assert rect.points == ((10, 300), (60, 300), (60, 350), (10, 350))
    assert _signed_area(rect.points) == pytest.approx(2500)


def test_clockwise_polygons_are_reversed_and_closing_vertex_dropped():
    clockwise = [[400, 50], [400, 100], [450, 100], [450, 50], [400, 50]]
    doc = _with(obstacles=[{"type": "polygon", "points": clockwise}])
    (poly,) = problem_from_dict(doc).obstacles
    assert poly.kind == "polygon"
    assert poly.points == ((450, 50), (450, 100), (400, 100), (400, 50))
    assert _signed_area(poly.points) == pytest.approx(2500)


def test_counter_clockwise_polygons_are_kept_and_repeats_dropped():
    ccw = [[300, 50], [380, 60], [380, 60], [340, 120]]
    (poly,) = problem_from_dict(_with(obstacles=[{"type": "polygon", "points": ccw}])).obstacles
    assert poly.points == ((300, 50), (380, 60), (340, 120))


def test_non_convex_polygon_is_accepted():
    ell = [[0, 0], [100, 0], [100, 20], [20, 20], [20, 100], [0, 100]]
    doc = _with(start=[200, 20], obstacles=[{"type": "polygon", "points": ell}])
    (poly,) = problem_from_dict(doc).obstacles
    assert len(poly.points) == 6 and _signed_area(poly.points) == pytest.approx(3600)


def test_optional_keys_default_and_null_means_absent():
    doc = {k: SINGLE_CIRCLE[k] for k in ("bounds", "start", "goal", "robot")}
    p = problem_from_dict(doc, name="stem")
    assert p.name == "stem" and p.description == "" and p.units == ""
    assert p.goal_tolerance == 0.0 and p.obstacles == () and p.moving_obstacles == ()
    assert p.planner.type is None and p.planner.time_limit is None and p.planner.seed is None
    assert dict(p.planner.params) == {}
    assert p.goal_yaw is None
    nulls = dict.fromkeys(
        ("description", "units", "goal_tolerance", "goal_yaw", "obstacles", "moving_obstacles",
         "planner")
    )  # fmt: skip
    q = problem_from_dict({**doc, **nulls}, name="stem")
    assert q == p
    r = problem_from_dict({**doc, "planner": dict.fromkeys(("type", "time_limit", "seed"))})
    assert r.planner == p.planner


@pytest.mark.parametrize(
    ("written", "read"),
    [(90, 90.0), (-90.5, -90.5), (180, 180.0), (-180, 180.0), (540, 180.0), (270, -90.0),
     (-190, 170.0), (720, 0.0), (-0.0, 0.0), (1e300, math.remainder(1e300, 360.0)),
     (7.25e5, -40.0)],
)  # fmt: skip
def test_goal_yaw_is_degrees_normalised_to_the_half_open_circle(written, read):
    """Any finite number of degrees (as heading_deg), read as the same heading in (-180, 180]."""
    p = problem_from_dict(_with(goal_yaw=written), source="mem")
    assert p.goal_yaw == read and -180.0 < p.goal_yaw <= 180.0
    assert math.copysign(1.0, p.goal_yaw) == 1.0 or p.goal_yaw < 0  # no -0.0


def test_name_defaults_to_the_file_stem(tmp_path):
    doc = _with(name=_DELETE)
    path = tmp_path / "my_problem.yaml"
    path.write_text(yaml.safe_dump(doc))
    assert load_problem(path).name == "my_problem"
    assert problem_from_dict(doc).name == "problem"


def test_planner_block_is_read():
    doc = _with(planner={"type": "RRTstar", "time_limit": 2, "seed": 7, "params": {"range": 30}})
    cfg = problem_from_dict(doc).planner
    assert (cfg.type, cfg.time_limit, cfg.seed) == ("RRTstar", 2.0, 7)
    assert cfg.params == {"range": 30}
    with pytest.raises(TypeError):
        cfg.params["range"] = 1  # read-only
    # The loader does not judge planner names: plugins may register more.
    assert (
        problem_from_dict(_with(planner={"type": "NoSuchPlanner"})).planner.type == "NoSuchPlanner"
    )


def test_robot_drive_parameters_and_limits_are_optional_positive_numbers():
    robot = {"radius": 28.5, "wheel_radius": 7.6, "track_width": 38, "speed": 20}
    robot |= {"sample_time": 0.15, "sensor_range": 100}
    robot |= {"max_speed": 30, "max_wheel_speed": 25, "max_accel": 20}
    r = problem_from_dict(_with(robot=robot)).robot
    assert (r.wheel_radius, r.track_width, r.speed, r.sample_time) == (7.6, 38, 20, 0.15)
    assert (r.sensor_range, r.max_speed, r.max_wheel_speed, r.max_accel) == (100, 30, 25, 20)
    with pytest.raises(ProblemError, match=r"robot\.max_accel"):
        problem_from_dict(_with(robot={"radius": 1, "max_accel": 0}))


def test_point_robot_start_equal_goal_and_moving_obstacles_outside_are_fine():
    doc = _with(
        robot={"radius": 0},
        goal=[20, 20],
        goal_tolerance=5,
        moving_obstacles=[{"radius": 20, "start": [-100, 900], "speed": 0, "heading_deg": -45}],
    )
    p = problem_from_dict(doc)
    assert p.robot.radius == 0 and p.start == p.goal and p.goal_tolerance == 5
    assert p.moving_obstacles[0].start == (-100, 900)


def test_numpy_numbers_are_numbers():
    doc = _with(
        start=[np.float64(20), np.int64(20)],
        goal=np.array([450.0, 450.0]).tolist(),
        planner={"seed": np.uint32(3)},
    )
    p = problem_from_dict(doc)
    assert p.start == (20.0, 20.0) and p.planner.seed == 3 and type(p.planner.seed) is int


def test_touching_start_is_allowed():
    """The robot disc may touch an obstacle exactly (clearance == radius)."""
    r = 80 + 28.5
    doc = _with(start=[250 - r, 250])
    assert problem_from_dict(doc).start == (250 - r, 250)
    with pytest.raises(ProblemError):
        problem_from_dict(_with(start=[250 - r + 1e-3, 250]))


def test_overlap_message_reports_the_clearance():
    with pytest.raises(ProblemError) as info:
        problem_from_dict(_with(start=[180, 180]), source="f.yaml")
    d = math.hypot(70, 70) - 80
    assert str(info.value) == (
        f"f.yaml: start: the robot disc (radius 28.5) at (180, 180) overlaps obstacles[0] "
        f"(circle): clearance {d:.4g} < 28.5"
    )


_OBSTACLES = [
    {"type": "circle", "center": [250, 250], "radius": 80},
    {"type": "rectangle", "min": [60, 300], "max": [160, 340]},
    {"type": "polygon", "points": [[300, 50], [380, 60], [340, 120]]},
    {"type": "polygon", "points": [[380, 300], [480, 300], [480, 320], [400, 320], [400, 400]]},
]


@settings(max_examples=300, deadline=None)
@given(
    x=st.floats(0, 500),
    y=st.floats(0, 500),
    radius=st.sampled_from([0.0, 5.0, 28.5]),
)
def test_free_start_agrees_with_the_planners_world(x, y, radius):
    """A start the loader accepts is exactly one the planners' collision checker calls free."""
    doc = _with(start=[x, y], goal=[0, 500], robot={"radius": radius}, obstacles=_OBSTACLES)
    world = World.from_problem(
        problem_from_dict(_with(robot={"radius": radius}, obstacles=_OBSTACLES))
    )
    try:
        problem_from_dict(doc)
        accepted = True
    except ProblemError as err:
        assert err.key == "start"
        accepted = False
    if accepted != world.point_free(x, y):
        # Only a hair's breadth from touching may the two exact computations round differently.
        clearance = float(world.point_clearance(np.array([[x, y]]))[0])
        assert clearance == pytest.approx(world.threshold, abs=1e-9)


def test_moving_obstacle_follows_eqs_14_15():
    doc = _with(
        moving_obstacles=[{"radius": 20, "start": [310, 250], "speed": 10, "heading_deg": 124}]
    )
    mo = problem_from_dict(doc).moving_obstacles[0]
    assert mo == MovingObstacle(radius=20, start=(310, 250), speed=10, heading_deg=124)
    h = math.radians(124)
    # x = x0 + v cos(h) t, y = y0 + v sin(h) t
    assert np.allclose(mo.position(2.0), [310 + 20 * math.cos(h), 250 + 20 * math.sin(h)])
    assert np.allclose(mo.velocity, [10 * math.cos(h), 10 * math.sin(h)])
    # Eqs. 14-15 stepped at Ts = 0.15 s give the same point as the closed form.
    p = np.array([310.0, 250.0])
    for _ in range(20):
        p = p + 10 * np.array([math.cos(h), math.sin(h)]) * 0.15
    assert np.allclose(mo.position(20 * 0.15), p)
    assert mo.position(np.array([0.0, 1.0])).shape == (2, 2)
    assert np.allclose(mo.position(0.0), [310, 250])


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_dict_and_file_agree(tmp_path, path):
    data = yaml.safe_load(path.read_text())
    assert load_problem(path) == problem_from_dict(data, source=str(path), name=path.stem)
    # And a problem written back out loads to the same thing (a map path made absolute).
    if isinstance(data.get("map"), str):
        data["map"] = str(path.parent / data["map"])
    copy_path = tmp_path / path.name
    copy_path.write_text(yaml.safe_dump(data))
    from_copy = load_problem(copy_path)
    assert from_copy == problem_from_dict(data, source=str(copy_path), name="ignored")


# ----------------------------------------------------------------------------------------------
# Junk anywhere: only ever a ProblemError
# ----------------------------------------------------------------------------------------------
JSONISH = st.recursive(
    st.none()
    | st.booleans()
    | st.integers()
    | st.integers(-(10**400), 10**400)
    | st.floats(allow_nan=True)
    | st.text(max_size=5)
    | st.sampled_from(["circle", "rectangle", "polygon", "1e3", "28.5", ""]),
    lambda children: (
        st.lists(children, max_size=4)
        | st.dictionaries(
            st.text(max_size=6) | st.sampled_from(["type", "center", "radius", "points"]),
            children,
            max_size=4,
        )
    ),
    max_leaves=12,
)
KEYS = [
    "",
    "bounds",
    "bounds.0",
    "bounds.1.0",
    "start",
    "start.0",
    "goal",
    "goal.1",
    "robot",
    "robot.radius",
    "robot.speed",
    "robot.wheel_radius",
    "robot.radus",
    "obstacles",
    "obstacles.0",
    "obstacles.0.center",
    "obstacles.0.center.1",
    "obstacles.0.radius",
    "obstacles.0.type",
    "obstacles.0.points",
    "planner",
    "planner.type",
    "planner.seed",
    "planner.time_limit",
    "planner.params",
    "moving_obstacles",
    "goal_tolerance",
    "name",
    "description",
    "units",
    "junk",
]


def _put(data, key, junk):
    """Put ``junk`` at a dotted path (``""`` is the whole document).

    Missing mappings on the way are created; a path that an earlier put has made impossible
    (a list that became shorter, a mapping that became a number) is left alone.
    """
    if not key:
        return junk
    *parents, last = key.split(".")
    node = data
    try:
        for p in parents:
            node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
        node[int(last) if isinstance(node, list) else last] = junk
    except (IndexError, TypeError, AttributeError, ValueError):
        pass
    return data


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(puts=st.lists(st.tuples(st.sampled_from(KEYS), JSONISH), min_size=1, max_size=3))
def test_junk_anywhere_only_raises_problem_error(puts):
    data = copy.deepcopy(SINGLE_CIRCLE)
    for key, junk in puts:
        data = _put(data, key, junk)
    try:
        problem_from_dict(data, source="junk.yaml")
    except ProblemError as err:
        assert str(err).startswith("junk.yaml")


@settings(max_examples=300, deadline=None)
@given(
    where=st.integers(0, 10_000),
    junk=st.text(max_size=12)
    | st.sampled_from(["[", "]", "{", ": ", "\n  - ", "&a ", "*a", "!!int ", "? ", "\t", "'"]),
)
def test_junk_text_only_raises_problem_error(tmp_path_factory, where, junk):
    text = (PROBLEMS / "static" / "paper_static.yaml").read_text()
    where %= len(text) + 1
    path = tmp_path_factory.mktemp("junk") / "junk.yaml"
    path.write_text(text[:where] + junk + text[where:], encoding="utf-8", errors="surrogatepass")
    try:
        load_problem(path)
    except ProblemError as err:
        assert str(err).startswith(f"{path}: ")


#: Every key of the format, and a few that are not.
_FORMAT_KEYS = sorted({*TOP.names(), "radius", "center", "type", "min", "max", "points", "speed",
                       "heading_deg", "params", "seed", "time_limit", "x"})  # fmt: skip
_YAMLISH = st.recursive(
    st.none() | st.booleans() | st.integers(-(2**70), 2**70) | st.floats()
    | st.text(max_size=8) | st.sampled_from(["circle", "rectangle", "polygon"]),
    lambda inner: st.lists(inner, max_size=4)
    | st.dictionaries(st.sampled_from(_FORMAT_KEYS), inner, max_size=5),
    max_leaves=25,
)  # fmt: skip


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(doc=_YAMLISH)
def test_generated_yaml_documents_only_raise_problem_error(tmp_path_factory, doc):
    """Whole documents of the format's keys and random values, written by PyYAML and read back
    by the loader: a Problem or one short ProblemError, nothing else."""
    path = tmp_path_factory.mktemp("gen") / "gen.yaml"
    path.write_text(yaml.safe_dump(doc, allow_unicode=True))
    try:
        load_problem(path)
    except ProblemError as err:
        assert str(err).startswith(f"{path}") and len(str(err)) < 600


def test_a_problem_knows_every_file_it_was_read_from(tmp_path):
    """Problem.inputs (after loading) and input_files (without loading) name the problem file,
    its map YAML and the map's image, resolved through links: the outputs must avoid them all."""
    import os
    import shutil

    from rrtpso_ompl.model.problem import input_files

    shutil.copytree(PROBLEMS / "maps", tmp_path / "maps")
    (tmp_path / "maps/link.yaml").symlink_to("office_corridor.yaml")
    grids = tmp_path / "maps" / "grids"
    (grids / "office.pgm").rename(grids / "real.pgm")
    (grids / "office.pgm").symlink_to("real.pgm")
    want = tuple(
        os.path.realpath(p)
        for p in (tmp_path / "maps/office_corridor.yaml", grids / "office.yaml", grids / "real.pgm")
    )
    assert load_problem(tmp_path / "maps/link.yaml").inputs == want
    assert input_files(tmp_path / "maps/link.yaml") == want
    assert load_problem(PROBLEMS / "static" / "single_circle.yaml").inputs == (
        str(PROBLEMS / "static" / "single_circle.yaml"),
    )
    # Best effort: what cannot be read is left out (loading the problem reports it).
    (tmp_path / "bad.yaml").write_text("map: [")
    assert input_files(tmp_path / "bad.yaml") == (str(tmp_path / "bad.yaml"),)


# ----------------------------------------------------------------------------------------------
# Issue 22: arguments of the wrong kind, and exactness at every scale
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", [None, 3, ["p.yaml"]])
def test_load_problem_of_something_that_is_not_a_path(path):
    with pytest.raises(ArgumentError, match="load_problem: path must be a file name"):
        load_problem(path)


def test_problem_from_dict_names_its_source_with_a_string():
    with pytest.raises(ArgumentError, match="source must be a str"):
        problem_from_dict(SINGLE_CIRCLE, source=None)
    with pytest.raises(ArgumentError, match="name must be a str"):
        problem_from_dict(SINGLE_CIRCLE, name=5)


def test_a_micrometre_workspace_is_as_exact_as_any():
    """The round-off allowance is 1e-9 of the workspace's scale (1e-15 here), as the docs say:
    a start 5e-10 inside an obstacle's safety zone overlaps it (the old absolute 1e-9 floor
    accepted it), one 5e-10 outside is free."""
    doc = {"bounds": [[0, 0], [1e-6, 1e-6]], "goal": [9e-7, 9e-7], "robot": {"radius": 5e-8},
           "obstacles": [{"type": "circle", "center": [5e-7, 5e-7], "radius": 1e-7}]}  # fmt: skip
    with pytest.raises(ProblemError, match="overlaps obstacles"):
        problem_from_dict({**doc, "start": [5e-7 + 1.5e-7 - 5e-10, 5e-7]})
    assert problem_from_dict({**doc, "start": [5e-7 + 1.5e-7 + 5e-10, 5e-7]})


def test_a_workspace_far_from_the_origin_needs_sides_relative_to_its_coordinates():
    """Far from the origin the round-off allowance grows with the coordinates: a side must stay
    a thousand allowances long."""
    doc = {**SINGLE_CIRCLE, "obstacles": [], "robot": {"radius": 0}}
    far = {**doc, "bounds": [[1e6, 1e6], [1e6 + 0.5, 1e6 + 0.5]], "start": [1e6 + 0.1, 1e6 + 0.1],
           "goal": [1e6 + 0.4, 1e6 + 0.4]}  # fmt: skip
    with pytest.raises(ProblemError, match=r"at least 1 \(1e-06 of its coordinates' magnitude"):
        problem_from_dict(far)
    far["bounds"] = [[1e6, 1e6], [1e6 + 2, 1e6 + 2]]
    assert problem_from_dict(far).bounds[1] == (1e6 + 2, 1e6 + 2)
