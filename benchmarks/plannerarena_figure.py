"""Draw Planner Arena's own box plot of a benchmark database (a check that it reads ours).

Planner Arena is not a dependency of rrtpso-ompl; run this with its environment::

    python3 -m venv pa && pa/bin/pip install plannerarena
    pa/bin/python benchmarks/plannerarena_figure.py bench/benchmark.db paper_static_1s \
        docs/img/plannerarena_paper_static.png

It loads the database with ``plannerarena.database.load_database`` (what the app does), selects
one experiment and draws ``solution length`` before and after simplification with
``plannerarena.performance.boxplot_with_simplified``, exactly as the app's "Overall performance"
tab does with "Include results after simplification" ticked.
"""

from __future__ import annotations

import sys


def main(argv: list[str]) -> int:
    import plotnine as p9
    import polars as pl
    from plannerarena.database import load_database
    from plannerarena.performance import boxplot_with_simplified

    db, experiment, out = argv
    data = load_database(db)
    if experiment not in data["problem_names"]:
        print(f"no experiment {experiment!r}; the database has {data['problem_names']}")
        return 2
    attr = "solution length"
    df = (
        data["runs"]
        .filter(pl.col("experiment") == experiment)
        .unpivot(index=["planner"], on=[attr, f"simplified {attr}"], variable_name="key",
                 value_name="value")
        .with_columns(pl.col("key").cast(pl.Categorical))
    )  # fmt: skip
    plot = boxplot_with_simplified(df, attr, "o", False)
    plot = plot + p9.ggtitle(f"Planner Arena: {experiment}")
    plot.save(out, width=8, height=4, dpi=110, verbose=False)
    print(f"wrote {out}: {len(df) // 2} runs of {df['planner'].n_unique()} planners")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
