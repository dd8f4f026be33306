"""The gates between a map's cells (groundtruth/gates.py): a lower bound on a disc's path that is
never above the exact optimum, close to it in one-cell corridors, and the optimum the same with
the bound as without it; and the raster searched again cell by cell where its blocks lost the
map's walls."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import assert_same_optimum_without, cells_world

from rrtpso_ompl.groundtruth import free_grid
from rrtpso_ompl.groundtruth.gates import Gates
from rrtpso_ompl.groundtruth.map_kinds import _maze as perfect_maze
from rrtpso_ompl.groundtruth.optimum import shortest_path_in_world
from rrtpso_ompl.model import World


def _queries(world: World, blocked: np.ndarray, rng: np.random.Generator, n: int):
    """Up to ``n`` start (anywhere in a free cell) and goal (a free cell's centre) pairs the
    disc can stand on."""
    free = np.argwhere(~blocked)
    for _ in range(4 * n):
        (ra, ca), (rb, cb) = free[rng.choice(len(free), 2, replace=False)]
        start = np.array([ca, ra]) + rng.uniform(0.15, 0.85, 2)
        goal = np.array([cb + 0.5, rb + 0.5])
        if (world.point_clearance(np.array([start, goal])) >= world.threshold).all():
            yield start, goal
            n -= 1
            if not n:
                return


def test_a_corridors_gates_keep_the_clearance_from_its_walls():
    blocked = np.ones((3, 6), dtype=bool)
    blocked[1, :] = False  # a corridor along row 1
    blocked[2, 3] = False  # and a side opening above cell (1, 3)
    gates = Gates(blocked, 0.3, [((5.5, 1.5), 0.0)])
    # Vertical edges x = 1..5 along the corridor, then the horizontal edge y = 2 at i = 3.
    np.testing.assert_allclose(gates.lo, [1.3, 1.3, 1.3, 1.3, 1.3, 3.3])
    np.testing.assert_allclose(gates.hi, [1.7, 1.7, 1.7, 1.7, 1.7, 3.7])
    blocked[2, 3] = True
    gates = Gates(blocked, 0.3, [((5.5, 1.5), 0.0)])
    np.testing.assert_allclose(gates.to[0], [4.5, 3.5, 2.5, 1.5, 0.5])  # a cell per gate
    assert gates.bound(0, np.array([[0.5, 1.5]]))[0] == pytest.approx(5.0)
    assert gates.bound(0, np.array([[5.2, 1.4]]))[0] == pytest.approx(np.hypot(0.3, 0.1))


def test_round_a_walls_corner_the_bound_is_the_discs_arc():
    """An L-shaped corridor: through the turn's cell the way between its two gates keeps the
    clearance from the wall's corner (a quarter circle of radius 0.3), which the exact optimum
    also does."""
    blocked = np.ones((4, 3), dtype=bool)
    blocked[1, :] = False  # along row 1 ...
    blocked[1:, 2] = False  # ... and up column 2
    start, goal = np.array([0.5, 1.5]), np.array([2.5, 3.5])
    gates = Gates(blocked, 0.3, [(goal, 0.0)])
    bound = gates.bound(0, start[None])[0]
    assert bound == pytest.approx(0.5 + 1.0 + 0.15 * np.pi + 1.0 + 0.5)
    exact = shortest_path_in_world(cells_world(blocked, 0.3), start, goal).length
    assert bound <= exact < bound + 0.1


@pytest.mark.parametrize("seed", range(8))
def test_the_bound_is_never_above_the_optimum(seed):
    """On perfect mazes of one-cell corridors with loops, and on random walls with pinches, for
    discs of 0.05 to 0.45 cells, goals with and without a tolerance: the bound at the start is at
    most the exact optimum; in the mazes within 15 % of it (median), closer than the raster's."""
    rng = np.random.default_rng(seed)
    if seed % 2:
        blocked = perfect_maze(rng, 25, 1, 1, 0.3)[::-1].copy()
    else:
        blocked = rng.random((20, 20)) < 0.3
    world = cells_world(blocked, float(rng.uniform(0.05, 0.45)))
    ratios, raster = [], []
    for start, goal in _queries(world, blocked, rng, 6):
        tol = float(rng.choice([0.0, 0.7]))
        found = shortest_path_in_world(world, start, goal, tol)
        gates = Gates(blocked, world.threshold, [(start, 0.0), (goal, tol)])
        bound = gates.bound(1, start[None])[0]
        if found.length is None:
            continue
        assert bound <= found.length * (1.0 + 1e-12)
        if tol == 0.0:  # the path backwards, from the goal to the start
            assert gates.bound(0, goal[None])[0] <= found.length * (1.0 + 1e-12)
        grid = free_grid.FreeGrid.for_world(world, start, goal, tol)
        grid.gates = None
        ratios.append(bound / found.length)
        raster.append(grid.lower_bound(1, start[None])[0] / found.length)
    assert ratios
    if seed % 2:  # in the mazes, well above the raster's bound
        assert np.median(ratios) > 0.85
        assert np.median(ratios) > np.median(raster) + 0.05


def test_a_diagonal_pinch_has_no_gate():
    """Two blocked cells that meet at a corner close the way between them for any disc."""
    blocked = np.zeros((4, 4), dtype=bool)
    blocked[:2, :2] = True
    blocked[2:, 2:] = True
    blocked[1, 1] = False  # the free cells (1, 1) and (2, 2) meet only at the corner (2, 2)
    gates = Gates(blocked, 0.05, [((2.5, 2.5), 0.0)])
    assert gates.bound(0, np.array([[1.5, 1.5]]))[0] == np.inf
    world = cells_world(blocked, 0.05)
    assert shortest_path_in_world(world, (1.5, 1.5), (2.5, 2.5)).length is None


def test_gates_are_built_only_where_most_are_pinched():
    maze = perfect_maze(np.random.default_rng(1), 21, 1, 1, 0.0)
    assert Gates.where_pinched(maze, 0.3, [((1.5, 1.5), 0.0)]) is not None
    wide = perfect_maze(np.random.default_rng(1), 21, 4, 1, 0.0)  # four-cell corridors
    assert Gates.where_pinched(wide, 0.3, [((1.5, 1.5), 0.0)]) is None
    assert Gates.where_pinched(np.zeros((10, 10), dtype=bool), 0.3, [((1.5, 1.5), 0.0)]) is None


@pytest.mark.parametrize("seed", range(3))
def test_the_optimum_is_the_same_without_the_gates(seed, monkeypatch):
    """The gates only tighten the search's bounds: the same optimum (to 1e-9) without them,
    and a valid path."""
    rng = np.random.default_rng(seed)
    blocked = perfect_maze(rng, 31, 1, 1, 0.2)[::-1].copy()
    world = cells_world(blocked, 0.35)
    queries = list(_queries(world, blocked, rng, 4))
    for start, goal in queries:
        assert free_grid.FreeGrid.for_world(world, start, goal).gates is not None

    def without_gates(m):
        m.setattr(Gates, "where_pinched", classmethod(lambda cls, *args: None))

    assert assert_same_optimum_without(world, queries, monkeypatch, without_gates) >= 2


def test_blocks_that_lose_the_walls_are_refined(monkeypatch):
    """Rooms with one-cell walls, in blocks of 4 x 4 cells for their size: the blocks lose the
    walls (the raster's bound is the straight line) and the point's path shows it, so the raster
    is searched again cell by cell; the optimum is the one of the raster searched cell by cell
    from the start."""
    from rrtpso_ompl.groundtruth.optimum import query

    blocked = np.zeros((64, 64), dtype=bool)
    blocked[16::16, :] = True  # walls across, a door at alternate ends
    for row in range(16, 64, 16):
        door = 1 if (row // 16) % 2 else 61
        blocked[row, door : door + 2] = False
    world = cells_world(blocked, 0.4)
    start, goal = (32.5, 2.5), (32.5, 61.5)
    monkeypatch.setattr(free_grid, "FAST_SEARCH_CELLS", 256)  # blocks of 4 x 4
    monkeypatch.setattr(free_grid, "MAX_SEARCH_FREE", 256)
    grids = []
    build = free_grid.FreeGrid.for_world

    def spy(*args, **kwargs):
        grids.append(build(*args, **kwargs))
        return grids[-1]

    monkeypatch.setattr(query.FreeGrid, "for_world", spy)
    refined = shortest_path_in_world(world, start, goal)
    assert [g.k for g in grids] == [4, 1]
    monkeypatch.setattr(free_grid, "MAX_SEARCH_FREE", 10**7)
    monkeypatch.setattr(free_grid, "FAST_SEARCH_CELLS", 10**7)
    fine = shortest_path_in_world(world, start, goal)
    assert grids[-1].k == 1 and len(grids) == 3
    assert refined.length == pytest.approx(fine.length, rel=1e-9)
    assert refined.length > 3 * 59  # through the doors, not across the walls
