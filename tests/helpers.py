"""Shared test data and helpers (``from helpers import ...``: tests/ is on the path)."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PROBLEMS = REPO / "problems"

#: The single-circle problem of the issue: its shortest path (tangent, arc, tangent) is 647.45.
SINGLE_CIRCLE = {
    "name": "single_circle",
    "units": "cm",
    "bounds": [[0, 0], [500, 500]],
    "start": [20, 20],
    "goal": [450, 450],
    "robot": {"radius": 28.5},
    "obstacles": [{"type": "circle", "center": [250, 250], "radius": 80}],
}
SINGLE_CIRCLE_OPTIMUM = 647.45


def rrtpso_exe() -> list[str]:
    """The installed console script (tests drive the real command, as a user would)."""
    exe = shutil.which("rrtpso", path=os.path.dirname(sys.executable))
    return [exe] if exe else [sys.executable, "-m", "rrtpso_ompl"]


def write_yaml(path: Path, text: str) -> Path:
    path.write_text(text)
    return path
