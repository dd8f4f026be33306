"""The Dynamic Window Approach peer (issue 14): admissible arcs, limits, exact static validity."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
from helpers import PROBLEMS, corridor, rrtpso_exe

from rrtpso_ompl.dynamic.dwa import SUBSTEPS, DWAParams, simulate_dwa
from rrtpso_ompl.model.problem import load_problem
from rrtpso_ompl.model.world import World


def control_speeds(motion, dt):
    """Linear and angular speed of each control period of a DWA motion."""
    xy, th = motion.xy[1:], motion.theta[1:]
    n = len(xy) // SUBSTEPS
    xy = np.vstack([motion.xy[:1], xy[: n * SUBSTEPS]])
    th = np.concatenate([motion.theta[:1], th[: n * SUBSTEPS]])
    chord = np.hypot(*np.diff(xy, axis=0).T).reshape(n, SUBSTEPS).sum(axis=1)
    turn = np.diff(th[::SUBSTEPS])
    return chord / dt, turn / dt


def test_dwa_drives_an_empty_corridor_straight_within_its_limits():
    problem = corridor([])
    path = np.array([problem.start, problem.goal])
    res = simulate_dwa(problem, path, seed=1)
    assert res.strategy == "dwa" and res.status == "ok"
    assert res.reached_goal and res.collisions == 0
    assert np.allclose(res.motion.end, problem.goal)
    assert res.path_length == pytest.approx(440.0, rel=1e-3)
    # Never faster than the robot, and about as fast as it can be (accelerating from rest).
    assert res.total_time >= 440.0 / 20.0
    assert res.total_time <= 440.0 / 20.0 + 2.0
    dt = problem.robot.sample_time
    v, _ = control_speeds(res.motion, dt)
    assert v.max() <= 20.0 * (1 + 1e-6)
    accel = 20.0 / DWAParams().accel_time
    assert np.all(np.abs(np.diff(v)) <= accel * dt * (1 + 1e-6) + 1e-9)


def test_dwa_respects_the_wheel_speed_limit_around_obstacles():
    problem = load_problem(PROBLEMS / "dynamic" / "paper_dynamic.yaml")
    guide = np.array([[20, 20], [120, 160], [260, 200], [450, 450]], dtype=float)
    world = World.from_problem(problem)
    assert world.path_valid(guide)
    res = simulate_dwa(problem, guide, seed=1)
    dt = problem.robot.sample_time
    v, w = control_speeds(res.motion, dt)
    half_track = problem.robot.track_width / 2
    assert np.all(np.abs(v) + np.abs(w) * half_track <= 20.0 * (1 + 1e-3) + 1e-6)
    # Static validity is checked exactly and reported, never assumed.
    clipped = not world.path_valid(res.motion.xy)
    assert clipped == (res.status != "ok")


def test_dwa_avoids_a_crossing_obstacle_and_is_seeded():
    problem = load_problem(PROBLEMS / "dynamic" / "crossing_from_below.yaml")
    path = np.array([problem.start, problem.goal])
    a = simulate_dwa(problem, path, seed=4)
    b = simulate_dwa(problem, path, seed=4)
    assert a.reached_goal and a.collisions == 0 and a.status == "ok"
    assert min(a.min_separation_continuous) >= a.contact_distance[0]
    assert np.array_equal(a.motion.xy, b.motion.xy)


def test_dwa_without_a_guide_path_reports_it():
    problem = corridor([])
    res = simulate_dwa(problem, np.empty((0, 2)))
    assert not res.reached_goal and res.status == "no static path"


@pytest.mark.parametrize(
    "bad",
    [{"horizon": 0}, {"v_samples": 1}, {"accel_time": -1}, {"weight_path": math.nan},
     {"v_samples": 200, "w_samples": 200}],
)  # fmt: skip
def test_dwa_parameters_are_checked(bad):
    with pytest.raises(ValueError, match="DWAParams"):
        DWAParams(**bad)


def test_simulate_command_runs_the_dwa(tmp_path):
    out = tmp_path / "dwa.json"
    proc = subprocess.run(
        [*rrtpso_exe(), "simulate", str(PROBLEMS / "dynamic" / "head_on.yaml"), "--strategy",
         "dwa", "--time", "0.3", "--seed", "3", "--json", str(out),
         "--gif", str(tmp_path / "a.gif")],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["strategy"] == "dwa" and data["planner"] == "DWA"
    assert data["reached_goal"] and data["collisions"] == 0 and data["replans"] == []
    assert data["trajectory"][-1][1:3] == [470, 250]
