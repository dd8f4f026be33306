"""Pictures: worlds, paths and best-cost curves. The only module that imports matplotlib.

Figures are drawn with the non-interactive Agg backend and written through a temporary file, so a
failed or interrupted plot never leaves half an image behind.
"""

from __future__ import annotations

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

from .model.problem import Circle, Polygon, Problem
from .outputs import atomic_path
from .planners.solve import SolveResult

__all__ = [
    "animate_simulation",
    "draw_map",
    "draw_world",
    "plot_bench",
    "plot_optimum",
    "plot_simulation",
    "plot_solution",
    "plot_velocities",
    "save_figure",
]

OBSTACLE = "#5b6770"
SAFETY = "#e0a030"
RRT_COLOUR = "#8c8c8c"
PATH_COLOUR = "#d62728"
MOVING = "#7b3294"
DETOUR = "#1a9641"


def draw_world(ax: Axes, problem: Problem, *, safety_zones: bool = True) -> None:
    """Obstacles (filled), their safety zones (the obstacles grown by the robot radius, dashed:
    the robot's centre must stay outside them), bounds, start and goal."""
    r = problem.robot.radius
    if problem.map is not None:
        draw_map(ax, problem, safety_zones=safety_zones)
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


def draw_map(ax: Axes, problem: Problem, *, safety_zones: bool = True) -> None:
    """The occupancy grid under everything: occupied cells dark, unknown cells grey (light grey
    when ``unknown: free``), free cells white; the robot's clearance zone around the blocked
    cells shaded.

    The shading is drawing only (cells whose centre lies within the robot radius of a blocked
    cell's centre, from a Euclidean distance transform); the checks use the exact squares.
    """
    from scipy.ndimage import distance_transform_edt

    grid = problem.map
    (x0, y0), (x1, y1) = grid.extent
    rgb = np.ones((*grid.state.shape, 3))
    rgb[grid.state == -1] = 0.62 if grid.unknown_blocks else 0.85
    rgb[grid.state == 1] = np.array([0x5B, 0x67, 0x70]) / 255.0  # OBSTACLE
    r = problem.robot.radius
    if safety_zones and r > 0 and grid.blocked.any() and not grid.blocked.all():
        near = distance_transform_edt(~grid.blocked, sampling=grid.resolution) <= r
        zone = near & ~grid.blocked
        rgb[zone] = 0.55 * rgb[zone] + 0.45 * np.array([0xE0, 0xA0, 0x30]) / 255.0  # SAFETY
    # Image row 0 is the top of the map, as in the file.
    ax.imshow(rgb, extent=(x0, x1, y0, y1), origin="upper", interpolation="nearest", zorder=0)


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


def plot_optimum(problem: Problem, result: Any) -> Figure:
    """The world with the exact shortest path (an :class:`~rrtpso_ompl.evaluation.OptimumResult`):
    its tangent segments and its arcs around the inflated obstacles."""
    fig, ax = plt.subplots(figsize=(6.5, 6))
    draw_world(ax, problem)
    path = result.polyline(np.radians(0.5))
    if len(path):
        ax.plot(path[:, 0], path[:, 1], "-", color=PATH_COLOUR, lw=1.8, zorder=4,
                label=f"shortest path ({result.length:.2f})")  # fmt: skip
        bends = np.array([p.end for p in result.pieces[:-1]]).reshape(-1, 2)
        ax.plot(bends[:, 0], bends[:, 1], "o", color=PATH_COLOUR, ms=3, zorder=5)
        ax.legend(loc="best", fontsize=8)
    found = f"length {result.length:.4f}" if result.found else "no path"
    ax.set_title(f"{problem.name}: exact optimum, {found}")
    fig.tight_layout()
    return fig


#: Lowest excess over the optimum that :func:`plot_bench` draws, in percent (log axis).
EXCESS_FLOOR = 1e-3


def plot_bench(summary: Any, what: str = "ratio") -> Figure:
    """Benchmark summary (:class:`~rrtpso_ompl.evaluation.SummaryRow` list) against the time budget:
    ``what="ratio"`` the median excess length over the optimum, ``100 (length / optimum - 1)``
    in percent on a log axis (quartiles shaded), ``"success"`` the success rate; one panel per
    problem, one line per planner."""
    problems = list(dict.fromkeys(s.problem for s in summary))
    planners = list(dict.fromkeys(s.planner for s in summary))
    cols = min(4, max(1, len(problems)))
    rows = -(-len(problems) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, problem in zip(axes.flat, problems, strict=False):
        for i, planner in enumerate(planners):
            mine = sorted(
                (s for s in summary if s.problem == problem and s.planner == planner),
                key=lambda s: s.budget,
            )
            c = colours[i % len(colours)]
            t = [s.budget for s in mine]
            if what == "success":
                ax.plot(t, [100 * s.success for s in mine], "o-", color=c, ms=3, label=planner)
                continue
            pts = [(s.budget, s.median_ratio, s.q1_ratio, s.q3_ratio) for s in mine
                   if s.median_ratio is not None]  # fmt: skip
            if pts:
                # Excess in percent on a log axis: a planner 20 % off and one 0.01 % off are both
                # readable in the same panel. The floor keeps exact optima on the axis.
                b, m, lo, hi = (np.asarray(v, dtype=float) for v in zip(*pts, strict=True))
                m, lo, hi = (np.maximum(100 * (v - 1), EXCESS_FLOOR) for v in (m, lo, hi))
                ax.plot(b, m, "o-", color=c, ms=3, label=planner)
                ax.fill_between(b, lo, hi, color=c, alpha=0.15)
        ax.set_xscale("log")
        budgets = sorted({s.budget for s in summary})
        ax.set_xticks(budgets, [f"{b:g}" for b in budgets])
        ax.minorticks_off()
        ax.set_title(problem, fontsize=9)
        ax.grid(alpha=0.3)
        ax.set_ylabel("success (%)" if what == "success" else "over optimum (%)", fontsize=8)
        ax.set_xlabel("time budget (s)", fontsize=8)
        if what == "success":
            ax.set_ylim(-5, 105)
        else:
            ax.set_yscale("log")
    for ax in axes.flat[len(problems) :]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(planners), fontsize=8)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
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


def image_formats() -> set[str]:
    """The file suffixes (without the dot) that :func:`save_figure` can write."""
    return set(Figure().canvas.get_supported_filetypes())


def save_figure(fig: Figure, path: str | Path, dpi: int = 120) -> None:
    """Save ``fig`` atomically (temporary file, then rename) and close it."""
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi)
    finally:
        plt.close(fig)


# ----------------------------------------------------------------------------------------------
# Simulations with moving obstacles (paper Figs. 23-24)
# ----------------------------------------------------------------------------------------------
def plot_simulation(problem: Problem, sim: Any) -> Figure:
    """The paper's Fig. 24 for a :class:`~rrtpso_ompl.dynamic.SimulationResult`: (a) the world,
    the static path, the driven path with its detours and each moving obstacle's track from its
    first position (grey) to its position at the end (black); (b) the centre distance to each
    moving obstacle over time against the contact distance ``SR + SO``."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 6), gridspec_kw={"width_ratios": [1.1, 1]})
    draw_world(ax, problem)
    static = np.asarray(sim.static_path, dtype=float).reshape(-1, 2)
    if len(static):
        ax.plot(*static.T, "--", color=RRT_COLOUR, lw=1.2, zorder=3, label="static path")
    traj = sim.trajectory
    t_end = float(traj[-1, 0]) if len(traj) else 0.0
    if len(traj):
        ax.plot(traj[:, 1], traj[:, 2], "-", color=PATH_COLOUR, lw=1.8, zorder=4,
                label=f"driven path ({sim.path_length:.1f})")  # fmt: skip
    for i, rep in enumerate(sim.replans):
        label = "detours" if i == 0 else None
        if rep.detour is not None:
            ax.plot(*np.asarray(rep.detour).T, "-", color=DETOUR, lw=1.2, zorder=5, label=label)
        ax.plot(*rep.cross_point, "x", color="k", ms=8, zorder=6,
                label="predicted cross point" if i == 0 else None)  # fmt: skip
        side = f" {rep.side}" if rep.side else ""
        ax.annotate(f"{rep.kind}{side} @ {rep.t:.1f}s", rep.start, fontsize=7, zorder=6)
    for k, tr in enumerate(sim.tracks):
        ts = np.linspace(0.0, t_end, 200)
        q = tr.position(ts)
        ax.plot(q[:, 0], q[:, 1], ":", color=MOVING, lw=1.0, zorder=3)
        ax.add_patch(CirclePatch(q[0], tr.radius, color="0.7", alpha=0.8, zorder=3))
        ax.add_patch(CirclePatch(q[-1], tr.radius, color="k", alpha=0.8, zorder=3))
        ax.annotate(f"M{k}", q[0], ha="center", va="center", fontsize=7, color="k", zorder=4)
    verdict = "goal reached" if sim.reached_goal else "goal NOT reached"
    ax.set_title(f"{problem.name}: {sim.strategy}, {verdict}, {sim.collisions} collisions")
    ax.legend(loc="best", fontsize=7)
    for k, tr in enumerate(sim.tracks):
        if not len(traj):
            break
        d = np.hypot(*(traj[:, 1:3] - tr.position(traj[:, 0])).T)
        line = bx.plot(traj[:, 0], d, lw=1.3, label=f"M{k}")[0]
        bx.axhline(sim.contact_distance[k], color=line.get_color(), ls="--", lw=0.9)
    for rep in sim.replans:
        bx.axvline(rep.t, color="0.6", lw=0.8)
    bx.set_xlabel("t [s]")
    unit = f" [{problem.units}]" if problem.units else ""
    bx.set_ylabel(f"centre distance{unit}")
    bx.set_title("separation (dashed: contact SR + SO; grey: replans)")
    bx.grid(alpha=0.3)
    if sim.tracks:
        bx.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def animate_simulation(
    problem: Problem, sim: Any, path: str | Path, *, max_frames: int = 150, fps: int = 10
) -> None:
    """Write a GIF of the simulation: static and moving obstacles, the robot and its sensor range,
    the plan it is driving, the predicted cross points and the detours (atomically)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    traj = sim.trajectory
    if not len(traj):
        raise ValueError("nothing to animate: the simulation has no trajectory")
    frames = np.unique(np.linspace(0, len(traj) - 1, min(max_frames, len(traj))).astype(int))
    fig, ax = plt.subplots(figsize=(6.5, 6.5))
    draw_world(ax, problem, safety_zones=False)
    r = problem.robot.radius
    sensor = CirclePatch((0, 0), problem.robot.sensor_range or 0.0, fill=False, ls=":",
                         ec="tab:blue", lw=0.8, zorder=3)  # fmt: skip
    body = CirclePatch((0, 0), r, color=PATH_COLOUR, alpha=0.6, zorder=6)
    ax.add_patch(sensor)
    ax.add_patch(body)
    (heading,) = ax.plot([], [], "-", color="k", lw=1.2, zorder=7)
    (trace,) = ax.plot([], [], "-", color=PATH_COLOUR, lw=1.5, zorder=4)
    (plan_line,) = ax.plot([], [], "--", color=RRT_COLOUR, lw=1.0, zorder=3)
    (cross,) = ax.plot([], [], "x", color="k", ms=9, zorder=7)
    obstacles = [CirclePatch((0, 0), tr.radius, color=MOVING, alpha=0.7, zorder=5)
                 for tr in sim.tracks]  # fmt: skip
    for patch in obstacles:
        ax.add_patch(patch)
    detour_lines = [ax.plot([], [], "-", color=DETOUR, lw=1.3, zorder=5)[0] for _ in sim.replans]
    title = ax.set_title("")
    switch_times = np.array([t for t, _ in sim.plans])

    def update(i: int) -> list[Any]:
        t, x, y, th = traj[i]
        body.center = sensor.center = (x, y)
        heading.set_data([x, x + r * np.cos(th)], [y, y + r * np.sin(th)])
        trace.set_data(traj[: i + 1, 1], traj[: i + 1, 2])
        plan = sim.plans[int(np.searchsorted(switch_times, t, side="right")) - 1][1]
        ahead = plan.waypoints_after(t)
        plan_line.set_data(ahead[:, 0], ahead[:, 1])
        live = [rep for rep in sim.replans if rep.t <= t <= rep.t_cross]
        if live:
            cross.set_data([live[-1].cross_point[0]], [live[-1].cross_point[1]])
        else:
            cross.set_data([], [])
        for line, rep in zip(detour_lines, sim.replans, strict=True):
            if rep.detour is not None and rep.t <= t:
                line.set_data(*np.asarray(rep.detour).T)
        for patch, tr in zip(obstacles, sim.tracks, strict=True):
            patch.center = tuple(tr.position(t))
        title.set_text(
            f"{problem.name}: t = {t:5.1f} s, replans {sum(rep.t <= t for rep in sim.replans)}"
        )
        return [body, sensor, heading, trace, plan_line, cross, title, *obstacles, *detour_lines]

    anim = FuncAnimation(fig, update, frames=frames, blit=False)
    try:
        with atomic_path(path, suffix=".gif") as tmp:
            anim.save(tmp, writer=PillowWriter(fps=fps), dpi=80)
    finally:
        plt.close(fig)
