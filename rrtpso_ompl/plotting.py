"""Pictures: worlds, paths and best-cost curves. The only module that imports matplotlib.

Figures are drawn with the non-interactive Agg backend and written through a temporary file, so a
failed or interrupted plot never leaves half an image behind.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # files only; never open a window (CI, SSH, batch workers)

import matplotlib.pyplot as plt
import numpy as np
import shapely
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon as PolygonPatch

from .problem import Circle, Polygon, Problem
from .results import SolveResult, publish_atomic

__all__ = ["draw_world", "plot_solution", "plot_velocities", "save_figure"]

OBSTACLE = "#5b6770"
SAFETY = "#e0a030"
RRT_COLOUR = "#8c8c8c"
PATH_COLOUR = "#d62728"


def draw_world(ax: Axes, problem: Problem, *, safety_zones: bool = True) -> None:
    """Obstacles (filled), their safety zones (the obstacles grown by the robot radius, dashed:
    the robot's centre must stay outside them), bounds, start and goal."""
    r = problem.robot.radius
    for obs in problem.obstacles:
        if isinstance(obs, Circle):
            ax.add_patch(CirclePatch(obs.center, obs.radius, color=OBSTACLE, zorder=2))
            if safety_zones and r > 0:
                ax.add_patch(
                    CirclePatch(
                        obs.center, obs.radius + r, fill=False, ls="--", lw=0.9, ec=SAFETY, zorder=1
                    )
                )
        elif isinstance(obs, Polygon):
            ax.add_patch(
                PolygonPatch(np.asarray(obs.points), closed=True, color=OBSTACLE, zorder=2)
            )
            if safety_zones and r > 0:
                # Drawing only: the checks use exact distances, never this buffered outline.
                grown = shapely.Polygon(obs.points).buffer(r, quad_segs=32)
                ax.plot(*grown.exterior.xy, ls="--", lw=0.9, color=SAFETY, zorder=1)
    (xmin, ymin), (xmax, ymax) = problem.bounds
    ax.plot([xmin, xmax, xmax, xmin, xmin], [ymin, ymin, ymax, ymax, ymin], color="k", lw=0.8)
    ax.add_patch(CirclePatch(problem.start, r, fill=False, ec="tab:green", lw=1.0, zorder=4))
    ax.add_patch(
        CirclePatch(
            problem.goal,
            max(r, problem.goal_tolerance),
            fill=False,
            ec="tab:blue",
            lw=1.0,
            zorder=4,
        )
    )
    ax.plot(*problem.start, "o", color="tab:green", zorder=5, label="start")
    ax.plot(*problem.goal, "*", color="tab:blue", ms=11, zorder=5, label="goal")
    pad = 0.02 * max(xmax - xmin, ymax - ymin)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")
    unit = f" [{problem.units}]" if problem.units else ""
    ax.set_xlabel(f"x{unit}")
    ax.set_ylabel(f"y{unit}")


def plot_solution(problem: Problem, result: SolveResult, curve: Any = None) -> Figure:
    """The paper's Fig. 15: the world with the raw RRT* path and the final path (a), and the PSO's
    best cost per iteration (b) when the planner ran a swarm. ``curve`` (a
    :class:`~rrtpso_ompl.kinematics.ReferenceCurve`) adds the smooth reference the robot drives."""
    stages: dict[str, Any] = result.stages or {}
    history = stages.get("pso_history") or []
    fig, axes = plt.subplots(
        1, 2 if history else 1, figsize=(12 if history else 6.5, 6), squeeze=False
    )
    ax = axes[0, 0]
    draw_world(ax, problem)
    raw = np.asarray(stages.get("rrt_path") or [], dtype=float).reshape(-1, 2)
    if len(raw):
        ax.plot(
            raw[:, 0],
            raw[:, 1],
            "o--",
            color=RRT_COLOUR,
            ms=3,
            lw=1.2,
            zorder=3,
            label=f"RRT* path ({stages.get('rrt_length', float('nan')):.1f})",
        )
    path = np.asarray(result.path, dtype=float).reshape(-1, 2)
    if len(path):
        ax.plot(
            path[:, 0],
            path[:, 1],
            "o-",
            color=PATH_COLOUR,
            ms=3,
            lw=1.8,
            zorder=4,
            label=f"{result.planner} path ({result.length:.1f})",
        )
    if curve is not None:
        ax.plot(
            curve.x,
            curve.y,
            "-",
            color="tab:blue",
            lw=1.0,
            zorder=5,
            label=f"reference curve ({curve.kind})",
        )
    title = f"{problem.name}: {result.planner}, {result.status}"
    if result.length is not None:
        title += f", length {result.length:.2f}"
    ax.set_title(title)
    ax.legend(loc="best", fontsize=8)
    if history:
        bx = axes[0, 1]
        h = np.asarray(history, dtype=float)
        bx.plot(np.arange(len(h)), h, color=PATH_COLOUR)
        bx.set_xlabel("PSO iteration (all rounds)")
        bx.set_ylabel("best cost")
        bx.set_title("PSO best cost per iteration")
        bx.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_velocities(traj: Any, units: str = "") -> Figure:
    """The paper's Figs. 17-18: v_ref and omega_ref, then the wheels' linear and angular speeds,
    against time (``traj`` is a :class:`~rrtpso_ompl.kinematics.Trajectory`)."""
    u = units or "units"
    fig, axes = plt.subplots(2, 2, figsize=(12, 7), sharex=True)
    panels = [
        (axes[0, 0], [("v", "v_ref")], f"linear velocity [{u}/s]"),
        (axes[0, 1], [("omega", "ω_ref")], "angular velocity [rad/s]"),
        (axes[1, 0], [("v_right", "v_R"), ("v_left", "v_L")], f"wheel linear speed [{u}/s]"),
        (
            axes[1, 1],
            [("omega_right", "ω_R"), ("omega_left", "ω_L")],
            "wheel angular speed [rad/s]",
        ),
    ]
    for ax, series, label in panels:
        for name, legend in series:
            ax.plot(traj.t, getattr(traj, name), label=legend, lw=1.3)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    fig.suptitle(f"Reference velocities ({traj.profile} profile, Ts = {traj.sample_time:g} s)")
    fig.tight_layout()
    return fig


def save_figure(fig: Figure, path: str | Path, dpi: int = 120) -> None:
    """Save ``fig`` atomically (temporary file, then rename) and close it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.stem}.", suffix=path.suffix or ".png", dir=path.parent
    )
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=dpi)
        publish_atomic(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    finally:
        plt.close(fig)
