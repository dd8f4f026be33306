"""Problem files: every shipped file loads, every bad input gets one clear ProblemError."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from conftest import PROBLEMS, SINGLE_CIRCLE
from hypothesis import given, settings
from hypothesis import strategies as st

from rrtpso_ompl.problem import Circle, Polygon, ProblemError, load_problem, problem_from_dict


@pytest.mark.parametrize("path", sorted(PROBLEMS.glob("*.yaml")), ids=lambda p: p.stem)
def test_shipped_problems_load(path):
    problem = load_problem(path)
    assert problem.name == path.stem
    assert problem.description and problem.robot.radius > 0
    assert problem.planner.type == "RRTstarPSO"


def test_paper_static_has_the_papers_robot():
    p = load_problem(PROBLEMS / "paper_static.yaml")
    assert p.bounds == ((0, 0), (500, 500)) and p.start == (20, 20) and p.goal == (450, 450)
    r = p.robot
    assert (r.radius, r.wheel_radius, r.track_width, r.sample_time) == (28.5, 7.6, 38, 0.15)
    assert r.radius == pytest.approx(1.5 * r.track_width / 2)
    assert "reconstruction" in p.description.lower()


def _with(**changes):
    data = yaml.safe_load(yaml.safe_dump(SINGLE_CIRCLE))
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


_DELETE = object()

# (id, document, the key the message must name, a fragment of the message)
BAD = [
    ("not-a-mapping", [1, 2], "", "mapping"),
    ("missing-bounds", _with(bounds=_DELETE), "bounds", "missing"),
    ("missing-robot-radius", _with(robot={}), "robot.radius", "missing"),
    ("unknown-top-key", _with(obstacle=[]), "obstacle", "did you mean 'obstacles'"),
    ("unknown-robot-key", _with(robot={"radius": 1, "radus": 2}), "robot.radus", "unknown"),
    ("negative-radius", _with(robot={"radius": -1}), "robot.radius", ">= 0"),
    ("string-radius", _with(robot={"radius": "big"}), "robot.radius", "number"),
    ("bool-radius", _with(robot={"radius": True}), "robot.radius", "number"),
    ("nan-radius", _with(robot={"radius": float("nan")}), "robot.radius", "finite"),
    ("zero-speed", _with(robot={"radius": 1, "speed": 0}), "robot.speed", "> 0"),
    ("bounds-inverted", _with(bounds=[[500, 0], [0, 500]]), "bounds", "xmin < xmax"),
    ("bounds-shape", _with(bounds=[0, 0, 500, 500]), "bounds", "[[xmin"),
    ("point-shape", _with(start=[1, 2, 3]), "start", "[x, y]"),
    ("start-outside", _with(start=[-5, 20]), "start", "outside the bounds"),
    ("goal-outside", _with(goal=[450, 501]), "goal", "outside the bounds"),
    ("start-in-obstacle", _with(start=[250, 250]), "start", "overlaps obstacles[0]"),
    ("goal-disc-overlaps", _with(goal=[250, 350]), "goal", "overlaps obstacles[0]"),
    ("negative-tolerance", _with(goal_tolerance=-1), "goal_tolerance", ">= 0"),
    ("circle-negative", _with(obstacles__0__radius=-3), "obstacles[0].radius", "> 0"),
    ("circle-zero", _with(obstacles__0__radius=0), "obstacles[0].radius", "> 0"),
    (
        "circle-no-center",
        _with(obstacles=[{"type": "circle", "radius": 3}]),
        "obstacles[0].center",
        "missing",
    ),
    (
        "obstacle-unknown-type",
        _with(obstacles=[{"type": "hexagon"}]),
        "obstacles[0].type",
        "circle, rectangle, polygon",
    ),
    (
        "obstacle-no-type",
        _with(obstacles=[{"center": [1, 1], "radius": 1}]),
        "obstacles[0].type",
        "missing",
    ),
    ("obstacle-not-mapping", _with(obstacles=[[1, 2]]), "obstacles[0]", "mapping"),
    ("obstacles-not-list", _with(obstacles={"type": "circle"}), "obstacles", "list"),
    (
        "rectangle-inverted",
        _with(obstacles=[{"type": "rectangle", "min": [10, 10], "max": [5, 20]}]),
        "obstacles[0]",
        "min < max",
    ),
    (
        "polygon-two-points",
        _with(obstacles=[{"type": "polygon", "points": [[0, 0], [1, 1]]}]),
        "obstacles[0].points",
        "at least 3",
    ),
    (
        "polygon-collinear",
        _with(obstacles=[{"type": "polygon", "points": [[0, 0], [1, 1], [2, 2]]}]),
        "obstacles[0].points",
        "collinear",
    ),
    (
        "polygon-bowtie",
        _with(obstacles=[{"type": "polygon", "points": [[0, 0], [10, 10], [0, 10], [10, 0]]}]),
        "obstacles[0].points",
        "not a simple polygon",
    ),
    (
        "moving-missing-speed",
        _with(moving_obstacles=[{"radius": 1, "start": [0, 0], "heading_deg": 0}]),
        "moving_obstacles[0].speed",
        "missing",
    ),
    (
        "moving-negative-speed",
        _with(moving_obstacles=[{"radius": 1, "start": [0, 0], "speed": -1, "heading_deg": 0}]),
        "moving_obstacles[0].speed",
        ">= 0",
    ),
    ("time-limit-zero", _with(planner={"time_limit": 0}), "planner.time_limit", "> 0"),
    ("time-limit-negative", _with(planner={"time_limit": -2}), "planner.time_limit", "> 0"),
    ("seed-negative", _with(planner={"seed": -1}), "planner.seed", "non-negative"),
    ("seed-float", _with(planner={"seed": 1.5}), "planner.seed", "integer"),
    ("planner-type-empty", _with(planner={"type": ""}), "planner.type", "non-empty"),
    ("params-not-mapping", _with(planner={"params": [1]}), "planner.params", "mapping"),
]


@pytest.mark.parametrize("doc,key,fragment", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_names_file_and_key(tmp_path, doc, key, fragment):
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ProblemError) as info:
        load_problem(path)
    err = info.value
    assert err.key == key
    assert str(err).startswith(f"{path}: ")
    assert fragment in err.message


@pytest.mark.parametrize(
    "text,fragment",
    [
        ("bounds: [[0, 0], [1, 1]\nstart: [0, 0]\n", "malformed YAML at line"),
        ("", "mapping"),
        ("- just\n- a list\n", "mapping"),
    ],
    ids=["unclosed-bracket", "empty", "list"],
)
def test_malformed_files(tmp_path, text, fragment):
    path = tmp_path / "m.yaml"
    path.write_text(text)
    with pytest.raises(ProblemError, match=fragment):
        load_problem(path)


def test_missing_and_binary_files(tmp_path):
    with pytest.raises(ProblemError, match="no such file"):
        load_problem(tmp_path / "absent.yaml")
    blob = tmp_path / "blob.yaml"
    blob.write_bytes(b"\xff\xfe\x00\x01")
    with pytest.raises(ProblemError):
        load_problem(blob)


def test_rectangles_and_polygons_are_stored_counter_clockwise():
    doc = _with(
        obstacles=[
            {"type": "rectangle", "min": [10, 300], "max": [60, 350]},
            {
                "type": "polygon",
                "points": [[400, 50], [400, 100], [450, 100], [450, 50], [400, 50]],
            },
        ]
    )
    rect, poly = problem_from_dict(doc).obstacles
    assert isinstance(rect, Polygon) and rect.kind == "rectangle" and len(rect.points) == 4
    assert poly.kind == "polygon" and len(poly.points) == 4  # closing vertex dropped

    def area(pts):
        return 0.5 * sum(
            x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1], strict=True)
        )

    assert area(rect.points) == pytest.approx(2500) and area(poly.points) == pytest.approx(2500)


def test_touching_start_is_allowed():
    """The robot disc may touch an obstacle exactly (clearance == radius)."""
    r = 80 + 28.5
    doc = _with(start=[250 - r, 250])
    assert problem_from_dict(doc).start == (250 - r, 250)
    with pytest.raises(ProblemError):
        problem_from_dict(_with(start=[250 - r + 1e-3, 250]))


def test_moving_obstacle_follows_eqs_14_15():
    doc = _with(
        moving_obstacles=[{"radius": 20, "start": [310, 250], "speed": 10, "heading_deg": 124}]
    )
    mo = problem_from_dict(doc).moving_obstacles[0]
    h = math.radians(124)
    assert np.allclose(mo.position(2.0), [310 + 20 * math.cos(h), 250 + 20 * math.sin(h)])
    # Eqs. 14-15 stepped at Ts = 0.15 s give the same point as the closed form.
    p = np.array([310.0, 250.0])
    for _ in range(20):
        p = p + 10 * np.array([math.cos(h), math.sin(h)]) * 0.15
    assert np.allclose(mo.position(20 * 0.15), p)
    assert mo.position(np.array([0.0, 1.0])).shape == (2, 2)


def test_dict_and_file_agree(tmp_path):
    path = tmp_path / "single_circle.yaml"
    path.write_text(yaml.safe_dump(SINGLE_CIRCLE))
    from_file = load_problem(path)
    from_dict = problem_from_dict(SINGLE_CIRCLE, source=str(path), name="ignored")
    assert from_file == from_dict
    assert from_file.obstacles == (Circle((250.0, 250.0), 80.0),)


JSONISH = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**6), 10**6)
    | st.floats(allow_nan=True)
    | st.text(max_size=5),
    lambda children: (
        st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4)
    ),
    max_leaves=12,
)
KEYS = [
    "bounds",
    "start",
    "goal",
    "robot",
    "robot.radius",
    "robot.speed",
    "obstacles",
    "obstacles.0",
    "obstacles.0.center",
    "obstacles.0.radius",
    "obstacles.0.type",
    "planner",
    "planner.params",
    "moving_obstacles",
    "goal_tolerance",
    "name",
]


@settings(max_examples=300, deadline=None)
@given(key=st.sampled_from(KEYS), junk=JSONISH)
def test_junk_anywhere_only_raises_problem_error(key, junk):
    data = yaml.safe_load(yaml.safe_dump(SINGLE_CIRCLE))
    parts = key.split(".")
    node = data
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
        if not isinstance(node, dict | list):
            return
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = junk
    else:
        node[last] = junk
    try:
        problem_from_dict(data, source="junk.yaml")
    except ProblemError as err:
        assert str(err).startswith("junk.yaml")


def test_robot_limits_are_optional_positive_numbers():
    doc = _with(robot={"radius": 28.5, "max_speed": 30, "max_wheel_speed": 25, "max_accel": 20})
    robot = problem_from_dict(doc).robot
    assert (robot.max_speed, robot.max_wheel_speed, robot.max_accel) == (30, 25, 20)
    with pytest.raises(ProblemError, match=r"robot\.max_accel"):
        problem_from_dict(_with(robot={"radius": 1, "max_accel": 0}))
