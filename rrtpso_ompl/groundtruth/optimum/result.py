"""What the exact optimum returns: the path as tangent segments and arcs, its length, and the
search's limits.

A :class:`Piece` is a straight segment or an arc of a circle (an obstacle's, grown by the robot
radius, or a polygon vertex's of radius ``R``); :class:`OptimumResult` holds the pieces, their
total length (problem units) and the size of the search; :meth:`OptimumResult.polyline` turns
arcs into circumscribed polygons, so every segment of the polyline keeps the robot's radius.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import RrtpsoError
from ...model.world import World

__all__ = ["MAX_NODES", "OptimumResult", "OptimumTooLarge", "Piece"]


@dataclass(frozen=True)
class Piece:
    """One piece of the optimal path: a straight segment or an arc.

    Attributes
    ----------
    kind : str
        ``"line"`` or ``"arc"``.
    start, end : (float, float)
        End points, problem units.
    center : (float, float) or None
        Arc centre (an obstacle centre or a polygon vertex).
    radius : float
        Arc radius (obstacle radius plus robot radius), 0 for a line.
    angle : float
        Angle of ``start`` seen from ``center``, radians.
    sweep : float
        Signed angle the arc turns through, radians (positive counter-clockwise).
    """

    kind: str
    start: tuple[float, float]
    end: tuple[float, float]
    center: tuple[float, float] | None = None
    radius: float = 0.0
    angle: float = 0.0
    sweep: float = 0.0

    @property
    def length(self) -> float:
        """Length of the piece, problem units."""
        if self.kind == "arc":
            return abs(self.sweep) * self.radius
        return math.dist(self.start, self.end)

    def points(self, max_angle: float = math.radians(2.0)) -> np.ndarray:
        """The piece as a polyline from ``start`` to ``end`` that never comes closer to an arc's
        centre than its radius.

        An arc becomes the polygon *circumscribed* about it: its vertices lie at radius
        ``rho / cos(delta / 2)`` between the tangent points, every ``delta <= max_angle``, so each
        of its segments is tangent to the circle (chords would cut into the robot's safety zone
        by up to ``rho (1 - cos(delta / 2))``). It is longer than the arc by a factor of at most
        ``tan(delta / 2) / (delta / 2)`` (1.0001 at 2 degrees).
        """
        if self.kind != "arc" or self.radius == 0.0:
            return np.array([self.start, self.end], dtype=float)
        n = max(1, math.ceil(abs(self.sweep) / max_angle))
        delta = self.sweep / n
        a = self.angle + delta * (np.arange(n) + 0.5)
        rho = self.radius / math.cos(0.5 * delta)
        middle = np.column_stack(
            [self.center[0] + rho * np.cos(a), self.center[1] + rho * np.sin(a)]
        )
        return np.vstack([self.start, middle, self.end])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary."""
        d: dict[str, Any] = {"kind": self.kind, "start": list(self.start), "end": list(self.end)}
        if self.kind == "arc":
            d.update(center=list(self.center), radius=self.radius, sweep=self.sweep)
        d["length"] = self.length
        return d


@dataclass(frozen=True)
class OptimumResult:
    """The shortest path of a problem, or the proof that there is none.

    Attributes
    ----------
    problem : str
        Problem name.
    length : float or None
        Length of the shortest path, problem units; None when start and goal are not connected.
    pieces : list of Piece
        The path as tangent segments and arcs.
    exact : bool
        False only with a ``goal_tolerance`` disc that is not wholly free, where the length is
        that of the best path to the goal point's tangents (an upper bound).
    n_nodes, n_edges : int
        Size of the tangent graph of the last round.
    time : float
        Seconds spent.
    stopped : bool
        The search was stopped (its ``terminate`` callback) before it knew: ``length`` is None
        and says nothing.
    rounds : int
        Rounds of growing bounds the search took (package docstring).
    """

    problem: str
    length: float | None
    pieces: list[Piece] = field(default_factory=list)
    exact: bool = True
    n_nodes: int = 0
    n_edges: int = 0
    time: float = 0.0
    stopped: bool = False
    rounds: int = 0

    @property
    def found(self) -> bool:
        """Whether a path exists."""
        return self.length is not None

    def polyline(self, max_angle: float = math.radians(2.0)) -> np.ndarray:
        """The path as an (m, 2) polyline: tangent segments, and arcs as their circumscribed
        polygons (:meth:`Piece.points`), so the robot keeps its radius along every segment.

        Its length exceeds :attr:`length` by a relative ``1e-4`` at most (at 2 degrees); use
        :attr:`pieces` for the exact geometry.
        """
        if not self.pieces:
            return np.empty((0, 2))
        parts = [self.pieces[0].points(max_angle)[:1]]
        parts += [p.points(max_angle)[1:] for p in self.pieces]
        pts = np.concatenate(parts)
        keep = np.ones(len(pts), dtype=bool)
        keep[1:] = np.any(np.diff(pts, axis=0) != 0.0, axis=1)
        return pts[keep]

    def valid_polyline(self, world: World) -> np.ndarray:
        """:meth:`polyline`, finer where needed until the exact check accepts it.

        An arc's circumscribed polygon bulges out by ``rho (1 / cos(delta / 2) - 1)``; where the
        path runs that close to a second obstacle, smaller angles shrink the bulge. The finest
        try is returned either way (valid in every case but a path squeezed between two
        obstacles that touch it at one point).
        """
        pts = self.polyline()
        for degrees in (1.0, 0.5, 0.25, 0.125):
            if not len(pts) or world.path_valid(pts):
                return pts
            pts = self.polyline(math.radians(degrees))
        return pts

    def to_dict(self, world: World | None = None) -> dict[str, Any]:
        """JSON-ready dictionary: the contract's ``length`` and ``path`` first (with ``world``,
        the path is refined until the exact check accepts it, :meth:`valid_polyline`)."""
        path = self.valid_polyline(world) if world is not None else self.polyline()
        return {
            "length": self.length,
            "path": path.tolist(),
            "problem": self.problem,
            "exact": self.exact,
            "pieces": [p.to_dict() for p in self.pieces],
            "graph": {"nodes": self.n_nodes, "edges": self.n_edges, "rounds": self.rounds},
            "time": self.time,
        }


#: Most tangent nodes one search may create (memory: a few hundred bytes each).
MAX_NODES = 5_000_000


class OptimumTooLarge(RrtpsoError):
    """The search for the exact optimum would need more memory than it is allowed."""
