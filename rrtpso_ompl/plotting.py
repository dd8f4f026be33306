"""Pictures: worlds, paths and best-cost curves. The only module that imports matplotlib.

Figures are drawn with the non-interactive Agg backend and written through a temporary file, so a
failed or interrupted plot never leaves half an image behind.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # files only; never open a window (CI, SSH, batch workers)

import matplotlib.pyplot as plt
import numpy as np
import shapely
from matplotlib import ticker
from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch, Rectangle
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.text import Text
from matplotlib.transforms import Affine2D, ScaledTranslation

from .model.problem import Circle, Polygon, Problem
from .outputs import atomic_path
from .planners.result import SolveResult

__all__ = [
    "animate_simulation",
    "draw_costmap",
    "draw_map",
    "draw_world",
    "plot_bench",
    "plot_clearance_profile",
    "plot_cost_reference",
    "plot_optimum",
    "plot_simulation",
    "plot_solution",
    "plot_velocities",
    "save_figure",
    "simulation_frames",
    "world_legend",
    "world_width",
]

OBSTACLE = "#5b6770"
SAFETY = "#e0a030"
RRT_COLOUR = "#8c8c8c"
PATH_COLOUR = "#d62728"
MOVING = "#7b3294"
DETOUR = "#1a9641"
START = "tab:green"
GOAL = "tab:blue"
#: Map cells: unknown space drawn blocked, or free (``unknown: free``).
UNKNOWN_BLOCKED, UNKNOWN_FREE = "0.62", "0.85"
#: The inflation cost (the costmap's shade, the inflated band of the clearance profile).
COSTMAP = "#1f8a8a"
#: Opacity of the costmap's shade where the cost is 1 (the robot touching an obstacle).
COSTMAP_ALPHA = 0.6
#: Most pixels along the longer side of the costmap's raster (one clearance query per pixel).
COSTMAP_PIXELS = 400
#: Most clearance samples along one path of :func:`plot_clearance_profile`.
PROFILE_SAMPLES = 200_000
#: One marker per planner in the benchmark figures (with its colour, so that planners whose
#: lines coincide stay apart).
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h")


def draw_world(ax: Axes, problem: Problem, *, safety_zones: bool = True) -> list[Any]:
    """Obstacles (filled), their safety zones (the obstacles grown by the robot radius, dashed:
    the robot's centre must stay outside them), bounds, start and goal.

    Returns
    -------
    list
        The legend handles of what was drawn (the world's key), for :func:`world_legend`.
    """
    key: list[Any] = []
    if problem.map is not None:
        key += draw_map(ax, problem, safety_zones=safety_zones)
    key += _draw_obstacles(ax, problem, safety_zones=safety_zones)
    (xmin, ymin), (xmax, ymax) = problem.bounds
    ax.plot([xmin, xmax, xmax, xmin, xmin], [ymin, ymin, ymax, ymax, ymin], color="k", lw=0.8)
    key += _draw_ends(ax, problem)
    pad = 0.02 * max(xmax - xmin, ymax - ymin)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")
    unit = f" [{problem.units}]" if problem.units else ""
    ax.set_xlabel(f"x{unit}")
    ax.set_ylabel(f"y{unit}")
    return key


def _draw_obstacles(ax: Axes, problem: Problem, *, safety_zones: bool) -> list[Any]:
    """The static obstacles, and their safety zones when asked and the robot has a radius;
    returns their legend handles."""
    r = problem.robot.radius
    # One collection per kind (not a patch per obstacle): 10,000 obstacles draw in a second.
    shapes, zones = [], []
    for obs in problem.obstacles:
        if isinstance(obs, Circle):
            shapes.append(CirclePatch(obs.center, obs.radius))
            if safety_zones and r > 0:
                zones.append(CirclePatch(obs.center, obs.radius + r))
        elif isinstance(obs, Polygon):
            shapes.append(PolygonPatch(np.asarray(obs.points), closed=True))
            if safety_zones and r > 0:
                # Drawing only: the checks use exact distances, never this buffered outline.
                grown = shapely.Polygon(obs.points).buffer(r, quad_segs=32)
                zones.append(PolygonPatch(np.column_stack(grown.exterior.xy), closed=True))
    if shapes:
        ax.add_collection(PatchCollection(shapes, fc=OBSTACLE, ec=OBSTACLE, lw=1.0, zorder=2),
                          autolim=False)  # fmt: skip
    if zones:
        ax.add_collection(PatchCollection(zones, fc="none", ec=SAFETY, ls="--", lw=0.9, zorder=1),
                          autolim=False)  # fmt: skip
    if not problem.obstacles:
        return []
    key: list[Any] = [Patch(color=OBSTACLE, label="obstacle")]
    if safety_zones and r > 0:
        key.append(Line2D([], [], ls="--", lw=0.9, color=SAFETY,
                          label="safety zone (robot centre stays out)"))  # fmt: skip
    return key


def _draw_ends(ax: Axes, problem: Problem) -> list[Any]:
    """Start and goal, each a marker inside a circle: the robot's disc (or, at the goal, the
    goal tolerance when it is larger); returns their legend handles."""
    r = problem.robot.radius
    goal_r = max(r, problem.goal_tolerance)
    ax.add_patch(CirclePatch(problem.start, r, fill=False, ec=START, lw=1.0, zorder=4))
    ax.add_patch(CirclePatch(problem.goal, goal_r, fill=False, ec=GOAL, lw=1.0, zorder=4))
    ax.plot(*problem.start, "o", color=START, zorder=5)
    ax.plot(*problem.goal, "*", color=GOAL, ms=11, zorder=5)
    # A marker inside a circle, as drawn; the circle is the robot (or the goal's tolerance).
    ring = {"ls": "", "marker": "o", "ms": 13, "mfc": "none", "mew": 1.0}
    goal_ring = "goal tolerance" if problem.goal_tolerance > r else "robot at the goal"
    return [
        (Line2D([], [], color=START, marker="o", ls="", label="start (circle: the robot)"),
         Line2D([], [], mec=START, **ring)),
        (Line2D([], [], color=GOAL, marker="*", ms=9, ls="", label=f"goal (circle: {goal_ring})"),
         Line2D([], [], mec=GOAL, **ring)),
    ]  # fmt: skip


#: Room for :func:`world_legend` beside a world (inches).
LEGEND_WIDTH = 3.0


def world_width(problem: Problem, height: float) -> float:
    """Width in inches of a world's panel with its legend beside it, in a figure ``height``
    inches tall: the world keeps its aspect (a tall warehouse is narrow), within limits."""
    (xmin, ymin), (xmax, ymax) = problem.bounds
    aspect = (xmax - xmin) / max(ymax - ymin, 1e-12)
    return float(np.clip((height - 1.2) * aspect, 2.5, 9.0)) + 1.0 + LEGEND_WIDTH


def world_legend(ax: Axes, handles: list[Any], fontsize: float = 8) -> Legend:
    """The legend of a world's axes, beside them (right, top-aligned), so that it hides nothing:
    not the start, not the path, not an obstacle, however the world is filled.

    ``handles`` are artists with labels, or tuples of artists drawn on top of each other (the
    first one's label is used), as :func:`draw_world` returns them.
    """
    labels = [(h[0] if isinstance(h, tuple) else h).get_label() for h in handles]
    # An equal-aspect world narrower than its panel shrinks towards the panel's left edge, not its
    # centre: centred, it pushed the legend beside it past the figure's right edge.
    ax.set_anchor("W")
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0),
                     borderaxespad=0.0, fontsize=fontsize)  # fmt: skip


def fit_layout(fig: Figure) -> None:
    """``tight_layout``, then, should a world's legend (:func:`world_legend`) still reach past the
    figure's right edge (long labels: a planner spec and a long path's length), its font made
    smaller until it fits (down to 5 points)."""
    fig.tight_layout()
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None:
            continue
        size = legend.get_texts()[0].get_fontsize() if legend.get_texts() else 8.0
        while size > 5.0:
            fig.canvas.draw()
            if legend.get_window_extent().x1 <= fig.bbox.x1 - 2:
                break
            size -= 0.5
            for text in legend.get_texts():
                text.set_fontsize(size)


def draw_map(ax: Axes, problem: Problem, *, safety_zones: bool = True) -> list[Any]:
    """The occupancy grid under everything: occupied cells dark, unknown cells grey (light grey
    when ``unknown: free``), free cells white; the robot's clearance zone around the blocked
    cells shaded; when unknown space blocks, the bounds beyond the map grey too. A turned map
    (origin yaw) is drawn turned about its origin, as RViz shows it. Returns the legend handles
    of the kinds of cells the map has.

    The shading is drawing only (cells whose centre lies within the robot radius of a blocked
    cell's centre, from a Euclidean distance transform); the checks use the exact squares.
    """
    from matplotlib.colors import to_rgb
    from scipy.ndimage import distance_transform_edt

    grid = problem.map
    (x0, y0), (x1, y1) = grid.extent
    unknown = UNKNOWN_BLOCKED if grid.unknown_blocks else UNKNOWN_FREE
    rgb = np.ones((*grid.state.shape, 3))
    rgb[grid.state == -1] = to_rgb(unknown)
    rgb[grid.state == 1] = to_rgb(OBSTACLE)
    key: list[Any] = []
    if (grid.state == 1).any():
        key.append(Patch(color=OBSTACLE, label="occupied cells"))
    (bx0, by0), (bx1, by1) = problem.bounds
    if grid.frame is not None:
        beyond = bool(problem.map_outside)
    else:
        beyond = bx0 < x0 or by0 < y0 or bx1 > x1 or by1 > y1
    beyond = beyond and grid.unknown_blocks
    if beyond:  # the bounds beyond the map, under the image
        ax.add_patch(Rectangle((bx0, by0), bx1 - bx0, by1 - by0, fc=unknown, ec="none", zorder=0))
    if (grid.state == -1).any() or beyond:
        what = "blocked" if grid.unknown_blocks else "treated as free"
        key.append(Patch(color=unknown, label=f"unknown space ({what})"))
    r = problem.robot.radius
    if safety_zones and r > 0 and grid.blocked.any() and not grid.blocked.all():
        near = distance_transform_edt(~grid.blocked, sampling=grid.resolution) <= r
        zone = near & ~grid.blocked
        shade = 0.55 + 0.45 * np.asarray(to_rgb(SAFETY))  # over white, as most of the zone lies
        rgb[zone] = 0.55 * rgb[zone] + 0.45 * np.asarray(to_rgb(SAFETY))
        key.append(Patch(color=tuple(shade), label="clearance zone (robot centre stays out)"))
    # Image row 0 is the top of the map, as in the file.
    image = ax.imshow(rgb, extent=(x0, x1, y0, y1), origin="upper", interpolation="nearest",
                      zorder=0)  # fmt: skip
    if grid.frame is not None:  # turned about the image's lower-left corner (the origin)
        image.set_transform(Affine2D().rotate_around(*grid.origin, grid.yaw) + ax.transData)
    return key


def draw_costmap(ax: Axes, problem: Problem, world: Any = None,
                 pixels: int = COSTMAP_PIXELS) -> list[Any]:  # fmt: skip
    """Shade the inflation cost ``c(d)`` (:mod:`rrtpso_ompl.model.objective`) over the visible
    area, when the robot has inflation: opaque in :data:`COSTMAP` where the robot touches an
    obstacle (``c = 1``), fading to nothing at the inflation radius. Call it after
    :func:`draw_world` (it covers the axes' limits).

    A raster of at most ``pixels`` along the longer side, its clearances from one call of
    :meth:`~rrtpso_ompl.model.World.point_clearance` (with the inflation radius as its cap).
    Inside obstacles nothing is shaded (they are drawn). Returns the legend handles (none without
    inflation).
    """
    from .model.objective import InflationCost
    from .model.world import World

    cost = InflationCost.of(problem.robot)
    if not cost.active:
        return []
    world = world if world is not None else World.from_problem(problem)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    side = max(x1 - x0, y1 - y0)
    nx = max(1, round(pixels * (x1 - x0) / side))
    ny = max(1, round(pixels * (y1 - y0) / side))
    gx, gy = np.meshgrid(x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx,
                         y0 + (np.arange(ny) + 0.5) * (y1 - y0) / ny)  # fmt: skip
    d = world.point_clearance(np.column_stack([gx.ravel(), gy.ravel()]),
                              cap=cost.inflation_radius).reshape(ny, nx)  # fmt: skip
    from matplotlib.colors import to_rgb

    rgba = np.zeros((ny, nx, 4))
    rgba[..., :3] = to_rgb(COSTMAP)
    rgba[..., 3] = np.where(d > 0.0, COSTMAP_ALPHA * cost.cost(d), 0.0)
    ax.imshow(rgba, extent=(x0, x1, y0, y1), origin="lower", interpolation="bilinear",
              zorder=0.5)  # fmt: skip
    ax.set_xlim(x0, x1)  # imshow would reset the limits to its extent (the same, but exactly)
    ax.set_ylim(y0, y1)
    unit = f" {problem.units}" if problem.units else ""
    return [
        Patch(
            color=COSTMAP,
            alpha=COSTMAP_ALPHA,
            label=f"inflation cost (0 beyond R_i = {cost.inflation_radius:g}{unit})",
        )
    ]


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
    from .model.objective import InflationCost
    from .model.world import World

    world = world if world is not None else World.from_problem(problem)
    cost = InflationCost.of(problem.robot)
    r = problem.robot.radius
    (xmin, ymin), (xmax, ymax) = problem.bounds
    top = 2.5 * max(cost.inflation_radius if cost.active else 0.0, r)
    top = top if top > 0 else 0.05 * max(xmax - xmin, ymax - ymin)
    u = problem.units or "length units"
    unit = f" {problem.units}" if problem.units else ""
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
    fig.tight_layout()
    return fig


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
    """The paper's Fig. 15: the world with the raw RRT* path and the final path (a), and the PSO's
    best cost per iteration (b) when the planner ran a swarm. ``curve`` (a
    :class:`~rrtpso_ompl.kinematics.ReferenceCurve`) adds the smooth reference the robot drives."""
    stages: dict[str, Any] = result.stages or {}
    history = stages.get("pso_history") or []
    width = world_width(problem, 6.0)
    widths = [width, 5.5] if history else [width]
    fig, axes = plt.subplots(1, len(widths), figsize=(sum(widths), 6), squeeze=False,
                             gridspec_kw={"width_ratios": widths})  # fmt: skip
    ax = axes[0, 0]
    key = draw_world(ax, problem)
    key += draw_costmap(ax, problem)
    raw = np.asarray(stages.get("rrt_path") or [], dtype=float).reshape(-1, 2)
    if len(raw):
        key += ax.plot(
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
        key += ax.plot(
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
        key += ax.plot(
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
    world_legend(ax, key)
    if history:
        inflated = bool(problem.robot.inflation_radius
                        and problem.robot.inflation_radius > problem.robot.radius)  # fmt: skip
        _draw_pso_history(axes[0, 1], history, problem.units, inflated)
    fit_layout(fig)
    return fig


def _draw_pso_history(bx: Axes, history: Any, units: str, inflated: bool = False) -> None:
    """Panel (b) of :func:`plot_solution`: the swarm's best cost per iteration, over all its
    rounds (with an inflation cost, the objective J's)."""
    h = np.asarray(history, dtype=float)
    bx.plot(np.arange(len(h)), h, color=PATH_COLOUR)
    bx.xaxis.set_major_locator(ticker.MaxNLocator(integer=True))
    bx.set_xlabel("PSO iteration (all rounds)")
    # The swarm's best is always collision-free, so its cost is the path length plus the
    # turning penalty (smoothness_weight, 0 by default): a length.
    what = "J = length + w x inflation cost" if inflated else "length + turning penalty"
    bx.set_ylabel(f"best cost: {what} [{units or 'length units'}]")
    bx.set_title("PSO best cost per iteration")
    bx.grid(alpha=0.3)


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


#: Lowest excess over the optimum that :func:`plot_bench` draws, in percent (log axis).
EXCESS_FLOOR = 1e-3


#: Horizontal offset between neighbouring planners' markers in :func:`plot_bench` (points), so
#: that planners with equal values (all at 100 % success) do not hide each other.
DODGE_PT = 7.0


def plot_bench(summary: Any, what: str = "ratio") -> Figure:
    """Benchmark summary (:class:`~rrtpso_ompl.harness.SummaryRow` list) against the time budget:
    ``what="ratio"`` the median excess length over the optimum, ``100 (length / optimum - 1)``
    in percent on a log axis (quartiles shaded), ``"success"`` the success rate; one panel per
    problem, one line and marker per planner.

    Each planner's points are shifted sideways by a few points (``DODGE_PT``, in display space,
    the same at every budget), so equal values stay distinguishable; the budgets are the ticks.
    """
    problems = list(dict.fromkeys(s.problem for s in summary))
    planners = list(dict.fromkeys(s.planner for s in summary))
    cols = min(4, max(1, len(problems)))
    rows = -(-len(problems) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows + 0.3), squeeze=False)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    style = {p: {"color": colours[i % len(colours)], "marker": MARKERS[i % len(MARKERS)]}
             for i, p in enumerate(planners)}  # fmt: skip
    budgets = sorted({s.budget for s in summary})
    for ax, problem in zip(axes.flat, problems, strict=False):
        for i, planner in enumerate(planners):
            mine = sorted(
                (s for s in summary if s.problem == problem and s.planner == planner),
                key=lambda s: s.budget,
            )
            shift = ScaledTranslation((i - (len(planners) - 1) / 2) * DODGE_PT / 72, 0,
                                      fig.dpi_scale_trans)  # fmt: skip
            moved = {"transform": ax.transData + shift, **style[planner]}
            if what == "success":
                ax.plot([s.budget for s in mine], [100 * s.success for s in mine], "-", ms=4,
                        label=planner, **moved)  # fmt: skip
                continue
            pts = [(s.budget, s.median_ratio, s.q1_ratio, s.q3_ratio) for s in mine
                   if s.median_ratio is not None]  # fmt: skip
            if pts:
                # Excess in percent on a log axis: a planner 20 % off and one 0.01 % off are both
                # readable in the same panel. The floor keeps exact optima on the axis.
                b, m, lo, hi = (np.asarray(v, dtype=float) for v in zip(*pts, strict=True))
                m, lo, hi = (np.maximum(100 * (v - 1), EXCESS_FLOOR) for v in (m, lo, hi))
                ax.plot(b, m, "-", ms=4, label=planner, **moved)
                ax.fill_between(b, lo, hi, color=style[planner]["color"], alpha=0.15, lw=0)
                # A shifted line is not in the data limits by itself.
                ax.update_datalim(np.column_stack([b, m]))
        _bench_axes(ax, problem, budgets, what)
    for ax in axes.flat[len(problems) :]:
        ax.axis("off")
    # Every planner in the key, also one that no panel could draw (no solved run anywhere).
    handles = [Line2D([], [], ms=4, label=p, **style[p]) for p in planners]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(planners), 5), fontsize=8)
    key_rows = -(-len(planners) // 5)
    fig.tight_layout(rect=(0, (0.1 + 0.22 * key_rows) / fig.get_figheight(), 1, 1))
    return fig


def _bench_axes(ax: Axes, title: str, budgets: list[float], what: str) -> None:
    """The axes of a :func:`plot_bench` panel, once its lines are drawn: the budgets as the
    ticks of a log x axis, success in percent or the excess length on a plainly labelled log y
    axis."""
    ax.set_xscale("log")
    ax.set_xticks(budgets, [f"{b:g}" for b in budgets])
    ax.minorticks_off()
    # Room for the shifted markers beside the first and last budgets.
    ax.set_xlim(budgets[0] / 1.4, budgets[-1] * 1.4)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.set_xlabel("time budget [s]", fontsize=8)
    if what == "success":
        ax.set_ylabel("success [%]", fontsize=8)
        ax.set_ylim(-5, 105)
    else:
        ax.set_ylabel("length over optimum [%]", fontsize=8)
        _plain_log_yaxis(ax)
        ax.autoscale_view()
    ax.tick_params(labelsize=8)


def _plain_log_yaxis(ax: Axes) -> None:
    """A log y scale labelled with plain numbers, ``0.1, 0.2, 0.5, 1, 2, 5, 10``, not matplotlib's
    ``10^-1`` (nor ``8.95x10^0``, which it writes when the range spans less than a decade).

    Within one step of the ticks it falls back to linear ticks (``8.9, 8.92, ...``), labelled the
    same way; over many decades only the powers of ten are labelled, so the labels stay apart.
    """
    ax.set_yscale("log")
    axis = ax.yaxis
    lo, hi = axis.get_data_interval()
    decades = np.log10(hi / lo) if lo > 0 and hi > lo else 0.0
    subs = (1.0, 2.0, 3.0, 5.0) if decades < 1 else (1.0, 2.0, 5.0) if decades <= 3 else (1.0,)
    axis.set_major_locator(_LogTicks(subs=subs))
    axis.set_major_formatter(ticker.FuncFormatter(_plain_number))
    axis.set_minor_locator(ticker.LogLocator(subs="auto"))
    axis.set_minor_formatter(ticker.NullFormatter())


class _LogTicks(ticker.LogLocator):
    """LogLocator, or linear ticks when fewer than two of its ticks fall in the view (a panel
    whose values lie within one step of ``subs``, such as 8.4-11.7 %)."""

    def tick_values(self, vmin: float, vmax: float) -> np.ndarray:
        ticks = super().tick_values(vmin, vmax)
        lo, hi = sorted((vmin, vmax))
        if ((ticks >= lo) & (ticks <= hi)).sum() < 2:
            return ticker.AutoLocator().tick_values(vmin, vmax)
        return ticks


def _plain_number(x: float, pos: int | None = None) -> str:
    """``0.001``, ``0.5``, ``10``, ``8.95``: three significant digits, never an exponent."""
    return np.format_float_positional(float(f"{x:.3g}"), trim="-")


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
    widths = [world_width(problem, 6.0), 6.0]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(sum(widths), 6),
                                 gridspec_kw={"width_ratios": widths})  # fmt: skip
    key = draw_world(ax, problem)
    static = np.asarray(sim.static_path, dtype=float).reshape(-1, 2)
    if len(static):
        key += ax.plot(*static.T, "--", color=RRT_COLOUR, lw=1.2, zorder=3, label="static path")
    traj = sim.trajectory
    t_end = float(traj[-1, 0]) if len(traj) else 0.0
    if len(traj):
        key += ax.plot(traj[:, 1], traj[:, 2], "-", color=PATH_COLOUR, lw=1.8, zorder=4,
                       label=f"driven path ({sim.path_length:.1f})")  # fmt: skip
    for rep in sim.replans:
        if rep.detour is not None:
            ax.plot(*np.asarray(rep.detour).T, "-", color=DETOUR, lw=1.2, zorder=5)
        ax.plot(*rep.cross_point, "x", color="k", ms=8, zorder=6)
        side = f" {rep.side}" if rep.side else ""
        ax.annotate(f"{rep.kind}{side} @ {rep.t:.1f}s", rep.start, fontsize=7, zorder=6)
    if any(rep.detour is not None for rep in sim.replans):
        key.append(Line2D([], [], color=DETOUR, lw=1.2, label="detours"))
    if sim.replans:
        key.append(Line2D([], [], ls="", marker="x", color="k", ms=8,
                          label="predicted cross point"))  # fmt: skip
    for k, tr in enumerate(sim.tracks):
        ts = np.linspace(0.0, t_end, 200)
        q = tr.position(ts)
        ax.plot(q[:, 0], q[:, 1], ":", color=MOVING, lw=1.0, zorder=3)
        ax.add_patch(CirclePatch(q[0], tr.radius, color="0.7", alpha=0.8, zorder=3))
        ax.add_patch(CirclePatch(q[-1], tr.radius, color="k", alpha=0.8, zorder=3))
        ax.annotate(f"M{k}", q[0], ha="center", va="center", fontsize=7, color="k", zorder=4)
    if sim.tracks:
        key += [
            Patch(color="0.7", alpha=0.8, label="moving obstacle at t = 0"),
            Patch(color="k", alpha=0.8, label=f"... at the end (t = {t_end:.1f} s)"),
            Line2D([], [], ls=":", color=MOVING, lw=1.0, label="its track"),
        ]
    verdict = "goal reached" if sim.reached_goal else "goal NOT reached"
    ax.set_title(f"{problem.name}: {sim.strategy}, {verdict}, {sim.collisions} collisions")
    world_legend(ax, key, fontsize=7)
    _draw_separation(bx, sim, problem.units)
    fit_layout(fig)
    return fig


def _draw_separation(bx: Axes, sim: Any, units: str) -> None:
    """Panel (b) of :func:`plot_simulation`: the centre distance from the robot to each moving
    obstacle over time, its contact distance dashed, the replans grey."""
    traj = sim.trajectory
    for k, tr in enumerate(sim.tracks):
        if not len(traj):
            break
        d = np.hypot(*(traj[:, 1:3] - tr.position(traj[:, 0])).T)
        line = bx.plot(traj[:, 0], d, lw=1.3, label=f"M{k}")[0]
        bx.axhline(sim.contact_distance[k], color=line.get_color(), ls="--", lw=0.9)
    for rep in sim.replans:
        bx.axvline(rep.t, color="0.6", lw=0.8)
    bx.set_xlabel("t [s]")
    unit = f" [{units}]" if units else ""
    bx.set_ylabel(f"centre distance{unit}")
    bx.set_title("separation (dashed: contact SR + SO; grey: replans)")
    bx.grid(alpha=0.3)
    if sim.tracks:
        bx.legend(loc="best", fontsize=8)


def simulation_frames(
    problem: Problem, sim: Any, max_frames: int = 150
) -> tuple[Figure, Callable[[int], list[Any]], np.ndarray]:
    """The figure of :func:`animate_simulation`, with its legend beside the world.

    Returns
    -------
    fig : Figure
        The figure; each frame redraws its moving parts.
    draw : callable
        ``draw(i)`` moves everything to trajectory sample ``i``; returns the changed artists.
    frames : ndarray of int
        The trajectory samples shown, at most ``max_frames``, evenly spread.
    """
    traj = sim.trajectory
    if not len(traj):
        raise ValueError("nothing to animate: the simulation has no trajectory")
    frames = np.unique(np.linspace(0, len(traj) - 1, min(max_frames, len(traj))).astype(int))
    fig, ax = plt.subplots(figsize=(world_width(problem, 6.5), 6.5))
    key = draw_world(ax, problem, safety_zones=False)
    scene = _MovingScene(ax, problem, sim)
    world_legend(ax, key + scene.key())
    fit_layout(fig)
    return fig, scene.draw, frames


class _MovingScene:
    """What moves in :func:`simulation_frames`: the robot (its disc, heading and sensor range),
    its trace, the plan ahead, the predicted cross point, the detours, the moving obstacles and
    the title's clock."""

    def __init__(self, ax: Axes, problem: Problem, sim: Any) -> None:
        self.name, self.sim, self.r = problem.name, sim, problem.robot.radius
        self.sensor = CirclePatch((0, 0), problem.robot.sensor_range or 0.0, fill=False, ls=":",
                                  ec="tab:blue", lw=0.8, zorder=3)  # fmt: skip
        self.body = CirclePatch((0, 0), self.r, color=PATH_COLOUR, alpha=0.6, zorder=6)
        ax.add_patch(self.sensor)
        ax.add_patch(self.body)
        (self.heading,) = ax.plot([], [], "-", color="k", lw=1.2, zorder=7)
        (self.trace,) = ax.plot([], [], "-", color=PATH_COLOUR, lw=1.5, zorder=4,
                                label="driven path")  # fmt: skip
        (self.plan_line,) = ax.plot([], [], "--", color=RRT_COLOUR, lw=1.0, zorder=3,
                                    label="plan ahead")  # fmt: skip
        (self.cross,) = ax.plot([], [], "x", color="k", ms=9, zorder=7,
                                label="predicted cross point")  # fmt: skip
        self.obstacles = [CirclePatch((0, 0), tr.radius, color=MOVING, alpha=0.7, zorder=5)
                          for tr in sim.tracks]  # fmt: skip
        for patch in self.obstacles:
            ax.add_patch(patch)
        self.detours = [ax.plot([], [], "-", color=DETOUR, lw=1.3, zorder=5)[0]
                        for _ in sim.replans]  # fmt: skip
        # The longest title, so that the layout leaves room for every frame's.
        t_end = sim.trajectory[-1, 0]
        self.title = ax.set_title(f"{self.name}: t = {t_end:5.1f} s, replans {len(sim.replans)}")
        self.switch_times = np.array([t for t, _ in sim.plans])

    def key(self) -> list[Any]:
        """The legend handles of what moves (only what the animation will show)."""
        key = [
            (Patch(color=PATH_COLOUR, alpha=0.6, label="robot (line: heading)"),
             Line2D([], [], color="k", lw=1.2)),
            Line2D([], [], ls=":", color="tab:blue", lw=0.8, label="sensor range"),
            self.trace,
            self.plan_line,
        ]  # fmt: skip
        if self.sim.tracks:
            key.append(Patch(color=MOVING, alpha=0.7, label="moving obstacle"))
        if self.sim.replans:
            key += [self.cross, Line2D([], [], color=DETOUR, lw=1.3, label="detour")]
        return key

    def draw(self, i: int) -> list[Any]:
        """Move everything to trajectory sample ``i``; returns the changed artists."""
        sim, r = self.sim, self.r
        traj = sim.trajectory
        t, x, y, th = traj[i]
        self.body.center = self.sensor.center = (x, y)
        self.heading.set_data([x, x + r * np.cos(th)], [y, y + r * np.sin(th)])
        self.trace.set_data(traj[: i + 1, 1], traj[: i + 1, 2])
        plan = sim.plans[int(np.searchsorted(self.switch_times, t, side="right")) - 1][1]
        ahead = plan.waypoints_after(t)
        self.plan_line.set_data(ahead[:, 0], ahead[:, 1])
        live = [rep for rep in sim.replans if rep.t <= t <= rep.t_cross]
        if live:
            self.cross.set_data([live[-1].cross_point[0]], [live[-1].cross_point[1]])
        else:
            self.cross.set_data([], [])
        for line, rep in zip(self.detours, sim.replans, strict=True):
            if rep.detour is not None and rep.t <= t:
                line.set_data(*np.asarray(rep.detour).T)
            else:  # not planned yet at t (frames may be drawn in any order)
                line.set_data([], [])
        for patch, tr in zip(self.obstacles, sim.tracks, strict=True):
            patch.center = tuple(tr.position(t))
        replans = sum(rep.t <= t for rep in sim.replans)
        self.title.set_text(f"{self.name}: t = {t:5.1f} s, replans {replans}")
        return [self.body, self.sensor, self.heading, self.trace, self.plan_line, self.cross,
                self.title, *self.obstacles, *self.detours]  # fmt: skip


def frame_images(fig: Figure, draw: Callable[[int], list[Any]], frames: np.ndarray) -> list[Any]:
    """The frames of a one-panel figure as PIL images, each as ``fig.canvas.draw()`` would render
    it after ``draw(i)``, pixel for pixel, at a fraction of the cost.

    What lies below the lowest layer (``zorder``) that ``draw`` changes is drawn once and kept,
    and so is what lies beside the panel (the legend) where nothing that moves reaches: for each
    frame that picture is put back and the rest (what moves, and whatever static lies at or
    above it within the panel: the start and goal) is drawn over it in the order ``Axes.draw``
    uses (by ``zorder``, ties in the order added). Artists clipped to the panel stay inside it; a
    frame whose unclipped moving artist (the title) would reach what was kept is drawn whole.
    """
    from operator import attrgetter

    from PIL import Image

    canvas = fig.canvas
    (ax,) = fig.axes
    moving = draw(int(frames[0]))
    lowest = min(a.get_zorder() for a in moving)
    upper = sorted((a for a in ax.get_children() if a.get_zorder() >= lowest and a is not ax.patch),
                   key=attrgetter("zorder"))  # fmt: skip
    canvas.draw()  # places the titles (a hidden one would be placed elsewhere)
    renderer = canvas.get_renderer()
    panel = ax.bbox.padded(2)  # antialiased edges reach a pixel beyond an extent
    kept = [a for a in upper if not any(a is m for m in moving) and a.get_visible()
            and not a.get_window_extent(renderer).padded(2).overlaps(panel)]  # fmt: skip
    redrawn = [a for a in upper if not any(a is k for k in kept)]
    unclipped = [a for a in moving if not a.get_clip_on()]
    shown = [(a.get_visible(), a.get_position() if isinstance(a, Text) else None)
             for a in redrawn]  # fmt: skip
    for a in redrawn:
        a.set_visible(False)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    for a, (visible, position) in zip(redrawn, shown, strict=True):
        a.set_visible(visible)
        if position is not None:
            a.set_position(position)
    kept_extents = [a.get_window_extent(renderer).padded(2) for a in kept]
    images = []
    for i in frames:
        draw(int(i))
        reach = [a.get_window_extent(renderer).padded(2) for a in unclipped if a.get_visible()]
        if any(r.overlaps(k) for r in reach for k in kept_extents):
            canvas.draw()
        else:
            canvas.restore_region(background)
            for a in redrawn:
                if a.get_visible():
                    ax.draw_artist(a)
        images.append(Image.fromarray(np.asarray(canvas.buffer_rgba())[..., :3]))
    return images


def animate_simulation(
    problem: Problem, sim: Any, path: str | Path, *, max_frames: int = 150, fps: int = 10
) -> None:
    """Write a GIF of the simulation (:func:`simulation_frames`): static and moving obstacles,
    the robot and its sensor range, the plan it is driving, the predicted cross points and the
    detours, with a legend beside the world (atomically).

    Each frame is drawn once and grabbed from the canvas (matplotlib's animation writers draw a
    frame three times), and only from the lowest layer that moves up (:func:`frame_images`):
    what lies below it (a map, the static obstacles) is drawn once for all frames.
    """
    fig, draw, frames = simulation_frames(problem, sim, max_frames)
    try:
        fig.set_dpi(80)
        images = frame_images(fig, draw, frames)
        with atomic_path(path, suffix=".gif") as tmp:
            images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                           duration=int(1000 / fps), loop=0)  # fmt: skip
    finally:
        plt.close(fig)
