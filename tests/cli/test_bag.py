"""``--bag`` on ``solve``, ``optimum`` and ``simulate`` as a user runs it: the bag read back
with ``rosbags`` against the command's own JSON, and bad bag places refused before planning."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from helpers import PROBLEMS, _corridor, run

pytestmark = pytest.mark.slow


def read_bag(path: Path) -> dict:
    """``{topic: [(log time ns, message), ...]}``."""
    from rosbags.highlevel import AnyReader

    out: dict[str, list] = {}
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, reader.deserialize(raw, conn.msgtype)))
    return out


def plan_xy(path_msg) -> np.ndarray:
    return np.array([(p.pose.position.x, p.pose.position.y) for p in path_msg.poses])


def assert_waypoints_are_poses(poses: np.ndarray, waypoints: np.ndarray) -> None:
    for w in waypoints:
        assert np.hypot(*(poses - w).T).min() < 1e-9, w


def test_solve_bag_holds_the_json_path_in_metres(tmp_path):
    # paper_static is in centimetres: the bag's plan is the JSON path divided by 100.
    out, js = tmp_path / "run.mcap", tmp_path / "r.json"
    proc = run(
        "solve",
        str(PROBLEMS / "static" / "paper_static.yaml"),
        "--time",
        "0.2",
        "--seed",
        "1",
        "--json",
        str(js),
        "--bag",
        str(out),
    )
    assert proc.returncode == 0, proc.stderr
    path = np.array(json.loads(js.read_text())["path"])
    msgs = read_bag(out)
    assert set(msgs) == {"/obstacles", "/initialpose", "/goal_pose", "/plan"}
    poses = plan_xy(msgs["/plan"][0][1])
    assert_waypoints_are_poses(poses, path / 100)
    assert np.allclose(poses[[0, -1]], path[[0, -1]] / 100)
    assert np.hypot(*np.diff(poses, axis=0).T).max() <= 0.05 + 1e-12


def test_optimum_bag_on_a_map_problem_is_a_bag_directory(tmp_path):
    prob = _corridor(tmp_path)
    (tmp_path / "run").mkdir()  # an empty folder may receive the bag
    out, js = tmp_path / "run", tmp_path / "o.json"
    proc = run(
        "optimum",
        prob,
        "--json",
        str(js),
        "--bag",
        str(out),
        "--frame-id",
        "world",
        "--path-resolution",
        "0.1",
    )
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in out.iterdir()) == ["metadata.yaml", "run.db3"]
    msgs = read_bag(out)
    assert set(msgs) == {"/map", "/obstacles", "/initialpose", "/goal_pose", "/plan"}
    grid = msgs["/map"][0][1]
    assert (grid.info.width, grid.info.height, grid.info.resolution) == (20, 10, 0.5)
    assert grid.header.frame_id == "world"
    plan = msgs["/plan"][0][1]
    path = np.array(json.loads(js.read_text())["path"])  # metres already: a map problem
    poses = plan_xy(plan)
    assert_waypoints_are_poses(poses, path)
    assert np.hypot(*np.diff(poses, axis=0).T).max() <= 0.1 + 1e-12
    assert plan.header.frame_id == "world"


def test_simulate_bag_replays_the_json_trajectory(tmp_path):
    out, js = tmp_path / "sim.mcap", tmp_path / "s.json"
    proc = run(
        "simulate",
        str(PROBLEMS / "dynamic" / "head_on.yaml"),
        "--time",
        "0.2",
        "--replan-time",
        "0.05",
        "--seed",
        "2",
        "--json",
        str(js),
        "--bag",
        str(out),
    )
    assert proc.returncode in (0, 1), proc.stderr
    data = json.loads(js.read_text())
    traj = np.array(data["trajectory"])
    msgs = read_bag(out)
    odom = msgs["/odom"]
    assert len(odom) == len(msgs["/cmd_vel"]) == len(msgs["/tf"]) == len(traj)
    stamps = np.array([t for t, _ in odom])
    assert np.all(np.diff(stamps) > 0)
    assert np.array_equal(stamps, np.round(traj[:, 0] * 1e9).astype(np.int64))
    xy = np.array([(m.pose.pose.position.x, m.pose.pose.position.y) for _, m in odom])
    assert np.allclose(xy, traj[:, 1:3] / 100, atol=1e-12)
    # The commands drive the JSON's samples: a straight step at v, a turning step at omega.
    v = np.array([m.linear.x for _, m in msgs["/cmd_vel"]])
    w = np.array([m.angular.z for _, m in msgs["/cmd_vel"]])
    ts = 0.15
    held = (v[:-1] == v[1:]) & (w[:-1] == w[1:]) & np.isclose(np.diff(traj[:, 0]), ts)
    step = np.hypot(*np.diff(traj[:, 1:3], axis=0).T) / 100
    straight, turning = held & (w[:-1] == 0), held & (w[:-1] != 0)
    assert straight.sum() > len(traj) / 2
    assert np.allclose(step[straight], v[:-1][straight] * ts, atol=1e-9)
    assert np.allclose(np.diff(traj[:, 3])[turning], w[:-1][turning] * ts, atol=1e-9)
    # A plan at the start and one more at every replan (and re-shortening).
    plans = msgs["/plan"]
    assert len(plans) >= 1 + len(data["replans"]) and plans[0][0] == 0
    replan_times = {round(r["t"] * 1e9) for r in data["replans"]}
    assert replan_times <= {t for t, _ in plans}
    assert len(msgs["/moving_obstacles"]) == len(traj)


@pytest.mark.parametrize(
    ("command", "problem", "make", "bag", "words"),
    [
        ("solve", "static/single_circle.yaml", "file", "a_file/run.mcap", "is a file"),
        ("solve", "static/single_circle.yaml", "full", "full", "exists and is not empty"),
        ("optimum", "static/single_circle.yaml", "text", "notes.mcap", "not an MCAP file"),
        ("simulate", "dynamic/head_on.yaml", "text", "notes", "is a regular file"),
        ("solve", "static/single_circle.yaml", "", "x" * 252, "the bag's database"),
    ],
)
def test_a_bad_bag_place_is_refused_before_planning(tmp_path, command, problem, make, bag, words):
    if make == "file":
        (tmp_path / "a_file").write_text("a file, not a folder\n")
    elif make == "full":
        (tmp_path / "full").mkdir()
        (tmp_path / "full" / "keep.txt").write_text("mine\n")
    elif make == "text":
        (tmp_path / bag).write_text("mine\n")
    before = sorted((p.relative_to(tmp_path), p.stat().st_mtime_ns) for p in tmp_path.rglob("*"))
    js = tmp_path / "out.json"
    budget = [] if command == "optimum" else ["--time", "5"]  # refused long before it runs out
    proc = run(
        command, str(PROBLEMS / problem), "--bag", str(tmp_path / bag), "--json", str(js), *budget
    )
    assert proc.returncode == 2, proc.stderr
    assert "--bag" in proc.stderr and words in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr
    after = sorted((p.relative_to(tmp_path), p.stat().st_mtime_ns) for p in tmp_path.rglob("*"))
    assert after == before  # nothing written, nothing touched, nothing planned (no JSON)


def test_an_unknown_unit_is_refused_for_a_bag_before_planning(tmp_path):
    prob = tmp_path / "p.yaml"
    text = (PROBLEMS / "static" / "single_circle.yaml").read_text()
    prob.write_text(
        text.replace("units: cm", "units: furlong")
        if "units:" in text
        else "units: furlong\n" + text
    )
    proc = run("solve", str(prob), "--bag", str(tmp_path / "b.mcap"), "--time", "5")
    assert proc.returncode == 2, proc.stderr
    assert "units" in proc.stderr and "furlong" in proc.stderr
    assert not (tmp_path / "b.mcap").exists()


def test_a_path_resolution_too_fine_for_a_bag_is_refused_before_planning(tmp_path):
    js = tmp_path / "r.json"
    proc = run("solve", str(PROBLEMS / "static" / "paper_static.yaml"), "--bag",
               str(tmp_path / "b.mcap"), "--path-resolution", "1e-5", "--json", str(js),
               "--time", "5")  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    assert "--bag: even the straight line to the goal" in proc.stderr
    assert "--path-resolution" in proc.stderr and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []
