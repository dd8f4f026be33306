"""Moving obstacles: exact prediction, the replanning manager (sides, splicing, fallbacks) and whole
simulations through the library and the real ``rrtpso simulate`` command."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
from helpers import BOUNDED_ARGS, PROBLEMS, corridor, manager_for, observe, rrtpso_exe

from rrtpso_ompl.dynamic import (
    DynamicOptions,
    Motion,
    ObstacleTrack,
    capsule,
    closest_approach,
    first_entry,
    predict_threats,
    simulate,
)
from rrtpso_ompl.model.problem import MovingObstacle, load_problem
from rrtpso_ompl.model.world import World


def const(pos, vel):
    pos, vel = np.asarray(pos, float), np.asarray(vel, float)
    return lambda ts: pos + np.asarray(ts, float)[..., None] * vel


# ----------------------------------------------------------------------------------------------
# Motions
# ----------------------------------------------------------------------------------------------
def test_stop_and_turn_motion_timing():
    path = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 50.0]])
    m = Motion.from_path(path, 2.0, None, speed=10.0, turn_rate=0.5)
    # 10 s straight, a quarter turn at 0.5 rad/s (pi s), 5 s straight.
    assert m.t_end == pytest.approx(2.0 + 10.0 + math.pi + 5.0)
    assert np.allclose(m.position(7.0), [50.0, 0.0])
    assert np.allclose(m.position(12.0 + math.pi / 2), [100.0, 0.0])  # turning in place
    assert float(m.heading(12.0 + math.pi / 2)) == pytest.approx(math.pi / 4)
    assert np.allclose(m.position(100.0), [100.0, 50.0])  # rests at the end
    assert m.path_length() == pytest.approx(150.0)
    # Wheel speeds (eqs. 9-10): equal when driving, opposite when turning.
    vr, vl = m.wheel_speeds(track_width=40.0)
    assert np.allclose(vr[[0, 2]], 10.0) and np.allclose(vl[[0, 2]], 10.0)
    assert vr[1] == pytest.approx(10.0) and vl[1] == pytest.approx(-10.0)


def test_sampling_runs_from_start_to_arrival():
    m = Motion.from_path(np.array([[0.0, 0.0], [10.0, 0.0]]), 0.0, None, 3.0, None)
    rows = m.sample(1.0)
    assert rows[0, 0] == 0.0 and np.allclose(rows[0, 1:3], [0, 0])
    assert rows[-1, 0] == pytest.approx(10 / 3) and np.allclose(rows[-1, 1:3], [10, 0])
    assert np.all(np.diff(rows[:, 0]) > 0)


def test_obstacle_track_follows_eqs_14_15_and_turns():
    tr = ObstacleTrack.from_obstacle(MovingObstacle(10, (310, 250), 5.0, 90.0))
    assert np.allclose(tr.position(2.0), [310, 260])
    tr.turn(2.0, 0.0)  # now heading +x
    assert np.allclose(tr.position(2.0), [310, 260])
    assert np.allclose(tr.position(4.0), [320, 260])
    assert np.allclose(tr.position(1.0), [310, 255])  # the past is unchanged


# ----------------------------------------------------------------------------------------------
# Prediction: analytic crossings
# ----------------------------------------------------------------------------------------------
def test_head_on_entry_time_is_exact():
    robot = Motion.from_path(np.array([[0.0, 0.0], [200.0, 0.0]]), 0.0, None, 1.0, None)
    hit = first_entry(robot, const([100.0, 0.0], [-1.0, 0.0]), 0.0, robot.t_end, 30.0)
    # Distance 100 - 2 t reaches 30 at t = 35; they overlap until the obstacle is 30 behind:
    # 2 t - 100 = 30 at t = 65.
    assert hit == pytest.approx((35.0, 65.0))


def test_perpendicular_crossing_matches_the_quadratic():
    # Robot along +x at 2, obstacle along +y at 1 through (50, -40): offset r(t) = (2t-50, 40-t).
    robot = Motion.from_path(np.array([[0.0, 0.0], [200.0, 0.0]]), 0.0, None, 2.0, None)
    obstacle = const([50.0, -40.0], [0.0, 1.0])
    radius = 20.0
    t_enter, t_exit = first_entry(robot, obstacle, 0.0, robot.t_end, radius)
    # |r|^2 = 5 t^2 - 280 t + 4100 = 400  ->  t = (140 -+ sqrt(140^2 - 5 * 3700)) / 5
    root = math.sqrt(140**2 - 5 * 3700)
    assert t_enter == pytest.approx((140 - root) / 5)
    assert t_exit == pytest.approx((140 + root) / 5)
    d, t_min = closest_approach(robot, obstacle, 0.0, robot.t_end)
    assert t_min == pytest.approx(28.0)  # derivative 10 t - 280 = 0
    assert d == pytest.approx(math.sqrt(5 * 28**2 - 280 * 28 + 4100))
    # Against dense sampling.
    ts = np.linspace(0, robot.t_end, 200001)
    dist = np.hypot(*(robot.position(ts) - obstacle(ts)).T)
    assert dist.min() == pytest.approx(d, abs=1e-6)
    assert ts[np.argmax(dist < radius)] == pytest.approx(t_enter, abs=1e-3)


def test_no_entry_when_the_obstacle_passes_behind():
    robot = Motion.from_path(np.array([[0.0, 0.0], [100.0, 0.0]]), 0.0, None, 1.0, None)
    assert first_entry(robot, const([30.0, -100.0], [0.0, 1.0]), 0.0, robot.t_end, 20.0) is None


def test_entry_across_a_turn_in_place():
    # The robot waits (turns) at (100, 0) while the obstacle arrives there.
    m = Motion.from_path(np.array([[0.0, 0], [100, 0], [100, 100]]), 0.0, None, 10.0, 0.1)
    obstacle = const([100.0, -100.0], [0.0, 5.0])  # at (100, 0) at t = 20, inside the turn
    t_enter, _ = first_entry(m, obstacle, 0.0, m.t_end, 10.0)
    assert 10.0 < t_enter < 10.0 + math.pi / 2 / 0.1
    assert t_enter == pytest.approx(18.0)  # |y| = 100 - 5 t < 10


def test_predict_threats_reports_the_cross_point():
    plan = Motion.from_path(np.array([[0.0, 0.0], [300.0, 0.0]]), 0.0, None, 10.0, None)
    obs = {0: (np.array([150.0, -150.0]), np.array([0.0, 10.0]), 10.0)}
    (threat,) = predict_threats(plan, 0.0, obs, robot_radius=10.0, margin=0.0)
    assert threat.obstacle == 0
    assert np.allclose(threat.cross_point, plan.position(threat.t_enter))
    assert math.hypot(*(threat.cross_point - threat.obstacle_point)) == pytest.approx(20.0)


def test_capsule_is_the_exact_sweep_of_a_disc():
    a, b, r = np.array([10.0, 20.0]), np.array([110.0, 70.0]), 15.0
    parts = capsule(a, b, r)
    circles = [(*p.center, p.radius) for p in parts if hasattr(p, "center")]
    polys = [np.asarray(p.points) for p in parts if not hasattr(p, "center")]
    world = World(((-100, -100), (300, 300)), circles, polys, robot_radius=0.0)
    rng = np.random.default_rng(3)
    pts = rng.uniform(-50, 200, size=(4000, 2))
    ab = b - a
    u = np.clip((pts - a) @ ab / (ab @ ab), 0, 1)
    to_axis = np.hypot(*(pts - (a + u[:, None] * ab)).T)
    clearance = world.point_clearance(pts)
    outside = to_axis > r + 1e-9
    assert np.allclose(clearance[outside], to_axis[outside] - r, atol=1e-9)
    assert np.all(clearance[~outside] <= 1e-9)


# ----------------------------------------------------------------------------------------------
# The manager: choice of side, splicing, fallbacks
# ----------------------------------------------------------------------------------------------
def test_side_choice_avoids_the_blocked_side_and_splices_continuously():
    # A block above the route leaves no room to pass the rising obstacle in front ("up", on the
    # robot's left); only "down" (behind it) exists. The obstacle is slow, so waiting for it to
    # pass arrives later than the detour behind it.
    block = {"type": "rectangle", "min": [150, 285], "max": [350, 500]}
    problem = corridor(
        [{"radius": 28.5, "start": [250, 180], "speed": 6, "heading_deg": 90}], [block]
    )
    manager, turn = manager_for(problem)
    plan = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    t_now = 3.0
    obs = observe(problem, t_now)
    threats = predict_threats(plan, t_now, obs, 28.5, 2.85)
    assert threats, "the crossing must be predicted"
    new, rec = manager.react(t_now, plan, obs, threats)
    assert rec.kind == "contour" and rec.side == "down"
    sides = {c["side"]: c for c in rec.candidates}
    assert not sides["up"]["valid"]
    assert sides["wait"]["valid"] and sides["wait"]["arrival"] > sides["down"]["arrival"]
    # Splice: identical before the detour starts, continuous at its start, statically valid.
    t_s = t_now + 0.6
    ts = np.linspace(0, t_s, 50)
    assert np.allclose(new.position(ts), plan.position(ts))
    assert np.allclose(rec.start, plan.position(t_s))
    assert np.allclose(rec.detour[0], rec.start) and np.allclose(rec.detour[-1], rec.goal)
    assert float(new.heading(t_s)) == pytest.approx(float(plan.heading(t_s)))
    assert np.all(np.diff(new.t) >= 0)
    assert World.from_problem(problem).path_valid(new.xy)
    assert np.allclose(new.end, problem.goal)
    # The rejoin point lies on the old route past the collision zone.
    assert rec.goal[1] == pytest.approx(250.0) and rec.goal[0] > rec.cross_point[0]
    # And the new plan is predicted collision-free.
    assert not predict_threats(new, t_now, obs, 28.5, 2.85)


def test_detour_downwards_when_the_obstacle_comes_from_above():
    problem = corridor(
        [{"radius": 28.5, "start": [250, 320], "speed": 6, "heading_deg": -90}],
        [{"type": "rectangle", "min": [150, 0], "max": [350, 215]}],
    )
    manager, turn = manager_for(problem, seed=1)
    plan = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    obs = observe(problem, 3.0)
    threats = predict_threats(plan, 3.0, obs, 28.5, 2.85)
    _, rec = manager.react(3.0, plan, obs, threats)
    assert rec.side == "up"  # behind the falling obstacle, on the robot's left


def test_fallback_when_the_collision_is_too_close_to_plan():
    # Head-on and already close: no time for a detour, the robot must step aside (verified).
    problem = corridor([{"radius": 28.5, "start": [200, 250], "speed": 15, "heading_deg": 180}])
    manager, turn = manager_for(problem)
    plan = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    obs = observe(problem, 0.0)
    threats = predict_threats(plan, 0.0, obs, 28.5, 2.85)
    assert threats[0].t_enter < 0.6 + 4.0
    new, rec = manager.react(0.0, plan, obs, threats)
    assert rec.kind in ("wait", "evade")
    assert not predict_threats(new, 0.0, obs, 28.5, 2.85)
    assert np.allclose(new.end, problem.goal)


def test_options_are_checked():
    with pytest.raises(ValueError, match=r"no strategy 'teleport'.*known: contour, global"):
        simulate(corridor([]), DynamicOptions(strategy="teleport"))
    with pytest.raises(ValueError, match="replan_time"):
        DynamicOptions(replan_time=0)
    with pytest.raises(ValueError, match="stretch"):
        DynamicOptions(stretch=0.5)
    with pytest.raises(ValueError, match="params"):
        DynamicOptions(params=[1, 2])


# ----------------------------------------------------------------------------------------------
# Whole simulations
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["crossing_from_below", "head_on"])
def test_robot_reaches_the_goal_without_collision(name):
    problem = load_problem(PROBLEMS / "dynamic" / f"{name}.yaml")
    sim = simulate(problem, DynamicOptions(initial_time=0.3), seed=1)
    assert sim.reached_goal
    assert sim.collisions == 0
    assert sim.replans
    for d, contact in zip(sim.min_separation_continuous, sim.contact_distance, strict=True):
        assert d >= contact  # SR + SO, exact between samples too
    traj = sim.trajectory
    assert np.allclose(traj[0, 1:3], problem.start) and np.allclose(traj[-1, 1:3], problem.goal)
    assert np.all(np.diff(traj[:, 0]) > 0)
    assert World.from_problem(problem).path_valid(sim.motion.xy)
    # Steps of at most one sample time at the robot's speed (no jumps at the splices).
    step = np.hypot(*np.diff(traj[:, 1:3], axis=0).T)
    assert step.max() <= problem.robot.speed * problem.robot.sample_time + 1e-6


def test_without_replanning_the_same_scenario_collides():
    problem = load_problem(PROBLEMS / "dynamic" / "crossing_from_below.yaml")
    path = np.array([problem.start, problem.goal])
    sim = simulate(problem, DynamicOptions(strategy="none"), seed=1, initial_path=path)
    assert sim.reached_goal and sim.collisions > 0 and not sim.success
    assert min(sim.min_separation) < sim.contact_distance[0]


def test_heading_changes_are_seeded_and_still_avoided():
    problem = load_problem(PROBLEMS / "dynamic" / "crossing_from_below.yaml")
    path = np.array([problem.start, problem.goal])
    opts = DynamicOptions(heading_changes=0.3, heading_change_deg=60, replan_time=0.3)
    a = simulate(problem, opts, seed=7, initial_path=path)
    blind = DynamicOptions(strategy="none", heading_changes=0.3, heading_change_deg=60)
    b = simulate(problem, blind, seed=7, initial_path=path)
    # Same seed, same obstacle behaviour, whatever the robot does.
    assert len(a.tracks[0].knots) > 1
    assert a.tracks[0].knots == b.tracks[0].knots
    assert a.reached_goal and a.collisions == 0


def test_simulate_command_writes_the_contract(tmp_path):
    """The JSON and the PNG of the paper's scenario (the GIF the command writes is checked by
    ``test_readme_office_dwa_run_reaches_the_goal`` and on a short run below: 150 frames of
    this one take 13 s)."""
    out = tmp_path / "run.json"
    png = tmp_path / "run.png"
    proc = subprocess.run(
        [*rrtpso_exe(), "simulate", str(PROBLEMS / "dynamic" / "paper_dynamic.yaml"), "--json",
         str(out), "--plot", str(png), "--seed", "2", *BOUNDED_ARGS],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    for key in ("reached_goal", "collisions", "min_separation", "trajectory", "replans",
                "total_time", "path_length"):  # fmt: skip
        assert key in data
    assert data["reached_goal"] is True and data["collisions"] == 0
    assert len(data["min_separation"]) == 1 and data["min_separation"][0] >= 57.0
    assert data["trajectory"][0][1:3] == [20, 20] and data["trajectory"][-1][1:3] == [450, 450]
    assert all(len(row) == 4 for row in data["trajectory"])
    assert data["replans"] and {"t", "start", "goal", "side", "planning_time", "length"} <= set(
        data["replans"][0]
    )
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow  # the rrtpso command end to end
def test_simulate_command_writes_a_gif(tmp_path):
    """``--gif`` on a short run (head-on, the goal a few seconds away): a GIF, one frame per
    sample of the drive."""
    from PIL import Image

    problem = tmp_path / "short.yaml"
    text = (PROBLEMS / "dynamic" / "head_on.yaml").read_text()
    problem.write_text(text.replace("goal: [470, 250]", "goal: [90, 250]"))
    gif, out = tmp_path / "run.gif", tmp_path / "run.json"
    proc = subprocess.run(
        [*rrtpso_exe(), "simulate", str(problem), "--gif", str(gif), "--json", str(out),
         *BOUNDED_ARGS], capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert gif.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    samples = len(json.loads(out.read_text())["trajectory"])
    with Image.open(gif) as image:
        assert 2 <= image.n_frames <= samples


def test_simulate_rejects_a_problem_without_sensor(tmp_path):
    src = tmp_path / "p.yaml"
    src.write_text(
        "bounds: [[0, 0], [10, 10]]\nstart: [1, 1]\ngoal: [9, 9]\n"
        "robot: {radius: 0.5, speed: 1, sample_time: 0.1}\n"
    )
    out = tmp_path / "o.json"
    proc = subprocess.run([*rrtpso_exe(), "simulate", str(src), "--json", str(out)],
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert proc.returncode == 2
    assert "robot.sensor_range" in proc.stderr and str(src) in proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists()
