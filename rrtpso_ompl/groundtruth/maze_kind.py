"""A perfect maze with its walls as rectangles (``rrtpso generate maze``, :class:`MazeOptions`).

A maze on a grid of ``cells x cells`` cells has exactly one route between any two cells; it is
carved by randomised depth-first search (long winding corridors) or randomised Kruskal (many
short dead ends), each wall left standing an obstacle rectangle. Start and goal are the centres
of opposite corner cells. Every random choice comes from the generator's one seeded stream
(:mod:`.kinds`).
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from ..errors import GenerationError
from ..params import Rule, declared, param
from .certify import GRID_POINTS
from .kinds import GeneratorOptions, register_kind

__all__ = ["MAX_CELLS", "MazeOptions"]

#: Most cells per side of a maze (a maze of 200 x 200 cells has about 80,000 walls): the bound
#: of every loop and allocation.
MAX_CELLS = 200


@register_kind
@declared(
    rules=(
        Rule(("wall", "size", "cells"), lambda w, size, c: w is None or 0 < w < size / c,
             "0 < wall < size / cells (the cell size)"),
    )
)  # fmt: skip
class MazeOptions(GeneratorOptions):
    """A perfect maze on a cells x cells grid; one rectangle per wall between two cells
    (``rrtpso generate maze``)."""

    KIND: ClassVar[str] = "maze"

    robot_radius: float | None = param(
        None,
        "Robot radius (0: a point robot); the robot must fit the corridors. Default: a fifth of "
        "a cell (size / cells).",
        unit="length",
        low=0.0,
    )
    cells: int = param(8, "Cells per side.", low=2, high=MAX_CELLS)
    wall: float | None = param(
        None,
        "Wall thickness, 0 < wall < size / cells. Default: a tenth of a cell.",
        unit="length",
        low=0.0,
    )
    algorithm: str = param(
        "dfs",
        "dfs: randomised depth-first search (long winding corridors); kruskal: randomised "
        "Kruskal (many short dead ends). Both give a perfect maze.",
        choices=("dfs", "kruskal"),
    )

    def resolved(self) -> MazeOptions:
        cell = self.size / self.cells
        wall = 0.1 * cell if self.wall is None else self.wall
        robot = 0.2 * cell if self.robot_radius is None else self.robot_radius
        corridor = cell - wall - 2.0 * robot  # free width for the robot's centre
        if corridor <= 0:
            raise GenerationError(
                f"the robot (diameter {2 * robot:g}) does not fit the maze corridors "
                f"(cell {cell:g} minus wall {wall:g} = {cell - wall:g}); use a smaller "
                "robot_radius or wall, or fewer cells"
            )
        # At least four grid points across every corridor, so the certificate cannot miss one.
        resolution = min(self.size / GRID_POINTS, corridor / 4.0)
        return self._resolve(resolution, wall=wall, robot_radius=robot)

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        cell = self.size / self.cells
        return (np.array([0.5 * cell, 0.5 * cell]),
                np.array([self.size - 0.5 * cell, self.size - 0.5 * cell]))  # fmt: skip

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        c = self.cells
        # Interior walls: vertical ones between (r, k) and (r, k + 1), then horizontal ones
        # between (r, k) and (r + 1, k); a cell (r, k) is the integer r * c + k.
        vertical = [(r * c + k, r * c + k + 1) for r in range(c) for k in range(c - 1)]
        horizontal = [(r * c + k, (r + 1) * c + k) for r in range(c - 1) for k in range(c)]
        walls = vertical + horizontal
        carve = _dfs_tree if self.algorithm == "dfs" else _kruskal_tree
        opened = carve(rng, c, walls)
        cell = self.size / c
        h = 0.5 * self.wall
        obstacles = []
        # Each wall runs along its cell edge and half a thickness beyond both ends, so walls
        # meeting at a corner overlap (no leak) and walls reaching the border pass it (no gap).
        for w, (p, q) in enumerate(walls):
            if w in opened:
                continue
            r, k = divmod(p, c)
            if q == p + 1:  # vertical wall at x = (k + 1) cell
                lo = [(k + 1) * cell - h, r * cell - h]
                hi = [(k + 1) * cell + h, (r + 1) * cell + h]
            else:  # horizontal wall at y = (r + 1) cell
                lo = [k * cell - h, (r + 1) * cell - h]
                hi = [(k + 1) * cell + h, (r + 1) * cell + h]
            obstacles.append({"type": "rectangle", "min": lo, "max": hi})
        return obstacles

    def describe(self) -> str:
        how = "randomised depth-first search" if self.algorithm == "dfs" else "randomised Kruskal"
        n_walls = (self.cells - 1) ** 2
        return (
            f"A perfect maze ({how}) of {self.cells} x {self.cells} cells in a {self.size:g} x "
            f"{self.size:g} workspace: its {n_walls} interior walls of thickness {self.wall:g} are "
            "rectangles (the bounds are the outer wall), so exactly one corridor route joins any "
            f"two cells. Robot radius {self.robot_radius:g}; start and goal at the centres of "
            "opposite corner cells."
        )


def _dfs_tree(rng: np.random.Generator, c: int, walls: list[tuple[int, int]]) -> set[int]:
    """Walls opened by a randomised depth-first search (recursive backtracker) from cell 0."""
    wall_of: dict[tuple[int, int], int] = {}
    for w, (p, q) in enumerate(walls):
        wall_of[(p, q)] = wall_of[(q, p)] = w
    visited = np.zeros(c * c, dtype=bool)
    visited[0] = True
    stack = [0]
    opened: set[int] = set()
    while stack:
        p = stack[-1]
        r, k = divmod(p, c)
        options = [
            q
            for q, inside in (
                (p - c, r > 0),
                (p + c, r < c - 1),
                (p - 1, k > 0),
                (p + 1, k < c - 1),
            )
            if inside and not visited[q]
        ]
        if not options:
            stack.pop()
            continue
        q = options[int(rng.integers(len(options)))]
        opened.add(wall_of[(p, q)])
        visited[q] = True
        stack.append(q)
    return opened


def _kruskal_tree(rng: np.random.Generator, c: int, walls: list[tuple[int, int]]) -> set[int]:
    """Walls opened by randomised Kruskal: walls in random order, opened when they join two
    separate regions (union-find with path halving)."""
    parent = list(range(c * c))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    opened: set[int] = set()
    for w in rng.permutation(len(walls)).tolist():
        p, q = walls[w]
        rp, rq = find(p), find(q)
        if rp != rq:
            parent[rp] = rq
            opened.add(w)
    return opened
