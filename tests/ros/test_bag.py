"""ROS 2 bags (``--bag``) read back with ``rosbags``: topics, types, counts, stamps, metres, the
map cell by cell, the markers, a simulation's clock, and whole-or-nothing writing."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import PROBLEMS, _map

from rrtpso_ompl.errors import OutputError
from rrtpso_ompl.model import load_problem
from rrtpso_ompl.ros import RosFrame
from rrtpso_ompl.ros.bag import (
    MCAP_MAGIC,
    TOPICS,
    WHEEL_JOINTS,
    commands,
    write_plan_bag,
    write_simulation_bag,
)

FORMATS = ["run.mcap", "run_bag"]  # one MCAP file; a sqlite3 bag directory
PLAN_TOPICS = {"/obstacles", "/initialpose", "/goal_pose", "/plan"}


def read_bag(path: Path) -> tuple[dict, dict]:
    """``{topic: [(log time ns, message), ...]}`` and ``{topic: connection}`` of a bag."""
    from rosbags.highlevel import AnyReader

    out: dict[str, list] = {}
    with AnyReader([path]) as reader:
        conns = {c.topic: c for c in reader.connections}
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    return out, conns


def xy_yaw(pose) -> tuple[float, float, float]:
    q = pose.orientation
    assert q.x == 0.0 and q.y == 0.0
    assert q.z**2 + q.w**2 == pytest.approx(1.0)
    return pose.position.x, pose.position.y, 2.0 * math.atan2(q.z, q.w)


def triangles_area(tri: np.ndarray) -> float:
    """Total area of (k, 3, 2) triangles."""
    a, b = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    return float(0.5 * np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum())


# ----------------------------------------------------------------------------------------------
# A plan: solve and optimum
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", FORMATS)
def test_a_plan_bag_has_the_scene_and_the_plan_in_metres(tmp_path, name):
    problem = load_problem(PROBLEMS / "static" / "paper_static.yaml")  # units: cm
    frame = RosFrame.for_problem(problem)
    path = np.array([problem.start, [250.0, 40.0], [470.0, 200.0], problem.goal])
    out = tmp_path / name
    write_plan_bag(problem, frame, path, out)
    if name.endswith(".mcap"):
        assert out.is_file() and out.read_bytes()[:8] == MCAP_MAGIC
    else:
        assert sorted(p.name for p in out.iterdir()) == ["metadata.yaml", "run_bag.db3"]
    assert [p.name for p in tmp_path.iterdir()] == [name]  # no temporary left beside it
    msgs, conns = read_bag(out)
    assert set(msgs) == PLAN_TOPICS  # no map: no /map
    for topic, conn in conns.items():
        assert conn.msgtype == TOPICS[topic][0]
        assert conn.msgcount == len(msgs[topic]) == 1
        ((t, msg),) = msgs[topic]
        assert t == 0
        if hasattr(msg, "header"):
            assert msg.header.frame_id == "map" and msg.header.stamp.sec == 0
    durability = {t: c.ext.offered_qos_profiles[0].durability.name for t, c in conns.items()}
    assert durability["/obstacles"] == "TRANSIENT_LOCAL" and durability["/plan"] == "VOLATILE"

    plan = msgs["/plan"][0][1]
    poses = np.array([xy_yaw(p.pose) for p in plan.poses])
    # Metres: every waypoint (cm) is a pose at a hundredth of it; spacing at most 5 cm.
    for w in path / 100.0:
        assert np.hypot(*(poses[:, :2] - w).T).min() < 1e-12
    gaps = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    assert gaps.max() <= frame.resolution + 1e-12 and frame.resolution == 0.05
    seg = np.diff(path, axis=0)
    assert poses[0, 2] == pytest.approx(math.atan2(seg[0, 1], seg[0, 0]))
    assert poses[-1, 2] == pytest.approx(math.atan2(seg[-1, 1], seg[-1, 0]))
    x, y, yaw = xy_yaw(msgs["/initialpose"][0][1].pose.pose)
    assert (x, y) == (0.2, 0.2) and yaw == pytest.approx(poses[0, 2])
    assert not msgs["/initialpose"][0][1].pose.covariance.any()  # the start is known exactly
    x, y, yaw = xy_yaw(msgs["/goal_pose"][0][1].pose)
    assert (x, y) == (4.5, 4.5) and yaw == pytest.approx(poses[-1, 2])


def test_the_goal_heading_and_frame_id_reach_the_bag(tmp_path):
    problem = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    frame = RosFrame(scale=0.01, resolution=0.2, frame_id="world", goal_yaw=math.radians(-90))
    out = tmp_path / "g.mcap"
    write_plan_bag(problem, frame, np.array([problem.start, [20, 450], problem.goal]), out)
    msgs, _ = read_bag(out)
    plan = msgs["/plan"][0][1]
    assert plan.header.frame_id == "world"
    assert xy_yaw(plan.poses[-1].pose)[2] == pytest.approx(-math.pi / 2)
    assert xy_yaw(msgs["/goal_pose"][0][1].pose)[2] == pytest.approx(-math.pi / 2)
    assert {m.header.frame_id for m in msgs["/obstacles"][0][1].markers} == {"world"}


def test_an_unsolved_problem_gets_the_scene_without_a_plan(tmp_path):
    problem = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    out = tmp_path / "u.mcap"
    write_plan_bag(problem, RosFrame.for_problem(problem), None, out)
    msgs, _ = read_bag(out)
    assert set(msgs) == PLAN_TOPICS - {"/plan"}
    # Without a plan the robot faces the goal.
    sx, sy = problem.start
    gx, gy = problem.goal
    assert xy_yaw(msgs["/initialpose"][0][1].pose.pose)[2] == pytest.approx(
        math.atan2(gy - sy, gx - sx)
    )


def test_obstacle_markers_have_the_shapes_sizes_and_safety_zones(tmp_path):
    import shapely

    problem = load_problem(PROBLEMS / "static" / "paper_static.yaml")
    out = tmp_path / "o.mcap"
    write_plan_bag(problem, RosFrame.for_problem(problem), None, out)
    markers = read_bag(out)[0]["/obstacles"][0][1].markers
    from rosbags.typesys import Stores, get_typestore

    Marker = get_typestore(Stores.ROS2_HUMBLE).types["visualization_msgs/msg/Marker"]
    assert markers[0].action == Marker.DELETEALL  # clears what an earlier bag drew
    by_ns: dict[str, list] = {}
    for m in markers[1:]:
        assert m.action == Marker.ADD
        by_ns.setdefault(m.ns, []).append(m)
    for ns, group in by_ns.items():
        assert [m.id for m in group] == list(range(len(group))), ns  # unique ids per namespace
    circles = [o for o in problem.obstacles if o.kind == "circle"]
    polygons = [o for o in problem.obstacles if o.kind != "circle"]
    robot_r = problem.robot.radius
    assert len(by_ns["circles"]) == len(circles) == 9
    for m, c in zip(by_ns["circles"], circles, strict=True):
        assert m.type == Marker.CYLINDER
        assert (m.scale.x, m.scale.y) == pytest.approx((0.02 * c.radius, 0.02 * c.radius))
        assert (m.pose.position.x, m.pose.position.y) == pytest.approx(np.array(c.center) / 100)
        assert m.color.a == 1.0
    zones = by_ns["safety"]
    assert len(zones) == len(circles) + len(polygons)
    for m, c in zip(zones[: len(circles)], circles, strict=True):
        assert m.type == Marker.CYLINDER and m.scale.x == pytest.approx(0.02 * (c.radius + robot_r))
        assert 0.0 < m.color.a < 1.0  # translucent
    outlines, fills = by_ns["polygons"], by_ns["polygon_fill"]
    assert len(outlines) == len(fills) == len(polygons) == 3
    for line, fill, poly in zip(outlines, fills, polygons, strict=True):
        assert line.type == Marker.LINE_STRIP and fill.type == Marker.TRIANGLE_LIST
        ring = np.array([(p.x, p.y) for p in line.points])
        assert np.allclose(ring[:-1], np.array(poly.points) / 100) and np.all(ring[0] == ring[-1])
        tri = np.array([(p.x, p.y) for p in fill.points]).reshape(-1, 3, 2)
        assert triangles_area(tri) == pytest.approx(shapely.Polygon(poly.points).area / 1e4)
    for m, poly in zip(zones[len(circles) :], polygons, strict=True):  # the grown polygons
        tri = np.array([(p.x, p.y) for p in m.points]).reshape(-1, 3, 2)
        grown = shapely.Polygon(poly.points).buffer(robot_r, quad_segs=8).area / 1e4
        assert triangles_area(tri) == pytest.approx(grown)
    assert len(by_ns["robot"]) == 2  # the robot's disc at start and goal
    assert by_ns["robot"][0].scale.x == pytest.approx(0.02 * robot_r)


# ----------------------------------------------------------------------------------------------
# The map, cell by cell
# ----------------------------------------------------------------------------------------------
def read_pgm(path: Path) -> np.ndarray:
    """An 8-bit binary PGM, read here independently of the package."""
    data = path.read_bytes()
    tokens, pos = [], 0
    while len(tokens) < 4:  # magic, width, height, maxval; comments from '#' to end of line
        while data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        tokens.append(data[pos:end])
        pos = end
    assert tokens[0] == b"P5" and int(tokens[3]) == 255
    w, h = int(tokens[1]), int(tokens[2])
    return np.frombuffer(data[pos + 1 : pos + 1 + w * h], dtype=np.uint8).reshape(h, w)


def expected_trinary(grey: np.ndarray, occ: float, free: float) -> np.ndarray:
    p = (255.0 - grey) / 255.0
    out = np.full(grey.shape, -1, dtype=np.int8)
    out[p <= free] = 0
    out[p >= occ] = 100
    return out


def test_the_office_map_is_published_as_map_server_would(tmp_path):
    problem = load_problem(PROBLEMS / "maps" / "office_corridor.yaml")
    out = tmp_path / "office_bag"
    write_plan_bag(problem, RosFrame.for_problem(problem), None, out)
    msgs, conns = read_bag(out)
    assert conns["/map"].ext.offered_qos_profiles[0].durability.name == "TRANSIENT_LOCAL"
    assert conns["/map"].ext.offered_qos_profiles[0].depth == 1
    grid = msgs["/map"][0][1]
    grey = read_pgm(PROBLEMS / "maps" / "grids" / "office.pgm")
    h, w = grey.shape
    assert (grid.info.width, grid.info.height) == (w, h) == (600, 400)
    assert grid.info.resolution == pytest.approx(0.05)
    assert xy_yaw(grid.info.origin) == (0.0, 0.0, 0.0)
    assert grid.header.frame_id == "map"
    # Row 0 of the message is the image's last row.
    data = np.asarray(grid.data).reshape(h, w)
    expected = expected_trinary(grey, 0.65, 0.196)[::-1]
    assert np.array_equal(data, expected)
    assert {0, 100, -1} <= set(np.unique(data).tolist())  # free, occupied and unknown cells


def _map_problem(tmp_path, img, start, goal, **keys) -> Path:
    """A problem on the map ``img`` (0.5 m cells), unknown cells free."""
    _map(tmp_path, img, **keys)
    prob = tmp_path / "p.yaml"
    prob.write_text(
        json.dumps(
            {
                "map": {"file": "m.yaml", "unknown": "free"},
                "start": start,
                "goal": goal,
                "robot": {"radius": 0.2},
            }
        )
    )
    return prob


def test_an_offset_map_with_nav2_thresholds_keeps_its_origin_and_rows(tmp_path):
    # map_saver's origin [-10, -5, 0] and Nav2's free_thresh 0.25, under which grey 205 is free.
    img = np.full((10, 12), 254, dtype=np.uint8)
    img[0, :] = 0  # the top row: occupied; must be the message's *last* row
    img[5, 3:6] = 205
    img[8, 9] = 100  # occupancy 0.61: unknown
    prob = _map_problem(
        tmp_path, img, [-8.75, -3.75], [-6.25, -1.25], origin=[-10.0, -5.0, 0.0], free_thresh=0.25
    )
    problem = load_problem(prob)
    out = tmp_path / "b.mcap"
    write_plan_bag(problem, RosFrame.for_problem(problem), None, out)
    grid = read_bag(out)[0]["/map"][0][1]
    assert (grid.info.origin.position.x, grid.info.origin.position.y) == (-10.0, -5.0)
    assert grid.info.resolution == 0.5
    data = np.asarray(grid.data).reshape(10, 12)
    assert np.array_equal(data, expected_trinary(img, 0.65, 0.25)[::-1])
    assert np.all(data[-1] == 100) and np.all(data[4, 3:6] == 0) and data[1, 9] == -1


def test_a_turned_map_is_published_with_its_yaw_and_unturned_cells(tmp_path):
    # map_server turns the image about its lower-left corner: the message keeps the cells in
    # their rows and says the turn in the origin's orientation.
    img = np.full((10, 12), 254, dtype=np.uint8)
    img[0, :] = 0
    prob = _map_problem(tmp_path, img, [1.0, 1.0], [2.0, 2.0], origin=[0.0, 0.0, 0.3])
    problem = load_problem(prob)
    out = tmp_path / "turned.mcap"
    write_plan_bag(problem, RosFrame.for_problem(problem), None, out)
    grid = read_bag(out)[0]["/map"][0][1]
    assert xy_yaw(grid.info.origin) == pytest.approx((0.0, 0.0, 0.3))
    data = np.asarray(grid.data).reshape(10, 12)
    assert np.array_equal(data, expected_trinary(img, 0.65, 0.196)[::-1])


def test_scale_and_raw_maps_keep_the_values_between_the_thresholds(tmp_path):
    grey = np.array([[0, 50, 100, 150], [200, 230, 254, 120]], dtype=np.uint8)
    prob = _map_problem(tmp_path, np.tile(grey, (3, 3)), [1.25, 2.25], [3.25, 1.25], mode="scale")
    problem = load_problem(prob)
    write_plan_bag(problem, RosFrame.for_problem(problem), None, tmp_path / "s.mcap")
    data = np.asarray(read_bag(tmp_path / "s.mcap")[0]["/map"][0][1].data).reshape(6, 12)
    p = (255.0 - np.tile(grey, (3, 3))) / 255.0
    want = np.rint((p - 0.196) / (0.65 - 0.196) * 100).clip(0, 100)
    want[p >= 0.65], want[p <= 0.196] = 100, 0
    assert np.array_equal(data, want[::-1].astype(np.int8))
    assert set(np.unique(data).tolist()) - {0, 100}  # values in between exist

    raw = np.array([[0, 40, 100, 101, 255, 7]], dtype=np.uint8)
    (tmp_path / "s.mcap").unlink()
    prob = _map_problem(tmp_path, np.tile(raw, (6, 2)), [0.25, 1.75], [5.75, 1.75], mode="raw")
    problem = load_problem(prob)
    write_plan_bag(problem, RosFrame.for_problem(problem), None, tmp_path / "r.mcap")
    data = np.asarray(read_bag(tmp_path / "r.mcap")[0]["/map"][0][1].data).reshape(6, 12)
    assert data[0].tolist() == [0, 40, 100, -1, -1, 7] * 2


# ----------------------------------------------------------------------------------------------
# A simulation, on its own clock
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def head_on():
    from rrtpso_ompl.dynamic import DynamicOptions, simulate

    problem = load_problem(PROBLEMS / "dynamic" / "head_on.yaml")
    path = np.array([problem.start, problem.goal])
    sim = simulate(problem, DynamicOptions(replan_time=0.05), seed=2, initial_path=path)
    assert sim.reached_goal and sim.replans
    return problem, sim


@pytest.mark.parametrize("name", FORMATS)
def test_a_simulation_bag_replays_the_run_on_the_simulation_clock(tmp_path, head_on, name):
    problem, sim = head_on
    frame = RosFrame.for_problem(problem)
    out = tmp_path / name
    write_simulation_bag(problem, frame, sim, out)
    msgs, conns = read_bag(out)
    samples = sim.trajectory
    n = len(samples)
    assert set(msgs) == PLAN_TOPICS | {
        "/tf_static",
        "/tf",
        "/odom",
        "/cmd_vel",
        "/wheel_speeds",
        "/moving_obstacles",
    }
    for topic, conn in conns.items():
        assert conn.msgtype == TOPICS[topic][0]
        stamps = [t for t, _ in msgs[topic]]
        assert stamps == sorted(stamps), topic  # monotone
    for topic in ("/odom", "/tf", "/cmd_vel", "/wheel_speeds", "/moving_obstacles"):
        assert len(msgs[topic]) == n, topic
    # Stamps are the simulation's sample times (nanoseconds), header and log time alike.
    log = np.array([t for t, _ in msgs["/odom"]])
    assert np.array_equal(log, np.round(samples[:, 0] * 1e9).astype(np.int64))
    odom = [m for _, m in msgs["/odom"]]
    assert [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in odom] == log.tolist()
    assert {(m.header.frame_id, m.child_frame_id) for m in odom} == {("odom", "base_link")}
    pose = np.array([xy_yaw(m.pose.pose) for m in odom])
    assert np.allclose(pose[:, :2], samples[:, 1:3] / 100, atol=1e-12)  # cm to m
    assert np.allclose(np.angle(np.exp(1j * (pose[:, 2] - samples[:, 3]))), 0, atol=1e-9)
    tf = [m.transforms[0] for _, m in msgs["/tf"]]
    assert [(x.transform.translation.x, x.transform.translation.y) for x in tf] == [
        (p[0], p[1]) for p in pose[:, :2].tolist()
    ]
    static = msgs["/tf_static"][0][1].transforms[0]
    assert (static.header.frame_id, static.child_frame_id) == ("map", "odom")
    assert conns["/tf_static"].ext.offered_qos_profiles[0].durability.name == "TRANSIENT_LOCAL"

    # /cmd_vel: where a command holds over a whole sample step, the step is what it commands.
    v = np.array([m.linear.x for _, m in msgs["/cmd_vel"]])
    w = np.array([m.angular.z for _, m in msgs["/cmd_vel"]])
    assert np.array_equal([m.twist.twist.linear.x for m in odom], v)
    ts = problem.robot.sample_time
    held = (v[:-1] == v[1:]) & (w[:-1] == w[1:]) & np.isclose(np.diff(samples[:, 0]), ts)
    step = np.hypot(*np.diff(samples[:, 1:3], axis=0).T) / 100
    turn = np.diff(samples[:, 3])
    straight, turning = held & (w[:-1] == 0), held & (w[:-1] != 0)
    assert straight.sum() > n / 2 and turning.sum() >= 3
    assert np.allclose(step[straight], np.abs(v[:-1][straight]) * ts, atol=1e-9)
    assert np.allclose(turn[turning], w[:-1][turning] * ts, atol=1e-9)
    assert np.allclose(step[turning], 0, atol=1e-12) and np.all(v[:-1][turning] == 0)
    assert v.max() == pytest.approx(problem.robot.speed / 100)  # 20 cm/s
    assert v[-1] == 0 and w[-1] == 0  # arrived
    # Wheel speeds, eqs. 9-12: rad/s of each wheel.
    wheels = np.array([m.velocity for _, m in msgs["/wheel_speeds"]])
    assert msgs["/wheel_speeds"][0][1].name == list(WHEEL_JOINTS)
    L, r = problem.robot.track_width / 100, problem.robot.wheel_radius / 100
    assert np.allclose(wheels[:, 0], (v + 0.5 * L * w) / r)
    assert np.allclose(wheels[:, 1], (v - 0.5 * L * w) / r)

    # /plan: the static plan at 0, then the plan from where the robot is at every change.
    plans = msgs["/plan"]
    assert len(plans) == len(sim.plans) >= 2
    assert [t for t, _ in plans] == [round(t * 1e9) for t, _ in sim.plans]
    for (t, plan), (_, msg) in zip(sim.plans, plans, strict=True):
        first = xy_yaw(msg.poses[0].pose)
        assert np.allclose(first[:2], plan.position(t) / 100)
        last = xy_yaw(msg.poses[-1].pose)
        assert np.allclose(last[:2], np.array(problem.goal) / 100)
    # The moving obstacle where the simulation had it, with its contact zone SO + SR.
    track = sim.tracks[0]
    for k in (0, n // 2, n - 1):
        cyl, zone = msgs["/moving_obstacles"][k][1].markers
        at = track.position(samples[k, 0]) / 100
        assert (cyl.pose.position.x, cyl.pose.position.y) == pytest.approx(tuple(at))
        assert cyl.scale.x == pytest.approx(2 * track.radius / 100)
        assert zone.scale.x == pytest.approx(2 * (track.radius + problem.robot.radius) / 100)


def test_commands_are_those_of_the_piece_under_way():
    from rrtpso_ompl.dynamic.motion import Motion

    # Drive 2 units east in 1 s, turn a quarter in 0.5 s, drive 1 unit north in 0.5 s.
    m = Motion(
        np.array([0.0, 1.0, 1.5, 2.0]),
        np.array([[0, 0], [2, 0], [2, 0], [2, 1]]),
        np.array([0.0, 0.0, math.pi / 2, math.pi / 2]),
    )
    v, w = commands(m, np.array([0.0, 0.5, 1.0, 1.2, 1.5, 1.9, 2.0, 3.0]))
    assert v.tolist() == [2, 2, 0, 0, 2, 2, 0, 0]
    assert w == pytest.approx([0, 0, math.pi, math.pi, 0, 0, 0, 0])


# ----------------------------------------------------------------------------------------------
# Whole or nothing
# ----------------------------------------------------------------------------------------------
def _failing_writes(monkeypatch, after: int):
    """The bag writer's disk fills up after ``after`` messages."""
    from rosbags.rosbag2 import Writer

    real = Writer.write
    calls = {"n": 0}

    def write(self, connection, timestamp, data):
        calls["n"] += 1
        if calls["n"] > after:
            raise OSError(28, "No space left on device")
        return real(self, connection, timestamp, data)

    monkeypatch.setattr(Writer, "write", write)


@pytest.mark.parametrize("name", FORMATS)
def test_a_failed_write_leaves_nothing_and_keeps_the_old_bag(tmp_path, monkeypatch, name):
    problem = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    frame = RosFrame.for_problem(problem)
    out = tmp_path / "deep" / "er" / name
    _failing_writes(monkeypatch, after=2)
    with pytest.raises(OutputError, match="No space left on device"):
        write_plan_bag(problem, frame, np.array([problem.start, problem.goal]), out)
    assert list(tmp_path.iterdir()) == []  # no bag, no temporary, no folder made for it
    if name.endswith(".mcap"):
        # An earlier bag stays as it was until the new one is complete.
        monkeypatch.undo()
        out.parent.mkdir(parents=True)
        write_plan_bag(problem, frame, np.array([problem.start, problem.goal]), out)
        out.chmod(0o640)
        before = out.read_bytes()
        _failing_writes(monkeypatch, after=2)
        with pytest.raises(OutputError):
            write_plan_bag(problem, frame, None, out)
        assert out.read_bytes() == before and sorted(out.parent.iterdir()) == [out]
        monkeypatch.undo()
        write_plan_bag(problem, frame, None, out)  # replaced whole, keeping its permissions
        assert out.read_bytes() != before and (out.stat().st_mode & 0o777) == 0o640
        assert "/plan" not in read_bag(out)[0]


KILLED = """
import sys, time
from pathlib import Path
from rosbags.rosbag2 import Writer
from rrtpso_ompl.model import load_problem
from rrtpso_ompl.ros import RosFrame
from rrtpso_ompl.ros.bag import write_plan_bag

real = Writer.write
def slow(self, connection, timestamp, data):
    real(self, connection, timestamp, data)
    Path(sys.argv[2]).touch()  # the bag is part written
    time.sleep(30)
Writer.write = slow
problem = load_problem(sys.argv[3])
write_plan_bag(problem, RosFrame.for_problem(problem), None, sys.argv[1])
"""


@pytest.mark.parametrize("name", FORMATS)
def test_killed_mid_write_leaves_no_bag_at_the_target(tmp_path, name):
    out, begun = tmp_path / name, tmp_path / "begun"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-c",
            KILLED,
            str(out),
            str(begun),
            str(PROBLEMS / "static" / "single_circle.yaml"),
        ]
    )
    try:
        deadline = time.monotonic() + 60
        while not begun.exists() and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        assert begun.exists(), "the writer never started"
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
    assert not out.exists() and not os.path.lexists(out)
    # Only the hidden scratch folder of the killed writer is left beside it, with its part.
    left = [p.name for p in tmp_path.iterdir() if p.name != "begun"]
    assert left and all(p.startswith(".") for p in left)


# ----------------------------------------------------------------------------------------------
# The shipped RViz2 configuration
# ----------------------------------------------------------------------------------------------
def test_the_shipped_rviz_config_shows_the_bag_topics_with_their_qos():
    import yaml

    config = yaml.safe_load(
        (Path(__file__).parents[2] / "docs" / "ros" / "rrtpso.rviz").read_text()
    )
    manager = config["Visualization Manager"]
    assert manager["Global Options"]["Fixed Frame"] == "map"
    shown = {}
    for display in manager["Displays"]:
        topic = display.get("Topic")
        if isinstance(topic, dict):
            shown[topic["Value"]] = (display["Class"], topic["Durability Policy"])
    plugin = {
        "nav_msgs/msg/OccupancyGrid": "Map",
        "visualization_msgs/msg/MarkerArray": "MarkerArray",
        "nav_msgs/msg/Path": "Path",
        "nav_msgs/msg/Odometry": "Odometry",
        "geometry_msgs/msg/PoseStamped": "Pose",
        "geometry_msgs/msg/PoseWithCovarianceStamped": "PoseWithCovariance",
    }
    for topic, (msgtype, latched) in TOPICS.items():
        if msgtype in plugin:
            cls, durability = shown.pop(topic)
            assert cls == f"rviz_default_plugins/{plugin[msgtype]}", topic
            # A latched topic needs a transient-local subscription to get the recorded message.
            assert durability == ("Transient Local" if latched else "Volatile"), topic
    assert not shown  # no display of a topic the bag does not have
    assert "rviz_default_plugins/TF" in {d["Class"] for d in manager["Displays"]}


# ----------------------------------------------------------------------------------------------
# Bounds
# ----------------------------------------------------------------------------------------------
def test_a_long_run_is_thinned_to_the_bounds(tmp_path, head_on, monkeypatch):
    from rrtpso_ompl.ros import bag

    problem, sim = head_on
    monkeypatch.setattr(bag, "MAX_SAMPLES", 50)
    monkeypatch.setattr(bag, "MAX_MOVING", 20)
    out = tmp_path / "thin.mcap"
    write_simulation_bag(problem, RosFrame.for_problem(problem), sim, out)
    msgs, _ = read_bag(out)
    samples = sim.trajectory
    odom = [t for t, _ in msgs["/odom"]]
    assert len(samples) > 50 and len(odom) == 50
    assert odom[0] == 0 and odom[-1] == round(samples[-1, 0] * 1e9)  # first and last kept
    moving = [t for t, _ in msgs["/moving_obstacles"]]
    assert len(moving) <= 20 and moving[-1] == odom[-1] and moving[0] == 0


def test_too_many_obstacles_for_a_bag_are_refused_before_planning(monkeypatch):
    import argparse

    from rrtpso_ompl.cli.ros_flags import ros_frame
    from rrtpso_ompl.errors import UsageError
    from rrtpso_ompl.ros import markers

    problem = load_problem(PROBLEMS / "static" / "paper_static.yaml")  # 12 obstacles
    args = argparse.Namespace(problem="paper_static.yaml", bag="b.mcap", path_out=None,
                              frame_id="map", path_resolution=None)  # fmt: skip
    assert ros_frame(args, problem) is not None
    monkeypatch.setattr(markers, "MAX_OBSTACLES", 11)
    with pytest.raises(UsageError, match="--bag: the problem has 12 obstacles, more than the 11"):
        ros_frame(args, problem)
    args.bag = None
    args.path_out = "p.yaml"
    assert ros_frame(args, problem) is not None  # the bound is the bag's


def test_a_plan_with_too_many_poses_writes_no_bag(tmp_path, monkeypatch):
    from rrtpso_ompl.ros import bag

    problem = load_problem(PROBLEMS / "static" / "single_circle.yaml")
    frame = RosFrame(scale=0.01, resolution=0.05)
    path = np.array([problem.start, [20, 450], problem.goal])  # 4.3 + 4.3 m: 172 poses
    monkeypatch.setattr(bag, "MAX_PLAN_POSES", 171)
    out = tmp_path / "long.mcap"
    with pytest.raises(OutputError, match=r"needs about 172 poses at --path-resolution 0.05 m"):
        write_plan_bag(problem, frame, path, out)
    assert list(tmp_path.iterdir()) == []
    monkeypatch.setattr(bag, "MAX_PLAN_POSES", 172)
    write_plan_bag(problem, frame, path, out)
    assert len(read_bag(out)[0]["/plan"][0][1].poses) == 173  # both ends
