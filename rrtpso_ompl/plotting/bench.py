"""The benchmark figure: excess length over the optimum (or success rate) against the time
budget, one panel per problem, one line and marker per planner, on plainly labelled log axes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib import ticker
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.transforms import ScaledTranslation

from .canvas import plt

__all__ = ["DODGE_PT", "EXCESS_FLOOR", "MARKERS", "plot_bench"]

#: One marker per planner in the benchmark figures (with its colour, so that planners whose
#: lines coincide stay apart).
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h")


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
