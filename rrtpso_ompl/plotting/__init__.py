"""Pictures: worlds, paths, profiles, benchmark curves and animations. The only package that
imports matplotlib.

One module per family of figures:

- :mod:`.styles`: the colours and sizes every figure shares (no matplotlib);
- :mod:`.canvas`: the Agg backend (files only) and :func:`save_figure` (atomic);
- :mod:`.world`: a world on axes (:func:`draw_world`, :func:`draw_map`, :func:`draw_costmap`,
  :func:`world_legend`): the primitives of every figure of a problem;
- :mod:`.paths`: a world and a path (:func:`plot_solution`, the paper's Fig. 15;
  :func:`plot_optimum`; :func:`plot_cost_reference`);
- :mod:`.profiles`: quantities along a path (:func:`plot_clearance_profile`;
  :func:`plot_velocities`, the paper's Figs. 17-18);
- :mod:`.bench`: benchmark summaries against the time budget (:func:`plot_bench`);
- :mod:`.simulation`: a simulation with moving obstacles (:func:`plot_simulation`, Fig. 24);
- :mod:`.animation`: the same as a GIF (:func:`animate_simulation`).

The names below are imported on first use (:mod:`rrtpso_ompl.lazy`): importing the package loads
no matplotlib; drawing a picture does.
"""

from ..lazy import export_lazily

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

#: Every public name of the package's modules (``__all__`` above lists the figures and the
#: drawing primitives; the colours, sizes and helpers are importable too, as before the split).
_EXPORTS = {
    **dict.fromkeys(
        ("COSTMAP", "COSTMAP_ALPHA", "DETOUR", "GOAL", "LEGEND_WIDTH", "MOVING", "OBSTACLE",
         "PATH_COLOUR", "RRT_COLOUR", "SAFETY", "START", "UNKNOWN_BLOCKED", "UNKNOWN_FREE"),
        ".styles",
    ),
    **dict.fromkeys(("fit_layout", "image_formats", "save_figure"), ".canvas"),
    **dict.fromkeys(
        ("COSTMAP_PIXELS", "draw_costmap", "draw_map", "draw_world", "world_legend",
         "world_width"),
        ".world",
    ),
    **dict.fromkeys(("plot_cost_reference", "plot_optimum", "plot_solution"), ".paths"),
    **dict.fromkeys(("PROFILE_SAMPLES", "plot_clearance_profile", "plot_velocities"), ".profiles"),
    **dict.fromkeys(("DODGE_PT", "EXCESS_FLOOR", "MARKERS", "plot_bench"), ".bench"),
    "plot_simulation": ".simulation",
    **dict.fromkeys(("animate_simulation", "frame_images", "simulation_frames"), ".animation"),
}  # fmt: skip

export_lazily(__name__, _EXPORTS)
