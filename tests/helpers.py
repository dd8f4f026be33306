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


# -- moving obstacles (tests/dynamic) ----------------------------------------------------------
#: The paper's robot with a 150 cm sensor.
ROBOT = {
    "radius": 28.5,
    "wheel_radius": 7.6,
    "track_width": 38,
    "speed": 20,
    "sample_time": 0.15,
    "sensor_range": 150,
}


def corridor(moving, obstacles=()):
    """A 500 x 500 cm world, route along y = 250."""
    from rrtpso_ompl.model.problem import problem_from_dict

    return problem_from_dict(
        {
            "name": "corridor",
            "bounds": [[0, 0], [500, 500]],
            "start": [30, 250],
            "goal": [470, 250],
            "robot": ROBOT,
            "obstacles": list(obstacles),
            "moving_obstacles": moving,
        }
    )


def manager_for(problem, seed=0, **kw):
    """A replanning manager for ``problem`` (0.6 s replans, 5.7 cm margin) and the turn rate."""
    import numpy as np

    from rrtpso_ompl.dynamic import DynamicOptions, ReplanningManager

    opts = DynamicOptions(replan_time=0.6, **kw)
    speed, turn = problem.robot.speed, 2 * problem.robot.speed / problem.robot.track_width
    return ReplanningManager(problem, opts, speed, turn, 5.7, np.random.default_rng(seed)), turn


def observe(problem, t):
    """What the robot senses at time ``t``: every moving obstacle, exactly."""
    out = {}
    for j, m in enumerate(problem.moving_obstacles):
        out[j] = (m.position(t), m.velocity, m.radius)
    return out
