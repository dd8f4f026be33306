"""The pictures of README.md and docs/, redrawn with the commands the docs quote.

- ``docs/img/paper_static.png``: the README's first command, ``rrtpso solve
  problems/static/paper_static.yaml --plot ...``;
- ``docs/img/paper_dynamic.png`` and ``.gif``: docs/dynamic.md's ``rrtpso simulate
  problems/dynamic/paper_dynamic.yaml --plot ... --gif ...``;
- ``docs/img/optimum_maze.png``: ``rrtpso optimum problems/static/maze.yaml --plot ...``;
- ``docs/img/corridor_choice.png``: RRTstarPSO and BIT* with OMPL's simplifier at 0.25 s on
  report-set maps of ``benchmarks/families.py`` (``rrtpso generate rooms_map`` and ``maze_map``,
  seed 101), each run a ``rrtpso solve`` of its own, lengths over the exact optimum;
- ``docs/img/bench_ratio.png`` and ``bench_success.png``: the figures ``rrtpso bench`` draws,
  from the committed summary of the measured benchmark (``docs/bench/report.csv``; its runs are
  not committed, docs/benchmarking.md "Reproduce" reruns them).

Usage::

    python benchmarks/doc_figures.py            # all of them (about a minute on 2 cores)
    python benchmarks/doc_figures.py bench      # only the two benchmark figures
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
IMG = REPO / "docs" / "img"

#: Each figure: the rrtpso command the docs quote, and where its outputs go.
COMMANDS = {
    "paper_static": (
        ["solve", "problems/static/paper_static.yaml", "--plot", "{tmp}/path.png"],
        {"path.png": "paper_static.png"},
    ),
    "paper_dynamic": (
        ["simulate", "problems/dynamic/paper_dynamic.yaml", "--plot", "{tmp}/run.png", "--gif",
         "{tmp}/run.gif"],
        {"run.png": "paper_dynamic.png", "run.gif": "paper_dynamic.gif"},
    ),
    "optimum_maze": (
        ["optimum", "problems/static/maze.yaml", "--plot", "{tmp}/opt.png"],
        {"opt.png": "optimum_maze.png"},
    ),
}  # fmt: skip


def rrtpso() -> list[str]:
    """The ``rrtpso`` of this Python (the venv's console script, else ``python -m``)."""
    exe = shutil.which("rrtpso", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "rrtpso_ompl"]


def command_figure(name: str) -> None:
    args, outputs = COMMANDS[name]
    with tempfile.TemporaryDirectory() as tmp:
        given = [a.format(tmp=tmp) for a in args]
        print("$ rrtpso", " ".join(given).replace(tmp, "."))
        cmd = [*rrtpso(), *given, "-q"]
        subprocess.run(cmd, cwd=REPO, check=True)
        for made, target in outputs.items():
            shutil.copyfile(Path(tmp) / made, IMG / target)
            print("  ->", (IMG / target).relative_to(REPO))


def bench_figures() -> None:
    from rrtpso_ompl.harness.bench import read_report_csv
    from rrtpso_ompl.plotting import plot_bench, save_figure

    summary = read_report_csv(REPO / "docs" / "bench" / "report.csv")
    for what in ("ratio", "success"):
        save_figure(plot_bench(summary, what), IMG / f"bench_{what}.png")
        print("  ->", f"docs/img/bench_{what}.png")


#: The corridor figure's maps: kind, options (as benchmarks/families.py poses them), title.
CORRIDOR_MAPS = (
    ("rooms_map", {"cells": 128}, "rooms_map (robot: a quarter cell)"),
    ("maze_map", {"cells": 128, "corridor": 2, "loops": 0.1, "robot_radius": 0},
     "maze_map, 2-cell corridors (point robot)"),
)  # fmt: skip


def corridor_figure(budget: float = 0.25, seed: int = 101) -> None:
    """RRTstarPSO and BITstar+simplify on report-set maps, each length over the exact optimum."""
    import json

    import matplotlib.pyplot as plt
    import numpy as np

    from rrtpso_ompl.groundtruth import shortest_path
    from rrtpso_ompl.groundtruth.generate import generate_to_file
    from rrtpso_ompl.model import World, load_problem
    from rrtpso_ompl.plotting import draw_world, save_figure, world_legend

    fig, axes = plt.subplots(1, len(CORRIDOR_MAPS), figsize=(6.5 * len(CORRIDOR_MAPS), 5.6))
    with tempfile.TemporaryDirectory() as tmp:
        for ax, (kind, options, title) in zip(axes, CORRIDOR_MAPS, strict=True):
            path = generate_to_file(kind, seed, Path(tmp) / f"{kind}.yaml", **options)
            problem = load_problem(path)
            best = shortest_path(problem, World.from_problem(problem))
            key = draw_world(ax, problem, safety_zones=False)
            for planner, colour in (("BITstar+simplify", "tab:blue"), ("RRTstarPSO", "tab:red")):
                out = Path(tmp) / f"{kind}_{planner}.json"
                done = subprocess.run([*rrtpso(), "solve", str(path), "--planner", planner,
                                       "--time", str(budget), "--seed", "1", "--json", str(out),
                                       "-q"], check=False)  # fmt: skip
                if done.returncode not in (0, 1):  # 1: no path, which the legend says
                    raise RuntimeError(f"rrtpso solve failed on {path.name} ({planner})")
                row = json.loads(out.read_text())
                xy = np.asarray(row["path"] or [[np.nan, np.nan]])
                what = (f"{row['length'] / best.length:.4f} x optimum" if row["solved"]
                        else "no path")  # fmt: skip
                (line,) = ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=1.6,
                                  label=f"{planner}: {what}")  # fmt: skip
                key.append(line)
            ax.set_title(f"{title}, seed {seed}, {budget:g} s", fontsize=10)
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
            ax.set_aspect("equal")
            world_legend(ax, key)
    fig.tight_layout()
    save_figure(fig, IMG / "corridor_choice.png")
    print("  ->", "docs/img/corridor_choice.png")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    names = [*COMMANDS, "bench", "corridor"]
    parser.add_argument("which", nargs="*", help=f"figures to redraw: {', '.join(names)} "
                        "(default: all)")  # fmt: skip
    args = parser.parse_args(argv)
    unknown = [n for n in args.which if n not in names]
    if unknown:
        parser.error(f"unknown figure {unknown[0]!r} (known: {', '.join(names)})")
    which = args.which or names
    for name in which:
        if name == "bench":
            bench_figures()
        elif name == "corridor":
            corridor_figure()
        else:
            command_figure(name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
