"""Where figures are drawn and how they are saved: matplotlib's non-interactive Agg backend
(files only: never a window, on CI, over SSH, in batch workers), and :func:`save_figure`, which
writes through a temporary file (:func:`rrtpso_ompl.outputs.atomic_path`), so a failed or
interrupted plot never leaves half an image behind.

Every module of the package that draws imports this one first (``plt`` from here), so the
backend is chosen before anything is drawn.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; never open a window (CI, SSH, batch workers)

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from ..outputs import atomic_path

__all__ = ["fit_layout", "image_formats", "plt", "save_figure"]


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
