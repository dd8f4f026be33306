"""Figures of a world and a path through it: a planner's solution with its stages and the
swarm's best cost per iteration (the paper's Fig. 15), the exact optimum, and the grid reference
of the inflation objective over its costmap.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib import ticker
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..model.problem_types import Problem
from ..planners.result import SolveResult
from .canvas import fit_layout, plt
from .styles import PATH_COLOUR, RRT_COLOUR
from .world import draw_costmap, draw_world, world_legend, world_width

__all__ = ["plot_cost_reference", "plot_optimum", "plot_solution"]


def plot_cost_reference(problem: Problem, result: Any) -> Figure:
    """The world, its costmap (:func:`draw_costmap`) and the grid reference of the inflation
    objective (a :class:`~rrtpso_ompl.groundtruth.costgrid.CostGridResult`)."""
    fig, ax = plt.subplots(figsize=(world_width(problem, 6.0), 6))
    key = draw_world(ax, problem)
    key += draw_costmap(ax, problem)
    path = np.asarray(result.path, dtype=float).reshape(-1, 2)
    if result.found:
        key += ax.plot(path[:, 0], path[:, 1], "-", color=PATH_COLOUR, lw=1.8, zorder=4,
                       label=f"grid reference (J {result.cost:.2f})")  # fmt: skip
    world_legend(ax, key)
    found = (f"J {result.cost:.4f}, length {result.length:.4f}" if result.found
             else "no path on the grid")  # fmt: skip
    ax.set_title(f"{problem.name}: grid reference (h = {result.resolution:.3g}), {found}",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    return fig


def plot_solution(problem: Problem, result: SolveResult, curve: Any = None) -> Figure:
    """The paper's Fig. 15: the world with what each stage gave (a), and the swarm's best cost
    per iteration (b) when the swarm ran more than one iteration. ``curve`` (a
    :class:`~rrtpso_ompl.kinematics.ReferenceCurve`) adds the smooth reference the robot drives.

    Each line is credited to the stage that made it: RRT*'s path only when it reached the goal
    ("RRT*'s best, short of the goal" else, "no RRT* path" without one), the swarm's seed when
    it came from another stage (the corridor route, BIT*, the cost route), and the final path;
    the swarm's panel says what the swarm itself gained (from its seed to its result).
    """
    stages: dict[str, Any] = result.stages or {}
    history = np.asarray(stages.get("pso_history") or [], dtype=float)
    panel = len(history) >= 2
    width = world_width(problem, 6.0)
    widths = [width, 5.5] if panel else [width]
    fig, axes = plt.subplots(1, len(widths), figsize=(sum(widths), 6), squeeze=False,
                             gridspec_kw={"width_ratios": widths})  # fmt: skip
    ax = axes[0, 0]
    key = draw_world(ax, problem)
    key += draw_costmap(ax, problem)
    # A car's paths are curves drawn by their chords: marked at their waypoint poses only.
    car = stages.get("car")
    key += _draw_stage_paths(ax, problem, stages, bool(car))
    path = np.asarray(result.path, dtype=float).reshape(-1, 2)
    if len(path):
        what = f"{car['space']} curves" if car else "path"
        key += ax.plot(path[:, 0], path[:, 1], "-" if car else "o-", color=PATH_COLOUR, ms=3,
                       lw=1.8, zorder=4,
                       label=f"{result.planner} {what} ({result.length:.1f})")  # fmt: skip
    if car and len(path):
        key += _draw_poses(ax, np.asarray(stages.get("poses") or [], dtype=float), problem)
    if curve is not None:
        key += ax.plot(curve.x, curve.y, "-", color="tab:blue", lw=1.0, zorder=5,
                       label=f"reference curve ({curve.kind})")  # fmt: skip
    title = f"{problem.name}: {result.planner}, {result.status}"
    if result.length is not None:
        title += f", length {result.length:.2f}"
    ax.set_title(title)
    world_legend(ax, key)
    if panel:
        _draw_pso_history(axes[0, 1], history, problem.units, problem.objective.active,
                          bool(car), stages)  # fmt: skip
    fit_layout(fig)
    return fig


#: The stages a swarm's seed may come from other than RRT*, as the legend names them.
_SEED_NAMES = {"corridor": "corridor route", "costroute": "cost route", "BITstar": "BIT* path"}


def _draw_stage_paths(ax: Axes, problem: Problem, stages: dict[str, Any], car: bool) -> list:
    """RRT*'s path (or why there is none to draw) and the swarm's seed when another stage made
    it; their legend handles."""
    key: list = []
    raw = np.asarray(stages.get("rrt_path") or [], dtype=float).reshape(-1, 2)
    if "rrt_path" in stages or "rrt_length" in stages:
        goal = np.asarray(problem.goal, dtype=float)
        scale = max(1.0, float(np.abs(raw).max())) if len(raw) else 1.0
        reached = len(raw) > 1 and bool(
            np.hypot(*(raw[-1] - goal)) <= problem.goal_tolerance + 1e-9 * scale
        )
        if reached:
            label = f"RRT* path ({stages.get('rrt_length') or float('nan'):.1f})"
        elif len(raw):
            label = "RRT*'s best, short of the goal"
        else:
            label = "no RRT* path"
        xs, ys = (raw[:, 0], raw[:, 1]) if len(raw) else ([], [])
        key += ax.plot(xs, ys, "--" if car else "o--", color=RRT_COLOUR, ms=3, lw=1.2,
                       zorder=3, label=label)  # fmt: skip
    source = str(stages.get("seed_source") or "").split("+")[0]
    seed = np.asarray(stages.get("seed_path") or [], dtype=float).reshape(-1, 2)
    if source in _SEED_NAMES and len(seed) > 1:
        length = float(np.hypot(*np.diff(seed, axis=0).T).sum())
        key += ax.plot(seed[:, 0], seed[:, 1], ":", color="tab:green", lw=1.6, zorder=3,
                       label=f"{_SEED_NAMES[source]} ({length:.1f}), the swarm's seed")  # fmt: skip
    return key


def _draw_pso_history(bx: Axes, history: np.ndarray, units: str, inflated: bool = False,
                      car: bool = False, stages: dict[str, Any] | None = None) -> None:  # fmt: skip
    """Panel (b) of :func:`plot_solution`: the swarm's best cost per iteration, over all its
    rounds (with an inflation cost, the objective J's; for a car, its curves' length), titled
    with what the swarm itself gained, from its seed's cost to its result's."""
    bx.plot(np.arange(len(history)), history, color=PATH_COLOUR)
    bx.xaxis.set_major_locator(ticker.MaxNLocator(integer=True))
    # Whole values on the axis: no "+9.47e1" offset that hides what the ticks mean.
    bx.yaxis.set_major_formatter(ticker.ScalarFormatter(useOffset=False))
    bx.set_xlabel("PSO iteration (all rounds)")
    # The swarm's best is always collision-free, so its cost is the path length plus the
    # turning penalty (smoothness_weight, 0 by default): a length.
    what = "J = length + w x inflation cost" if inflated else "length + turning penalty"
    if car:  # outside the plane the swarm lowers the curves' length alone
        what = "length of the curves"
    unit = units or "length units"
    bx.set_ylabel(f"best cost: {what} [{unit}]")
    stages = stages or {}
    seed = stages.get("seed_cost", stages.get("seed_length"))
    before = float(history[0]) if seed is None else float(seed)
    after = stages.get("pso_cost", stages.get("pso_length"))
    after = float(history[-1]) if after is None else float(after)
    gain = before - after
    if gain > 1e-9 * max(abs(before), 1.0):
        told = (f"{before:.6g} -> {after:.6g} {unit}, -{gain:.2g} {unit} "
                f"(-{100.0 * gain / before:.2g} %)")  # fmt: skip
    else:
        told = f"no gain on its seed ({before:.4g} {unit})"
    bx.set_title(f"PSO best cost per iteration\n{told}", fontsize=10)
    bx.grid(alpha=0.3)


def _draw_poses(ax: Axes, poses: np.ndarray, problem: Problem) -> list:
    """A car's waypoint poses as arrows along its heading, 3 % of the world's larger side long."""
    if not len(poses):
        return []
    (x0, y0), (x1, y1) = problem.bounds
    size = 0.03 * max(x1 - x0, y1 - y0)
    q = ax.quiver(poses[:, 0], poses[:, 1], np.cos(poses[:, 2]), np.sin(poses[:, 2]),
                  color=PATH_COLOUR, angles="xy", scale_units="xy", scale=1.0 / size,
                  width=0.004, zorder=6, label="waypoint poses (heading)")  # fmt: skip
    return [q]


def plot_optimum(problem: Problem, result: Any) -> Figure:
    """The world with the exact shortest path (an :class:`~rrtpso_ompl.groundtruth.OptimumResult`):
    its tangent segments and its arcs around the inflated obstacles."""
    fig, ax = plt.subplots(figsize=(world_width(problem, 6.0), 6))
    key = draw_world(ax, problem)
    path = result.polyline(np.radians(0.5))
    if len(path):
        key += ax.plot(path[:, 0], path[:, 1], "-", color=PATH_COLOUR, lw=1.8, zorder=4,
                       label=f"shortest path ({result.length:.2f})")  # fmt: skip
        bends = np.array([p.end for p in result.pieces[:-1]]).reshape(-1, 2)
        key += ax.plot(bends[:, 0], bends[:, 1], "o", color=PATH_COLOUR, ms=3, zorder=5,
                       label="bends (tangent points)")  # fmt: skip
    world_legend(ax, key)
    found = f"length {result.length:.4f}" if result.found else "no path"
    ax.set_title(f"{problem.name}: exact optimum, {found}")
    fit_layout(fig)
    return fig
