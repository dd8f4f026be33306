"""Car-like robots planned from problem files (issue 35): Dubins and Reeds-Shepp curves checked
soundly against the exact world, solved by RRTstarPSO and OMPL's planners, driven without a
turn in place, handed to ROS with their own headings.

Planning runs are bounded by iterations (``rrt_max_iterations``, the swarm's ``iterations``)
under a generous time limit, so the same work is done on any machine.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
import yaml

from rrtpso_ompl.kinematics import CSV_HEADER, drive_car
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.model.world import World
from rrtpso_ompl.ompl_setup import make_context, seed_ompl
from rrtpso_ompl.ompl_setup.car import CarModel
from rrtpso_ompl.planners import solve
from rrtpso_ompl.ros.poses import dense_poses

DOC = {
    "name": "car",
    "units": "m",
    "bounds": [[0, 0], [20, 12]],
    "start": [2, 2],
    "start_yaw": 0,
    "goal": [18, 10],
    "goal_yaw": 90,
    "robot": {"radius": 0.4, "turning_radius": 1.5, "speed": 1.0, "sample_time": 0.1,
              "wheel_radius": 0.1, "track_width": 0.5},
    "obstacles": [
        {"type": "circle", "center": [10, 6], "radius": 2.5},
        {"type": "rectangle", "min": [5, 0], "max": [6, 4]},
        {"type": "polygon", "points": [[14, 8], [16, 12], [13, 12]]},
    ],
}  # fmt: skip
#: Work bounds: iterations under a time limit no machine reaches.
BOUNDED = {"rrt_max_iterations": 1500, "iterations": 30, "refine_rounds": 1,
           "polish_rounds": 0}  # fmt: skip


def _problem(reverse: bool = False):
    doc = json.loads(json.dumps(DOC))
    doc["robot"]["reverse"] = reverse
    return problem_from_dict(doc, source="car.yaml")


def _dense_clearance(ctx, a, b, n: int = 20000) -> float:
    """The least clearance of the robot's centre along the space's curve, ``n`` states (the
    bounds count as a wall at their edges: ``-inf`` outside)."""
    space, s = ctx.car.space, ctx.car.space.allocState()
    pts = []
    for t in np.linspace(0.0, 1.0, n):
        space.interpolate(a, b, float(t), s)
        pts.append((s.getX(), s.getY()))
    pts = np.array(pts)
    (x0, y0), (x1, y1) = ctx.problem.bounds
    edge = np.minimum.reduce([pts[:, 0] - x0, x1 - pts[:, 0], pts[:, 1] - y0, y1 - pts[:, 1]])
    if edge.min() < 0:
        return -math.inf
    return float(min(ctx.world.point_clearance(pts).min(), ctx.world.robot_radius + edge.min()))


@pytest.mark.parametrize("reverse", [False, True])
def test_the_curve_check_is_sound_and_refuses_only_within_its_margin(reverse):
    ctx = make_context(_problem(reverse))
    validator, car = ctx.motion_validator, ctx.car
    margin = validator.margin
    spacing_slack = 40.0 / 20000  # the dense states' spacing on the longest curves here
    rng = np.random.default_rng(7)
    a, b = car.space.allocState(), car.space.allocState()
    seen = {True: 0, False: 0}
    for _ in range(120):
        for state in (a, b):
            state.setXY(*rng.uniform([0.5, 0.5], [19.5, 11.5]))
            state.setYaw(rng.uniform(-math.pi, math.pi))
        if not (ctx.checker.isValid(a) and ctx.checker.isValid(b)):
            continue
        free = validator.checkMotion(a, b)
        clearance = _dense_clearance(ctx, a, b)
        seen[free] += 1
        if free:  # never a collision
            assert clearance >= ctx.world.robot_radius - 1e-9
        else:  # a refusal is a collision, or within three margins of one
            assert clearance < ctx.world.robot_radius + 3 * margin + spacing_slack
    assert seen[True] >= 10 and seen[False] >= 10


def test_a_reeds_shepp_curve_lies_within_the_sagitta_of_its_chords_even_at_cusps():
    car = CarModel.of(_problem(reverse=True))
    space = car.space
    a, b, s = space.allocState(), space.allocState(), space.allocState()
    rng = np.random.default_rng(3)
    cusps = 0
    for _ in range(40):
        a.setXY(*rng.uniform(0, 4, 2))
        a.setYaw(rng.uniform(-math.pi, math.pi))
        b.setXY(a.getX() + rng.uniform(-1, 1), a.getY() + rng.uniform(-1, 1))  # short: cusps
        b.setYaw(rng.uniform(-math.pi, math.pi))
        poses = car.samples(a, b)
        dense = []
        for t in np.linspace(0, 1, 4000):
            space.interpolate(a, b, float(t), s)
            dense.append((s.getX(), s.getY()))
        dense = np.array(dense)
        p, q = poses[:-1, :2], poses[1:, :2]
        d = q - p
        w = dense[:, None, :] - p[None]
        t = np.clip((w * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0, 1)
        dist = np.linalg.norm(w - t[..., None] * d, axis=-1).min(axis=1)
        assert dist.max() <= car.sagitta * 1.001 + 1e-12
        cusps += int(len(poses) > math.ceil(space.distance(a, b) / car.step) + 1)
    assert cusps >= 5  # pieces were halved around cusps


@pytest.mark.parametrize("reverse", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_rrtstarpso_solves_a_car_problem_with_curves_that_keep_the_radius(reverse):
    problem = _problem(reverse)
    result = solve(problem, "RRTstarPSO", time_limit=120.0, seed=3, params=BOUNDED)
    assert result.solved and result.status == "exact"
    stages = result.stages
    assert stages["stages"][:2] == ["corridor", "RRTstar"] and stages["stages"][-1] == "pso"
    assert stages["seed_source"] in ("corridor", "RRTstar", "RRTstar+repair")
    world = World.from_problem(problem)
    assert world.path_valid(result.path)  # the chords, with the robot's radius
    poses = np.array(stages["poses"])
    assert poses[0].tolist() == [2.0, 2.0, 0.0]
    assert poses[-1][:2].tolist() == [18.0, 10.0]
    assert poses[-1][2] == pytest.approx(math.pi / 2, abs=1e-12)
    yaw = np.array(stages["path_yaw"])
    assert len(yaw) == len(result.path)
    car = stages["car"]
    assert car["space"] == ("Reeds-Shepp" if reverse else "Dubins")
    # Never longer than its seed, nor than RRT*'s path or the corridor's; the polyline is the
    # curves' chords.
    assert car["curve_length"] <= stages["seed_length"] + 1e-9
    for other in (stages["rrt_length"], stages["corridor_length"]):
        assert other is None or stages["seed_length"] <= other + 1e-9
    assert result.length <= car["curve_length"] + 1e-9
    assert result.length > 0.999 * car["curve_length"]
    if not reverse:  # a forward car turns at most 1 / rho per unit of arc
        chord = np.hypot(*np.diff(result.path, axis=0).T)
        turn = np.abs(np.angle(np.exp(1j * np.diff(yaw))))
        assert (turn <= 2 * np.arcsin(np.minimum(1.0, chord / 3.0)) + 1e-9).all()


@pytest.mark.slow
def test_the_same_seed_gives_the_same_car_path():
    paths = [solve(_problem(), "RRTstarPSO", time_limit=120.0, seed=5, params=BOUNDED).path
             for _ in range(2)]  # fmt: skip
    assert np.array_equal(paths[0], paths[1])


def test_ompl_s_planners_and_the_pso_post_pass_plan_cars_and_never_lengthen():
    seed_ompl(1)
    result = solve(_problem(), "RRTstar+simplify+pso", time_limit=0.5, seed=1)
    if result.solved:  # time-bounded: whether RRT* found a path depends on the machine
        assert World.from_problem(_problem()).path_valid(result.path)
        for step in result.stages["post"]:
            assert step["length_after"] <= step["length_before"] + 1e-9


def test_plane_only_planners_refuse_a_car_before_planning():
    from rrtpso_ompl.errors import UnsupportedSpaceError

    for name in ("PSO", "Exact"):
        with pytest.raises(UnsupportedSpaceError, match="plane only"):
            solve(_problem(), name, time_limit=1.0)


def _cusp_poses():
    """A Reeds-Shepp car moving sideways by 0.6 m: a curve with cusps (it backs)."""
    car = CarModel.of(_problem(reverse=True))
    a, b = car.space.allocState(), car.space.allocState()
    a.setXY(5.0, 5.0)
    a.setYaw(0.0)
    b.setXY(5.0, 5.6)
    b.setYaw(0.0)
    return car.samples(a, b)


def test_a_car_is_driven_forwards_and_backwards_with_no_turn_in_place():
    poses = _cusp_poses()
    robot = _problem(reverse=True).robot
    motion = drive_car(poses, robot, "constant", "Reeds-Shepp")
    tr = motion.trajectory
    assert (tr.v < -0.5).any() and (tr.v > 0.5).any()  # both gears
    moving = np.abs(tr.v) > 1e-9
    # |omega| = |v| / rho on the arcs; a step over a cusp carries the mean of its pieces.
    assert (np.abs(tr.omega[moving]) <= np.abs(tr.v[moving]) / 1.5 * (1 + 1e-3)).all()
    assert not ((~moving) & (np.abs(tr.omega) > 1e-9)).any()  # never a turn in place
    assert np.allclose(tr.v_right - tr.v_left, tr.omega * robot.track_width)
    assert (tr.x[0], tr.y[0], tr.theta[0]) == (5.0, 5.0, 0.0)
    assert math.hypot(tr.x[-1] - 5.0, tr.y[-1] - 5.6) < 1e-9
    assert motion.open_loop_error < 0.05
    assert np.abs(np.diff(tr.theta)).max() < 1.0  # one unwrapped heading, no 2 pi jumps


def test_ros_poses_of_a_car_keep_its_own_headings():
    poses = _cusp_poses()
    dense = dense_poses(poses, 0.01)
    assert dense.yaw[0] == 0.0 and abs(dense.yaw[-1]) < 1e-12
    # Backing, a car faces away from its motion: its yaw is not the segments' direction.
    seg = np.diff(dense.xy, axis=0)
    along = np.cos(dense.yaw[:-1]) * seg[:, 0] + np.sin(dense.yaw[:-1]) * seg[:, 1]
    assert (along < 0).any() and (along > 0).any()


@pytest.mark.slow
def test_the_command_line_solves_a_car_file_and_writes_its_trajectory(tmp_path):
    path = tmp_path / "car.yaml"
    path.write_text(yaml.safe_dump(DOC))
    out, csv = tmp_path / "out.json", tmp_path / "traj.csv"
    params = [a for k, v in BOUNDED.items() for a in ("--param", f"{k}={v}")]
    run = subprocess.run([sys.executable, "-m", "rrtpso_ompl", "solve", str(path), "--time",
                          "120", "--seed", "2", *params, "--json", str(out), "--trajectory",
                          str(csv)], capture_output=True, text=True, timeout=600)  # fmt: skip
    assert run.returncode == 0, run.stderr
    data = json.loads(out.read_text())
    assert data["solved"] and data["stages"]["car"]["space"] == "Dubins"
    assert World.from_problem(_problem()).path_valid(np.array(data["path"]))
    assert csv.read_text().splitlines()[0] == ",".join(CSV_HEADER)
    refused = subprocess.run([sys.executable, "-m", "rrtpso_ompl", "solve", str(path),
                              "--planner", "PSO"], capture_output=True, text=True,
                             timeout=600)  # fmt: skip
    assert refused.returncode == 2 and "plane only" in refused.stderr
    assert "Traceback" not in refused.stderr
