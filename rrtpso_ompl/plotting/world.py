"""A world drawn on axes: the primitives of every figure of a problem.

:func:`draw_world` draws the obstacles, their safety zones (the obstacles grown by the robot
radius), the bounds, start and goal, and the occupancy map under them (:func:`draw_map`);
:func:`draw_costmap` shades the inflation cost over it; :func:`world_legend` puts the key beside
the world (hiding nothing) and :func:`world_width` sizes a panel for both. Drawing only: the
checks use exact distances, never these outlines.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import shapely
from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch, Rectangle
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.transforms import Affine2D

from ..model.problem_types import Circle, Polygon, Problem
from . import canvas  # noqa: F401 - chooses the Agg backend before anything is drawn
from .styles import (
    COSTMAP,
    COSTMAP_ALPHA,
    GOAL,
    LEGEND_WIDTH,
    OBSTACLE,
    SAFETY,
    START,
    UNKNOWN_BLOCKED,
    UNKNOWN_FREE,
)

__all__ = [
    "COSTMAP_PIXELS",
    "draw_costmap",
    "draw_map",
    "draw_world",
    "world_legend",
    "world_width",
]

#: Most pixels along the longer side of the costmap's raster (one clearance query per pixel).
COSTMAP_PIXELS = 400


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
    from ..model.world import World

    cost = problem.objective
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
