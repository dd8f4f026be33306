"""The swarm as a post-pass for every planner (issue 15): PSOPathOptimizer, planner specs such as
``BITstar+simplify+pso``, ``rrtpso solve --post`` and the OMPL log of ``rrtpso bench``."""

from __future__ import annotations

import itertools
import json
import math
import sqlite3
import subprocess
import time

import numpy as np
import pytest
from helpers import PROBLEMS, SINGLE_CIRCLE, rrtpso_exe
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.errors import ParameterError, UnsupportedSpaceError
from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.ompl_setup import array_to_path, make_context, path_to_array
from rrtpso_ompl.planners import (
    POST_STEPS,
    PSOPathOptimizer,
    default_registry,
    solve,
    split_spec,
)
from rrtpso_ompl.planners.base import SpaceInformationCollisionModel
from rrtpso_ompl.planners.post import run_post


def test_specs_name_a_planner_and_its_post_passes():
    assert split_spec("BITstar") == ("BITstar", ())
    assert split_spec("PRMstar+simplify+pso") == ("PRMstar", ("simplify", "pso"))
    with pytest.raises(ParameterError, match="known: simplify, pso"):
        split_spec("RRT+smooth")
    assert POST_STEPS == ("simplify", "pso")


@pytest.mark.parametrize("name", default_registry().names())
def test_the_post_pass_never_lengthens_or_invalidates_for_any_planner(name):
    """The contract, for every registered planner: each step leaves the path no longer than it
    found it, and the final path is valid (exact check) and no longer than the planner's."""
    problem = problem_from_dict(SINGLE_CIRCLE)
    result = solve(problem, f"{name}+simplify+pso", time_limit=0.3, seed=5)
    assert result.planner == f"{name}+simplify+pso"
    if not result.solved:
        pytest.skip(f"{name} found no path in 0.24 s")
    steps = result.stages["post"]
    assert [s["step"] for s in steps] == ["simplify", "pso"]
    for s in steps:
        assert s["length_after"] <= s["length_before"] + 1e-9
    assert steps[1]["length_before"] == pytest.approx(steps[0]["length_after"])
    assert result.length == pytest.approx(steps[-1]["length_after"])
    assert World.from_problem(problem).path_valid(result.path)
    run = result.benchmark
    assert run.simplified_length == pytest.approx(result.length)
    assert run.simplified_length <= run.solution_length + 1e-9
    assert run.simplification_time >= steps[0]["time"] + steps[1]["time"] - 1e-9


def test_a_path_through_a_narrow_gap_stays_in_its_gap():
    # wall_gap: a point robot, a gap 1 unit wide at y = 9.5..10.5 in a wall at x = -5..5. A path
    # through the gap must still cross x = 0 inside it after the swarm (not jump the wall).
    problem = load_problem(PROBLEMS / "static" / "wall_gap.yaml")
    world = World.from_problem(problem)
    ctx = make_context(problem, world)
    route = np.array([[-20, 0], [-8, 9.0], [-5, 10.0], [5, 10.0], [8, 9.0], [20, 0]], float)
    assert world.path_valid(route)
    path = array_to_path(ctx.si, route)
    optimizer = PSOPathOptimizer(ctx.si, rng=np.random.default_rng(3))
    assert optimizer.model is world  # our setup: the exact vectorised world
    assert optimizer.optimize(path, 0.3)
    out = path_to_array(path)
    assert world.path_valid(out)
    assert optimizer.last_result.length < optimizer.last_result.input_length
    crossing = [a + (b - a) * (0 - a[0]) / (b[0] - a[0])
                for a, b in itertools.pairwise(out) if a[0] * b[0] < 0]  # fmt: skip
    assert len(crossing) == 1 and 9.5 <= crossing[0][1] <= 10.5
    assert optimizer.last_result.length >= 45.51 - 1e-6  # never below the exact optimum


def foreign_setup():
    """test_optimal_planning's world in a plain SimpleSetup with the user's own checker."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    ss = og.SimpleSetup(space)
    calls = {"n": 0}

    def valid(s) -> bool:
        calls["n"] += 1
        return not (0.3 < s[0] < 0.7 and 0.3 < s[1] < 0.7)

    ss.setStateValidityChecker(valid)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.1, 0.1, 0.9, 0.9
    ss.setStartAndGoalStates(start, goal, 1e-9)
    ss.setOptimizationObjective(ob.PathLengthOptimizationObjective(ss.getSpaceInformation()))
    return ss, valid, calls


def test_a_foreign_validity_checker_is_honoured():
    ss, valid, calls = foreign_setup()
    si = ss.getSpaceInformation()
    # A detour that stays clear of the square (a planner's path may cut its corner between two
    # coarse checks, and then the swarm rightly leaves it alone: test_foreign_checker.py).
    path = array_to_path(si, np.array([[0.1, 0.1], [0.2, 0.8], [0.9, 0.9]]))
    before = path.length()
    optimizer = PSOPathOptimizer(si, swarm_size=20, rng=np.random.default_rng(1))
    assert isinstance(optimizer.model, SpaceInformationCollisionModel)
    n0 = calls["n"]
    changed = optimizer.optimize(path, 0.3)
    assert calls["n"] > n0  # candidates went through the user's checker
    assert changed and path.length() < before
    # Valid under the user's own checks, segment by segment.
    states = path.getStates()
    assert all(si.checkMotion(a, b) for a, b in itertools.pairwise(states))
    assert all(valid(s) for s in states)
    # Not below the true optimum around the square (1.26491 = 2 * |(0.1, 0.1) - (0.3, 0.7)|).
    assert path.length() >= 2 * math.hypot(0.2, 0.6) - 0.01


def test_nothing_to_gain_leaves_the_path_alone():
    ss, _, _ = foreign_setup()
    si = ss.getSpaceInformation()
    straight = array_to_path(si, np.array([[0.1, 0.1], [0.1, 0.9]]))
    assert not PSOPathOptimizer(si, rng=np.random.default_rng(0)).optimize(straight, 0.1)
    assert path_to_array(straight).tolist() == [[0.1, 0.1], [0.1, 0.9]]
    with pytest.raises(ParameterError, match="swarm_sizes"):
        PSOPathOptimizer(si, swarm_sizes=3)


def _se2_path(points):
    """An SE(2) space over [0, 10]^2 with a checker that accepts everything, and a path."""
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda state: True)
    si.setup()
    path = og.PathGeometric(si)
    for x, y, yaw in points:
        state = space.allocState()
        state.setXY(x, y)
        state.setYaw(yaw)
        path.append(state)
    return si, path


def _poses(path):
    return [(s.getX(), s.getY(), s.getYaw()) for s in path.getStates()]


DETOUR = [(1.0, 1.0, 0.0), (5.0, 8.0, 0.5), (9.0, 1.0, 0.0)]


def test_the_optimizer_refuses_a_space_it_does_not_read_at_construction():
    """The swarm reads the plane, R^n, SE(2), Dubins and Reeds-Shepp (issue 35): given SE(3) or
    SO(2) it says so at once, instead of reading two coordinates of each state (issue 32)."""
    space = ob.SE3StateSpace()
    bounds = ob.RealVectorBounds(3)
    bounds.setLow(0.0)
    bounds.setHigh(1.0)
    space.setBounds(bounds)
    with pytest.raises(
        UnsupportedSpaceError,
        match=r"^PSOPathOptimizer: the state space .*\(ob\.SE3StateSpace, 6 dimensions\) is "
        r"none of those",
    ):
        PSOPathOptimizer(ob.SpaceInformation(space))
    with pytest.raises(UnsupportedSpaceError, match=r"\(ob\.SO2StateSpace, 1 dimension\)"):
        PSOPathOptimizer(ob.SpaceInformation(ob.SO2StateSpace()), rng=np.random.default_rng(0))


class LongerIsCheaper(ob.OptimizationObjective):
    """An objective that any shortcut raises (each motion costs minus its length)."""

    def __init__(self, si):
        super().__init__(si)
        self.si = si

    def stateCost(self, state):
        return ob.Cost(0.0)

    def motionCost(self, a, b):
        return ob.Cost(-self.si.distance(a, b))


def test_the_simplify_post_pass_works_in_any_space_and_the_swarm_in_se2():
    """``run_post``: OMPL's simplifier in SE(2) (a step that raises the objective is undone, its
    states put back as they were), and the swarm (issue 35) leaves a single motion as it is."""
    si, path = _se2_path(DETOUR)
    (step,) = run_post(si, path, ["simplify"], time.perf_counter() + 1.0,
                       objective=LongerIsCheaper(si))  # fmt: skip
    assert _poses(path) == DETOUR  # the shortcut raised the objective: undone, exactly
    assert step.cost_after == step.cost_before
    (step,) = run_post(si, path, ["simplify"], time.perf_counter() + 1.0)
    assert _poses(path) == [DETOUR[0], DETOUR[-1]] and step.length_after < step.length_before
    (step,) = run_post(si, path, ["pso"], time.perf_counter() + 1.0)
    assert _poses(path) == [DETOUR[0], DETOUR[-1]] and step.length_after == step.length_before


def test_an_undone_simplify_step_puts_a_plane_path_back_exactly():
    ss, _, _ = foreign_setup()
    si = ss.getSpaceInformation()
    xy = np.array([[0.1, 0.1], [0.15, 0.25], [0.2, 0.1]])  # clear of the square
    path = array_to_path(si, xy)
    (step,) = run_post(si, path, ["simplify"], time.perf_counter() + 1.0,
                       objective=LongerIsCheaper(si))  # fmt: skip
    assert np.array_equal(path_to_array(path), xy) and step.cost_after == step.cost_before
    run_post(si, path, ["simplify"], time.perf_counter() + 1.0)  # no objective: shortened
    assert path_to_array(path).tolist() == [[0.1, 0.1], [0.2, 0.1]]


def test_rrtstarpso_and_the_post_pass_share_one_optimiser(monkeypatch):
    from rrtpso_ompl.planners import post

    made = []
    original = post.PSOPathOptimizer.optimize_array

    def spy(self, xy, *args):
        made.append(len(xy))
        return original(self, xy, *args)

    monkeypatch.setattr(post.PSOPathOptimizer, "optimize_array", spy)
    result = solve(problem_from_dict(SINGLE_CIRCLE), "RRTstarPSO", time_limit=0.3, seed=2)
    assert result.solved and made  # RRTstarPSO's swarm stage is the post-pass optimiser


def test_post_passes_share_the_one_budget(monkeypatch):
    problem = problem_from_dict(SINGLE_CIRCLE)
    limits = []  # the planner's own termination condition: what it was given, not how long it ran
    timed = ob.timedPlannerTerminationCondition

    def spy(seconds, *args):
        limits.append(seconds)
        return timed(seconds, *args)

    monkeypatch.setattr(ob, "timedPlannerTerminationCondition", spy)
    plain = solve(problem, "PRMstar", time_limit=0.4, seed=3, params={"post_fraction": 0.5},
                  post=["pso"])  # fmt: skip
    monkeypatch.undo()
    assert plain.planner == "PRMstar"  # as asked; the post-passes are in the stages
    assert limits[0] == pytest.approx(0.4 * 0.5)  # the planner had half
    assert plain.stages["post"][0]["step"] == "pso"
    with pytest.raises(ParameterError, match="post_fraction"):
        solve(problem, "PRMstar", time_limit=0.4, seed=3, params={"post_fraction": 0.95},
              post=["pso"])  # fmt: skip


def run_cli(*args, timeout=120):
    return subprocess.run([*rrtpso_exe(), *args], capture_output=True, text=True, timeout=timeout)


def test_solve_post_flag_reports_each_step(tmp_path):
    out = tmp_path / "r.json"
    proc = run_cli("solve", str(PROBLEMS / "static" / "single_circle.yaml"), "--planner", "RRT",
                   "--post", "simplify,pso", "--time", "0.3", "--seed", "2",
                   "--json", str(out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["planner"] == "RRT"  # as asked (the contract); the post-passes are in the stages
    steps = data["stages"]["post"]
    assert [s["step"] for s in steps] == ["simplify", "pso"]
    assert all(set(s) == {"step", "length_before", "length_after", "time"} for s in steps)
    assert data["length"] == pytest.approx(steps[-1]["length_after"])


@pytest.mark.parametrize(
    ("args", "fragment"),
    [(["--post", "pso,smooth"], "--post: unknown post-pass 'smooth' (known: simplify, pso)"),
     (["--planner", "RRT+zap"], "--planner: unknown post-pass 'zap' (known: simplify, pso)"),
     (["--post", "pso", "--param", "post_fraction=1.5"], "post_fraction")],
)  # fmt: skip
def test_solve_post_errors_exit_2(tmp_path, args, fragment):
    out = tmp_path / "r.json"
    proc = run_cli("solve", str(PROBLEMS / "static" / "single_circle.yaml"), *args,
                   "--json", str(out))  # fmt: skip
    assert proc.returncode == 2
    assert fragment in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()


@pytest.mark.slow  # seconds of work: the full run only
def test_bench_logs_each_spec_as_a_configuration(tmp_path):
    proc = run_cli("bench", str(PROBLEMS / "static" / "single_circle.yaml"), "--planner",
                   "RRT+simplify,RRT+simplify+pso", "--runs", "2", "--time", "0.2", "--jobs", "2",
                   "--out", str(tmp_path / "b"), "-q", timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    db = sqlite3.connect(tmp_path / "b" / "benchmark.db")
    names = {n for (n,) in db.execute("SELECT name FROM plannerConfigs")}
    assert {"geometric_RRT+simplify", "geometric_RRT+simplify+pso"} <= names
    rows = db.execute(
        "SELECT c.name, r.solution_length, r.simplified_solution_length, r.simplification_time "
        "FROM runs r JOIN plannerConfigs c ON r.plannerid = c.id"
    ).fetchall()
    assert len(rows) == 4
    for _, raw, simplified, seconds in rows:
        assert simplified <= raw + 1e-9 and seconds >= 0


@pytest.mark.slow  # the rrtpso command end to end
def test_batch_takes_post_pass_parameters_for_the_specs_that_have_post_passes(tmp_path):
    out = tmp_path / "b.jsonl"
    proc = run_cli("batch", str(PROBLEMS / "static" / "single_circle.yaml"), "--planner",
                   "RRT+pso,BITstar", "--param", "post_fraction=0.5", "--time", "0.2",
                   "--out", str(out), "-q")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    rows = {r["planner"]: r for r in map(json.loads, out.read_text().splitlines())}
    assert rows["RRT+pso"]["stages"]["post"][0]["step"] == "pso"
    assert "post" not in rows["BITstar"]["stages"] and rows["BITstar"]["error"] is None
    bad = run_cli("batch", str(PROBLEMS / "static" / "single_circle.yaml"), "--planner",
                  "RRT+pso", "--param", "post_fraction=5",
                  "--out", str(tmp_path / "c.jsonl"))  # fmt: skip
    assert bad.returncode == 2 and "post_fraction" in bad.stderr
