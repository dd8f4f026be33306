"""How the costs grow with the world: obstacle counts from 10^2 to 10^4, maps from 10^5 to
2 x 10^6 cells. Writes docs/scaling.md and docs/img/scaling.png.

Worlds:

- ``lattice N``: N circles on a jittered square lattice in 1000 x 1000 (radii 15-30 % of the
  lattice cell, robot radius 5 % of it), start (1, 1), goal (999, 999): the worlds of issue 12's
  measurements, so before and after compare;
- ``warehouse C``: the warehouse of ``benchmarks/make_maps.py`` (racks, pallets, scan speckle,
  an unmapped bay) drawn at 5 cm on an area of C cells, corner to far corner, robot radius
  0.35 m.

For each: the cost of one motion check (OMPL's callback, a random segment up to a fifth of the
workspace long) and of one point check, RRT*'s iterations per second inside RRTstarPSO, the
path length of RRTstarPSO and of BIT* after 2 s (each in its own ``rrtpso solve`` process with a
hard cap, since OMPL's BIT* does not always stop at its time limit), and the exact optimum's time
and peak memory (``rrtpso optimum``, in its own process). One seed, one run each: the trends are
the point, not the last digit.

Usage::

    python benchmarks/scaling.py            # about 5 minutes; writes docs/scaling.md
    python benchmarks/scaling.py --quick    # smaller sizes, for a smoke test
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / "benchmarks"))

#: Hard cap of a planner's process (its budget is 2 s).
PLANNER_CAP = 60.0


def lattice_doc(n: int, seed: int = 0, size: float = 1000.0) -> dict:
    rng = np.random.default_rng(seed)
    k = math.ceil(math.sqrt(n))
    cell = size / k
    ij = np.array([(i, j) for i in range(k) for j in range(k)])[:n]
    c = (ij + 0.5 + rng.uniform(-0.25, 0.25, (n, 2))) * cell
    r = rng.uniform(0.15, 0.3, n) * cell
    obstacles = [
        {"type": "circle", "center": [round(float(x), 6), round(float(y), 6)],
         "radius": round(float(rr), 6)}
        for (x, y), rr in zip(c, r, strict=True)
    ]  # fmt: skip
    return {"name": f"lattice_{n}", "bounds": [[0, 0], [size, size]], "start": [1, 1],
            "goal": [999, 999], "robot": {"radius": round(0.05 * cell, 6)},
            "obstacles": obstacles}  # fmt: skip


def warehouse_files(cells: int, folder: Path) -> Path:
    """A warehouse map of about ``cells`` cells and a corner-to-corner problem on it."""
    from make_maps import FREE, _box, warehouse
    from PIL import Image

    res = 0.05
    w_m = round(math.sqrt(cells * res * res / 1.7), 2)  # the shape of the 50 x 85 m one
    h_m = round(1.7 * w_m, 2)
    img = warehouse(np.random.default_rng(cells), w_m, h_m, res)
    start, goal = (1.5, 1.5), (w_m - 2.0, 0.87 * h_m - 2.0)
    for cx, cy in (start, goal):
        _box(img, res, cx - 0.8, cy - 0.8, cx + 0.8, cy + 0.8, FREE)
    name = f"warehouse_{img.size}"
    Image.fromarray(img, mode="L").save(folder / f"{name}.png")
    (folder / f"{name}.map.yaml").write_text(
        f"image: {name}.png\nresolution: {res}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    path = folder / f"{name}.yaml"
    path.write_text(
        f"name: {name}\nmap: {name}.map.yaml\nstart: [{start[0]}, {start[1]}]\n"
        f"goal: [{goal[0]}, {goal[1]}]\nrobot: {{radius: 0.35}}\n"
    )
    return path


def check_costs(problem_file: Path) -> dict:
    """Microseconds per scalar motion check and point check (20,000 random queries)."""
    from rrtpso_ompl.model import World, load_problem

    problem = load_problem(problem_file)
    world = World.from_problem(problem)
    (x0, y0), (x1, y1) = problem.bounds
    rng = np.random.default_rng(1)
    n = 20_000
    a = rng.uniform((x0, y0), (x1, y1), (n, 2))
    ang = rng.uniform(0, 2 * np.pi, n)
    length = rng.uniform(0, 0.2 * max(x1 - x0, y1 - y0), n)
    b = np.clip(a + np.column_stack([np.cos(ang), np.sin(ang)]) * length[:, None],
                (x0, y0), (x1, y1))  # fmt: skip
    pairs = list(zip(a.tolist(), b.tolist(), strict=True))
    t = time.perf_counter()
    for p, q in pairs:
        world.motion_free(p[0], p[1], q[0], q[1])
    motion = (time.perf_counter() - t) / n * 1e6
    t = time.perf_counter()
    for p in a.tolist():
        world.point_free(p[0], p[1])
    point = (time.perf_counter() - t) / n * 1e6
    t = time.perf_counter()
    world.segments_free(a, b)
    vector = (time.perf_counter() - t) / n * 1e6
    return {"motion_us": motion, "point_us": point, "vector_us": vector,
            "obstacles": world.n_obstacles}  # fmt: skip


def run_solve(problem_file: Path, planner: str, folder: Path) -> dict:
    out = folder / f"{problem_file.stem}.{planner}.json"
    cmd = [sys.executable, "-m", "rrtpso_ompl", "solve", str(problem_file), "--planner", planner,
           "--time", "2", "--seed", "1", "--json", str(out), "-q"]  # fmt: skip
    t = time.perf_counter()
    try:
        subprocess.run(cmd, capture_output=True, timeout=PLANNER_CAP, check=False)
    except subprocess.TimeoutExpired:
        return {"wall": PLANNER_CAP, "length": None, "killed": True}
    wall = time.perf_counter() - t
    if not out.exists():
        return {"wall": wall, "length": None}
    doc = json.loads(out.read_text())
    stages = doc.get("stages") or {}
    rate = None
    if stages.get("rrt_time"):
        rate = stages.get("rrt_iterations", 0) / stages["rrt_time"]
    return {"wall": wall, "length": doc["length"] if doc["solved"] else None,
            "planner_time": doc["time"], "rrt_rate": rate}  # fmt: skip


_CHILD = """
import json, resource, sys, time
from rrtpso_ompl.groundtruth import shortest_path
from rrtpso_ompl.model import World, load_problem
t = time.perf_counter()
p = load_problem(sys.argv[1])
r = shortest_path(p, World.from_problem(p))
print(json.dumps({"time": time.perf_counter() - t, "length": r.length,
                  "nodes": r.n_nodes, "rss_mb": resource.getrusage(
                      resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def run_optimum(problem_file: Path) -> dict:
    proc = subprocess.run([sys.executable, "-c", _CHILD, str(problem_file)],
                          capture_output=True, text=True, timeout=900, check=False)  # fmt: skip
    if proc.returncode:
        return {"time": None, "length": None, "error": proc.stderr.strip()[-200:]}
    return json.loads(proc.stdout)


def measure(problem_file: Path, folder: Path, label: str, size: int) -> dict:
    row = {"label": label, "size": size, **check_costs(problem_file)}
    row["optimum"] = run_optimum(problem_file)
    for planner in ("RRTstarPSO", "BITstar"):
        row[planner] = run_solve(problem_file, planner, folder)
    print(json.dumps(row), file=sys.stderr)
    return row


def _ratio(length, best) -> str:
    if length is None:
        return "not solved"
    if not best:
        return f"{length:.1f}"
    return f"{length / best:.4f}"


def write_report(rows: list[dict], out: Path, plot: Path, quick: bool) -> None:
    from rrtpso_ompl.harness.report import markdown_table

    lines = [
        "# Scaling: from a dozen shapes to maps of millions of cells",
        "",
        f"Generated by `python benchmarks/scaling.py{' --quick' if quick else ''}` on "
        f"{platform.machine()}, Python {platform.python_version()}, one run per row (seed 1): "
        "the trends matter, not the last digit. Worlds: `lattice N` is N circles on a jittered "
        "lattice in 1000 x 1000 (robot radius 5 % of the lattice cell; the worlds of issue 12); "
        "`warehouse C` is `benchmarks/make_maps.py`'s warehouse drawn on C cells at 5 cm "
        "(racks, pallets, scan speckle, an unmapped bay), corner to far corner, robot radius "
        "0.35 m; its obstacles are the merged boxes of its blocked cells.",
        "",
        "Check costs are per call from Python: a motion check (OMPL's callback; random segments up "
        "to a fifth of the workspace), a point check, and a segment inside one vectorised "
        "`segments_free` call (the swarm's). Lengths are over the exact optimum after 2 s, each "
        "planner in its own `rrtpso solve` process.",
        "",
        markdown_table(["world", "obstacles", "motion check", "point check", "vectorised",
                        "RRT* it/s", "RRTstarPSO", "BIT*", "optimum", "optimum time",
                        "optimum memory"], [_report_row(r) for r in rows]),
    ]  # fmt: skip
    lines += ["", "![scaling](img/scaling.png)", "", *_targets(rows), *_before()]
    out.write_text("\n".join(lines) + "\n")
    _plot(rows, plot)


def _report_row(r: dict) -> list[str]:
    """One world's cells of the report's table."""
    opt = r["optimum"]
    best = opt.get("length")
    if best is None:
        return [r["label"], f"{r['obstacles']:,}", "-", "-", "-", "-", "-", "-",
                opt.get("error", "none"), "-", "-"]  # fmt: skip
    bit = r["BITstar"]
    bit_text = _ratio(bit["length"], best)
    if bit.get("killed"):
        bit_text = f"killed at {PLANNER_CAP:.0f} s"
    elif bit["wall"] > 10:
        bit_text += f" (stopped after {bit['wall']:.0f} s)"
    rate = r["RRTstarPSO"].get("rrt_rate")
    return [r["label"], f"{r['obstacles']:,}", f"{r['motion_us']:.1f} us",
            f"{r['point_us']:.1f} us", f"{r['vector_us']:.1f} us",
            f"{rate:,.0f}" if rate else "-", _ratio(r["RRTstarPSO"]["length"], best), bit_text,
            f"{best:.2f}", f"{opt['time']:.1f} s", f"{opt['rss_mb']:.0f} MB"]  # fmt: skip


def _before() -> list[str]:
    """Issue 12's measurements before the spatial index (the same lattice worlds)."""
    from rrtpso_ompl.harness.report import markdown_table

    return [
        "",
        "## Before the index (issue 12's measurements, the same lattice worlds)",
        "",
        markdown_table(
            ["obstacles", "motion check", "point check", "RRTstarPSO, 2 s", "BIT*, 2 s",
             "`rrtpso optimum`"],
            [["100", "10.8 us", "31.5 us", "solved", "solved", "1.0 s"],
             ["1,000", "73.9 us", "330 us", "solved, +4.4 % over the optimum", "+1.8 %",
              "204 s, 0.47 GB"],
             ["10,000", "303 us", "2,363 us", "not solved", "not solved", "killed at 24 GB"]],
        ),
        "",
        "Memory above is the peak resident size of the whole `rrtpso optimum` process, about "
        "100 MB of which is Python, numpy, scipy and shapely.",
        "",
    ]  # fmt: skip


def _targets(rows: list[dict]) -> list[str]:
    """Issue 12's targets against this run, in words."""
    by = {r["label"]: r for r in rows}
    out = ["## Targets", ""]
    lo, hi = by.get("lattice 100"), by.get("lattice 10,000")
    if lo and hi:
        ratio = hi["motion_us"] / lo["motion_us"]
        out.append(
            f"- Motion check at 10,000 obstacles within 2x of 100: {hi['motion_us']:.1f} us "
            f"against {lo['motion_us']:.1f} us, {ratio:.2f}x: "
            f"{'met' if ratio <= 2 else 'not met'}."
        )
        opt = hi["optimum"]
        if opt.get("time"):
            met = opt["time"] < 60 and opt["rss_mb"] < 2048
            out.append(
                f"- Exact optimum of 10,000 circles under 60 s and 2 GB: {opt['time']:.1f} s, "
                f"{opt['rss_mb']:.0f} MB: {'met' if met else 'not met'}."
            )
        length, best = hi["RRTstarPSO"]["length"], opt.get("length")
        if length is None:
            out.append(
                "- RRTstarPSO within 1 % of the optimum on 10,000 circles in 2 s: **not met** "
                "in this run (no path in 2 s; with another seed or machine load it finds one "
                "about 10 % over the optimum). RRT*'s tree needs most of the budget to cross a "
                "lattice of 100 x 100 obstacles with a range of a few cells, and the swarm "
                "cannot change the path's homotopy class. This is the subject of issue 13."
            )
        else:
            excess = length / best - 1.0
            out.append(
                f"- RRTstarPSO within 1 % of the optimum on 10,000 circles in 2 s: "
                f"{100 * excess:+.1f} %: {'met' if excess <= 0.01 else '**not met**'}."
            )
    wh = [r for r in rows if r["label"].startswith("warehouse_cross")]
    if wh and wh[0]["optimum"].get("time"):
        opt = wh[0]["optimum"]
        met = opt["time"] < 60 and opt["rss_mb"] < 2048
        out.append(
            f"- Exact optimum on the 1,000 x 1,700-cell warehouse map under 60 s and 2 GB: "
            f"{opt['time']:.1f} s, {opt['rss_mb']:.0f} MB: {'met' if met else 'not met'}."
        )
    out += [
        "- OMPL's BIT* does not always stop at its time limit among 10,000 circles: one "
        "in-process run with a 2 s budget returned after 95 s, having found its first solution "
        "just before the deadline; the time goes inside OMPL's C++ (we have not located "
        "where it stops polling the termination condition). The benchmark runs each planner "
        f"in its own process with a hard cap of {PLANNER_CAP:.0f} s and reports the wall time "
        "when it overran.",
        "",
    ]
    return out


def _plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for kind, marker in (("lattice", "o"), ("warehouse ", "s")):
        rs = [r for r in rows if r["label"].startswith(kind)]
        if not rs:
            continue
        x = [r["obstacles"] for r in rs]
        name = kind.strip()
        axes[0].loglog(x, [r["motion_us"] for r in rs], marker + "-", label=f"{name}: motion")
        axes[0].loglog(x, [r["point_us"] for r in rs], marker + "--", label=f"{name}: point")
        ok = [r for r in rs if r["optimum"].get("time")]
        axes[1].loglog([r["size"] for r in ok], [r["optimum"]["time"] for r in ok],
                       marker + "-", label=f"{kind.strip()}: optimum time [s]")  # fmt: skip
    axes[0].set_xlabel("obstacles (circles, or merged boxes of a map)")
    axes[0].set_ylabel("microseconds per check")
    axes[0].set_title("Collision checks")
    axes[1].set_xlabel("circles (lattice) or cells (warehouse)")
    axes[1].set_ylabel("seconds")
    axes[1].set_title("Exact optimum")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    ap.add_argument("--out", default=str(REPO / "docs" / "scaling.md"))
    args = ap.parse_args(argv)
    from rrtpso_ompl.model.problem_file import write_problem

    counts = (100, 1000) if args.quick else (100, 300, 1000, 3000, 10000)
    cells = (100_000,) if args.quick else (100_000, 300_000, 1_000_000, 2_000_000)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for n in counts:
            path = folder / f"lattice_{n}.yaml"
            write_problem(lattice_doc(n), path)
            rows.append(measure(path, folder, f"lattice {n:,}", n))
        for c in cells:
            path = warehouse_files(c, folder)
            rows.append(measure(path, folder, f"warehouse {c:,}", c))
        if not args.quick:  # the library's map: 1,000 x 1,700 cells
            path = REPO / "problems" / "maps" / "warehouse_cross.yaml"
            rows.append(measure(path, folder, "warehouse_cross (1.7 M)", 1_700_000))
    out = Path(args.out)
    (out.parent / "img").mkdir(parents=True, exist_ok=True)
    write_report(rows, out, out.parent / "img" / "scaling.png", args.quick)
    print(f"wrote {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
