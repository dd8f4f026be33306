"""The Dynamic Window Approach peer (issues 14 and 22): a DWB-like controller on exact geometry.

Admissibility (never a command whose stop collides), the kinematic limits, doors, oscillation,
recovery, the grid of its distance critics, and the README's office run.
"""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest
from helpers import PROBLEMS, ROBOT, corridor, rrtpso_exe

from rrtpso_ompl.dynamic import DynamicOptions, RobotState, simulate_local
from rrtpso_ompl.dynamic.dwa import DWAController, DWAParams, simulate_dwa
from rrtpso_ompl.dynamic.local import SUBSTEPS
from rrtpso_ompl.dynamic.motion import arc_position
from rrtpso_ompl.dynamic.navgrid import NavGrid
from rrtpso_ompl.model.problem import load_problem, problem_from_dict
from rrtpso_ompl.model.world import World


def control_speeds(motion, dt):
    """Linear and angular speed of each control period of a local controller's motion."""
    xy, th = motion.xy[1:], motion.theta[1:]
    n = len(xy) // SUBSTEPS
    xy = np.vstack([motion.xy[:1], xy[: n * SUBSTEPS]])
    th = np.concatenate([motion.theta[:1], th[: n * SUBSTEPS]])
    step = np.diff(xy, axis=0)
    heading = th[:-1]
    along = step[:, 0] * np.cos(heading) + step[:, 1] * np.sin(heading)
    chord = np.sign(along) * np.hypot(*step.T)
    return chord.reshape(n, SUBSTEPS).sum(axis=1) / dt, np.diff(th[::SUBSTEPS]) / dt


def walled(door_width: float, moving=()):
    """The corridor world with a wall across x = 250 and a door of ``door_width`` in it
    (centred on y = 330, off the straight route), cm."""
    top = 330 + door_width / 2
    bottom = 330 - door_width / 2
    return problem_from_dict(
        {
            "name": "door",
            "bounds": [[0, 0], [500, 500]],
            "start": [60, 150],
            "goal": [440, 150],
            "robot": ROBOT,
            "obstacles": [
                {"type": "polygon", "points": [[240, 0], [260, 0], [260, bottom], [240, bottom]]},
                {"type": "polygon", "points": [[240, top], [260, top], [260, 500], [240, 500]]},
            ],
            "moving_obstacles": list(moving),
        }
    )


class Recorder(DWAController):
    """The DWA, remembering every state it saw and every command it gave."""

    def reset(self, xy, theta):
        super().reset(xy, theta)
        self.log, self.admissible = [], []

    def step(self, state, obstacles, t):
        v, w = super().step(state, obstacles, t)
        self.log.append((state, v, w, self.last.mode))
        self.admissible.append(self.last.admissible)
        return v, w


def stopping_arc(controller, state, v, w, samples=200):
    """The arc the robot drives when it brakes right after one period of ``(v, w)``."""
    dt = controller.dt
    t_b = max(abs(v) / controller.acc, abs(w) / controller.alpha)
    tau = np.linspace(0.0, dt + 0.5 * t_b, samples)
    return arc_position(state.xy, state.theta, v, w, tau)


# -- the controller ----------------------------------------------------------------------------
def test_dwa_drives_an_empty_corridor_straight_within_its_limits():
    problem = corridor([])
    path = np.array([problem.start, problem.goal])
    res = simulate_dwa(problem, path, seed=1)
    assert res.strategy == "dwa" and res.planner == "DWA" and res.status == "ok"
    assert res.reached_goal and res.collisions == 0
    assert np.allclose(res.motion.end, problem.goal)
    assert res.path_length == pytest.approx(440.0, rel=1e-3)
    # Never faster than the robot, and about as fast as it can be (accelerating from rest).
    assert 440.0 / 20.0 <= res.total_time <= 440.0 / 20.0 + 2.0
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
    assert res.success and res.status == "ok"
    dt = problem.robot.sample_time
    v, w = control_speeds(res.motion, dt)
    half_track = problem.robot.track_width / 2
    assert np.all(np.abs(v) + np.abs(w) * half_track <= 20.0 * (1 + 1e-3) + 1e-6)
    assert world.path_valid(res.motion.xy)


def test_dwa_never_takes_a_command_whose_stop_would_collide():
    """Every command, braked to a stop right after its period, keeps off the static world,
    checked densely along the braking arc: through a narrow door, and from 300 random states
    right at the wall, heading anywhere at any speed the wheels allow."""
    problem = walled(2 * 28.5 + 12.0)
    world = World.from_problem(problem)
    guide = np.array([[60, 150], [200, 330], [300, 330], [440, 150]], dtype=float)
    dwa = Recorder(problem, guide)
    res = simulate_local(problem, dwa, guide, seed=1)
    assert res.reached_goal and res.status == "ok"
    for state, v, w, _ in dwa.log:
        arc = stopping_arc(dwa, state, v, w)
        assert world.segments_free(arc[:-1], arc[1:]).all()

    rng = np.random.default_rng(7)
    probe = DWAController(problem, guide)
    tried = refused = 0
    while tried < 300:
        # Just left of the wall (x = 240), 0-8 cm beyond contact, below the door.
        x = np.array([240 - 28.5 - rng.uniform(0.0, 8.0), rng.uniform(50, 250)])
        v = rng.uniform(-20, 20)
        w = rng.uniform(-1, 1) * (20 - abs(v)) / 19.0
        state = RobotState(x, rng.uniform(-np.pi, np.pi), v, w)
        # Only states the DWA can be in: braking from them right away keeps off the wall (the
        # previous period's command was admissible).
        t_b = max(abs(v) / probe.acc, abs(w) / probe.alpha)
        now = arc_position(x, state.theta, v, w, np.linspace(0.0, 0.5 * t_b, 100))
        if not world.segments_free(now[:-1], now[1:]).all():
            continue
        tried += 1
        cmd = probe.step(state, {}, 0.0)
        arc = stopping_arc(probe, state, *cmd)
        assert world.segments_free(arc[:-1], arc[1:]).all()
        refused += not probe.last.admissible.all()
    # Many of these windows hold commands that would hit the wall: the check refused them.
    assert refused >= 30


def test_a_braking_command_is_always_admissible():
    """Heading at full speed for a wall, the DWA can always brake along its arc."""
    problem = walled(80.0)
    guide = np.array([[60, 150], [200, 330], [300, 330], [440, 150]], dtype=float)
    dwa = DWAController(problem, guide)
    dt = dwa.dt
    # Full speed, straight at the wall: the braking distance is 20 * (dt + 0.15) = 6 cm.
    for gap in (7.0, 10.0, 20.0):
        x = np.array([240 - 28.5 - gap, 150.0])
        state = RobotState(x, 0.0, 20.0, 0.0)
        v, w = dwa.step(state, {}, 0.0)
        world = World.from_problem(problem)
        arc = stopping_arc(dwa, state, v, w)
        assert world.segments_free(arc[:-1], arc[1:]).all()
        assert v < 20.0 or gap > 20.0 * (dt + 0.5 * dwa.p.accel_time)


def test_dwa_passes_through_a_door_off_the_straight_line():
    """A door 1.6 SR wider than the robot, away from the straight line: the guide path leads
    through it and the distance critics, measured through free space, keep the robot from the
    wall beside it."""
    problem = walled(2 * 28.5 + 40.0)
    guide = np.array([[60, 150], [200, 330], [300, 330], [440, 150]], dtype=float)
    res = simulate_dwa(problem, guide, seed=1)
    assert res.success and res.status == "ok"
    xy = res.motion.xy
    crossing = xy[np.argmin(np.abs(xy[:, 0] - 250))]
    assert abs(crossing[1] - 330) < 20
    # Not much longer than the guide (no dithering in front of the door).
    assert res.path_length < 1.15 * np.hypot(*np.diff(guide, axis=0).T).sum()


def test_dwa_does_not_oscillate_in_front_of_a_standing_obstacle():
    """A person standing on the route: the DWA goes round it in one go, without flipping
    between forwards and backwards (or left and right on the spot)."""
    problem = corridor([{"radius": 25, "start": [250, 250], "speed": 0, "heading_deg": 0}])
    guide = np.array([problem.start, problem.goal], dtype=float)
    dwa = Recorder(problem, guide)
    res = simulate_local(problem, dwa, guide, seed=1)
    assert res.success and res.status == "ok"
    v = np.array([v for _, v, _, _ in dwa.log])
    flips = np.count_nonzero(np.diff(np.sign(v[np.abs(v) > 1e-9])))
    assert flips <= 2
    assert res.path_length < 1.3 * 440


def test_oscillation_critic_refuses_flipping_back_until_the_robot_has_moved():
    problem = corridor([])
    dwa = DWAController(problem, np.array([problem.start, problem.goal], dtype=float))
    x = np.array(problem.start, dtype=float)
    dwa._debrief(5.0, 0.0, x, 0.0)
    dwa._debrief(-5.0, 0.0, x, 0.0)  # a flip: forwards is refused now
    assert dwa._v_trend.refuses(np.array([3.0, -3.0, 0.0])).tolist() == [True, False, False]
    dwa._debrief(-5.0, 0.0, x + np.array([0.1 * 28.5, 0]), 0.0)  # not far enough yet
    assert dwa._v_trend.refuses(np.array([3.0])).all()
    dwa._debrief(-5.0, 0.0, x + np.array([0.3 * 28.5, 0]), 0.0)
    assert not dwa._v_trend.refuses(np.array([3.0])).any()


def test_dwa_recovers_from_a_guide_path_through_a_wall():
    """A guide path straight through the wall (the door is elsewhere): the distance critics,
    measured through free space, lead the robot round to the door, off the guide; it re-plans
    on the grid from where it stands and goes through."""
    problem = walled(2 * 28.5 + 40.0)
    guide = np.array([problem.start, problem.goal], dtype=float)
    dwa = Recorder(problem, guide)
    res = simulate_local(problem, dwa, guide, seed=1)
    assert res.success and res.status == "ok"
    assert 1 <= len(dwa.recoveries) <= DWAParams().max_recoveries
    assert World.from_problem(problem).path_valid(dwa.guide)  # the re-planned guide


def test_dwa_avoids_a_crossing_obstacle_and_is_seeded():
    problem = load_problem(PROBLEMS / "dynamic" / "crossing_from_below.yaml")
    path = np.array([problem.start, problem.goal])
    a = simulate_dwa(problem, path, seed=4)
    b = simulate_dwa(problem, path, seed=4)
    assert a.reached_goal and a.collisions == 0 and a.status == "ok"
    assert min(a.min_separation_continuous) >= a.contact_distance[0]
    assert np.array_equal(a.motion.xy, b.motion.xy)


@pytest.mark.parametrize(("speed", "radius", "y"), [(30, 28.5, 250), (26, 20, 250), (35, 25, 245)])
def test_dwa_steps_aside_for_an_obstacle_overtaking_it(speed, radius, y):
    """A faster obstacle from behind along the route: the robot lets it pass (the old carrot
    DWA, which predicted 4 s ahead and always drove on, was run over by it)."""
    problem = corridor([{"radius": radius, "start": [-100, y], "speed": speed, "heading_deg": 0}])
    res = simulate_dwa(problem, np.array([problem.start, problem.goal]), seed=1)
    assert res.success and res.status == "ok"
    assert min(res.min_separation_continuous) >= res.contact_distance[0]


def test_dwa_without_a_guide_path_reports_it():
    problem = corridor([])
    res = simulate_dwa(problem, np.empty((0, 2)))
    assert not res.reached_goal and res.status == "no static path"
    assert res.strategy == "dwa"


@pytest.mark.parametrize(
    "bad",
    [{"sim_time": 0}, {"v_samples": 1}, {"accel_time": -1}, {"path_dist": math.nan},
     {"v_samples": 200, "w_samples": 200}, {"reverse": 2}, {"resolution": 0}],
)  # fmt: skip
def test_dwa_parameters_are_checked(bad):
    with pytest.raises(ValueError, match="DWAParams"):
        DWAParams(**bad)


# -- the harness -------------------------------------------------------------------------------
class Greedy:
    """A controller that asks for more than the wheels can give."""

    name = "Greedy"

    def reset(self, xy, theta):
        self.calls = 0

    def step(self, state, obstacles, t):
        self.calls += 1
        return 1e3, 5.0


def test_simulate_local_saturates_commands_at_the_wheels():
    problem = corridor([])
    greedy = Greedy()
    res = simulate_local(problem, greedy, np.array([problem.start, problem.goal]),
                         DynamicOptions(max_time=3.0), seed=0)  # fmt: skip
    assert res.strategy == "greedy" and res.planner == "Greedy" and greedy.calls > 0
    v, w = control_speeds(res.motion, problem.robot.sample_time)
    assert np.all(np.abs(v) + np.abs(w) * 19.0 <= 20.0 * (1 + 1e-6))
    assert not res.reached_goal


# -- the grid of the distance critics ----------------------------------------------------------
def test_navgrid_measures_distance_through_free_space():
    world = World(((0, 0), (10, 10)), boxes=[(4, 0, 5, 8)], robot_radius=0.5)
    grid = NavGrid(world, 0.5, 0.1)
    field = grid.field(np.array([[2.0, 2.0]]), limit=100.0)
    here, beyond = grid.value(field, np.array([[2.0, 2.0], [7.0, 2.0]]))
    assert here < 0.1
    # Round the wall's end (3.5..5.5, 8.5), not through it: at least the taut string, and at
    # most 8 % more (octile distances).
    taut = 2 * math.hypot(1.5, 6.5) + 2.0
    assert taut <= beyond <= 1.09 * taut
    # Beyond the limit the field is empty.
    short = grid.field(np.array([[2.0, 2.0]]), limit=3.0)
    assert np.isinf(grid.value(short, np.array([[7.0, 2.0]])))[()]
    route = grid.route(np.array([2.0, 2.0]), np.array([7.0, 2.0]))
    assert route is not None and world.path_valid(route)
    assert np.allclose(route[0], [2, 2]) and np.allclose(route[-1], [7, 2])


def test_navgrid_is_bounded(monkeypatch):
    from rrtpso_ompl.dynamic import navgrid

    monkeypatch.setattr(navgrid, "MAX_CELLS", 10_000)
    world = World(((0, 0), (1e6, 1e6)), robot_radius=1.0)
    grid = NavGrid(world, 1.0, 1.0)
    assert grid.nx * grid.ny <= 1.01 * 10_000 and grid.h >= 1e4


# -- the command ---------------------------------------------------------------------------------
@pytest.mark.slow  # the rrtpso command end to end
def test_simulate_command_runs_the_dwa(tmp_path):
    out = tmp_path / "dwa.json"
    proc = subprocess.run(
        [*rrtpso_exe(), "simulate", str(PROBLEMS / "dynamic" / "head_on.yaml"), "--strategy",
         "dwa", "--time", "0.3", "--seed", "3", "--json", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["strategy"] == "dwa" and data["planner"] == "DWA"
    assert data["reached_goal"] and data["collisions"] == 0 and data["replans"] == []
    assert data["trajectory"][-1][1:3] == [470, 250]


@pytest.mark.slow
def test_readme_office_dwa_run_reaches_the_goal(tmp_path):
    """The README's line: the DWA on the office map (its doors, its two people) exits 0."""
    gif = tmp_path / "dwa.gif"
    proc = subprocess.run(
        [*rrtpso_exe(), "simulate", str(PROBLEMS / "dynamic" / "office_people.yaml"),
         "--strategy", "dwa", "--gif", str(gif)],
        capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "reached the goal, 0 collisions" in proc.stderr
    assert gif.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
