"""The point robot's exact optimum on a map by interval search (optimum/mesh.py and
optimum/intervals.py, issue 38): the mesh, the bounds, and the answers against the tangent
search, which the package used before for the same query (to 1e-9, valid)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from helpers import cells_world

from rrtpso_ompl.groundtruth.free_grid import Stopped
from rrtpso_ompl.groundtruth.optimum import OptimumTooLarge, shortest_path_in_world
from rrtpso_ompl.groundtruth.optimum import intervals as iv
from rrtpso_ompl.groundtruth.optimum.mesh import RectMesh
from rrtpso_ompl.model import World


def _grid(seed: int, size: int = 20, density: float = 0.22) -> np.ndarray:
    """Random blocked cells (rows from the bottom) with diagonal pinches and one-cell jogs of
    the walls; the corner cells free."""
    rng = np.random.default_rng(seed)
    blocked = rng.random((size, size)) < density
    for _ in range(3):
        r, c = rng.integers(1, size - 3, 2)
        blocked[r : r + 2, c : c + 2] = [[True, False], [False, True]]  # a pinch
        r, c = rng.integers(1, size - 4, 2)
        blocked[r : r + 3, c : c + 2] = [[True, False], [False, False], [False, True]]  # a jog
    blocked[0, 0] = blocked[-1, -1] = False
    return blocked


def _world(blocked: np.ndarray) -> World:
    """A point robot's world of unit cells (boxes on the lattice, as a map's)."""
    return cells_world(blocked)


def _tangent(world: World, start, goal):
    """The tangent search's answer for the same query: the point robot given its rounding
    radius (twice the tolerance) explicitly, which the interval search leaves to it."""
    return shortest_path_in_world(world.with_robot_radius(2.0 * world.tol), start, goal)


def test_the_mesh_covers_the_free_cells_and_meets_only_along_pieces():
    blocked = _grid(0)
    mesh = RectMesh.build(~blocked)
    nx = blocked.shape[1]
    assert np.array_equal(mesh.cell_rect < 0, blocked)
    area = sum((x1 - x0) * (y1 - y0) for x0, x1, y0, y1 in
               zip(mesh.x0, mesh.x1, mesh.y0, mesh.y1, strict=True))  # fmt: skip
    assert area == int((~blocked).sum())
    for q, (x0, x1, y0, y1) in enumerate(zip(mesh.x0, mesh.x1, mesh.y0, mesh.y1, strict=True)):
        assert (mesh.cell_rect[y0:y1, x0:x1] == q).all()
        for side in (x0 - 1, x1):  # the sides are walls all along
            assert side < 0 or side >= nx or blocked[y0:y1, side].all()
        for p0, p1, nb, pid in mesh.top[q]:
            assert p0 < p1 and mesh.y0[nb] == y1 and tuple(mesh.pieces[pid]) == (p0, p1, y1, q, nb)
            assert (~blocked[y1 - 1, p0:p1]).all() and (~blocked[y1, p0:p1]).all()
        assert sorted(mesh.top[q]) == mesh.top[q]
    count = np.pad(blocked, 1, constant_values=True).astype(int)
    count = count[:-1, :-1] + count[:-1, 1:] + count[1:, :-1] + count[1:, 1:]
    assert np.array_equal(mesh.corner, count == 1)


def test_the_pieces_bounds_are_lower_bounds_on_the_way_to_the_goal():
    blocked = _grid(1)
    world, mesh = _world(blocked), RectMesh.build(~blocked)
    goal = (19.5, 19.5)
    bound = mesh.bounds_to(*goal)
    rng = np.random.default_rng(1)
    for pid in rng.choice(len(mesh.pieces), 12, replace=False):
        p0, p1, y = mesh.pieces[pid, :3]
        mid = (0.5 * (p0 + p1), float(y))
        exact = _tangent(world, mid, goal).length
        if exact is None:
            assert not np.isfinite(bound[pid])
        else:
            assert bound[pid] <= exact * (1 + 1e-12)
    assert (bound[np.isfinite(bound)] >= 0).all()


@pytest.mark.parametrize("seed", range(1, 13))
def test_the_interval_search_agrees_with_the_tangent_search(seed):
    blocked = _grid(seed)
    world = _world(blocked)
    start, goal = (0.5, 0.5), (19.5, 19.5)
    new = shortest_path_in_world(world, start, goal)
    old = _tangent(world, start, goal)
    assert (new.length is None) == (old.length is None)
    if new.length is not None:
        assert new.length == pytest.approx(old.length, rel=1e-9)
        assert world.path_valid(new.valid_polyline(world))
        assert new.rounds == 1 and new.n_nodes > 0


def test_a_jog_of_the_walls_is_passed_between_its_two_corners():
    """A straight line along a wall on its left and on along one on its right: exact for sharp
    corners, but round the rounded ones the path must pass between the two corners it touches
    (their sides from the walls'); without them the path cut the second wall."""
    blocked = np.zeros((6, 3), dtype=bool)
    blocked[1, 0] = True  # left of x = 1 at y in [1, 2]
    blocked[3:5, 1] = True  # right of x = 1 at y in [3, 5]
    world = _world(blocked)
    start, goal = (1.5, 0.2), (0.5, 5.8)
    new = shortest_path_in_world(world, start, goal)
    assert world.path_valid(new.valid_polyline(world))
    assert new.length == pytest.approx(_tangent(world, start, goal).length, rel=1e-12)
    mesh = RectMesh.build(~blocked)
    points, sides = iv.corner_sides(mesh, [(1.5, 0.2), (1.0, 1.0), (1.0, 5.0), (0.5, 5.8)])
    assert (1.0, 2.0) in points and (1.0, 3.0) in points
    assert sides[points.index((1.0, 2.0))] == 1 and sides[points.index((1.0, 3.0))] == -1


def test_two_regions_joined_only_at_a_pinch_have_no_path():
    blocked = np.zeros((4, 4), dtype=bool)
    blocked[:2, 2:] = True
    blocked[2:, :2] = True  # the free quarters touch only at (2, 2)
    mesh = RectMesh.build(~blocked)
    assert iv.interval_path(mesh, (0.5, 0.5), (3.5, 3.5)) is None
    assert shortest_path_in_world(_world(blocked), (0.5, 0.5), (3.5, 3.5)).length is None


def test_the_search_stops_when_told_and_refuses_too_many_nodes(monkeypatch):
    blocked = _grid(1)
    mesh = RectMesh.build(~blocked)
    monkeypatch.setattr(iv, "_POLL", 1)
    with pytest.raises(Stopped):
        iv.interval_path(mesh, (0.5, 0.5), (19.5, 19.5), terminate=lambda: True)
    result = shortest_path_in_world(_world(blocked), (0.5, 0.5), (19.5, 19.5),
                                    terminate=iter([False] * 3 + [True] * 99).__next__)  # fmt: skip
    assert result.stopped and result.length is None
    monkeypatch.setattr(iv, "MAX_NODES", 5)
    with pytest.raises(OptimumTooLarge, match="interval search"):
        iv.interval_path(mesh, (0.5, 0.5), (19.5, 19.5))


def test_discs_goal_discs_and_shapes_keep_the_tangent_search(monkeypatch):
    from rrtpso_ompl.groundtruth.optimum import query

    calls = []
    real = query.TangentSearch

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(query, "TangentSearch", spy)
    blocked = _grid(4, density=0.1)
    world = _world(blocked)
    assert shortest_path_in_world(world, (0.5, 0.5), (19.5, 19.5)).length is not None
    assert calls == []
    with_circle = World(world.bounds, circles=[(10.0, 10.0, 0.3)], boxes=world.boxes)
    for w, tol in ((world.with_robot_radius(0.2), 0.0), (world, 0.3), (with_circle, 0.0)):
        assert shortest_path_in_world(w, (0.5, 0.5), (19.5, 19.5), tol).length is not None
        assert calls
        calls.clear()


@pytest.mark.parametrize("seed", range(6))
def test_a_discs_optimum_is_the_same_with_the_points_bound_and_guess(seed, monkeypatch):
    """The point's sharp path bounds a disc's from below, and its guess only places the first
    round: the disc's optimum is the same with them as without (to 1e-9), and valid."""
    from rrtpso_ompl.groundtruth.optimum import query

    blocked = _grid(seed, density=0.15)
    radius = (0.2, 0.35, 0.45)[seed % 3]
    world = _world(blocked).with_robot_radius(radius)
    rng = np.random.default_rng(seed)
    free = np.argwhere(~blocked)
    checked = 0
    for _ in range(4):
        a, b = free[rng.choice(len(free), 2, replace=False)]
        start, goal = (a[1] + 0.5, a[0] + 0.5), (b[1] + 0.5, b[0] + 0.5)
        if not (world.point_clearance(np.array([start, goal])) >= world.threshold).all():
            continue
        tol = 0.3 if checked % 2 else 0.0
        sharp, guess = query._point_path(world, np.array(start), np.array(goal), tol, None, "t")
        new = shortest_path_in_world(world, start, goal, goal_tolerance=tol)
        with monkeypatch.context() as m:
            m.setattr(query, "_point_path", lambda *args: (0.0, 0.0))
            old = shortest_path_in_world(world, start, goal, goal_tolerance=tol)
        if old.length is None:
            assert new.length is None
            continue
        checked += 1
        assert new.length == pytest.approx(old.length, rel=1e-9)
        assert sharp <= new.length + 1e-9 <= guess * 1.3
        assert world.path_valid(new.valid_polyline(world))
    assert checked >= 2


def test_the_points_bound_keeps_to_its_budget(monkeypatch):
    """Past its budget of expansions the interval search stops (OptimumTooLarge), and a disc's
    search goes on without the point's bound, to the same optimum."""
    from rrtpso_ompl.groundtruth.optimum import query

    blocked = _grid(2, density=0.1)
    mesh = RectMesh.build(~blocked)
    with pytest.raises(OptimumTooLarge, match="budget of 3 expansions"):
        iv.interval_path(mesh, (0.5, 0.5), (19.5, 19.5), budget=3)
    world = _world(blocked).with_robot_radius(0.3)
    start, goal = np.array([0.5, 0.5]), np.array([19.5, 19.5])
    full = shortest_path_in_world(world, start, goal)
    assert full.length is not None
    assert query._point_path(world, start, goal, 0.0, None, "t")[0] > 0.0
    monkeypatch.setattr(query, "_point_budget", lambda mesh: 0)
    assert query._point_path(world, start, goal, 0.0, None, "t") == (0.0, 0.0)
    assert shortest_path_in_world(world, start, goal).length == pytest.approx(full.length, 1e-12)


def test_no_point_path_proves_that_no_disc_passes(monkeypatch):
    """A wall of cells touching only at their corners: the raster's 8-connected search passes
    between them, the point's path search does not (the mesh meets along pieces, and no disc
    passes a point where two blocked cells touch), and the answer is "no path" without a
    tangent search."""
    from rrtpso_ompl.groundtruth.free_grid import FreeGrid
    from rrtpso_ompl.groundtruth.optimum import query

    blocked = np.zeros((10, 10), dtype=bool)
    blocked[np.arange(10), 9 - np.arange(10)] = True
    assert FreeGrid.for_world(_world(blocked).with_robot_radius(0.2), (1.5, 1.5),
                              (8.5, 8.5)).connected  # fmt: skip
    world = _world(blocked).with_robot_radius(0.2)
    sharp, guess = query._point_path(world, np.array([1.5, 1.5]), np.array([8.5, 8.5]), 0.0,
                                     None, "t")  # fmt: skip
    assert sharp == guess == math.inf
    monkeypatch.setattr(query, "TangentSearch", None)  # not reached
    assert shortest_path_in_world(world, (1.5, 1.5), (8.5, 8.5)).length is None


def test_rounded_corners_make_the_tangent_paths_length():
    """A left bend at (10, 0) round a circle of radius 0.5: tangents of sqrt(10^2 - 0.5^2) from
    each end, and an arc of a quarter turn plus twice asin(0.5 / 10)."""
    length, pieces = iv.rounded([(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)], [0, 1, 0], 0.5)
    arc = [p for p in pieces if p.kind == "arc"]
    assert len(arc) == 1 and arc[0].radius == 0.5
    sweep = 0.5 * math.pi + 2.0 * math.asin(0.05)
    assert arc[0].sweep == pytest.approx(sweep, rel=1e-12)
    assert length == pytest.approx(2.0 * math.sqrt(99.75) + 0.5 * sweep, rel=1e-12)
    assert length == pytest.approx(sum(p.length for p in pieces), rel=1e-15)
    for a, b in itertools.pairwise(pieces):  # joined end to end
        assert a.end == pytest.approx(b.start, abs=1e-12)
