"""The records of a simulation: each reaction of the replanning manager (:class:`Replan`) and the
run's outcome (:class:`SimulationResult`, the ``rrtpso simulate --json`` output)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .motion import Motion, ObstacleTrack

__all__ = ["Replan", "SimulationResult"]


@dataclass
class Replan:
    """One reaction of the manager (JSON-ready through :meth:`to_dict`).

    ``kind`` is the strategy's name (``"contour"``, ``"global"``) for a planned reaction
    (``side`` ``"up"``, ``"down"``, ``"wait"`` or None for one plan), ``"wait"`` or ``"evade"``
    for a fallback, ``"unavoidable"`` when nothing verified. ``planning_time`` is the measured
    wall-clock time of the planners, ``budget`` the simulated time it was charged.
    """

    t: float
    kind: str
    side: str | None
    start: np.ndarray
    goal: np.ndarray | None
    planning_time: float
    budget: float
    length: float | None
    obstacles: list[int]
    cross_point: np.ndarray
    t_cross: float
    candidates: list[dict[str, Any]] = field(default_factory=list)
    detour: np.ndarray | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "t": self.t,
            "kind": self.kind,
            "side": self.side,
            "start": self.start.tolist(),
            "goal": None if self.goal is None else self.goal.tolist(),
            "planning_time": self.planning_time,
            "budget": self.budget,
            "length": self.length,
            "obstacles": self.obstacles,
            "cross_point": self.cross_point.tolist(),
            "t_cross": self.t_cross,
            "candidates": self.candidates,
            "detour": None if self.detour is None else self.detour.tolist(),
        }


@dataclass
class SimulationResult:
    """The outcome of one simulation; :meth:`to_dict` is the ``rrtpso simulate --json`` output.

    Distances are centre to centre (units): the robot and obstacle ``k`` touch at
    ``SR + SO_k``. ``collisions`` counts the sample instants at which any separation was below
    that; ``min_separation_continuous`` is exact between samples too.
    """

    problem: str
    strategy: str
    planner: str
    seed: int | None
    reached_goal: bool
    collisions: int
    min_separation: list[float | None]
    min_separation_continuous: list[float | None]
    contact_distance: list[float]
    total_time: float
    path_length: float
    static_length: float | None
    sample_time: float
    motion: Motion | None
    static_path: np.ndarray
    tracks: list[ObstacleTrack]
    replans: list[Replan]
    plans: list[tuple[float, Motion]]
    status: str = "ok"

    @property
    def trajectory(self) -> np.ndarray:
        """``[t, x, y, theta]`` every sample time from the start to the goal (or the end)."""
        if self.motion is None:
            return np.empty((0, 4))
        return self.motion.sample(self.sample_time)

    @property
    def success(self) -> bool:
        """Goal reached without any collision."""
        return self.reached_goal and self.collisions == 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "problem": self.problem,
            "status": self.status,
            "strategy": self.strategy,
            "planner": self.planner,
            "seed": self.seed,
            "reached_goal": self.reached_goal,
            "collisions": self.collisions,
            "min_separation": self.min_separation,
            "min_separation_continuous": self.min_separation_continuous,
            "contact_distance": self.contact_distance,
            "total_time": self.total_time,
            "path_length": self.path_length,
            "static_length": self.static_length,
            "replans": [r.to_dict() for r in self.replans],
            "trajectory": self.trajectory.tolist(),
            "static_path": self.static_path.tolist(),
        }
