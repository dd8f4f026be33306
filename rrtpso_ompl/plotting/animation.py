"""A simulation as an animated GIF (the paper's Fig. 23 in motion): the figure and its moving
parts (:func:`simulation_frames`), its frames rendered fast from a kept background
(:func:`frame_images`), written atomically (:func:`animate_simulation`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch
from matplotlib.text import Text

from ..model.problem_types import Problem
from ..outputs import atomic_path
from .canvas import fit_layout, plt
from .styles import DETOUR, MOVING, PATH_COLOUR, RRT_COLOUR
from .world import draw_world, world_legend, world_width

__all__ = ["animate_simulation", "frame_images", "simulation_frames"]


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


def frame_images(fig: Figure, draw: Callable[[int], list[Any]], frames: np.ndarray,
                 progress: Callable[[int, int], None] | None = None) -> list[Any]:  # fmt: skip
    """The frames of a one-panel figure as PIL images, each as ``fig.canvas.draw()`` would render
    it after ``draw(i)``, pixel for pixel, at a fraction of the cost.

    What lies below the lowest layer (``zorder``) that ``draw`` changes is drawn once and kept,
    and so is what lies beside the panel (the legend) where nothing that moves reaches: for each
    frame that picture is put back and the rest (what moves, and whatever static lies at or
    above it within the panel: the start and goal) is drawn over it in the order ``Axes.draw``
    uses (by ``zorder``, ties in the order added). Artists clipped to the panel stay inside it; a
    frame whose unclipped moving artist (the title) would reach what was kept is drawn whole.
    ``progress(done, total)`` is called after each frame.
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
        if progress is not None:
            progress(len(images), len(frames))
    return images


def animate_simulation(
    problem: Problem,
    sim: Any,
    path: str | Path,
    *,
    max_frames: int = 150,
    fps: int = 10,
    progress: Callable[[int, int], None] | None = None,
) -> None:
    """Write a GIF of the simulation (:func:`simulation_frames`): static and moving obstacles,
    the robot and its sensor range, the plan it is driving, the predicted cross points and the
    detours, with a legend beside the world (atomically).

    Each frame is drawn once and grabbed from the canvas (matplotlib's animation writers draw a
    frame three times), and only from the lowest layer that moves up (:func:`frame_images`):
    what lies below it (a map, the static obstacles) is drawn once for all frames.
    ``progress(done, total)`` is called after each frame is drawn and once the file is written
    (``total + 1`` steps: encoding the GIF takes about as long as a tenth of the frames).
    """
    fig, draw, frames = simulation_frames(problem, sim, max_frames)
    try:
        fig.set_dpi(80)
        steps = len(frames) + 1

        def drawn(done: int, _total: int) -> None:
            if progress is not None:
                progress(done, steps)

        images = frame_images(fig, draw, frames, drawn)
        with atomic_path(path, suffix=".gif") as tmp:
            images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:],
                           duration=int(1000 / fps), loop=0)  # fmt: skip
        drawn(steps, steps)
    finally:
        plt.close(fig)
