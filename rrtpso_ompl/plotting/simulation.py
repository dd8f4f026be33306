"""The figure of a simulation with moving obstacles (the paper's Fig. 24): the world, the static
and the driven path with its detours and the moving obstacles' tracks, beside the centre
distance to each moving obstacle over time.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch

from ..model.problem_types import Problem
from .canvas import fit_layout, plt
from .styles import DETOUR, MOVING, PATH_COLOUR, RRT_COLOUR
from .world import draw_world, world_legend, world_width

__all__ = ["plot_simulation"]


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
