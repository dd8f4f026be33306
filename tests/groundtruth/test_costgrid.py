"""The grid reference of the inflation objective (groundtruth/costgrid.py)."""

from __future__ import annotations

import numpy as np
import pytest

from rrtpso_ompl.groundtruth import costgrid, shortest_path
from rrtpso_ompl.groundtruth.costgrid import CostGridError, cost_reference, smooth_path
from rrtpso_ompl.model import load_problem
from rrtpso_ompl.model.objective import InflationCost
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.model.world import World


def corridor(**robot):
    """A corridor 2 wide along x (walls below y = 0 and above y = 2), start low, goal high."""
    return problem_from_dict({
        "name": "corridor",
        "units": "m",
        "bounds": [[0, 0], [10, 2]],
        "start": [0.5, 0.4],
        "goal": [9.5, 1.6],
        "robot": {"radius": 0.2, **robot},
        "obstacles": [
            {"type": "rectangle", "min": [-1, -1], "max": [11, 0]},
            {"type": "rectangle", "min": [-1, 2], "max": [11, 3]},
        ],
    })  # fmt: skip


def door(width=0.8, **robot):
    """A wall across x = 5 with one door of ``width`` centred at y = 5; start and goal below it on
    either side, so that the shortest path brushes both door frames."""
    lo, hi = 5 - width / 2, 5 + width / 2
    return problem_from_dict({
        "name": "door",
        "units": "m",
        "bounds": [[0, 0], [10, 10]],
        "start": [1, 2],
        "goal": [9, 2],
        "robot": {"radius": 0.2, "inflation_radius": 1.0, **robot},
        "obstacles": [
            {"type": "rectangle", "min": [4.9, -1], "max": [5.1, lo]},
            {"type": "rectangle", "min": [4.9, hi], "max": [5.1, 11]},
        ],
    })  # fmt: skip


def exact_cost(problem):
    """J of the exact shortest path (the paper's reference) under the problem's objective."""
    world = World.from_problem(problem)
    path = shortest_path(problem, world).valid_polyline(world)
    return InflationCost.of(problem.robot).path_cost(world, path), path


def test_corridor_narrower_than_twice_the_inflation_keeps_to_its_middle():
    # Half-width 1 < R_i = 1.5: every point is inflated, and the cost is least where the nearest
    # wall is farthest: the middle, y = 1.
    problem = corridor(inflation_radius=1.5)
    ref = cost_reference(problem, resolution=0.05)
    assert ref.found
    world = World.from_problem(problem)
    assert world.path_valid(ref.path)
    # Sample the path densely in its middle stretch.
    s = np.linspace(0, 1, 2001)[:, None]
    seg = ref.path[:-1, None, :] + s[None] * np.diff(ref.path, axis=0)[:, None, :]
    pts = seg.reshape(-1, 2)
    middle = pts[(pts[:, 0] > 3) & (pts[:, 0] < 7)]
    assert len(middle) and np.abs(middle[:, 1] - 1.0).max() <= 0.06  # about a node spacing
    # The shortest path runs the straight diagonal, closer to the walls; the reference is cheaper.
    j_exact, _ = exact_cost(problem)
    assert ref.cost <= j_exact


def test_reference_passes_a_door_narrower_than_twice_the_inflation_and_keeps_its_middle():
    problem = door(width=0.8)  # 2 r = 0.4 < 0.8 < 2 R_i = 2.0
    ref = cost_reference(problem, resolution=0.05)
    world = World.from_problem(problem)
    assert ref.found and world.path_valid(ref.path)
    np.testing.assert_allclose(ref.path[0], problem.start)
    np.testing.assert_allclose(ref.path[-1], problem.goal)
    # Where it crosses the wall's line it is near the door's middle (clearance 0.4 there).
    crossing = np.flatnonzero(np.diff(np.sign(ref.path[:, 0] - 5.0)) != 0)[0]
    a, b = ref.path[crossing], ref.path[crossing + 1]
    y = a[1] + (5.0 - a[0]) * (b[1] - a[1]) / (b[0] - a[0])
    assert abs(y - 5.0) <= 0.05
    j_exact, exact = exact_cost(problem)
    cost = InflationCost.of(problem.robot)
    assert ref.cost < j_exact  # the exact shortest path brushes both door frames
    assert cost.near_share(world, ref.path) < cost.near_share(world, exact)


def test_reported_cost_is_the_objective_of_the_path_and_smoothing_never_raises_it():
    problem = door(width=1.2)
    ref = cost_reference(problem, resolution=0.1)
    world = World.from_problem(problem)
    cost = InflationCost.of(problem.robot)
    assert ref.cost == cost.path_cost(world, ref.path)
    assert ref.length == pytest.approx(np.hypot(*np.diff(ref.path, axis=0).T).sum())
    assert ref.smoothed and ref.cost <= ref.grid_cost
    raw = cost_reference(problem, resolution=0.1, smooth=False)
    assert not raw.smoothed and raw.cost == raw.grid_cost == ref.grid_cost
    assert len(ref.path) < len(raw.path)
    d = ref.to_dict()
    assert list(d)[:3] == ["length", "path", "cost"]
    assert d["grid"]["resolution"] == pytest.approx(0.1) and d["grid"]["connectivity"] == 16


def test_smoothing_keeps_only_shortcuts_that_lower_the_cost():
    problem = corridor(inflation_radius=1.5)
    world = World.from_problem(problem)
    cost = InflationCost.of(problem.robot)
    # A path along the middle, then down to the wall and back: the detour costs; cut it.
    path = np.array([[0.5, 1.0], [2, 1.0], [3, 0.3], [4, 1.0], [9.5, 1.0]])
    out = smooth_path(world, cost, path)
    assert cost.path_cost(world, out) < cost.path_cost(world, path)
    assert world.path_valid(out)
    # A path along the middle with vertices on it: a shortcut to the wall side never wins.
    straight = np.column_stack([np.linspace(0.5, 9.5, 10), np.full(10, 1.0)])
    kept = smooth_path(world, cost, straight)
    assert cost.path_cost(world, kept) <= cost.path_cost(world, straight)


def test_without_inflation_the_reference_is_a_length_grid_near_the_exact_optimum():
    problem = door(width=0.8, inflation_radius=None)
    ref = cost_reference(problem, resolution=0.05)
    exact = shortest_path(problem)
    assert ref.cost == pytest.approx(ref.length)
    assert exact.length <= ref.length <= 1.01 * exact.length


def test_resolution_defaults_coarsening_and_refusals(monkeypatch, tmp_path):
    problem = door()
    monkeypatch.setattr(costgrid, "TARGET_NODES", 20_000)
    ref = cost_reference(problem)
    assert 19_000 <= ref.nodes <= 20_000 and not ref.coarsened
    # A map: its own cells (20 x 10 of 0.5 m), nodes at their centres.
    from helpers import _corridor

    mapped = load_problem(_corridor(tmp_path, robot={"radius": 0.2, "inflation_radius": 1.0}))
    on_map = cost_reference(mapped)
    assert on_map.resolution == 0.5 and on_map.nodes == 200
    assert on_map.found and World.from_problem(mapped).path_valid(on_map.path)
    finer = cost_reference(mapped, resolution=0.125)
    assert finer.nodes == 3200 and finer.cost <= on_map.cost
    monkeypatch.setattr(costgrid, "MAX_NODES", 1000)
    monkeypatch.setattr(costgrid, "TARGET_NODES", 1500)
    small = cost_reference(problem)
    assert small.coarsened and small.nodes <= 1000
    with pytest.raises(CostGridError, match="at most 1,000"):
        cost_reference(problem, resolution=0.05)
    with pytest.raises(CostGridError, match="resolution must be > 0"):
        cost_reference(problem, resolution=0.0)


def test_start_already_at_the_goal_and_a_goal_tolerance():
    problem = problem_from_dict({
        "bounds": [[0, 0], [10, 10]], "start": [1, 1], "goal": [1.05, 1], "goal_tolerance": 0.1,
        "robot": {"radius": 0.2, "inflation_radius": 1.0},
    })  # fmt: skip
    ref = cost_reference(problem, resolution=0.5)
    assert ref.found and ref.cost == 0.0 and len(ref.path) == 1
    # A goal behind a closed wall, its tolerance reaching over it: a node within it will do.
    data = {
        "bounds": [[0, 0], [10, 10]], "start": [1, 5], "goal": [6, 5], "goal_tolerance": 1.5,
        "robot": {"radius": 0.2, "inflation_radius": 1.0},
        "obstacles": [{"type": "rectangle", "min": [4.9, -1], "max": [5.1, 11]}],
    }  # fmt: skip
    walled = problem_from_dict(data)
    ref = cost_reference(walled, resolution=0.1)
    assert ref.found and World.from_problem(walled).path_valid(ref.path)
    assert ref.path[-1][0] < 4.9 and np.hypot(*(ref.path[-1] - walled.goal)) <= 1.5
    # Without the tolerance the grid has no path (and says so).
    closed = cost_reference(problem_from_dict({**data, "goal_tolerance": 0.0}), resolution=0.1)
    assert not closed.found and closed.cost is None and len(closed.path) == 0
