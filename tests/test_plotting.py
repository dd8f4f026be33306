"""The pictures: legends hide nothing and explain the symbols, axes have units, benchmark figures
stay readable (issue 22, item 13). Real problems, real planners, real simulations; overlaps are
measured in display coordinates with matplotlib's window extents."""

from __future__ import annotations

import re

import numpy as np
import pytest
import shapely
from helpers import PROBLEMS, SINGLE_CIRCLE, turned_copy

from rrtpso_ompl import World, load_problem, problem_from_dict, solve
from rrtpso_ompl.harness.bench import SummaryRow
from rrtpso_ompl.plotting import (  # the Agg backend: files only
    plot_bench,
    plot_optimum,
    plot_simulation,
    plot_solution,
    save_figure,
)


def _close(fig):
    import matplotlib.pyplot as plt

    plt.close(fig)


def assert_legend_hides_nothing(fig, ax):
    """The world's legend overlaps none of the world's artists (start and goal markers, obstacles,
    safety zones, map, paths), nor the world's panel, nor another panel, and lies within the
    figure (not cut off)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legend = ax.get_legend()
    assert legend is not None
    box = legend.get_window_extent(renderer)
    artists = [*ax.lines, *ax.patches, *ax.images, *ax.texts]
    assert len(artists) >= 4
    hidden = [a for a in artists
              if _drawn(a) and _overlap(box, a.get_window_extent(renderer), a, ax)]  # fmt: skip
    assert not hidden, hidden[:5]
    for collection in ax.collections:  # every obstacle and safety zone, one by one
        lo, hi = _extents(collection)
        assert len(lo)
        if collection.get_clip_on():  # drawn only inside the axes
            lo = np.maximum(lo, ax.bbox.min)
            hi = np.minimum(hi, ax.bbox.max)
        # Bbox.overlaps: strictly inside on both axes (an extent clipped away is never inside).
        under = np.all((lo < box.max) & (box.min < hi) & (lo <= hi), axis=1)
        assert not under.any(), f"{int(under.sum())} obstacles under the legend"
    assert not box.overlaps(ax.get_window_extent(renderer))  # the whole world panel
    for other in fig.axes:
        if other is not ax:
            assert not box.overlaps(other.get_tightbbox(renderer))
    assert fig.bbox.contains(box.x0, box.y0) and fig.bbox.contains(box.x1, box.y1)


def _overlap(box, extent, artist, ax) -> bool:
    """Whether ``extent`` (display coordinates) overlaps ``box`` where the artist is drawn: an
    artist clipped to the axes (a safety zone of a wall on the border) only inside them."""
    from matplotlib.transforms import Bbox

    if artist.get_clip_on():
        extent = Bbox.intersection(extent, ax.bbox)
        if extent is None:
            return False
    return box.overlaps(extent)


def _extents(collection) -> tuple[np.ndarray, np.ndarray]:
    """The display extents of a collection's paths, ``(lo, hi)`` of shape ``(n, 2)``, all at
    once: the bounds of each path's vertices, end-of-polygon markers left out. For the straight
    edges and the circle arcs of the world's shapes (Bezier control points within the circle's
    box) these are ``path.get_extents``, 20,000 of which took seconds one by one."""
    from matplotlib.path import Path as MplPath

    paths = collection.get_paths()
    if not paths:
        return np.empty((0, 2)), np.empty((0, 2))
    where = collection.get_transform()
    kept, sizes = [], []
    for path in paths:
        v = path.vertices
        if path.codes is not None:
            v = v[path.codes != MplPath.CLOSEPOLY]
        kept.append(v)
        sizes.append(len(v))
    xy = where.transform(np.concatenate(kept))
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    return np.minimum.reduceat(xy, starts), np.maximum.reduceat(xy, starts)


def _drawn(artist) -> bool:
    if hasattr(artist, "get_xydata") and not len(artist.get_xydata()):
        return False  # an empty line (a GIF's trace before it starts)
    return artist.get_visible()


def legend_labels(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


# ----------------------------------------------------------------------------------------------
# Worlds
# ----------------------------------------------------------------------------------------------
@pytest.mark.slow  # seconds of work: the full run only
def test_the_legend_of_a_10000_circle_world_hides_nothing_and_explains_the_symbols():
    from rrtpso_ompl.groundtruth.generate import generate

    problem = problem_from_dict(generate("circles", seed=7, n=10000))
    result = solve(problem, "RRTstarPSO", time_limit=0.5, seed=1)
    fig = plot_solution(problem, result)
    try:
        ax = fig.axes[0]
        assert_legend_hides_nothing(fig, ax)
        labels = " | ".join(legend_labels(ax))
        for words in ("start (circle: the robot)", "goal", "obstacle", "safety zone"):
            assert words in labels, labels
    finally:
        _close(fig)


def test_the_legend_check_sees_one_obstacle_under_a_legend():
    """The check itself (its extents are computed all at once): a legend over the middle of a
    world whose only obstacle lies there is caught."""
    import matplotlib.pyplot as plt

    from rrtpso_ompl.plotting import draw_world

    problem = problem_from_dict({**SINGLE_CIRCLE, "start": [20, 480], "goal": [480, 480]})
    fig, ax = plt.subplots()
    try:
        key = draw_world(ax, problem)
        handles = [h[0] if isinstance(h, tuple) else h for h in key]
        ax.legend(handles, [h.get_label() for h in handles], loc="center")
        for line in ax.lines:  # the bounds' frame runs under it too: the obstacles are the point
            line.set_visible(False)
        with pytest.raises(AssertionError, match="1 obstacles under the legend"):
            assert_legend_hides_nothing(fig, ax)
    finally:
        _close(fig)


def test_the_legend_of_the_warehouse_map_hides_no_rack_and_explains_unknown_space():
    problem = load_problem(PROBLEMS / "maps" / "warehouse_aisles.yaml")
    result = solve(problem, "RRTstarPSO", time_limit=0.5, seed=1)
    fig = plot_solution(problem, result)
    try:
        ax = fig.axes[0]
        assert_legend_hides_nothing(fig, ax)
        labels = " | ".join(legend_labels(ax))
        for words in ("occupied cells", "unknown space (blocked)", "clearance zone", "start"):
            assert words in labels, labels
    finally:
        _close(fig)


def test_a_narrow_world_alone_in_its_figure_keeps_its_legend_inside():
    """The warehouse (50 x 85 m) drawn without a second panel (a planner without a swarm, or an
    unsolved run): its equal-aspect panel used to shrink towards its centre and push the legend
    past the figure's right edge."""
    problem = load_problem(PROBLEMS / "maps" / "warehouse_aisles.yaml")
    result = solve(problem, "BITstar", time_limit=0.3, seed=1)
    fig = plot_solution(problem, result)
    try:
        assert len(fig.axes) == 1
        assert_legend_hides_nothing(fig, fig.axes[0])
    finally:
        _close(fig)


def test_a_turned_map_is_drawn_turned_about_its_origin(tmp_path):
    """The image lands on the map's turned rectangle; a blocked cell's centre, a free point and
    the unknown corner beyond the map are painted in their colours (read back from the rendered
    pixels)."""
    from matplotlib.colors import to_rgb

    from rrtpso_ompl.plotting import OBSTACLE, UNKNOWN_BLOCKED

    path, move = turned_copy(tmp_path, "office_corridor", 0.3, pivot=(2.0, -1.0))
    problem = load_problem(path)
    m = problem.map
    result = solve(problem, "RRTstarPSO", time_limit=0.3, seed=1)
    fig = plot_solution(problem, result)
    try:
        ax = fig.axes[0]
        assert_legend_hides_nothing(fig, ax)
        assert "unknown space (blocked)" in legend_labels(ax)
        (image,) = ax.images
        x0, x1, y0, y1 = image.get_extent()
        corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
        on_data = (image.get_transform() - ax.transData).transform(corners)
        np.testing.assert_allclose(on_data, m.corners, atol=1e-9)
        # An occupied cell amid occupied ones (a desk's), a point in the corridor far from
        # every blocked cell, and the middle of an unknown corner beyond the map.
        occupied = m.state == 1
        inner = occupied[1:-1, 1:-1].copy()
        for di, dj in ((-1, 0), (1, 0), (0, -1), (0, 1), (-2, 0), (2, 0)):
            inner &= np.roll(occupied, (di, dj), axis=(0, 1))[1:-1, 1:-1]
        row, col = np.argwhere(inner)[len(np.argwhere(inner)) // 2] + 1
        blocked = m.cell_centre(row, col)
        free = move([12.0, 10.0])  # the corridor of the unturned map
        assert World.from_problem(problem).point_clearance(free[None])[0] > 1.0
        corner = shapely.Polygon(problem.map_outside[0].points).centroid
        for line in ax.lines:  # the paths (their route depends on the run) off the pixels read
            line.set_visible(False)
        fig.canvas.draw()
        pixels = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255.0
        height = pixels.shape[0]
        for point, colour in ((blocked, OBSTACLE), (free, "white"),
                              ((corner.x, corner.y), UNKNOWN_BLOCKED)):  # fmt: skip
            px, py = ax.transData.transform(point)
            got = pixels[height - 1 - round(py), round(px)]
            np.testing.assert_allclose(got, to_rgb(colour), atol=0.02)
        save_figure(fig, tmp_path / "turned.png")
    finally:
        _close(fig)


def test_the_best_cost_axis_has_a_unit():
    problem = load_problem(PROBLEMS / "static" / "paper_static.yaml")
    result = solve(problem, "RRTstarPSO", time_limit=0.5, seed=1)
    assert result.stages["pso_history"]
    fig = plot_solution(problem, result)
    try:
        assert_legend_hides_nothing(fig, fig.axes[0])
        assert fig.axes[1].get_ylabel().endswith("[cm]")
    finally:
        _close(fig)


def test_the_optimum_legend_hides_nothing():
    from rrtpso_ompl.groundtruth import shortest_path

    problem = load_problem(PROBLEMS / "static" / "maze.yaml")
    fig = plot_optimum(problem, shortest_path(problem))
    try:
        assert_legend_hides_nothing(fig, fig.axes[0])
    finally:
        _close(fig)


# ----------------------------------------------------------------------------------------------
# Clearance: the costmap under the path, the clearance profile
# ----------------------------------------------------------------------------------------------
#: A wall across x = 5 with a door 0.8 m wide at y = 5; the robot's inflation reaches 1 m.
DOOR = {
    "name": "door",
    "units": "m",
    "bounds": [[0, 0], [10, 10]],
    "start": [1, 2],
    "goal": [9, 2],
    "robot": {"radius": 0.2, "inflation_radius": 1.0},
    "obstacles": [
        {"type": "rectangle", "min": [4.9, -1], "max": [5.1, 4.6]},
        {"type": "rectangle", "min": [4.9, 5.4], "max": [5.1, 11]},
    ],
}


def test_the_costmap_is_shaded_under_the_path_only_with_inflation():
    from rrtpso_ompl.plotting import COSTMAP_ALPHA, COSTMAP_PIXELS

    problem = problem_from_dict(DOOR)
    result = solve(problem, "RRTstarPSO", time_limit=0.3, seed=1)
    fig = plot_solution(problem, result)
    try:
        ax = fig.axes[0]
        assert_legend_hides_nothing(fig, ax)
        assert any("inflation cost" in label for label in legend_labels(ax))
        (image,) = ax.get_images()
        rgba = np.asarray(image.get_array())
        assert max(rgba.shape[:2]) <= COSTMAP_PIXELS
        # Opaque next to the wall, clear far from it (the image's columns span the x limits).
        x0, x1 = ax.get_xlim()
        column = rgba[:, [int((x - x0) / (x1 - x0) * rgba.shape[1]) for x in (5.2, 2.0)], 3]
        assert column[:, 0].max() == pytest.approx(COSTMAP_ALPHA, rel=0.05)
        assert column[:, 1].max() == 0.0
        assert image.get_zorder() < 1  # under the safety zones, the obstacles and the paths
    finally:
        _close(fig)
    plain = problem_from_dict({**DOOR, "robot": {"radius": 0.2}})
    fig = plot_solution(plain, solve(plain, "RRTstarPSO", time_limit=0.2, seed=1))
    try:
        assert not fig.axes[0].get_images()
        assert not any("inflation" in label for label in legend_labels(fig.axes[0]))
    finally:
        _close(fig)


def test_the_clearance_profile_draws_each_path_and_both_radii_with_units():
    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.groundtruth.costgrid import cost_reference
    from rrtpso_ompl.model import World
    from rrtpso_ompl.plotting import plot_clearance_profile

    problem = problem_from_dict(DOOR)
    world = World.from_problem(problem)
    exact = shortest_path(problem, world).valid_polyline(world)
    ref = cost_reference(problem, world, resolution=0.1).path
    fig = plot_clearance_profile(problem, {"shortest": exact, "reference": ref}, world)
    try:
        ax = fig.axes[0]
        fig.canvas.draw()
        box = ax.get_legend().get_window_extent(fig.canvas.get_renderer())
        assert not box.overlaps(ax.get_window_extent(fig.canvas.get_renderer()))
        assert fig.bbox.contains(box.x0, box.y0) and fig.bbox.contains(box.x1, box.y1)
        assert ax.get_xlabel() == "arc length along the path [m]"
        assert ax.get_ylabel() == "clearance [m]"
        lines = {line.get_label(): line for line in ax.get_lines()}
        shortest = next(v for k, v in lines.items() if k.startswith("shortest ("))
        reference = next(v for k, v in lines.items() if k.startswith("reference ("))
        # The shortest path brushes the door's frames at the radius; the reference keeps to the
        # door's middle, 0.4 m from both frames.
        assert shortest.get_ydata().min() == pytest.approx(0.2, abs=1e-3)
        assert reference.get_ydata().min() == pytest.approx(0.4, abs=0.06)
        assert shortest.get_xdata()[-1] == pytest.approx(np.hypot(*np.diff(exact, axis=0).T).sum())
        flat = {k: v.get_ydata() for k, v in lines.items() if k.startswith(("robot", "inflation"))}
        assert [float(np.unique(v)[0]) for v in flat.values()] == [0.2, 1.0]
        assert "within R_i" in shortest.get_label() and "J " in shortest.get_label()
    finally:
        _close(fig)


def test_the_cost_reference_legend_hides_nothing():
    from rrtpso_ompl.groundtruth.costgrid import cost_reference
    from rrtpso_ompl.plotting import plot_cost_reference

    problem = problem_from_dict(DOOR)
    fig = plot_cost_reference(problem, cost_reference(problem, resolution=0.1))
    try:
        assert_legend_hides_nothing(fig, fig.axes[0])
        assert any(label.startswith("grid reference (J ") for label in legend_labels(fig.axes[0]))
    finally:
        _close(fig)


# ----------------------------------------------------------------------------------------------
# Simulations
# ----------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def simulated():
    """The paper's dynamic scenario from the exact shortest path (the same on every machine: a
    static path planned for a time budget is not, and on another path the obstacle may never
    cross the robot's), with a replanning budget two orders of magnitude above what a detour
    takes (the corridor stage finds one in milliseconds)."""
    from rrtpso_ompl.dynamic import DynamicOptions, simulate

    problem = load_problem(PROBLEMS / "dynamic" / "paper_dynamic.yaml")
    static = np.array(solve(problem, "Exact", time_limit=60.0).path)
    sim = simulate(problem, DynamicOptions(replan_time=0.5), seed=1, initial_path=static)
    return problem, sim


def test_the_simulation_plot_legend_hides_no_obstacle(simulated):
    problem, sim = simulated
    assert sim.replans  # the detour and the cross point are in the picture
    fig = plot_simulation(problem, sim)
    try:
        ax = fig.axes[0]
        assert_legend_hides_nothing(fig, ax)
        labels = " | ".join(legend_labels(ax))
        for words in ("detours", "predicted cross point", "moving obstacle", "safety zone"):
            assert words in labels, labels
    finally:
        _close(fig)


def test_gif_frames_are_drawn_as_the_whole_figure_would_be(simulated):
    """``frame_images`` keeps what does not move and redraws the rest: each frame is, pixel for
    pixel, what drawing the whole figure gives."""
    from rrtpso_ompl.plotting import frame_images, simulation_frames

    problem, sim = simulated
    fig, draw, frames = simulation_frames(problem, sim, max_frames=6)
    try:
        fig.set_dpi(40)
        fast = [np.asarray(image) for image in frame_images(fig, draw, frames)]
        for i, image in zip(frames, fast, strict=True):
            draw(int(i))
            fig.canvas.draw()
            whole = np.asarray(fig.canvas.buffer_rgba())[..., :3]
            assert np.array_equal(image, whole), int(i)
    finally:
        _close(fig)


def test_every_gif_frame_has_a_legend_that_hides_nothing(simulated, tmp_path):
    from PIL import Image

    from rrtpso_ompl.plotting import animate_simulation, simulation_frames

    problem, sim = simulated
    fig, draw, frames = simulation_frames(problem, sim, max_frames=30)
    try:
        ax = fig.axes[0]
        for i in (frames[0], frames[len(frames) // 2], frames[-1]):
            draw(int(i))
            assert_legend_hides_nothing(fig, ax)
        labels = " | ".join(legend_labels(ax))
        for words in (
            "robot",
            "sensor range",
            "moving obstacle",
            "plan ahead",
            "detour",
            "goal",
            "predicted cross point",
        ):
            assert words in labels, labels
    finally:
        _close(fig)
    out = tmp_path / "run.gif"
    calls = []
    animate_simulation(problem, sim, out, max_frames=12,
                       progress=lambda done, total: calls.append((done, total)))  # fmt: skip
    # The progress covers every frame and then the file (issue 36: no bar stuck at 90 %).
    assert calls == [(k, 13) for k in range(1, 14)]
    with Image.open(out) as gif:
        assert gif.n_frames == 12
        assert gif.size[0] > gif.size[1] * 1.2  # the world and its legend beside it


# ----------------------------------------------------------------------------------------------
# Benchmarks
# ----------------------------------------------------------------------------------------------
def _row(problem, planner, budget, success=1.0, ratio=None):
    q = None if ratio is None else (ratio - 1e-4, ratio + 1e-4)
    return SummaryRow(problem=problem, budget=budget, planner=planner, runs=10,
                      solved=int(10 * success), success=success, optimum=100.0,
                      median_length=None if ratio is None else 100 * ratio, median_ratio=ratio,
                      q1_ratio=q and q[0], q3_ratio=q and q[1], best_ratio=ratio,
                      median_raw_ratio=ratio, median_time=budget)  # fmt: skip


def _tick_texts(ax) -> list[str]:
    lo, hi = ax.get_ylim()
    ticks = [*ax.yaxis.get_major_ticks(), *ax.yaxis.get_minor_ticks()]
    return [t.label1.get_text() for t in ticks
            if t.label1.get_text() and lo <= t.get_loc() <= hi]  # fmt: skip


@pytest.mark.parametrize(
    "ratios",
    [(1.0895, 1.0897, 1.0899), (1.0001, 1.01, 1.3), (1.00002, 1.5, 3.0), (1.084, 1.09, 1.115)],
    ids=["within-a-tenth-of-a-percent", "two-decades", "five-decades", "8-to-12-percent"],
)
def test_ratio_axis_labels_are_plain_numbers(ratios):
    summary = [_row("p", pl, b, ratio=r) for pl, r in zip(("A", "B", "C"), ratios, strict=True)
               for b in (0.25, 1.0, 4.0)]  # fmt: skip
    summary.append(_row("p", "Never", 1.0, success=0.0))
    fig = plot_bench(summary, "ratio")
    try:
        fig.canvas.draw()
        ax = fig.axes[0]
        texts = _tick_texts(ax)
        assert len(texts) >= 2, texts
        for text in texts:
            assert re.fullmatch(r"\d+(\.\d+)?", text), texts  # no 10^0, no x, no mathtext
        assert "%" in ax.get_ylabel() and "[s]" in ax.get_xlabel()
        # every planner is in the key, also one that no panel could draw
        assert [t.get_text() for t in fig.legends[0].get_texts()] == ["A", "B", "C", "Never"]
    finally:
        _close(fig)


def test_success_markers_of_planners_at_100_percent_are_distinguishable():
    planners = ["RRTstarPSO", "RRTstar", "InformedRRTstar", "BITstar", "RRTConnect"]
    summary = [_row(p, pl, b) for p in ("p1", "p2") for pl in planners for b in (0.25, 1.0, 4.0)]
    fig = plot_bench(summary, "success")
    try:
        fig.canvas.draw()
        ax = fig.axes[0]
        lines = [line for line in ax.lines if line.get_label() in planners]
        assert len(lines) == len(planners)
        assert len({line.get_marker() for line in lines}) == len(planners)
        px = {line.get_label(): line.get_transform().transform(line.get_xydata())
              for line in lines}  # fmt: skip
        size = max(line.get_markersize() for line in lines) * fig.dpi / 72  # pixels
        for k in range(3):  # each budget: the markers stand apart, inside the panel
            xs = sorted(p[k, 0] for p in px.values())
            assert min(np.diff(xs)) >= size, xs
            box = ax.get_window_extent()
            assert all(box.x0 < x < box.x1 for x in xs)
    finally:
        _close(fig)


def test_bench_figures_are_written(tmp_path):
    summary = [_row("p", pl, b, ratio=1.01) for pl in ("A", "B") for b in (0.5, 2.0)]
    for what in ("ratio", "success"):
        save_figure(plot_bench(summary, what), tmp_path / f"{what}.png")
        assert (tmp_path / f"{what}.png").stat().st_size > 1000


# ----------------------------------------------------------------------------------------------
# Each stage credited with what it gave (issue 36, item 2)
# ----------------------------------------------------------------------------------------------
def _result_with(stages: dict, path=None):
    import dataclasses

    problem = problem_from_dict(SINGLE_CIRCLE)
    base = solve(problem, "RRTstarPSO", time_limit=60.0, seed=1,
                 params={"rrt_max_iterations": 200, "iterations": 10})  # fmt: skip
    return problem, dataclasses.replace(base, stages={**base.stages, **stages})


@pytest.mark.parametrize(
    ("stages", "label", "absent"),
    [
        ({"rrt_path": [[20, 20], [100, 100]], "rrt_length": 113.1},
         "RRT*'s best, short of the goal", "RRT* path ("),
        ({"rrt_path": [], "rrt_length": None}, "no RRT* path", "RRT* path ("),
    ],
)  # fmt: skip
def test_rrt_star_is_credited_only_with_a_path_that_reached_the_goal(stages, label, absent):
    problem, result = _result_with(stages)
    fig = plot_solution(problem, result)
    try:
        labels = legend_labels(fig.axes[0])
        assert label in labels and not any(absent in t for t in labels)
    finally:
        _close(fig)


def test_the_swarm_s_seed_from_the_corridor_is_drawn_and_its_gain_is_the_swarm_s_own():
    problem, result = _result_with({"seed_source": "corridor", "seed_length": 700.0,
                                    "seed_cost": 700.0,
                                    "seed_path": [[20, 20], [300, 100], [450, 450]]})  # fmt: skip
    fig = plot_solution(problem, result)
    try:
        labels = " | ".join(legend_labels(fig.axes[0]))
        assert "corridor route (" in labels and "the swarm's seed" in labels
        panel = fig.axes[1]
        assert panel.get_title().startswith("PSO best cost per iteration\n700 -> ")
        assert panel.yaxis.get_major_formatter().get_useOffset() is False  # no "+9.47e1"
    finally:
        _close(fig)


def test_no_swarm_panel_without_a_swarm_to_show():
    problem, result = _result_with({"pso_history": [647.5]})
    fig = plot_solution(problem, result)
    try:
        assert len(fig.axes) == 1
    finally:
        _close(fig)
