"""A* over tangent nodes, the graph built as it goes (package docstring, steps 2 and 5).

A node is a tangent point on a circle and the sense in which the path wraps that circle
(+1 counter-clockwise, -1 clockwise); from it the path follows the circle in that sense and
leaves along a free tangent (:class:`~.graph.TangentGraph`) to another circle. The heuristic
(the raster's geodesic lower bound to the goal) is admissible but not consistent, so a node whose
cost improves after its expansion is expanded again; a node reached at no more cost earlier on
a free arc, in the same sense, dominates a later one. Costs are lengths in the problem's unit.
"""

from __future__ import annotations

import heapq
import itertools
import math

import numpy as np

from ...model.world import World
from ..free_grid import FreeGrid
from .arcs import arcs_free
from .circles import NodeCircles
from .graph import TangentGraph
from .result import MAX_NODES, OptimumTooLarge, Piece
from .tangents import ANGLE_TOL, TWO_PI, cone_pos

__all__ = ["TangentSearch"]


class TangentSearch:
    """A* over tangent nodes within one bound, built as it goes (see the package docstring).

    Parameters
    ----------
    world, grid, nodes, goal_tol, bound
        As for :class:`~.graph.TangentGraph`.
    source : str
        Where the problem came from (for messages).
    terminate : callable or None
        Polled between expansions; True stops the search (:attr:`stopped`).
    """

    def __init__(self, world: World, grid: FreeGrid, nodes: NodeCircles, goal_tol: float,
                 bound: float, source: str, terminate) -> None:  # fmt: skip
        self.graph = TangentGraph(world, grid, nodes, goal_tol, bound)
        self.source = source
        self.terminate = terminate
        self.stopped = False
        # The graph's circles and bound, as plain attributes of the search's loops.
        g = self.graph
        self.circles, self.lo, self.width, self.sure = g.circles, g.lo, g.width, g.sure
        self.bound, self.eps = g.bound, g.eps
        self.n_nodes = 0
        self.n_edges = 0
        cap = 1024
        self.g = np.empty(cap)
        self.h = np.empty(cap)
        # Per node: (x, y), circle, angle, sense, parent, leave point, signed sweep.
        self.xy: list[tuple[float, float]] = []
        self.circle: list[int] = []
        self.angle: list[float] = []
        self.sense: list[int] = []
        self.parent: list[int] = []
        self.leave: list[tuple[float, float]] = []
        self.sweep: list[float] = []
        self._expanded: dict[tuple[int, int], list[tuple[float, float]]] = {}

    # ------------------------------------------------------------------------------------------
    def run(self) -> tuple[float, list[Piece]] | None:
        h0 = float(self.graph.grid.lower_bound(1, self.graph.start[None])[0])
        xy = (float(self.graph.start[0]), float(self.graph.start[1]))
        s = self._add(xy, 0, 0.0, 0, 0.0, -1, (0.0, 0.0), 0.0, h0)
        heap = [(self.h[s], s)]
        done = np.full(1024, math.inf)  # g at which each node was last expanded
        while heap:
            f, u = heapq.heappop(heap)
            g_u = self.g[u]
            if f > g_u + self.h[u] + self.eps:
                continue  # a stale entry: the node was improved since
            if u < len(done) and done[u] <= g_u + self.eps:
                continue  # expanded already with this g (the heuristic is not consistent)
            if self.terminate is not None and self.terminate():
                self.stopped = True
                return None
            if self.circle[u] == 1:
                return float(g_u), self._pieces(u)
            if self._dominated(u):
                continue
            if u >= len(done):  # nodes are added faster than expanded: grow past u at once
                done = np.concatenate([done, np.full(max(len(done), u + 1), math.inf)])
            done[u] = g_u
            for v in self._expand(u):
                heapq.heappush(heap, (self.g[v] + self.h[v], v))
        return None

    def _dominated(self, u: int) -> bool:
        """Whether a node expanded earlier on the same circle and sense reaches ``u``'s point along
        a free arc at no more cost (then everything ``u`` leads to, it led to already)."""
        i, s = self.circle[u], self.sense[u]
        if not self.sure[i] or self.width[i] >= TWO_PI:
            return False
        key = (i, s)
        rho = float(self.circles[i, 2])
        pos = float(cone_pos(self.angle[u], self.lo[i]))
        g = float(self.g[u])
        seen = self._expanded.setdefault(key, [])
        for g_a, pos_a in seen:
            ahead = (pos - pos_a) * s
            if ahead >= -1e-12 and g_a + rho * max(ahead, 0.0) <= g + self.eps:
                return True
        seen.append((g, pos))
        return False

    def _add(self, xy, circle, angle, sense, g, parent, leave, sweep, h) -> int:
        k = self.n_nodes
        if k >= MAX_NODES:
            raise OptimumTooLarge(
                f"{self.source}: the search for the exact optimum passed {MAX_NODES:,} tangent "
                "nodes; the problem is too large for it"
            )
        if k >= len(self.g):
            self.g = np.concatenate([self.g, np.empty(len(self.g))])
            self.h = np.concatenate([self.h, np.empty(len(self.h))])
        self.g[k], self.h[k] = g, h
        self.xy.append(xy)
        self.circle.append(circle)
        self.angle.append(angle)
        self.sense.append(sense)
        self.parent.append(parent)
        self.leave.append(leave)
        self.sweep.append(sweep)
        self.n_nodes = k + 1
        return k

    # ------------------------------------------------------------------------------------------
    def _expand(self, u: int) -> list[int]:
        """Create or improve the nodes reached from ``u`` by an arc and a free tangent."""
        i = self.circle[u]
        cand = self.graph.free_tangents(i, float(self.g[u]), float(self.g[u] + self.h[u]))
        if not len(cand.j):
            return []
        rho_i = float(self.circles[i, 2])
        s = self.sense[u]
        if rho_i > 0:
            idx = np.flatnonzero(cand.sense_i == s)
            if self.width[i] < TWO_PI:
                # The arc stays on the circle's free arc: from u's point on, in u's sense.
                pos_u = cone_pos(self.angle[u], self.lo[i])
                ahead = s * (cand.pos_i[idx] - pos_u)
                idx = idx[ahead >= -ANGLE_TOL]
                sweep = np.maximum(s * (cand.pos_i[idx] - pos_u), 0.0)
            else:
                # Leaving where it arrived is no turn, whichever way round-off goes.
                turn = s * (cand.angle_i[idx] - self.angle[u]) + ANGLE_TOL
                sweep = np.maximum(np.mod(turn, TWO_PI) - ANGLE_TOL, 0.0)
        else:
            idx = np.arange(len(cand.j))
            sweep = np.zeros(len(idx))
        g = self.g[u] + rho_i * sweep + cand.seg[idx]
        ok = g + cand.h[idx] <= self.bound
        idx, g, sweep = idx[ok], g[ok], sweep[ok]
        if not len(idx):
            return []
        # No better than a node already reached by this tangent: nothing to do.
        node = cand.node[idx]
        best = np.where(node >= 0, self.g[np.maximum(node, 0)], math.inf)
        better = g < best - self.eps
        idx, g, sweep, node = idx[better], g[better], sweep[better], node[better]
        if rho_i > 0 and len(idx) and not self.sure[i]:
            ok = self._arcs_ok(u, sweep)
            idx, g, sweep, node = idx[ok], g[ok], sweep[ok], node[ok]
        self.n_edges += len(idx)
        out = []
        for k, gk, sw, v in zip(idx.tolist(), g.tolist(), sweep.tolist(), node.tolist(),
                                strict=True):  # fmt: skip
            leave = (float(cand.p[k, 0]), float(cand.p[k, 1]))
            signed = s * sw if rho_i > 0 else 0.0
            if v >= 0:
                self.g[v] = gk
                self.parent[v], self.leave[v], self.sweep[v] = u, leave, signed
            else:
                v = self._add((float(cand.q[k, 0]), float(cand.q[k, 1])), int(cand.j[k]),
                              float(cand.angle_j[k]), int(cand.sense_j[k]), gk, u, leave,
                              signed, float(cand.h[k]))  # fmt: skip
                cand.node[k] = v
            out.append(v)
        return out

    def _arcs_ok(self, u: int, sweep: np.ndarray) -> np.ndarray:
        """Which arcs along node ``u``'s circle, from its angle through ``sweep``, are free."""
        ok = np.ones(len(sweep), dtype=bool)
        arcs = np.flatnonzero(sweep > 0)
        if len(arcs):
            s = sweep[arcs]
            i = self.circle[u]
            a0 = self.angle[u] if self.sense[u] > 0 else self.angle[u] - s
            center = np.broadcast_to(self.circles[i, :2], (len(arcs), 2))
            rho = np.full(len(arcs), self.circles[i, 2])
            ok[arcs] = arcs_free(self.graph.world, center, rho, np.broadcast_to(a0, s.shape), s)
        return ok

    def _pieces(self, v: int) -> list[Piece]:
        """The path from the start to node ``v`` as arcs and tangent segments."""
        chain = []
        while v != -1:
            chain.append(v)
            v = self.parent[v]
        chain.reverse()
        pieces: list[Piece] = []
        for u, v in itertools.pairwise(chain):
            leave = self.leave[v]
            if self.sweep[v] != 0.0:
                c = self.circles[self.circle[u]]
                pieces.append(Piece("arc", self.xy[u], leave, (float(c[0]), float(c[1])),
                                    float(c[2]), self.angle[u], self.sweep[v]))  # fmt: skip
            pieces.append(Piece("line", leave, self.xy[v]))
        return pieces
