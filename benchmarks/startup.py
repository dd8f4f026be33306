"""Start-up of the ``rrtpso`` command, side by side with ``python -c "import numpy, yaml"``.

Every command is a fresh process of this interpreter's installation (its ``rrtpso`` console
script), timed from start to exit. The commands run interleaved: each round runs every one once,
in an order rotated from round to round, so that a slower moment of the machine falls on all of
them alike; one round first, not counted, warms the file cache. Reported per command: the median
over the rounds, the fastest and slowest, and the median's ratio to the baseline's median.

``--also PYTHON`` times the same commands with another installation (an older checkout in a
virtual environment of its own, say) in the same rounds, for a before/after table.

Usage::

    python benchmarks/startup.py                    # updates the table of docs/startup.md
    python benchmarks/startup.py --rounds 5 --out -
    python benchmarks/startup.py --also ../old/.venv/bin/python
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
#: 12 obstacles (circles, rectangles and a triangle), no map: its optimum takes about 30 ms.
PROBLEM = REPO / "problems" / "static" / "paper_static.yaml"
BASELINE = "python -c 'import numpy, yaml'"


def commands(tmp: Path) -> dict[str, list[str] | None]:
    """What is timed: label -> arguments of ``rrtpso`` (None: the baseline)."""
    p = str(PROBLEM)
    out = {name: str(tmp / name) for name in ("o.json", "g.yaml", "s.json")}
    return {
        BASELINE: None,
        "rrtpso --version": ["--version"],
        "rrtpso --help": ["--help"],
        "rrtpso solve --help": ["solve", "--help"],
        "rrtpso optimum paper_static.yaml --json OUT": ["optimum", p, "--json", out["o.json"]],
        "rrtpso generate circles --seed 1 --out OUT": (
            ["generate", "circles", "--seed", "1", "--out", out["g.yaml"], "--overwrite"]
        ),
        "rrtpso solve paper_static.yaml --time 0.1 --json OUT": (
            ["solve", p, "--time", "0.1", "--seed", "1", "--json", out["s.json"]]
        ),
    }


def argv_of(python: str, args: list[str] | None) -> list[str]:
    """The command line: the installation's console script, or its ``python -m rrtpso_ompl``."""
    if args is None:
        return [python, "-c", "import numpy, yaml"]
    script = shutil.which("rrtpso", path=os.path.dirname(python))
    return [script, *args] if script else [python, "-m", "rrtpso_ompl", *args]


def timed(argv: list[str]) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    elapsed = time.perf_counter() - t0
    if proc.returncode not in (0, 1):  # 1: solve found no path; still a start-up
        raise SystemExit(f"{' '.join(argv)} failed ({proc.returncode}): {proc.stderr[-500:]}")
    return elapsed


def measure(pythons: list[str], rounds: int) -> dict[tuple[str, str], list[float]]:
    """Seconds per (python, label), interleaved rounds (see the module docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        cmds = commands(Path(tmp))
        jobs = [(py, label, argv_of(py, args)) for py in pythons for label, args in cmds.items()]
        for _, _, argv in jobs:  # warm-up, not counted
            timed(argv)
        times: dict[tuple[str, str], list[float]] = {(py, label): [] for py, label, _ in jobs}
        for r in range(rounds):
            k = r % len(jobs)
            for py, label, argv in jobs[k:] + jobs[:k]:
                times[py, label].append(timed(argv))
            print(f"round {r + 1}/{rounds}", file=sys.stderr)
    return times


def table(times: dict[tuple[str, str], list[float]], pythons: list[str]) -> list[str]:
    from rrtpso_ompl.harness.report import markdown_table

    labels = list(dict.fromkeys(label for _, label in times))
    header = ["command", "median s", "fastest-slowest s", "x baseline"]
    if len(pythons) > 1:
        header += ["before: median s", "before: x baseline"]
    rows = []
    for label in labels:
        row: list[object] = []
        for py in pythons:
            t = times[py, label]
            base = statistics.median(times[py, BASELINE])
            med = statistics.median(t)
            row += [f"{med:.3f}"] + ([f"{min(t):.3f}-{max(t):.3f}"] if py == pythons[0] else [])
            row.append(f"{med / base:.2f}")
        rows.append([f"`{label}`", *row])
    return markdown_table(header, rows).splitlines()


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    with_model = Path("/proc/cpuinfo")
    if with_model.exists():
        found = re.search(r"model name\s*:\s*(.+)", with_model.read_text())
        cpu = found.group(1).strip() if found else cpu
    return f"{cpu}, {os.cpu_count()} CPUs, {platform.system()}, Python {platform.python_version()}"


def commit() -> str:
    try:
        out = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, check=True)  # fmt: skip
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def block(times, pythons, rounds, argv: list[str]) -> list[str]:
    load = " / ".join(f"{v:.2f}" for v in os.getloadavg())
    lines = [
        f"Generated by `python benchmarks/startup.py {' '.join(argv)}`".rstrip() + " on "
        f"{datetime.date.today().isoformat()}, commit {commit()}: {machine()}; load average "
        f"after the run {load} (1, 5, 15 min). {rounds} interleaved rounds after one warm-up "
        "round; each command a fresh process, timed from start to exit.",
        "",
        *table(times, pythons),
    ]
    if len(pythons) > 1:
        lines += ["", f"Before: `{pythons[1]}` (another installation), in the same rounds."]
    return lines


def write(lines: list[str], out: str) -> None:
    """Replace the block between the markers of ``out`` (or write a new file with them)."""
    text = "\n".join(["<!-- startup:table -->", *lines, "<!-- /startup:table -->"])
    if out == "-":
        print(text)
        return
    path = Path(out)
    old = path.read_text() if path.exists() else ""
    pattern = re.compile(r"<!-- startup:table -->\n.*?<!-- /startup:table -->", re.S)
    if pattern.search(old):
        new = pattern.sub(lambda _: text, old)
    else:
        new = f"# Start-up of the rrtpso command\n\n{text}\n"
    path.write_text(new if new.endswith("\n") else new + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=15, help="timed rounds (default 15)")
    ap.add_argument("--also", metavar="PYTHON", help="another installation's interpreter")
    ap.add_argument("--out", default=str(REPO / "docs" / "startup.md"),
                    help="markdown file whose table is replaced, or -")  # fmt: skip
    args = ap.parse_args(argv)
    pythons = [sys.executable] + ([args.also] if args.also else [])
    times = measure(pythons, args.rounds)
    write(block(times, pythons, args.rounds, argv if argv is not None else sys.argv[1:]),
          args.out)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
