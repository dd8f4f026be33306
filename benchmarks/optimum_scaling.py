"""How the exact optimum's time grows with the map: city blocks, rooms and mazes from 64 x 64 to
2048 x 2048 cells, the 1.7-million-cell warehouse and 10,000 circles (issues 24 and 38's
targets). Writes docs/optimum-scaling.md and docs/img/optimum-scaling.png.

Maps come from ``benchmarks/grid_maps.py`` (seeded): ``city`` (blocks, streets 2-6 cells, a
diagonal avenue), ``rooms`` (32-cell rooms, doors 2-5 cells), ``maze-1`` and ``maze-4`` (perfect
mazes with corridors of 1 and 4 cells). Each map gets point-robot queries between random free
cells at least 0.4 of its side apart, and from 128 to 2048 cells disc-robot queries too (radius
0.4 and 1.5 cells, where they fit). Each map's queries run in their own process
(``shortest_path`` on the loaded problem, timed alone, and with the loading of the problem and
its map; the process's peak memory is reported), with a hard cap. A process's start-up (Python
and the imports of ``rrtpso optimum``, no OMPL) is measured once, in a process of its own: per
process, a query costs the start-up, the loading and the search.

Usage::

    python benchmarks/optimum_scaling.py             # about 10 minutes; writes the docs
    python benchmarks/optimum_scaling.py --quick     # 64 and 128 cells only, a smoke test
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "benchmarks"))

#: Seconds one map's process may take (all its queries).
CAP = 300.0
#: Disc robots (radii in cells) are measured on these sizes.
DISC_SIZES = (128, 256, 512, 1024, 2048)
DISC_RADII = (0.4, 1.5)

_CHILD = """
import json, resource, sys, time
from rrtpso_ompl.groundtruth.optimum import shortest_path
from rrtpso_ompl.model import World, load_problem
for f in sys.argv[1:]:
    t0 = time.perf_counter()
    p = load_problem(f)
    w = World.from_problem(p)
    t = time.perf_counter()
    r = shortest_path(p, w)
    t, load = time.perf_counter() - t, t - t0
    print(json.dumps({"file": f, "time": t, "load": load, "length": r.length, "nodes": r.n_nodes,
                      "rounds": r.rounds, "robot_radius": p.robot.radius,
                      "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}),
          flush=True)
"""


def start_up() -> float:
    """Seconds a fresh process takes to start Python and import what ``rrtpso optimum`` needs
    (the best of three)."""
    code = ("from rrtpso_ompl.groundtruth.optimum import shortest_path; "
            "from rrtpso_ompl.groundtruth.optimum import query; "
            "from rrtpso_ompl.model import World, load_problem")  # fmt: skip
    best = math.inf
    for _ in range(3):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        best = min(best, time.perf_counter() - t)
    return best


def convex_corners(blocked: np.ndarray) -> int:
    """Grid points where exactly one of the four cells around is blocked."""
    b = np.pad(blocked, 1).astype(np.int8)
    count = b[:-1, :-1] + b[:-1, 1:] + b[1:, :-1] + b[1:, 1:]
    return int(np.count_nonzero(count == 1))


def run_child(files: list[Path]) -> list[dict]:
    """The queries of one map in a fresh process; rows for those that finished in time."""
    try:
        proc = subprocess.run([sys.executable, "-c", _CHILD, *map(str, files)],
                              capture_output=True, text=True, timeout=CAP, check=False)  # fmt: skip
        out = proc.stdout
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode() if isinstance(exc.stdout, bytes) else (exc.stdout or "")
    rows = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    done = {r["file"] for r in rows}
    rows += [{"file": str(f), "time": None} for f in files if str(f) not in done]
    return rows


def problem_file(folder: Path, name: str, map_yaml: Path, start, goal, radius: float) -> Path:
    path = folder / f"{name}.yaml"
    path.write_text(f"name: {name}\nmap: {map_yaml.name}\nstart: [{start[0]}, {start[1]}]\n"
                    f"goal: [{goal[0]}, {goal[1]}]\nrobot: {{radius: {radius}}}\n")  # fmt: skip
    return path


def map_rows(kind: str, size: int, seed: int, n_queries: int, folder: Path) -> list[dict]:
    from grid_maps import KINDS, queries, write_map

    make, opts = KINDS[kind]
    rng = np.random.default_rng([seed, size, list(KINDS).index(kind)])
    blocked = make(rng, size=size, **opts)
    name = f"{kind}_{size}_{seed}"
    map_yaml = write_map(blocked, folder, name)
    from rrtpso_ompl.errors import ProblemError
    from rrtpso_ompl.model import load_problem

    files = []
    radii = [0.0] + (list(DISC_RADII) if size in DISC_SIZES else [])
    for radius in radii:
        # Candidates on cells with half a cell of room; the loader keeps those really free.
        kept = 0
        for q, (s, g) in enumerate(queries(rng, blocked, 10 * n_queries, radius - 0.21)):
            path = problem_file(folder, f"{name}_r{radius:g}_q{q}", map_yaml, s, g, radius)
            try:
                load_problem(path)
            except ProblemError:
                continue
            files.append(path)
            kept += 1
            if kept == n_queries:
                break
    rows = run_child(files)
    corners = convex_corners(blocked)
    for r in rows:
        r.update(kind=kind, size=size, cells=size * size, corners=corners)
        r.setdefault("robot_radius", float(r["file"].rsplit("_r", 1)[1].split("_")[0]))
    print(f"{name}: " + ", ".join("-" if r["time"] is None else f"{r['time']:.3f}s"
                                   for r in rows), file=sys.stderr)  # fmt: skip
    return rows


def extra_rows(folder: Path) -> list[dict]:
    """The warehouse map of problems/maps and 10,000 generated circles."""
    circles = folder / "circles_10000.yaml"
    subprocess.run([sys.executable, "-m", "rrtpso_ompl", "generate", "circles", "--n", "10000",
                    "--seed", "1", "--out", str(circles), "-q"], check=True)  # fmt: skip
    rows = []
    for label, path in (("warehouse_cross (1.7 M cells)", REPO / "problems" / "maps" /
                         "warehouse_cross.yaml"), ("10,000 circles", circles)):  # fmt: skip
        r = run_child([path])[0]
        r["label"] = label
        rows.append(r)
        print(f"{label}: {r['time']}", file=sys.stderr)
    return rows


def _fmt(t: float | None) -> str:
    return "> cap" if t is None else f"{t:.3f}"


def slope(x: list[float], y: list[float]) -> float:
    """Least-squares slope of log y against log x."""
    lx, ly = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    return float(np.polyfit(lx, ly, 1)[0])


def _per_process(r: dict, boot: float) -> float | None:
    """A query's seconds in a process of its own: start-up, loading and search."""
    return None if r.get("time") is None else boot + r.get("load", 0.0) + r["time"]


def write_report(rows: list[dict], extra: list[dict], sizes, args, out: Path, plot: Path):
    boot = next((r["time"] for r in extra if r["label"] == "start-up"), 0.0)
    extra = [r for r in extra if r["label"] != "start-up"]
    point = [r for r in rows if r["robot_radius"] == 0.0]
    disc = [r for r in rows if r["robot_radius"] > 0.0]
    cmd = "python benchmarks/optimum_scaling.py" + (" --quick" if args.quick else "")
    lines = [
        "# The exact optimum on maps: how its time grows",
        "",
        f"Generated by `{cmd}` on {platform.machine()}, Python {platform.python_version()}, "
        f"{args.seeds} map(s) per kind and size, {args.queries} point-robot queries per map "
        f"(and as many for disc robots of radius {' and '.join(map(str, DISC_RADII))} cells on "
        f"{DISC_SIZES[0]} to {DISC_SIZES[-1]} cells, where they fit). Times are of "
        f"`shortest_path` alone, in a fresh process per map (cap {CAP:g} s per map); memory is "
        "the peak resident size of "
        "that process (about 100 MB of it is Python, numpy, scipy and shapely). *Per process*: "
        f"the start-up of a fresh process ({boot:.2f} s, Python and the imports, no OMPL), the "
        "loading of the problem and its map, and the search. Point robots on a map alone go "
        "through the interval search (issue 38), everything else through the tangent search. "
        f"{args.note}",
        "",
        "Maps (`benchmarks/grid_maps.py`): `city` blocks and streets with a diagonal avenue, "
        "`rooms` of 32 cells with doors, `maze-1` and `maze-4` perfect mazes with corridors of "
        "1 and 4 cells; 1 unit per cell. Corners are the convex corners of the blocked cells "
        "(the tangent graph's vertices).",
        "",
        "## Point robot",
        "",
        "| kind | cells | corners | queries | median (s) | worst (s) | per process, worst (s) "
        "| nodes (median) | memory (MB) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for kind in dict.fromkeys(r["kind"] for r in rows):
        for size in sizes:
            group = [r for r in point if r["kind"] == kind and r["size"] == size]
            if not group:
                continue
            times = [r["time"] for r in group]
            done = [t for t in times if t is not None]
            worst = None if len(done) < len(times) else max(done)
            nodes = [r["nodes"] for r in group if r.get("nodes") is not None]
            mems = [r["rss_mb"] for r in group if r.get("rss_mb")]
            mem = f"{max(mems):.0f}" if mems else "-"
            whole = [_per_process(r, boot) for r in group]
            whole_worst = None if None in whole else max(whole)
            lines.append(
                f"| {kind} | {size}x{size} | {group[0]['corners']:,} | {len(group)} | "
                f"{_fmt(statistics.median(done) if done else None)} | {_fmt(worst)} | "
                f"{_fmt(whole_worst)} | {int(statistics.median(nodes)) if nodes else '-'} | "
                f"{mem} |"
            )
    if disc:
        lines += ["", "## Disc robots", "",
                  "| kind | cells | radius (cells) | queries | median (s) | worst (s) | "
                  "per process, worst (s) |",
                  "|---|---:|---:|---:|---:|---:|---:|"]  # fmt: skip
        for kind in dict.fromkeys(r["kind"] for r in disc):
            for size in DISC_SIZES:
                for radius in DISC_RADII:
                    group = [r for r in disc if r["kind"] == kind and r["size"] == size
                             and r["robot_radius"] == radius]  # fmt: skip
                    done = [r["time"] for r in group if r["time"] is not None]
                    if not group:
                        continue
                    med = statistics.median(done) if done else None
                    worst = max(done) if len(done) == len(group) else None
                    whole = None if worst is None else max(_per_process(r, boot) for r in group)
                    lines.append(
                        f"| {kind} | {size}x{size} | {radius:g} | {len(group)} | "
                        f"{_fmt(med)} | {_fmt(worst)} | {_fmt(whole)} |"
                    )
        lines += ["", f"A dash: not finished within the cap ({CAP:g} s for the map's process)."]
    lines += ["", "## Large worlds", "",
              "| world | time (s) | per process (s) | length | memory (MB) |",
              "|---|---:|---:|---:|---:|"]  # fmt: skip
    for r in extra:
        length = "-" if r.get("length") is None else f"{r['length']:.4f}"
        lines.append(f"| {r['label']} | {_fmt(r['time'])} | {_fmt(_per_process(r, boot))} | "
                     f"{length} | {r.get('rss_mb', 0.0):.0f} |")  # fmt: skip
    # Targets and growth.
    small = [r["time"] for r in rows if r["size"] <= 256]
    small_done = [t for t in small if t is not None]
    med = statistics.median(small_done) if small_done else math.inf
    worst = max(small_done) if len(small_done) == len(small) else math.inf
    mem = max((r.get("rss_mb") or 0.0) for r in rows + extra)
    timed = [r for r in point if r["time"] is not None and r["time"] > 0]
    lines += ["", "## Targets (issue 24)", "",
              f"- Up to 256 x 256 cells, every kind and robot ({len(small)} queries): median "
              f"{med:.3f} s (target 0.2 s: {'met' if med < 0.2 else '**not met**'}), worst "
              f"{_fmt(None if worst == math.inf else worst)} s (target 1 s: "
              f"{'met' if worst < 1.0 else '**not met**'})."]  # fmt: skip
    for r in extra:
        ok = r["time"] is not None and r["time"] < 2.0
        lines.append(f"- {r['label']}: {_fmt(r['time'])} s (target 2 s: "
                     f"{'met' if ok else '**not met**'}).")  # fmt: skip
    lines.append(
        f"- Peak memory: {mem:.0f} MB (target 1 GB: {'met' if mem < 1024 else '**not met**'})."
    )
    lines += ["", "## Targets (issue 38: per process, start-up included)", ""]
    for size, target in ((1024, 5.0), (2048, 20.0)):
        group = [r for r in point if r["size"] == size]
        if group:
            whole = [_per_process(r, boot) for r in group]
            worst = None if None in whole else max(whole)
            ok = worst is not None and worst <= target
            lines.append(f"- Point robots on {size} x {size} cells, every kind ({len(group)} "
                         f"queries): worst {_fmt(worst)} s (target {target:g} s: "
                         f"{'met' if ok else '**not met**'}).")  # fmt: skip
    for r in extra:
        whole = _per_process(r, boot)
        ok = whole is not None and whole <= 2.0
        lines.append(f"- {r['label']}: {_fmt(whole)} s (target 2 s: "
                     f"{'met' if ok else '**not met**'}).")  # fmt: skip
    for size, target in ((1024, 5.0), (2048, 20.0)):
        group = [r for r in disc if r["size"] == size]
        if group:
            whole = [_per_process(r, boot) for r in group]
            done = [w for w in whole if w is not None]
            kinds = sorted({r["kind"] for r, w in zip(group, whole, strict=True) if w is None})
            late = (f"; {len(group) - len(done)} did not finish within the cap ({', '.join(kinds)})"
                    if len(done) < len(group) else "")  # fmt: skip
            ok = len(done) == len(group) and max(done) <= target
            worst = _fmt(max(done) if done else None)
            lines.append(f"- Disc robots on {size} x {size} cells, every kind ({len(group)} "
                         f"queries): worst of those finished {worst} s{late} (target {target:g} "
                         f"s: {'met' if ok else '**not met**'}).")  # fmt: skip
    if len(timed) >= 4:
        by_kind = []
        for kind in dict.fromkeys(r["kind"] for r in timed):
            g = [r for r in timed if r["kind"] == kind]
            if len({r["size"] for r in g}) >= 2:
                by_kind.append(
                    f"{kind} {slope([r['cells'] for r in g], [r['time'] for r in g]):.2f}"
                )
        lines += [
            "",
            "## Growth",
            "",
            "Least-squares exponents of time against size over the point-robot queries (time "
            "~ size^k): against cells "
            f"{slope([r['cells'] for r in timed], [r['time'] for r in timed]):.2f}, against "
            f"corners {slope([r['corners'] for r in timed], [r['time'] for r in timed]):.2f}, "
            f"against the tangent nodes searched "
            f"{slope([max(r['nodes'], 1) for r in timed], [r['time'] for r in timed]):.2f}. "
            f"Per kind, against cells: {', '.join(by_kind)}.",
        ]
    lines += [
        "",
        "![time per query against cells](img/optimum-scaling.png)",
        "",
        "The figure shows the queries that finished within the cap, point robots and discs.",
        "",
    ]
    out.write_text("\n".join(lines))
    _plot(timed, [r for r in disc if r["time"] is not None and r["time"] > 0], plot)


def _plot(rows: list[dict], discs: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    colours = {}
    for kind in dict.fromkeys(r["kind"] for r in rows):
        g = [r for r in rows if r["kind"] == kind]
        dots = ax.scatter([r["cells"] for r in g], [r["time"] for r in g], label=f"{kind}, point",
                          alpha=0.8)  # fmt: skip
        colours[kind] = dots.get_facecolor()[0]
    for kind in dict.fromkeys(r["kind"] for r in discs):
        g = [r for r in discs if r["kind"] == kind]
        ax.scatter([r["cells"] for r in g], [r["time"] for r in g], label=f"{kind}, disc",
                   marker="^", facecolors="none", edgecolors=[colours.get(kind, "k")])  # fmt: skip
    for y, text, style in ((0.2, "0.2 s: issue 24's median", ":"),
                           (1.0, "1 s: issue 24's worst", "--")):  # fmt: skip
        ax.axhline(y, color="grey", lw=0.8, ls=style, label=text)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("map cells")
    ax.set_ylabel("time per query (s)")
    ax.set_title("Exact optimum: point robots (dots) and discs of 0.4-1.5 cells (triangles)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, title="map kind, robot",
              title_fontsize=8)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="64 and 128 cells only")
    ap.add_argument("--sizes", default="64,128,256,512,1024,2048")
    ap.add_argument("--seeds", type=int, default=1, help="maps per kind and size")
    ap.add_argument("--queries", type=int, default=2, help="queries per map and robot")
    ap.add_argument("--note", default="", help="a sentence for the report (machine load)")
    ap.add_argument("--out", default=str(REPO / "docs" / "optimum-scaling.md"))
    ap.add_argument("--plot", default=str(REPO / "docs" / "img" / "optimum-scaling.png"))
    ap.add_argument("--save-rows", metavar="JSON", help="also write the measured rows here")
    ap.add_argument("--load-rows", metavar="JSON",
                    help="write the report from rows saved before, measuring nothing")  # fmt: skip
    args = ap.parse_args(argv)
    sizes = (64, 128) if args.quick else tuple(int(s) for s in args.sizes.split(","))
    from grid_maps import KINDS

    t0 = time.perf_counter()
    if args.load_rows:
        saved = json.loads(Path(args.load_rows).read_text())
        write_report(saved["rows"], saved["extra"], sizes, args, Path(args.out), Path(args.plot))
        return 0
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for kind in KINDS:
            for size in sizes:
                for seed in range(1, args.seeds + 1):
                    rows += map_rows(kind, size, seed, args.queries, folder)
        extra = [] if args.quick else extra_rows(folder)
    extra.append({"label": "start-up", "time": start_up()})
    if args.save_rows:
        Path(args.save_rows).write_text(json.dumps({"rows": rows, "extra": extra}))
    write_report(rows, extra, sizes, args, Path(args.out), Path(args.plot))
    print(f"wrote {args.out} in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
