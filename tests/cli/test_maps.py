"""Map problems through the command line: bad map files, and every subcommand on a map."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
import shapely
from helpers import PROBLEMS, _corridor, _map, _pgm, map_shapes, rrtpso_exe

from rrtpso_ompl.model import World, load_problem

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(
    ("keys", "key", "words"),
    [
        ({"origin": [0, 0, "half"]}, "origin[2]", "must be a number"),
        ({"free_thresh": 0.7}, "free_thresh", "below occupied_thresh"),
        ({"occupied_thresh": 1.5}, "occupied_thresh", "between 0 and 1"),
        ({"negate": 2}, "negate", "0 or 1"),
        ({"mode": "fancy"}, "mode", "trinary, scale, raw"),
        ({"resolution": 0}, "resolution", "> 0"),
        ({"image": "missing.pgm"}, "image", "no such image file"),
    ],
)
def test_bad_map_files_exit_2_naming_the_map_and_key(tmp_path, keys, key, words):
    img = np.full((4, 4), 254, dtype=np.uint8)
    _pgm(tmp_path / "m.pgm", img)
    _map(tmp_path, img, **{"image": "m.pgm", **keys})
    prob = tmp_path / "p.yaml"
    prob.write_text("map: m.yaml\nstart: [0.5, 0.5]\ngoal: [1.5, 1.5]\nrobot: {radius: 0.1}\n")
    out = tmp_path / "out.json"
    proc = subprocess.run([*rrtpso_exe(), "solve", str(prob), "--json", str(out)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    assert "m.yaml" in proc.stderr and key in proc.stderr and words in proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists()


def test_solve_optimum_and_batch_on_a_map_problem(tmp_path):
    prob = _corridor(tmp_path)
    exe = rrtpso_exe()
    sol, opt, nav = tmp_path / "s.json", tmp_path / "o.json", tmp_path / "path.yaml"
    run = subprocess.run([*exe, "solve", prob, "--time", "0.5", "--seed", "3", "--json", str(sol),
                          "--path-out", str(nav), "--plot", str(tmp_path / "s.png")],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    run = subprocess.run([*exe, "optimum", prob, "--json", str(opt)],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    s, o = json.loads(sol.read_text()), json.loads(opt.read_text())
    world = World.from_problem(load_problem(prob))
    assert world.path_valid(np.array(s["path"])) and world.path_valid(np.array(o["path"]))
    assert o["length"] <= s["length"] + 1e-9
    # The way round the wall's end: longer than straight, as long as the bend demands.
    assert o["length"] > math.dist((2.0, 3.0), (8.0, 2.5)) + 0.5
    import yaml

    doc = yaml.safe_load(nav.read_text())
    assert doc["header"]["frame_id"] == "map"
    # Dense poses, about one per map cell (the map's resolution, metres), every waypoint kept.
    xy = np.array([[q["pose"]["position"]["x"], q["pose"]["position"]["y"]] for q in doc["poses"]])
    resolution = load_problem(prob).map.resolution
    assert np.hypot(*np.diff(xy, axis=0).T).max() <= resolution + 1e-9
    assert len(xy) >= s["length"] / resolution
    assert all(np.hypot(*(xy - w).T).min() < 1e-9 for w in s["path"])
    q = doc["poses"][0]["pose"]["orientation"]
    heading = math.atan2(s["path"][1][1] - s["path"][0][1], s["path"][1][0] - s["path"][0][0])
    assert 2 * math.atan2(q["z"], q["w"]) == pytest.approx(heading)
    rows = tmp_path / "b.jsonl"
    run = subprocess.run([*exe, "batch", prob, str(PROBLEMS / "maps" / "lab_clutter.yaml"),
                          "--time", "0.3", "--out", str(rows), "--jobs", "1"],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    got = [json.loads(line) for line in rows.read_text().splitlines()]
    assert len(got) == 2 and all(r["solved"] for r in got)


def test_simulate_and_bench_accept_map_problems(tmp_path):
    prob = _corridor(
        tmp_path,
        robot={"radius": 0.2, "wheel_radius": 0.05, "track_width": 0.3, "speed": 0.5,
               "sample_time": 0.1, "sensor_range": 2.0},
        moving_obstacles=[{"radius": 0.2, "start": [4.0, 3.5], "speed": 0.0, "heading_deg": 0}],
    )  # fmt: skip
    exe = rrtpso_exe()
    out = tmp_path / "sim.json"
    run = subprocess.run([*exe, "simulate", prob, "--json", str(out), "--seed", "1"],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    doc = json.loads(out.read_text())
    assert doc["reached_goal"] and doc["collisions"] == 0
    world = World.from_problem(load_problem(prob))
    xy = np.array(doc["trajectory"])[:, 1:3]
    # Every sampled pose keeps the radius (chords between samples may cut a corner the robot
    # drives round, so they are not checked).
    assert (world.point_clearance(xy) >= world.threshold).all()
    run = subprocess.run([*exe, "bench", prob, "--planner", "RRTstarPSO", "--runs", "1",
                          "--time", "0.2", "--out", str(tmp_path / "b")],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "b" / "benchmark.db").exists()


def _turned_corridor(tmp_path, yaw: float, **problem) -> str:
    """:func:`_corridor` with its map turned by ``yaw`` about the origin, start and goal with it."""
    prob = _corridor(tmp_path, **problem)
    grid = tmp_path / "corridor.yaml"
    doc = json.loads(grid.read_text())
    doc["origin"] = [0.0, 0.0, yaw]
    grid.write_text(json.dumps(doc))
    c, s = math.cos(yaw), math.sin(yaw)
    doc = json.loads((tmp_path / "prob.yaml").read_text())
    for key in ("start", "goal"):
        x, y = doc[key]
        doc[key] = [c * x - s * y, s * x + c * y]
    (tmp_path / "prob.yaml").write_text(json.dumps(doc))
    return prob


def test_solve_optimum_and_simulate_on_a_turned_map(tmp_path):
    """A map whose origin yaw is 0.4 rad: planned, proved and driven exactly (paths checked
    against shapely's turned squares), drawn turned."""
    prob = _turned_corridor(
        tmp_path, 0.4,
        robot={"radius": 0.3, "wheel_radius": 0.05, "track_width": 0.3, "speed": 0.5,
               "sample_time": 0.1, "sensor_range": 2.0},
    )  # fmt: skip
    exe = rrtpso_exe()
    sol, opt, sim = tmp_path / "s.json", tmp_path / "o.json", tmp_path / "sim.json"
    run = subprocess.run([*exe, "solve", prob, "--time", "0.5", "--seed", "3", "--json", str(sol),
                          "--plot", str(tmp_path / "s.png")],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    run = subprocess.run([*exe, "optimum", prob, "--json", str(opt)],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    problem = load_problem(prob)
    shapes = map_shapes(problem)
    tol = World.from_problem(problem).tol
    for doc in (json.loads(sol.read_text()), json.loads(opt.read_text())):
        path = np.array(doc["path"])
        d = shapely.distance(shapes, shapely.linestrings(np.stack([path[:-1], path[1:]], 1)))
        assert d.min() >= 0.3 - tol
    o, s = json.loads(opt.read_text()), json.loads(sol.read_text())
    assert o["length"] <= s["length"] + 1e-9
    # The unturned problem's optimum: a rotation keeps lengths.
    (tmp_path / "flat").mkdir()
    flat = _corridor(tmp_path / "flat", robot={"radius": 0.3})
    run = subprocess.run([*exe, "optimum", flat, "--json", str(tmp_path / "f.json")],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert json.loads((tmp_path / "f.json").read_text())["length"] == pytest.approx(
        o["length"], abs=1e-6)
    doc = json.loads((tmp_path / "prob.yaml").read_text())
    c, s = math.cos(0.4), math.sin(0.4)  # from (8.5, 4) on the unturned map, toward -x
    doc["moving_obstacles"] = [{"radius": 0.2, "start": [8.5 * c - 4 * s, 8.5 * s + 4 * c],
                                "speed": 0.3, "heading_deg": 180 + math.degrees(0.4)}]  # fmt: skip
    (tmp_path / "prob.yaml").write_text(json.dumps(doc))
    run = subprocess.run([*exe, "simulate", prob, "--json", str(sim), "--seed", "1"],
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    doc = json.loads(sim.read_text())
    assert doc["reached_goal"] and doc["collisions"] == 0
    xy = np.array(doc["trajectory"])[:, 1:3]
    assert shapely.distance(shapes, shapely.points(xy)).min() >= 0.3 - tol
