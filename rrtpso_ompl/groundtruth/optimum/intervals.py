"""The exact shortest path of a point robot on a map: A* over intervals of the rectangle mesh
(:mod:`.mesh`), in the manner of Polyanya (Cui, Harabor and Grastien, *Compromise-free
Pathfinding on a Navigation Mesh*, IJCAI 2017).

A search node is a *root* (the start or a wall corner, where the path last bent) and an
*interval* of a rectangle's top or bottom edge that is visible from it; it stands for every path
that comes straight from the root through the interval into the rectangle beyond. Expanding it
projects the interval through that rectangle onto its far edge: the parts of the far edge's
pieces inside the projection are the successors with the same root (the rectangle's sides are
walls). An end of the interval that is a wall corner becomes a root: from there the path may bend
into every rectangle that touches the corner, through all of their pieces (a superset of
Polyanya's non-observable successors, which keeps the search simple: every corner is opened once,
at its least cost, and a later, costlier arrival is pruned, Polyanya's root-level pruning). The
heuristic is the larger of the straight distance from the root through the interval to the goal
(the goal mirrored in the interval's line when it lies on the root's side) and the distance to
the interval plus its piece's bound (:meth:`.mesh.RectMesh.bounds_to`, which follows a maze's
corridors); both are admissible, so the first goal taken from the queue is the optimum.

The search's path bends at the corners themselves. :func:`corner_sides` adds the corners it
only touches and the side it passes each one; :func:`rounded` draws it round circles at them
(the package rounds a point robot's corners, :mod:`.query`).

Coordinates are the grid's (cells); the caller scales. The search's work follows the region it
explores (the rectangles within the optimum's ellipse, for a maze the corridors), not the number
of wall corners: on a 1024 x 1024 maze of one-cell corridors the tangent graph had 183,000
corners and did not finish in 300 s.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from dataclasses import dataclass

from ..free_grid import Stopped
from .mesh import RectMesh
from .result import MAX_NODES, OptimumTooLarge

__all__ = ["IntervalPath", "corner_sides", "interval_path", "rounded"]

#: Round-off allowance, cells.
_EPS = 1e-9

#: Expansions between polls of the caller's ``terminate``.
_POLL = 4096


@dataclass(frozen=True)
class IntervalPath:
    """A shortest path found by :func:`interval_path`.

    Attributes
    ----------
    vertices : list of (float, float)
        The start, the wall corners the path bends round, the goal (grid coordinates).
    n_nodes, n_edges : int
        Nodes expanded and queued.
    """

    vertices: list
    n_nodes: int
    n_edges: int


def interval_path(mesh: RectMesh, start, goal, terminate: Callable[[], bool] | None = None,
                  source: str = "<world>",
                  budget: int | None = None) -> IntervalPath | None:  # fmt: skip
    """A shortest path from ``start`` to ``goal`` (grid coordinates, both in free cells); None
    when none exists.

    Raises
    ------
    Stopped
        When ``terminate()`` returns True (polled every :data:`_POLL` expansions).
    OptimumTooLarge
        When the search would queue more than :data:`~.result.MAX_NODES` nodes, or expand more
        than ``budget`` intervals.
    """
    return _Search(mesh, goal, source).run(start, terminate, budget)


class _Search:
    """The state of one search: the queue of ``(f, order, g, root, a, b, y, sense, beyond)``
    (an interval ``[a, b]`` on the line ``y``, seen from the root, the rectangle ``beyond`` on the
    side ``sense``; ``beyond`` -1 for the goal reached straight from the root), and each root's
    cost, parent and place."""

    def __init__(self, mesh: RectMesh, goal, source: str) -> None:
        self.mesh, self.source = mesh, source
        self.gx, self.gy = float(goal[0]), float(goal[1])
        self.goal_rects = set(mesh.rects_at(self.gx, self.gy))
        self.bound = mesh.bounds_to(self.gx, self.gy).tolist()
        self.root_g: dict[int, float] = {}
        self.parent: dict[int, int] = {}
        self.where: dict[int, tuple[float, float]] = {}
        self.heap: list = []
        self.pushed = 0

    def run(self, start, terminate, budget: int | None = None) -> IntervalPath | None:
        """A* from ``start`` until the goal leaves the queue (or the queue is empty, or more than
        ``budget`` expansions were made: OptimumTooLarge)."""
        budget = math.inf if budget is None else budget
        self.open_root(-1, float(start[0]), float(start[1]), 0.0, -2)
        heap, root_g, pop = self.heap, self.root_g, heapq.heappop
        expansions = 0
        while heap:
            _, _, g, key, a, b, y, sense, q = pop(heap)
            if g != root_g[key]:
                continue  # its root was reached more cheaply since: regenerated from there
            if q < 0:  # the goal, reached straight from this root
                out = [(self.gx, self.gy)]
                while key != -2:
                    out.append(self.where[key])
                    key = self.parent[key]
                return IntervalPath(out[::-1], expansions, self.pushed)
            expansions += 1
            if terminate is not None and expansions % _POLL == 0 and terminate():
                raise Stopped
            if expansions > budget:
                raise OptimumTooLarge(f"{self.source}: the interval search passed its budget of "
                                      f"{budget:,} expansions")  # fmt: skip
            self.expand(g, key, a, b, y, sense, q)
        return None

    def h(self, rx, ry, a, b, y, pid) -> float:
        """A lower bound from the root through ``[a, b]`` (on the line ``y``, piece ``pid``) to
        the goal: the straight distance (the goal mirrored in the line when it lies on the
        root's side), or the distance to the interval plus the piece's bound."""
        gx, gy = self.gx, self.gy
        ty = 2.0 * y - gy if (ry - y) * (gy - y) > 0.0 else gy
        p = rx if ty == ry else rx + (gx - rx) * (y - ry) / (ty - ry)
        p = a if p < a else b if p > b else p
        near = a if rx < a else b if rx > b else rx
        straight = math.hypot(rx - p, ry - y) + math.hypot(p - gx, y - ty)
        return max(straight, math.hypot(rx - near, ry - y) + self.bound[pid])

    def push_goal(self, g, key, rx, ry) -> None:
        """The goal, straight from the root ``key`` at ``(rx, ry)`` reached at cost ``g``."""
        d = g + math.hypot(self.gx - rx, self.gy - ry)
        heapq.heappush(self.heap, (d, self.pushed, g, key, 0.0, 0.0, 0, 0, -1))
        self.pushed += 1

    def open_root(self, key, rx, ry, g, up) -> None:
        """Make ``(rx, ry)`` a root reached at cost ``g`` from root ``up``: every piece of the
        rectangles that touch it is visible from it. A costlier arrival is pruned."""
        if g >= self.root_g.get(key, math.inf) - _EPS:
            return
        self.root_g[key], self.parent[key], self.where[key] = g, up, (rx, ry)
        mesh, heap, h, push = self.mesh, self.heap, self.h, heapq.heappush
        for q in mesh.rects_at(rx, ry):
            if q in self.goal_rects:
                self.push_goal(g, key, rx, ry)
            for edge, sense, y in ((mesh.top[q], 1, mesh.y1[q]), (mesh.bottom[q], -1, mesh.y0[q])):
                for p0, p1, nb, pid in edge:
                    push(heap, (g + h(rx, ry, p0, p1, y, pid), self.pushed, g, key, p0, p1, y,
                                sense, nb))  # fmt: skip
                    self.pushed += 1
        if self.pushed > MAX_NODES:
            raise OptimumTooLarge(f"{self.source}: the interval search would queue more than "
                                  f"{MAX_NODES:,} nodes")  # fmt: skip

    def expand(self, g, key, a, b, y, sense, q) -> None:
        """The successors of the interval ``[a, b]`` seen from root ``key`` into rectangle ``q``:
        the goal if it is in ``q`` and seen through the interval; the far edge's pieces within
        the projection (same root); an end of the interval that is a wall corner, opened as a
        root."""
        mesh, gx, gy = self.mesh, self.gx, self.gy
        rx, ry = self.where[key]
        far = mesh.y1[q] if sense > 0 else mesh.y0[q]
        if ry != y:
            if q in self.goal_rects and (gy - y) * sense >= 0.0:
                at = rx + (gx - rx) * (y - ry) / (gy - ry) if gy != ry else gx
                if a - _EPS <= at <= b + _EPS:
                    self.push_goal(g, key, rx, ry)
            t = (far - ry) / (y - ry)
            lo, hi = max(rx + (a - rx) * t, mesh.x0[q]), min(rx + (b - rx) * t, mesh.x1[q])
            if lo <= hi + _EPS:
                heap, h, push = self.heap, self.h, heapq.heappush
                for p0, p1, nb, pid in mesh.top[q] if sense > 0 else mesh.bottom[q]:
                    u, v = max(p0, lo), min(p1, hi)
                    if u <= v + _EPS:
                        v = max(u, v)
                        push(heap, (g + h(rx, ry, u, v, far, pid), self.pushed, g, key, u, v, far,
                                    sense, nb))  # fmt: skip
                        self.pushed += 1
        elif q in self.goal_rects and gy == y and a - _EPS <= gx <= b + _EPS:
            self.push_goal(g, key, rx, ry)
        ncol = mesh.corner.shape[1]
        for e in (a, b):
            i = round(e)
            if abs(e - i) <= _EPS and mesh.corner[y, i]:
                self.open_root(y * ncol + i, float(i), float(y), g + math.hypot(i - rx, y - ry),
                               key)  # fmt: skip


def corner_sides(mesh: RectMesh, vertices) -> tuple[list, list]:
    """The path through ``vertices`` (grid coordinates) with every wall corner it touches
    between them added, and the side on which it passes each vertex: ``(points, sides)``,
    ``+1`` where the corner lies on the path's left (the path bends counter-clockwise round it),
    ``-1`` on its right, ``0`` for the start and the goal.

    A straight piece may run along a wall with the wall on its left and on along another with
    the wall on its right (a one-cell jog of the walls): exact for the sharp corners, but round
    the package's rounded corners (:mod:`.query`) the path must pass between the two corners it
    touches, so they become vertices too.
    """
    blocked = mesh.cell_rect < 0
    out, sides = [tuple(map(float, vertices[0]))], [0]
    for m in range(1, len(vertices)):
        (ax, ay), (bx, by) = vertices[m - 1], vertices[m]
        dx, dy = bx - ax, by - ay
        for cx, cy in _lattice_points(ax, ay, bx, by):
            if mesh.corner[cy, cx]:
                bi, bj = _blocked_cell(blocked, cx, cy)
                cross = dx * (bj + 0.5 - cy) - dy * (bi + 0.5 - cx)
                out.append((float(cx), float(cy)))
                sides.append(1 if cross > 0 else -1)
        if m < len(vertices) - 1:
            (cx, cy) = vertices[m + 1]
            cross = dx * (cy - by) - dy * (cx - bx)
            out.append((float(bx), float(by)))
            sides.append(1 if cross > 0 else -1 if cross < 0 else _side_of(blocked, bx, by, dx, dy))
    out.append(tuple(map(float, vertices[-1])))
    sides.append(0)
    return out, sides


def _blocked_cell(blocked, i: int, j: int) -> tuple[int, int]:
    """The blocked one of the four cells round the corner ``(i, j)``."""
    for ci, cj in ((i - 1, j - 1), (i, j - 1), (i - 1, j), (i, j)):
        if blocked[cj, ci]:
            return ci, cj
    raise AssertionError("not a corner")  # pragma: no cover - corners have one


def _side_of(blocked, x, y, dx, dy) -> int:
    """The side (+1 left) of the direction ``(dx, dy)`` on which the corner ``(x, y)``'s blocked
    cell lies."""
    bi, bj = _blocked_cell(blocked, round(x), round(y))
    return 1 if dx * (bj + 0.5 - y) - dy * (bi + 0.5 - x) > 0 else -1


def _lattice_points(ax, ay, bx, by) -> list[tuple[int, int]]:
    """The grid points strictly between ``(ax, ay)`` and ``(bx, by)`` on the segment joining
    them, in order from the first."""
    dx, dy = bx - ax, by - ay
    if abs(dx) >= abs(dy):
        if dx == 0.0:
            return []
        xs = range(math.floor(min(ax, bx)) + 1, math.ceil(max(ax, bx)))
        pts = [((x - ax) / dx, x, ay + (x - ax) * dy / dx) for x in xs]
    else:
        ys = range(math.floor(min(ay, by)) + 1, math.ceil(max(ay, by)))
        pts = [((y - ay) / dy, ax + (y - ay) * dx / dy, y) for y in ys]
    near = [(t, x, y, round(x), round(y)) for t, x, y in pts if 0.0 < t < 1.0]
    on = [(t, i, j) for t, x, y, i, j in near if abs(x - i) <= _EPS and abs(y - j) <= _EPS]
    return [(i, j) for _, i, j in sorted(on)]


def rounded(points, sides, rho: float) -> tuple[float, list]:
    """The path through ``points`` (start, corners, goal) round circles of radius ``rho`` at
    its corners, each passed on its side (:func:`corner_sides`): ``(length, pieces)``, the
    tangent segments and arcs the tangent search gives for the same corners (the package rounds
    a point robot's corners, :mod:`.query`).

    The segment from a circle of signed radius ``k1`` (positive when the path passes it
    counter-clockwise, the centre on its left) to one of ``k2`` has direction ``theta`` with
    ``D = L (cos theta, sin theta) + (k2 - k1) n``, ``n`` the left normal: ``L = sqrt(|D|^2 -
    (k2 - k1)^2)`` and ``theta = atan2(D) - atan2(k2 - k1, L)``.
    """
    from .result import Piece

    v = [tuple(map(float, p)) for p in points]
    k = [rho * s for s in sides]
    legs = []
    for m in range(len(v) - 1):
        (ax, ay), (bx, by), delta = v[m], v[m + 1], k[m + 1] - k[m]
        dx, dy = bx - ax, by - ay
        length = math.sqrt(max(dx * dx + dy * dy - delta * delta, 0.0))
        theta = math.atan2(dy, dx) - math.atan2(delta, length)
        nx, ny = -math.sin(theta), math.cos(theta)
        p = (ax - k[m] * nx, ay - k[m] * ny)
        q = (bx - k[m + 1] * nx, by - k[m + 1] * ny)
        legs.append((p, q, theta, length))
    pieces, total = [], 0.0
    for m, (p, q, theta, length) in enumerate(legs):
        if m > 0 and k[m] != 0.0:
            back, centre = legs[m - 1], v[m]
            turn = (theta - back[2]) % (2.0 * math.pi)
            sweep = turn if k[m] > 0.0 else turn - 2.0 * math.pi
            if abs(sweep) > 2.0 * math.pi - 1e-7:  # straight on, round-off to the other side
                sweep = turn - 2.0 * math.pi if sweep > 0.0 else turn
            start = back[1]
            angle = math.atan2(start[1] - centre[1], start[0] - centre[0])
            pieces.append(Piece("arc", start, p, centre, abs(k[m]), angle, sweep))
            total += abs(k[m] * sweep)
        pieces.append(Piece("line", p, q))
        total += length
    return total, pieces
