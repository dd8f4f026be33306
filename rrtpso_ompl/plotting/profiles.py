"""Figures of quantities along a path: the clearance profile (distance to the nearest obstacle
against arc length, with the robot and inflation radii) and the reference velocities and wheel
speeds against time (the paper's Figs. 17-18).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..model.problem_types import Problem
from .canvas import plt
from .styles import COSTMAP, LEGEND_WIDTH, SAFETY

__all__ = ["PROFILE_SAMPLES", "plot_clearance_profile", "plot_velocities"]

#: Most clearance samples along one path of :func:`plot_clearance_profile`.
PROFILE_SAMPLES = 200_000


def plot_clearance_profile(problem: Problem, paths: dict[str, Any], world: Any = None) -> Figure:
    """Clearance along each path: the distance from the robot's centre to the nearest obstacle
    against arc length, with the robot radius (below it the robot would touch an obstacle) and
    the inflation radius (below it the inflation cost is charged) drawn.

    Parameters
    ----------
    problem : Problem
        Gives the world, the radii and the units.
    paths : dict
        Name -> ``(n, 2)`` polyline; one line each, its length (and with inflation its ``J`` and
        the share of its length within the inflation radius) in the legend.
    world : World, optional
        The problem's static world, when already built.

    Notes
    -----
    Each path is sampled every :attr:`InflationCost.step
    <rrtpso_ompl.model.objective.InflationCost.step>` or finer (at least 1,000 samples, at most
    :data:`PROFILE_SAMPLES`), plus its vertices, where it turns round corners and its clearance is
    least. Clearances above 2.5 times the larger radius are drawn at the top of the axes.
    """
    from ..model.world import World

    world = world if world is not None else World.from_problem(problem)
    cost = problem.objective
    r = problem.robot.radius
    (xmin, ymin), (xmax, ymax) = problem.bounds
    top = 2.5 * max(cost.inflation_radius if cost.active else 0.0, r)
    top = top if top > 0 else 0.05 * max(xmax - xmin, ymax - ymin)
    fig, ax = plt.subplots(figsize=(9.0 + LEGEND_WIDTH, 4.5))
    for name, path in paths.items():
        p = np.asarray(path, dtype=float).reshape(-1, 2)
        if len(p) < 2:
            continue
        s, d = _clearance_along(world, cost, p, top)
        label = f"{name} (length {s[-1]:.2f}"
        if cost.active:
            with np.errstate(invalid="ignore"):  # near_share's cost of inf distances
                share = cost.near_share(world, p)
            label += f", J {cost.path_cost(world, p):.2f}, {share:.0%} of it within R_i"
        ax.plot(s, np.minimum(d, top), lw=1.4, label=label + ")")
    _draw_radii(ax, problem, cost, top)
    fig.tight_layout()
    return fig


def _draw_radii(ax: Axes, problem: Problem, cost: Any, top: float) -> None:
    """The rest of :func:`plot_clearance_profile`'s axes once its paths are drawn: the robot
    radius, with inflation the inflated band and the inflation radius of ``cost`` (an
    :class:`~rrtpso_ompl.model.objective.InflationCost`), clearances drawn up to ``top``, the
    labels, the title and the legend beside the axes."""
    r = problem.robot.radius
    u = problem.units or "length units"
    unit = f" {problem.units}" if problem.units else ""
    ax.axhline(r, color=SAFETY, ls="--", lw=1.2,
               label=f"robot radius r = {r:g}{unit} (touching an obstacle)")  # fmt: skip
    if cost.active:
        ax.axhspan(r, cost.inflation_radius, color=COSTMAP, alpha=0.12, lw=0,
                   label="inflated band (the cost is charged)")  # fmt: skip
        ax.axhline(cost.inflation_radius, color=COSTMAP, ls=":", lw=1.4,
                   label=f"inflation radius R_i = {cost.inflation_radius:g}{unit}")  # fmt: skip
    ax.set_ylim(0.0, top * 1.02)
    ax.set_xlim(left=0.0)
    ax.set_xlabel(f"arc length along the path [{u}]")
    ax.set_ylabel(f"clearance [{u}]")
    ax.set_title(f"{problem.name}: distance from the robot's centre to the nearest obstacle "
                 f"(drawn up to {top:g}{unit})", fontsize=10)  # fmt: skip
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, fontsize=8)


def _clearance_along(world: Any, cost: Any, p: np.ndarray, cap: float):
    """Arc lengths and clearances (``inf`` beyond ``cap``) of samples along a polyline: every
    :attr:`InflationCost.step` or finer, and the vertices."""
    cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(p, axis=0).T))])
    total = float(cum[-1])
    spacing = min(cost.step, total / 1000.0) if total > 0 else 1.0
    n = int(min(math.ceil(total / spacing), PROFILE_SAMPLES)) + 1 if total > 0 else 1
    s = np.unique(np.concatenate([np.linspace(0.0, total, n), cum]))
    pts = np.column_stack([np.interp(s, cum, p[:, 0]), np.interp(s, cum, p[:, 1])])
    return s, world.point_clearance(pts, cap=cap)


def plot_velocities(traj: Any, units: str = "") -> Figure:
    """The paper's Figs. 17-18: v_ref and omega_ref, then the wheels' linear and angular speeds,
    against time (``traj`` is a :class:`~rrtpso_ompl.kinematics.Trajectory`); the in-place turn
    to a goal heading, if any, shaded."""
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
        if traj.goal_turn_times is not None:
            ax.axvspan(*traj.goal_turn_times, color="0.85", zorder=0, label="turn to goal_yaw")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    slowed = ", slowed near obstacles" if traj.slow_near_obstacles else ""
    fig.suptitle(
        f"Reference velocities ({traj.profile} profile{slowed}, Ts = {traj.sample_time:g} s)"
    )
    fig.tight_layout()
    return fig
