"""``--path-out`` on ``solve``, ``optimum`` and ``simulate``: metres whatever the problem's units,
dense poses, the goal heading; JSON outputs say their units; bad ``goal_yaw`` and unknown units
refused before planning."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
import yaml
from helpers import PROBLEMS, SINGLE_CIRCLE, run

from rrtpso_ompl.ros import DEFAULT_PATH_RESOLUTION

pytestmark = pytest.mark.slow


PAPER = PROBLEMS / "static" / "paper_static.yaml"


def _problem(tmp_path, source=PAPER, **keys):
    """A copy of ``source`` (a file or a mapping) as ``problem.yaml`` with top-level ``keys``
    changed (None removes one)."""
    doc = yaml.safe_load(source.read_text()) if not isinstance(source, dict) else dict(source)
    for k, v in keys.items():
        if v is None:
            doc.pop(k, None)
        else:
            doc[k] = v
    path = tmp_path / "problem.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def _poses(path):
    """Positions (m) and headings (rad) of a nav_msgs/Path document."""
    doc = yaml.safe_load(path.read_text())  # JSON is YAML too
    xy = np.array([[p["pose"]["position"][k] for k in "xy"] for p in doc["poses"]])
    q = [p["pose"]["orientation"] for p in doc["poses"]]
    assert all(o["x"] == 0.0 and o["y"] == 0.0 for o in q)
    assert np.allclose([o["z"] ** 2 + o["w"] ** 2 for o in q], 1.0)  # unit quaternions about z
    return xy, np.array([2.0 * math.atan2(o["z"], o["w"]) for o in q]), doc


def _same_heading(a, b, tol=1e-9):
    return abs(math.remainder(a - b, 2 * math.pi)) < tol


def _waypoints_are_poses(xy, path_m):
    """Every waypoint (metres) is one of the poses, in order, with the first and last the ends."""
    assert np.allclose(xy[0], path_m[0], atol=1e-12) and np.allclose(xy[-1], path_m[-1], atol=1e-12)
    at = [int(np.argmin(np.hypot(*(xy - w).T))) for w in path_m]
    assert np.all(np.diff(at) > 0)
    assert np.hypot(*(xy[at] - path_m).T).max() < 1e-12


def test_solve_path_out_is_in_metres_dense_and_ends_facing_goal_yaw(tmp_path):
    """paper_static is in cm: the poses are the JSON path / 100, at most 5 cm apart, the last one
    facing goal_yaw; the CSV ends with the robot turned to goal_yaw at the goal, its header as
    documented; the JSON says its units."""
    prob = _problem(tmp_path, goal_yaw=-135)
    out = {k: tmp_path / n for k, n in (("json", "s.json"), ("nav", "p.yaml"), ("csv", "t.csv"))}
    proc = run("solve", str(prob), "--time", "0.3", "--seed", "2", "--json", str(out["json"]),
               "--path-out", str(out["nav"]), "--trajectory", str(out["csv"]))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out["json"].read_text())
    assert data["units"] == "cm" and data["metres_per_unit"] == 0.01
    path_m = np.array(data["path"]) / 100.0
    xy, yaw, doc = _poses(out["nav"])
    assert doc["header"]["frame_id"] == "map"
    _waypoints_are_poses(xy, path_m)
    gaps = np.hypot(*np.diff(xy, axis=0).T)
    assert gaps.max() <= DEFAULT_PATH_RESOLUTION + 1e-12 and gaps.min() > 0
    assert len(xy) >= data["length"] / 100.0 / DEFAULT_PATH_RESOLUTION
    assert _same_heading(yaw[-1], math.radians(-135))
    first = math.atan2(*(path_m[1] - path_m[0])[::-1])
    assert _same_heading(yaw[0], first)
    with out["csv"].open() as fh:
        rows = list(csv.reader(fh))
    assert ",".join(rows[0]) == "t,x,y,theta,v,omega,v_right,v_left,omega_right,omega_left"
    last = np.array(rows[-1], dtype=float)
    # (the CSV keeps 9 significant digits)
    assert np.allclose(last[1:3], [450, 450]) and _same_heading(last[3], math.radians(-135), 1e-7)
    turn = data["kinematics"]["goal_turn"]
    assert turn["duration"] > 0 and abs(turn["angle"]) <= math.pi


def test_a_millimetre_problem_is_divided_by_1000(tmp_path):
    prob = _problem(tmp_path, source=SINGLE_CIRCLE, units="mm", goal_yaw=90)
    nav, sol = tmp_path / "p.json", tmp_path / "s.json"
    proc = run("solve", str(prob), "--time", "0.2", "--seed", "1", "--json", str(sol), "--path-out",
               str(nav), "--path-resolution", "0.02", "--frame-id", "odom")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(sol.read_text())
    assert data["units"] == "mm" and data["metres_per_unit"] == 0.001
    xy, yaw, doc = _poses(nav)
    assert doc["header"]["frame_id"] == "odom"
    _waypoints_are_poses(xy, np.array(data["path"]) / 1000.0)
    assert np.hypot(*np.diff(xy, axis=0).T).max() <= 0.02 + 1e-12
    assert _same_heading(yaw[-1], math.pi / 2)


def test_an_unknown_unit_is_refused_only_when_a_ros_output_is_asked(tmp_path):
    prob = _problem(tmp_path, units="furlong")
    nav, sol = tmp_path / "p.yaml", tmp_path / "s.json"
    for cmd in ("solve", "optimum"):
        proc = run(cmd, str(prob), "--json", str(sol), "--path-out", str(nav),
                   *(["--time", "0.2"] if cmd == "solve" else []))  # fmt: skip
        assert proc.returncode == 2, proc.stderr
        assert proc.stderr.startswith(f"rrtpso: error: {prob}: units: unknown length unit")
        assert "Traceback" not in proc.stderr and "exact" not in proc.stderr  # nothing planned
        assert list(tmp_path.iterdir()) == [prob]  # nothing written
    proc = run("solve", str(prob), "--time", "0.2", "--seed", "1", "--json", str(sol))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(sol.read_text())
    assert data["units"] == "furlong" and "metres_per_unit" not in data


@pytest.mark.parametrize(
    ("cmd", "value"),
    [("solve", "north"), ("solve", ".nan"), ("solve", ".inf"), ("optimum", "-.inf"),
     ("simulate", ".nan"), ("simulate", "'90'")],
)  # fmt: skip
def test_a_bad_goal_yaw_is_refused_before_planning(tmp_path, cmd, value):
    text = (PROBLEMS / "dynamic" / "head_on.yaml").read_text() + f"goal_yaw: {value}\n"
    prob = tmp_path / "problem.yaml"
    prob.write_text(text)
    outs = [tmp_path / "o.json", tmp_path / "o.yaml"]
    proc = run(cmd, str(prob), "--json", str(outs[0]), "--path-out", str(outs[1]),
               *(["--time", "0.2"] if cmd != "optimum" else []))  # fmt: skip
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith(f"rrtpso: error: {prob}: goal_yaw: must be a")
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert not any(o.exists() for o in outs)


def test_optimum_path_out_is_the_exact_path_in_metres(tmp_path):
    prob = _problem(tmp_path, goal_yaw=30)
    nav, opt = tmp_path / "o.yaml", tmp_path / "o.json"
    proc = run("optimum", str(prob), "--json", str(opt), "--path-out", str(nav),
               "--path-resolution", "0.1")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(opt.read_text())
    assert data["units"] == "cm" and data["metres_per_unit"] == 0.01
    xy, yaw, _ = _poses(nav)
    _waypoints_are_poses(xy, np.array(data["path"]) / 100.0)
    assert np.hypot(*np.diff(xy, axis=0).T).max() <= 0.1 + 1e-12
    assert _same_heading(yaw[-1], math.radians(30))


def test_simulate_path_out_is_the_initial_static_plan(tmp_path):
    prob = PROBLEMS / "dynamic" / "head_on.yaml"
    nav, sim = tmp_path / "s.yaml", tmp_path / "s.json"
    proc = run("simulate", str(prob), "--time", "0.2", "--seed", "1", "--json", str(sim),
               "--path-out", str(nav))  # fmt: skip
    assert proc.returncode in (0, 1), proc.stderr
    data = json.loads(sim.read_text())
    assert data["units"] == "cm" and data["metres_per_unit"] == 0.01
    xy, _, _ = _poses(nav)
    _waypoints_are_poses(xy, np.array(data["static_path"]) / 100.0)
    assert np.hypot(*np.diff(xy, axis=0).T).max() <= DEFAULT_PATH_RESOLUTION + 1e-12


@pytest.mark.parametrize("cmd", ["optimum", "simulate"])
def test_a_bad_path_resolution_is_a_usage_error(tmp_path, cmd):
    nav = tmp_path / "p.yaml"
    proc = run(cmd, str(PROBLEMS / "dynamic" / "head_on.yaml"), "--path-out", str(nav),
               "--path-resolution", "0")  # fmt: skip
    assert proc.returncode == 2 and "--path-resolution" in proc.stderr, proc.stderr
    assert not nav.exists()


@pytest.mark.parametrize(
    ("resolution", "words"),
    [("1e-9", "even the straight line from start to goal"),  # refused before planning
     ("6.1e-7", "poses at resolution 6.1e-07 exceed the bound")],  # the path found is longer
)  # fmt: skip
def test_too_many_poses_is_a_usage_error_and_nothing_is_written(tmp_path, resolution, words):
    """paper_static's straight line is 6.08 m, its paths about 6.2 m: at 6.1e-7 m the line fits
    under the bound of 10 million poses and the path found does not. Either way: exit 2, one
    line naming --path-resolution, no output (the plot and the JSON neither)."""
    prob = _problem(tmp_path)
    out = {k: str(tmp_path / f"o.{k}") for k in ("yaml", "json", "png", "csv")}
    for cmd in ("solve", "optimum"):
        flags = ["--path-out", out["yaml"], "--json", out["json"], "--plot", out["png"]]
        if cmd == "solve":
            flags += ["--time", "0.1", "--seed", "1", "--trajectory", out["csv"]]
        proc = run(cmd, str(prob), *flags, "--path-resolution", resolution)
        assert proc.returncode == 2, proc.stderr
        assert proc.stderr.startswith(f"rrtpso: error: {prob}: --path-resolution: ")
        assert words in proc.stderr and proc.stderr.count("\n") == 1
        assert list(tmp_path.iterdir()) == [prob]
