"""The free grid searches small rasters in numpy and scipy large ones (so that ``rrtpso optimum``
of a small problem need not import scipy): both give the same step counts, bounds and optimum."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import PROBLEMS, cells_world
from scipy import ndimage

from rrtpso_ompl.groundtruth import free_grid, shortest_path
from rrtpso_ompl.groundtruth.free_grid import FreeGrid, _window_cells
from rrtpso_ompl.model import World, load_problem


def _grid(rng: np.random.Generator) -> FreeGrid:
    """A random raster of possibly-free cells (some walls, some islands), start and goal in it."""
    ny, nx = (int(v) for v in rng.integers(1, 45, size=2))
    free = rng.random((ny, nx)) < rng.uniform(0.35, 0.95)
    start, goal = rng.uniform(0, 1, size=2) * [nx, ny], rng.uniform(0, 1, size=2) * [nx, ny]
    return FreeGrid((0.0, 0.0), 1.0, free, start, goal)


@pytest.mark.parametrize("seed", range(12))
def test_the_numpy_search_gives_the_step_counts_of_scipys(seed, monkeypatch):
    numpy_grid = _grid(np.random.default_rng(seed))
    assert numpy_grid.cnx * numpy_grid.cny <= free_grid.NUMPY_SEARCH_CELLS
    monkeypatch.setattr(free_grid, "NUMPY_SEARCH_CELLS", 0)  # every grid through scipy
    scipy_grid = _grid(np.random.default_rng(seed))
    for (m8, m4), (s8, s4) in zip(numpy_grid._dist, scipy_grid._dist, strict=True):
        np.testing.assert_array_equal(m8, s8)
        np.testing.assert_array_equal(m4, s4)
    assert numpy_grid.connected == scipy_grid.connected
    circles = np.random.default_rng(seed).uniform(0, 45, size=(30, 3)) * [1, 1, 0.1]
    np.testing.assert_array_equal(numpy_grid.step_ranges(circles), scipy_grid.step_ranges(circles))


@pytest.mark.parametrize("w", [1, 2, 4])
def test_the_window_extremes_are_scipys_filters(w):
    grid = np.random.default_rng(w).integers(0, 50, size=(23, 31)).astype(float)
    grid[grid > 45] = np.inf
    grid[grid < 3] = -np.inf
    size = 2 * w + 1
    low = ndimage.minimum_filter(grid, size=size, mode="nearest")
    high = ndimage.maximum_filter(grid, size=size, mode="nearest")
    window = grid.ravel()[_window_cells(np.arange(grid.size), w, *grid.shape)]
    np.testing.assert_array_equal(window.min(axis=0).reshape(grid.shape), low)
    np.testing.assert_array_equal(window.max(axis=0).reshape(grid.shape), high)


@pytest.mark.parametrize("name", ["paper_static", "bug_trap", "dense_polygons"])
def test_the_optimum_is_the_same_through_either_search(name, monkeypatch):
    problem = load_problem(PROBLEMS / "static" / f"{name}.yaml")
    world = World.from_problem(problem)
    small = shortest_path(problem, world)
    monkeypatch.setattr(free_grid, "NUMPY_SEARCH_CELLS", 0)
    large = shortest_path(problem, world)
    assert small.found and small.length == large.length
    assert small.pieces == large.pieces and small.n_edges == large.n_edges


def test_a_winding_search_has_one_level_per_cell_and_scipys_counts(monkeypatch):
    """A serpentine corridor: the deepest search there is (about one level per free cell)."""
    free = np.ones((41, 40), dtype=bool)
    for j in range(1, 41, 2):  # walls with one gap, at alternate ends
        free[j, :] = False
        free[j, 39 if j % 4 == 1 else 0] = True
    start, goal = (0.5, 0.5), (0.5, 40.5)
    numpy_grid = FreeGrid((0.0, 0.0), 1.0, free, start, goal)
    monkeypatch.setattr(free_grid, "NUMPY_SEARCH_CELLS", 0)
    scipy_grid = FreeGrid((0.0, 0.0), 1.0, free, start, goal)
    m8 = numpy_grid._dist[0][0]
    assert np.nanmax(m8[np.isfinite(m8)]) > 20 * 40  # it winds through every row
    for ours, theirs in zip(numpy_grid._dist, scipy_grid._dist, strict=True):
        np.testing.assert_array_equal(ours[0], theirs[0])
        np.testing.assert_array_equal(ours[1], theirs[1])


@pytest.mark.parametrize("seed", range(4))
def test_the_lattice_test_of_segments_is_the_worlds(seed):
    """``segments_near_blocked`` (distances to the rim cells only, a sample in an inner cell
    counting as near) answers as the world's exact test, on solid blocks and thin walls, for
    segments from free points, through blocks and starting deep inside one."""
    rng = np.random.default_rng(seed)
    blocked = np.zeros((40, 40), dtype=bool)
    for _ in range(12):  # solid blocks, most of whose cells are inner
        x, y = rng.integers(0, 34, 2)
        w, h = rng.integers(2, 7, 2)
        blocked[y : y + h, x : x + w] = True
    blocked |= rng.random(blocked.shape) < 0.02
    world = cells_world(blocked, (0.3, 1.5, 1.2, 0.05)[seed])
    grid = FreeGrid.for_world(world, (0.5, 0.5), (39.5, 39.5))
    assert grid.band_ok(world.threshold) and grid._rim()[1].any()
    a = rng.uniform(0.0, 40.0, (3000, 2))
    b = np.clip(a + rng.normal(0.0, 6.0, a.shape), 0.0, 40.0)
    near = grid.segments_near_blocked(a, b, world.threshold)
    assert np.array_equal(near, ~world.segments_free(a, b))
    assert 0.1 < near.mean() < 0.95


@pytest.mark.parametrize("seed", range(3))
def test_the_sure_near_samples_never_contradict_the_world(seed):
    """The cheap first pass of ``segments_near_blocked`` (a sample close to the blocked cell
    nearest its cell) claims only segments the world finds near, finds most of those that come
    deep, and the window alone still answers as the world does."""
    rng = np.random.default_rng(seed)
    blocked = rng.random((48, 48)) < 0.25
    world = cells_world(blocked, (0.4, 1.0, 1.5)[seed])
    grid = FreeGrid.for_world(world, (0.5, 0.5), (47.5, 47.5))
    a = rng.uniform(0.0, 48.0, (4000, 2))
    b = np.clip(a + rng.normal(0.0, 3.0, a.shape), 0.0, 48.0)
    free = world.segments_free(a, b)
    deep = grid._deep(a, b, world.threshold)
    assert not (deep & free).any()
    assert deep.sum() > 0.5 * (~free).sum()
    np.testing.assert_array_equal(grid._near_by_window(a, b, world.threshold), ~free)


def test_blocks_are_used_only_where_they_keep_the_maps_shape(monkeypatch):
    """A maze of one-cell corridors merged into blocks of 2 x 2 loses its walls (every block
    possibly free) and with them the bound; it is searched cell by cell, while open rooms
    keep their blocks."""
    monkeypatch.setattr(free_grid, "FAST_SEARCH_CELLS", 400)
    maze = np.ones((40, 40), dtype=bool)
    maze[1::2, :] = False  # walls on alternate rows, a gap at alternate ends
    maze[1::4, -1] = maze[3::4, 0] = True
    rooms = np.ones((40, 40), dtype=bool)
    rooms[19:21, :30] = False
    start, goal = (0.5, 0.5), (0.5, 39.5)
    fine = FreeGrid((0.0, 0.0), 1.0, maze, start, goal)
    assert fine.k == 1
    assert fine.lower_bound(1, np.array([start]))[0] > 19 * 39  # along the corridor
    monkeypatch.setattr(free_grid, "BLOCK_GROWTH", 2.5)
    coarse = FreeGrid((0.0, 0.0), 1.0, maze, start, goal)
    assert coarse.k == 2 and coarse.lower_bound(1, np.array([start]))[0] < 2 * 39
    assert FreeGrid((0.0, 0.0), 1.0, rooms, start, goal).k == 2


def test_testing_tangents_piece_by_piece_gives_the_whole_segments_answer():
    """The search tests long tangents piece by piece from their start (optimum/graph.py's
    ``_in_stages``): a segment is near a blocked cell where one of its pieces is, so the answer
    is the whole segment's, for segments of up to 300 cells, and the cheap pass alone never says
    "near" where the whole test says free."""
    from rrtpso_ompl.groundtruth.optimum.graph import _in_stages

    rng = np.random.default_rng(7)
    blocked = np.zeros((320, 320), dtype=bool)
    for _ in range(60):  # city-like blocks with streets between
        x, y = rng.integers(0, 300, 2)
        w, h = rng.integers(4, 30, 2)
        blocked[y : y + h, x : x + w] = True
    world = cells_world(blocked, 1.5)
    grid = FreeGrid.for_world(world, (0.5, 0.5), (319.5, 319.5))
    a = rng.uniform(0.0, 320.0, (3000, 2))
    angle = rng.uniform(0.0, 2.0 * np.pi, 3000)
    b = np.clip(a + rng.uniform(1.0, 300.0, (3000, 1)) * np.column_stack(
        [np.cos(angle), np.sin(angle)]), 0.0, 320.0)  # fmt: skip
    whole = grid.segments_near_blocked(a, b, world.threshold)
    pieces = _in_stages(lambda p, q: grid.segments_near_blocked(p, q, world.threshold),
                        a, b, grid.h)  # fmt: skip
    np.testing.assert_array_equal(pieces, whole)
    cheap = _in_stages(lambda p, q: grid.segments_near_blocked(p, q, world.threshold, False),
                       a, b, grid.h)  # fmt: skip
    assert not (cheap & ~whole).any() and cheap.sum() > 0.5 * whole.sum()
    rest = np.flatnonzero(~cheap)  # the search's second pass: the windows alone on the rest
    windows = _in_stages(lambda p, q: grid.segments_near_blocked(p, q, world.threshold,
                                                                 sure_pass=False),
                         a[rest], b[rest], grid.h)  # fmt: skip
    np.testing.assert_array_equal(windows, whole[rest])
    assert 0.2 < whole.mean() < 0.99
