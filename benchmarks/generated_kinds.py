"""``docs/img/generated-kinds.png``: one problem of each kind ``rrtpso generate`` gained in issue
25 (the occupancy-grid map kinds and the shape kinds), as ``rrtpso generate`` writes it and
``rrtpso solve`` reads it.

Each panel is the problem file read back with ``load_problem`` (the map from beside it), drawn
with the project's world drawing, titled with the kind and the command's options; axes in metres.

Usage::

    python benchmarks/generated_kinds.py            # writes docs/img/generated-kinds.png
    python benchmarks/generated_kinds.py --out FILE.png
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from rrtpso_ompl.groundtruth.generate import GENERATORS, KINDS, generate_to_file
from rrtpso_ompl.model import load_problem
from rrtpso_ompl.plotting import draw_world, save_figure

REPO = Path(__file__).resolve().parent.parent
OUT = REPO / "docs" / "img" / "generated-kinds.png"
#: Seed of every panel.
SEED = 1
#: Options per kind (the defaults otherwise): maps of 128 cells.
OPTIONS: dict[str, dict] = {}


def new_kinds() -> list[str]:
    """The kinds added after the first three (circles, polygons, maze), in registration order."""
    return [k for k in GENERATORS if k not in KINDS]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    kinds = new_kinds()
    cols = min(len(kinds), 5)
    rows = math.ceil(len(kinds) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.9 * rows), squeeze=False)
    with tempfile.TemporaryDirectory() as tmp:
        for ax, kind in zip(axes.flat, kinds, strict=False):
            options = OPTIONS.get(kind, {})
            path = generate_to_file(kind, SEED, Path(tmp) / f"{kind}.yaml", **options)
            problem = load_problem(path)
            draw_world(ax, problem)
            words = " ".join(f"--{k} {v}" for k, v in options.items())
            ax.set_title(f"{kind} --seed {SEED} {words}".strip(), fontsize=9)
            ax.tick_params(labelsize=7)
            ax.xaxis.label.set_size(8)
            ax.yaxis.label.set_size(8)
    for ax in axes.flat[len(kinds) :]:
        ax.set_visible(False)
    fig.suptitle("rrtpso generate: one problem of each new kind (start: green dot, goal: star)",
                 fontsize=11)  # fmt: skip
    fig.tight_layout()
    save_figure(fig, args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
