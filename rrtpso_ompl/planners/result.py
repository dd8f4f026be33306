"""Typed results of a solve: the path and its checks, and the run as OMPL's Benchmark sees it."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

__all__ = ["STATUSES", "BenchmarkRun", "SolveResult"]


@dataclass(frozen=True, kw_only=True)
class BenchmarkRun:
    """One run in the terms of OMPL's ``Benchmark`` (the run properties Planner Arena shows).

    OMPL's Benchmark times the planner, then optionally OMPL's path simplifier, and logs both
    lengths. Each planner says which of its own stages plays which part (see its stats'
    ``benchmark_run``): for RRTstarPSO the RRT* stage is the planner and the swarm the
    simplification; for OMPL's planners run with ``--simplify`` the simplification is OMPL's
    simplifier; a planner without one has no simplification.

    Attributes
    ----------
    time : float
        Planning time, seconds (without the simplification).
    solution_length : float or None
        Length of the planner's own path, before simplification (problem units).
    simplification_time : float or None
        Seconds spent simplifying; None without a simplification stage.
    simplified_length : float or None
        Length after simplification; None without a simplification stage.
    properties : dict
        Planner-specific run properties: OMPL name -> ``(type, value)``, with type one of
        ``"INTEGER"``, ``"REAL"``, ``"BOOLEAN"`` (e.g. ``"iterations": ("INTEGER", 812)``).
    progress : list of (float, float)
        ``(time s, best cost)`` samples while the planner ran, times strictly increasing.
    """

    time: float
    solution_length: float | None = None
    simplification_time: float | None = None
    simplified_length: float | None = None
    properties: dict[str, tuple[str, Any]] = field(default_factory=dict)
    progress: list[tuple[float, float]] = field(default_factory=list)

    @property
    def total_time(self) -> float:
        """Planning plus simplification, seconds."""
        return self.time + (self.simplification_time or 0.0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary (properties as ``[type, value]`` pairs)."""
        d = asdict(self)
        d["properties"] = {k: [t, v] for k, (t, v) in self.properties.items()}
        d["progress"] = [list(p) for p in self.progress]
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> BenchmarkRun:
        """The inverse of :meth:`to_dict` (for rows read back from a results file)."""
        return cls(
            time=d["time"],
            solution_length=d.get("solution_length"),
            simplification_time=d.get("simplification_time"),
            simplified_length=d.get("simplified_length"),
            properties={k: (t, v) for k, (t, v) in (d.get("properties") or {}).items()},
            progress=[(float(t), float(c)) for t, c in d.get("progress") or []],
        )


#: The verdicts of a solve, one of them per result (the ``status`` of the JSON contract).
STATUSES = ("exact", "approximate", "none")


@dataclass(frozen=True, kw_only=True)
class SolveResult:
    """The outcome of solving one problem with one planner.

    One verdict, :attr:`status`; :attr:`solved` and :attr:`valid` are derived from it, and
    :attr:`ompl_status` is what OMPL said (a path OMPL called exact that failed the exact check
    is ``status`` "none" with ``ompl_status`` "Exact solution").

    Attributes
    ----------
    problem : str
        Problem name.
    planner : str
        Planner name as selected.
    status : {"exact", "approximate", "none"}
        ``"exact"``: a path to the goal that passed the exact validity check; ``"approximate"``:
        a valid path that stops short of the goal; ``"none"``: no path, or one that failed the
        check (it is never returned).
    ompl_status : str
        OMPL's own status text (``"Exact solution"``, ``"Timeout"``, ``"Crash"``, ...).
    length : float or None
        Euclidean length of ``path`` in problem units.
    time : float
        Wall-clock seconds spent in the planner and its post-passes.
    seed : int or None
        The seed OMPL and numpy ran with.
    path : (n, 2) ndarray
        The returned polyline (empty when there is none).
    time_limit : float
        The budget, seconds.
    params : dict
        Planner parameters as the planner holds them.
    stages : dict
        Per-stage figures (for RRTstarPSO: RRT* and PSO lengths, times, iterations, PSO best cost
        per iteration, the range used), as the planner's stats report them.
    clearance : float or None
        Smallest distance from the path to an obstacle, minus the robot radius (>= 0 when valid).
    cost : float or None
        The problem's objective ``J`` of ``path`` (problem units): its length plus the weighted
        inflation cost (:mod:`rrtpso_ompl.model.objective`); the length without inflation.
    benchmark : BenchmarkRun
        The run as OMPL's Benchmark records it (planning versus simplification, in the planner's
        own terms).
    """

    problem: str
    planner: str
    status: str
    ompl_status: str
    length: float | None
    time: float
    seed: int | None
    path: np.ndarray = field(repr=False)
    time_limit: float = 0.0
    params: dict[str, Any] = field(default_factory=dict)
    stages: dict[str, Any] = field(default_factory=dict)
    clearance: float | None = None
    cost: float | None = None
    benchmark: BenchmarkRun = field(default_factory=lambda: BenchmarkRun(time=0.0))

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status must be one of {STATUSES}, got {self.status!r}")

    @property
    def solved(self) -> bool:
        """True only for an exact path that passed the exact validity check."""
        return self.status == "exact"

    @property
    def valid(self) -> bool:
        """Whether a path is returned (it passed the exact check: bounds, every segment, robot
        radius); an approximate one is valid too."""
        return self.status != "none"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dictionary with the contract's keys first."""
        return {
            "problem": self.problem,
            "planner": self.planner,
            "status": self.status,
            "solved": self.solved,
            "length": self.length,
            "time": self.time,
            "seed": self.seed,
            "path": np.asarray(self.path, dtype=float).reshape(-1, 2).tolist(),
            "ompl_status": self.ompl_status,
            "time_limit": self.time_limit,
            "valid": self.valid,
            "clearance": self.clearance,
            "cost": self.cost,
            "params": self.params,
            "stages": self.stages,
            "benchmark": self.benchmark.to_dict(),
        }
