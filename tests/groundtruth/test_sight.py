"""The reach of straight segments on a lattice (optimum/sight.py): an upper bound, checked
against segments sampled finely, and the disc's optimum the same with it as without."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import assert_same_optimum_without, cells_world

from rrtpso_ompl.groundtruth.optimum import graph, shortest_path_in_world
from rrtpso_ompl.groundtruth.optimum import query as query_module
from rrtpso_ompl.groundtruth.optimum.sight import MAX_SWEEP, Reach


def _maze(seed: int, size: int = 24) -> np.ndarray:
    """Blocked cells (rows from the bottom): walls of one cell on a two-cell pattern with random
    openings, a few random cells and diagonal pinches."""
    rng = np.random.default_rng(seed)
    blocked = np.zeros((size, size), dtype=bool)
    blocked[::2, ::2] = True
    blocked[1::2, ::2] = rng.random((size // 2, size // 2)) < 0.5
    blocked[::2, 1::2] = rng.random((size // 2, size // 2)) < 0.5
    blocked |= rng.random((size, size)) < 0.05
    for _ in range(3):
        r, c = rng.integers(1, size - 3, 2)
        blocked[r : r + 2, c : c + 2] = [[True, False], [False, True]]
    return blocked


def _on_free(blocked: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether each point ``(n, 2)`` lies in the closure of a free cell."""
    ny, nx = blocked.shape
    out = np.zeros(len(p), dtype=bool)
    for i in (np.ceil(p[:, 0]) - 1, np.floor(p[:, 0])):
        for j in (np.ceil(p[:, 1]) - 1, np.floor(p[:, 1])):
            ok = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
            ii, jj = np.clip(i, 0, nx - 1).astype(int), np.clip(j, 0, ny - 1).astype(int)
            out |= ok & ~blocked[jj, ii]
    return out


@pytest.mark.parametrize("seed", range(4))
def test_a_segment_that_stays_out_of_the_walls_is_within_reach(seed):
    """Segments between lattice points (how far a line through two of them passes from a third
    is 0 or at least 1 / its length) and from points inside cells, sampled every 0.01 cell: every
    one that never goes into a blocked cell is one :meth:`Reach.may_see` keeps; and in a maze it
    drops most of the others."""
    blocked = _maze(seed)
    ny, nx = blocked.shape
    reach = Reach(~blocked, 1e-9)
    rng = np.random.default_rng(seed)
    corners = np.argwhere(np.ones((ny + 1, nx + 1), dtype=bool))[:, ::-1].astype(float)
    cells = np.argwhere(~blocked)[:, ::-1] + rng.uniform(0.05, 0.95, (int((~blocked).sum()), 2))
    points = np.vstack([corners, cells])
    a = points[rng.integers(len(points), size=3000)]
    b = np.clip(np.round(a + rng.uniform(-8.0, 8.0, a.shape)), 0, [nx, ny])
    runs = reach.runs(a[:, 0], a[:, 1])
    kept = reach.may_see(runs, b[:, 0] - a[:, 0], b[:, 1] - a[:, 1])
    clear = np.empty(len(a), dtype=bool)
    for k in range(len(a)):
        t = np.linspace(0.0, 1.0, max(2, int(np.hypot(*(b[k] - a[k])) / 0.01) + 1))
        clear[k] = _on_free(blocked, a[k] + t[:, None] * (b[k] - a[k])).all()
    assert clear.sum() >= 150
    assert kept[clear].all()
    assert (~kept[~clear]).mean() > 0.5


def test_runs_are_cut_at_the_walls_and_unbounded_in_the_open():
    blocked = np.zeros((5, 200), dtype=bool)
    blocked[:, 10] = True  # a wall across, ten cells to the right of the origin
    reach = Reach(~blocked, 1e-9)
    runs = reach.runs(np.array([0.0, 20.0]), np.array([2.0, 2.0]))
    assert runs[0, 0] == 11.0  # through column 9, into column 10 at most
    assert runs[0, 1] == 0.0  # the lattice's edge
    assert runs[1, 0] == np.inf  # open for more than MAX_SWEEP columns
    assert MAX_SWEEP < 180.0
    assert runs[1, 1] == 10.0  # back to the wall's right side


@pytest.mark.parametrize("seed", range(6))
def test_a_discs_optimum_is_the_same_within_reach(seed, monkeypatch):
    """The disc's optimum on a maze with the candidates within reach and the point's bounds is
    the one of the search without either (to 1e-9), and valid."""
    blocked = _maze(seed, 20)
    blocked[:, :2] = blocked[9:11, :] = False  # ways along the left side and across
    radius = (0.2, 0.3, 0.45)[seed % 3]
    world = cells_world(blocked, radius)
    rng = np.random.default_rng(seed)
    free = np.argwhere(~blocked)
    queries = []
    for _ in range(12):
        (ra, ca), (rb, cb) = free[rng.choice(len(free), 2, replace=False)]
        start, goal = (ca + 0.5, ra + 0.5), (cb + 0.5, rb + 0.5)
        if (world.point_clearance(np.array([start, goal])) >= world.threshold).all():
            queries.append((start, goal))

    def without_either(m):
        m.setattr(query_module, "_point_path", lambda *args: (0.0, 0.0))
        m.setattr(graph.TangentGraph, "_local_rows",
                  lambda self, batch: np.zeros(len(batch), dtype=bool))  # fmt: skip

    assert assert_same_optimum_without(world, queries, monkeypatch, without_either) >= 2


def test_a_mazes_batches_grow_and_keep_the_optimum(monkeypatch):
    """A maze's corners have few candidates each, so the batches of circles grow beyond the
    first 32 (their cost is mostly fixed); the optimum is the one found with batches of 32."""
    from rrtpso_ompl.groundtruth.map_kinds import _maze as perfect_maze

    blocked = perfect_maze(np.random.default_rng(5), 41, 1, 1, 0.0)[::-1]  # rows from the bottom
    world = cells_world(blocked, 0.3)
    start, goal = (1.5, 1.5), (39.5, 39.5)
    sizes = []
    prepare = graph.TangentGraph._prepare

    def spy(self, batch):
        sizes.append(len(batch))
        return prepare(self, batch)

    monkeypatch.setattr(graph.TangentGraph, "_prepare", spy)
    grown = shortest_path_in_world(world, start, goal)
    assert max(sizes) > graph._BATCH
    monkeypatch.setattr(graph, "_MAX_BATCH", graph._BATCH)
    sizes.clear()
    fixed = shortest_path_in_world(world, start, goal)
    assert max(sizes) == graph._BATCH
    assert grown.length == pytest.approx(fixed.length, rel=1e-9)
    assert grown.length > 100.0  # through the maze, not across it
    assert world.path_valid(grown.valid_polyline(world))
