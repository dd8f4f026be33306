"""The pictures of README.md and docs/, redrawn with the commands the docs quote.

- ``docs/img/paper_static.png``: the README's first command, ``rrtpso solve
  problems/static/paper_static.yaml --plot ...``;
- ``docs/img/paper_dynamic.png`` and ``.gif``: docs/dynamic.md's ``rrtpso simulate
  problems/dynamic/paper_dynamic.yaml --plot ... --gif ...``;
- ``docs/img/optimum_maze.png``: ``rrtpso optimum problems/static/maze.yaml --plot ...``;
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    names = [*COMMANDS, "bench"]
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
        else:
            command_figure(name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
