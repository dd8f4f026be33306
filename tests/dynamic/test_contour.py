"""Contour replanning's choices (issue 14): waiting as a candidate chosen by predicted arrival, the
wall-clock planning budget, re-shortening once the obstacle has passed, and ``Motion.delayed``."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest
from helpers import BOUNDED_ARGS, PROBLEMS, corridor, manager_for, observe, rrtpso_exe

from rrtpso_ompl.dynamic import DynamicOptions, Motion, predict_threats, simulate
from rrtpso_ompl.model.problem import load_problem
from rrtpso_ompl.model.world import World


def test_delayed_motion_stops_then_drives_the_same_route():
    plan = Motion.from_path(np.array([[0, 0], [10, 0], [10, 10]]), 0.0, None, 1.0, 2.0)
    late = plan.delayed(4.0, 2.5)
    assert late.t_end == pytest.approx(plan.t_end + 2.5)
    ts = np.linspace(0, 4, 9)
    assert np.allclose(late.position(ts), plan.position(ts))
    # Standing still during the stop...
    assert np.allclose(late.position(np.linspace(4.0, 6.5, 6)), plan.position(4.0))
    # ... and then the same motion, 2.5 s later.
    ts = np.linspace(4.0, plan.t_end, 17)
    assert np.allclose(late.position(ts + 2.5), plan.position(ts))
    assert np.allclose(late.heading(ts + 2.5), plan.heading(ts))
    assert late.path_length() == pytest.approx(plan.path_length())


def test_waiting_is_a_candidate_and_the_first_to_arrive_is_chosen():
    # An obstacle crosses the route from above at the robot's speed: letting it pass costs a few
    # seconds and no length; a detour around its sweep costs more of both.
    problem = corridor([{"radius": 28.5, "start": [250, 440], "speed": 20, "heading_deg": -90}])
    manager, turn = manager_for(problem, seed=3)
    plan = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    obs = observe(problem, 3.0)
    threats = predict_threats(plan, 3.0, obs, 28.5, 2.85)
    new, rec = manager.react(3.0, plan, obs, threats)
    sides = {c["side"]: c for c in rec.candidates}
    assert set(sides) == {"wait", "up", "down"}
    wait = sides["wait"]
    assert wait["valid"] and wait["wait"] > 0 and wait["margin_left"] >= 0
    valid = [c for c in rec.candidates if c["valid"]]
    assert new.t_end == pytest.approx(min(c["arrival"] for c in valid))
    assert sides[rec.side]["arrival"] == pytest.approx(new.t_end)
    if rec.side == "wait":  # the same route, later, so no longer
        assert new.path_length() == pytest.approx(plan.path_length())
        assert new.t_end == pytest.approx(plan.t_end + wait["wait"])
    assert not predict_threats(new, 3.0, obs, 28.5, 2.85)


def test_a_shorter_wait_would_collide():
    # The least verified wait is least: one control period less meets the obstacle.
    problem = corridor([{"radius": 28.5, "start": [250, 440], "speed": 20, "heading_deg": -90}])
    manager, turn = manager_for(problem)
    plan = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    obs = observe(problem, 3.0)
    threats = predict_threats(plan, 3.0, obs, 28.5, 2.85)
    _, rec = manager.react(3.0, plan, obs, threats)
    w = next(c for c in rec.candidates if c["side"] == "wait")["wait"]
    shorter = plan.delayed(3.6, w - problem.robot.sample_time)
    assert predict_threats(shorter, 3.0, obs, 28.5, 2.85)


def test_global_replanning_has_no_wait_candidate():
    problem = corridor([{"radius": 28.5, "start": [250, 440], "speed": 20, "heading_deg": -90}])
    from rrtpso_ompl.dynamic import ReplanningManager
    from rrtpso_ompl.dynamic.strategies import WholePath

    _, turn = manager_for(problem)
    opts = DynamicOptions(replan_time=0.6, planner="RRTstar")
    manager = ReplanningManager(problem, opts, 20.0, turn, 5.7, np.random.default_rng(0),
                                policy=WholePath.policy)  # fmt: skip
    plan = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    obs = observe(problem, 3.0)
    _, rec = manager.react(3.0, plan, obs, predict_threats(plan, 3.0, obs, 28.5, 2.85))
    assert [c["side"] for c in rec.candidates][:1] == [None]
    assert all(c.get("side") != "wait" for c in rec.candidates)


def test_reshorten_drops_a_passed_detour_bend_but_not_into_a_sensed_obstacle():
    problem = corridor([])
    manager, turn = manager_for(problem)
    bend = np.array([problem.start, [250, 350], problem.goal])
    plan = Motion.from_path(bend, 0.0, None, 20.0, turn)
    short = manager.reshorten(2.0, plan, {})
    assert short is not None and short.t_end < plan.t_end
    ts = np.linspace(0, 2.15, 20)  # unchanged until one control period from now
    assert np.allclose(short.position(ts), plan.position(ts))
    assert np.allclose(short.end, problem.goal)
    assert World.from_problem(problem).path_valid(short.xy)
    # A sensed obstacle parked on the shortcut: the bend stays.
    parked = {0: (np.array([300.0, 260.0]), np.zeros(2), 28.5)}
    assert manager.reshorten(2.0, plan, parked) is None
    # Nothing to gain on a straight plan.
    straight = Motion.from_path(np.array([problem.start, problem.goal]), 0.0, None, 20.0, turn)
    assert manager.reshorten(2.0, straight, {}) is None


@pytest.mark.parametrize("reshorten", [True, False])
def test_reshortening_is_an_option_of_the_simulation(reshorten):
    problem = load_problem(PROBLEMS / "dynamic" / "head_on.yaml")
    path = np.array([problem.start, problem.goal])
    opts = DynamicOptions(reshorten=reshorten)
    sim = simulate(problem, opts, seed=2, initial_path=path)
    assert sim.reached_goal and sim.collisions == 0
    assert World.from_problem(problem).path_valid(sim.motion.xy)
    assert len(sim.plans) >= len(sim.replans) + 1
    if not reshorten:
        assert len(sim.plans) == len(sim.replans) + 1  # only reactions change the plan


def test_planning_time_is_measured_per_replan():
    # The budget is simulated time and wall-clock time; what was used is reported (the benchmark,
    # not this test, measures it against the budget: machines are noisy).
    problem = load_problem(PROBLEMS / "dynamic" / "crossing_from_below.yaml")
    path = np.array([problem.start, problem.goal])
    sim = simulate(problem, DynamicOptions(replan_time=0.05), seed=1, initial_path=path)
    # Every reaction that planned (a contour detour, or a fallback after detours that found
    # nothing in time: which one depends on the machine) is charged; one with no time to plan is
    # charged nothing.
    planned = [r for r in sim.replans if r.budget > 0]
    assert planned and all(r.planning_time > 0 and r.budget == 0.05 for r in planned)
    assert all(r.planning_time == 0.0 for r in sim.replans if r.budget == 0)


@pytest.mark.slow  # the rrtpso command end to end
def test_simulate_command_takes_no_reshorten_and_the_default_budget(tmp_path):
    out = tmp_path / "run.json"
    proc = subprocess.run(
        [*rrtpso_exe(), "simulate", str(PROBLEMS / "dynamic" / "paper_dynamic.yaml"),
         "--no-reshorten", *BOUNDED_ARGS, "--json", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["replans"] and all(r["budget"] in (0.0, DynamicOptions().replan_time)
                                   for r in data["replans"])  # fmt: skip
