"""Every planner and post-pass under the inflation objective (issue 27): the cost they report is
the declared one, no post-pass raises it, and a door narrower than twice the inflation radius
is still passed."""

from __future__ import annotations

import time

import numpy as np
import pytest
from helpers import INFLATED_DOOR

from rrtpso_ompl.model import World
from rrtpso_ompl.model.objective import InflationCost
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.ompl_setup import array_to_path, make_context, path_to_array
from rrtpso_ompl.planners import solve
from rrtpso_ompl.planners.post import run_post
from rrtpso_ompl.planners.pso.path_optimizer import optimize_path

DOOR = INFLATED_DOOR


@pytest.fixture(scope="module")
def door():
    problem = problem_from_dict(DOOR)
    return problem, World.from_problem(problem), InflationCost.of(problem.robot)


@pytest.fixture(scope="module")
def hugging(door):
    """The exact shortest path: taut round the door's jambs and the pillar, at the radius."""
    from rrtpso_ompl.groundtruth import shortest_path

    problem, world, _ = door
    path = shortest_path(problem).valid_polyline(world)
    assert world.path_valid(path)
    return path


def test_the_swarm_moves_a_hugging_path_off_the_walls_and_never_raises_the_cost(door, hugging):
    _, world, cost = door
    out = optimize_path(hugging, world, rng=np.random.default_rng(1), objective=cost)
    assert out.improved and world.path_valid(out.path)
    assert out.cost == pytest.approx(cost.path_cost(world, out.path))
    assert out.cost < out.input_cost == pytest.approx(cost.path_cost(world, hugging))
    # The door's stretch is near its jambs whatever the path; the rest moves away.
    assert cost.near_share(world, out.path) < 0.8 * cost.near_share(world, hugging)
    # Still through the door: the path crosses x = 5 between its jambs.
    p = out.path
    i = np.flatnonzero((p[:-1, 0] < 5) & (p[1:, 0] >= 5))[0]
    t = (5 - p[i, 0]) / (p[i + 1, 0] - p[i, 0])
    assert 4.6 + 0.2 <= p[i, 1] + t * (p[i + 1, 1] - p[i, 1]) <= 5.4 - 0.2


def test_without_time_or_gain_the_swarm_returns_its_input(door):
    _, world, cost = door
    straight = np.array([[1, 8], [4, 8]])
    out = optimize_path(straight, world, rng=np.random.default_rng(0), objective=cost)
    assert not out.improved and out.path is not None and np.array_equal(out.path, straight)


@pytest.mark.parametrize("steps", [("simplify",), ("pso",), ("simplify", "pso")])
def test_no_post_pass_raises_the_objective(door, hugging, steps):
    problem, world, cost = door
    ctx = make_context(problem, world)
    path = array_to_path(ctx.si, hugging)
    done = run_post(ctx.si, path, steps, time.perf_counter() + 1.0,
                    world=world, rng=np.random.default_rng(2), objective=ctx.objective)  # fmt: skip
    for s in done:
        assert s.cost_after <= s.cost_before + 1e-12
    final = path_to_array(path)
    assert world.path_valid(final)
    assert cost.path_cost(world, final) <= cost.path_cost(world, hugging) + 1e-12
    if "pso" in steps:
        assert cost.path_cost(world, final) < cost.path_cost(world, hugging)


@pytest.mark.parametrize("planner", ["RRTstarPSO", "BITstar+simplify"])
def test_planners_report_the_objective_and_pass_the_narrow_door(door, planner):
    problem, world, cost = door
    result = solve(problem, planner, time_limit=0.5, seed=3)
    if not result.solved:
        pytest.skip(f"{planner} found no path in 0.5 s")
    assert world.path_valid(result.path)
    assert result.cost == pytest.approx(cost.path_cost(world, result.path), rel=1e-12)
    assert result.cost > result.length  # the door's jambs are within the inflation radius
    assert result.to_dict()["cost"] == result.cost


def test_rrtstarpso_lowers_the_objective_below_the_shortest_paths(door, hugging):
    problem, world, cost = door
    # Bounded by work (RRT*'s iterations, one swarm round), not by a budget a loaded machine may
    # not have: 60 s is a cap it never comes near (0.4 s here).
    bounded = {"rrt_max_iterations": 50, "iterations": 20, "refine_rounds": 0, "polish_rounds": 0}
    result = solve(problem, "RRTstarPSO", time_limit=60.0, seed=4, params=bounded)
    assert result.solved
    assert result.cost < cost.path_cost(world, hugging)
    assert result.stages["pso_cost"] <= result.stages["seed_cost"]


@pytest.mark.slow  # the rrtpso command, in a process of its own
def test_bitstar_survives_the_objective(tmp_path):
    """OMPL 2.0.1's BIT* crashed (a segmentation fault) under a PathLengthOptimizationObjective
    subclass with this cost (paper_static, seed 1): the objective derives from
    OptimizationObjective now. Run in a process of its own, so that a crash fails the test."""
    import subprocess

    import yaml
    from helpers import PROBLEMS, rrtpso_exe

    doc = yaml.safe_load((PROBLEMS / "static" / "paper_static.yaml").read_text())
    doc["robot"] |= {"inflation_radius": 114.0, "cost_scaling_factor": 0.0175}
    path = tmp_path / "inflated.yaml"
    path.write_text(yaml.safe_dump(doc))
    command = [*rrtpso_exe(), "solve", str(path), "--planner", "BITstar", "--time", "1",
               "--seed", "1"]  # fmt: skip
    run = subprocess.run(command, capture_output=True, text=True, timeout=60)
    assert run.returncode in (0, 1), run.stderr[-2000:]
