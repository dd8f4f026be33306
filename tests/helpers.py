"""Shared test data and helpers (``from helpers import ...``: tests/ is on the path)."""

from __future__ import annotations

import copy
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from rrtpso_ompl.kinematics import ReferenceCurve
from rrtpso_ompl.model.problem import Robot
from rrtpso_ompl.testing import SIMPLE_PROBLEM

REPO = Path(__file__).resolve().parent.parent
PROBLEMS = REPO / "problems"

#: The single-circle problem of the issue: its shortest path (tangent, arc, tangent) is 647.45
#: (the conformance kit's simple problem, under this name).
SINGLE_CIRCLE = copy.deepcopy({**SIMPLE_PROBLEM, "name": "single_circle"})
SINGLE_CIRCLE_OPTIMUM = 647.45


def rrtpso_exe() -> list[str]:
    """The installed console script (tests drive the real command, as a user would)."""
    exe = shutil.which("rrtpso", path=os.path.dirname(sys.executable))
    return [exe] if exe else [sys.executable, "-m", "rrtpso_ompl"]


#: RRTstarPSO bounded by work (RRT*'s iterations, one swarm round of bounded iterations) on the
#: command line: its path is the same on every machine, ``--time`` only a cap it never reaches
#: (a static path planned for a time budget differs with the machine's speed, and with it, say,
#: whether a moving obstacle crosses it).
BOUNDED_ARGS = ["--time", "30", "--param", "rrt_max_iterations=300", "--param", "iterations=20",
                "--param", "refine_rounds=0", "--param", "polish_rounds=0"]  # fmt: skip


def run(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """``rrtpso *args`` in a subprocess, its output captured as text."""
    return subprocess.run([*rrtpso_exe(), *args], capture_output=True, text=True, timeout=timeout)


class HeldBatch:
    """A batch that stays running after its first row until the test says (the batch's test hook
    :data:`~rrtpso_ompl.harness.batch.HOLD_ENV`): "a batch still running" by construction, not
    by a race with the machine's speed.

    ``env`` goes to the batch's ``subprocess.Popen``; :meth:`wait_for_rows` waits for the first
    row(s) to be written (the batch is then at the hold, or on its way to it); :meth:`release`
    lets it go on to the end.
    """

    def __init__(self, folder: Path) -> None:
        from rrtpso_ompl.harness.batch import HOLD_ENV

        self.fifo = folder / "hold.fifo"
        os.mkfifo(self.fifo)
        self.env = {**os.environ, HOLD_ENV: str(self.fifo)}

    @staticmethod
    def wait_for_rows(proc: subprocess.Popen, out: Path, rows: int = 1,
                      seconds: float = 300) -> None:  # fmt: skip
        """Wait until ``out`` holds ``rows`` whole lines (a deadline only against a hang: the
        batch cannot finish without :meth:`release`)."""
        import time

        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline and proc.poll() is None:
            if out.exists() and out.read_bytes().count(b"\n") >= rows:
                return
            time.sleep(0.05)
        raise AssertionError(f"no {rows} rows in {out} (exit status {proc.poll()})")

    def release(self, seconds: float = 300) -> None:
        """Open the fifo for reading: the held batch goes on."""
        import threading

        opener = threading.Thread(target=lambda: open(self.fifo, "rb").close(), daemon=True)
        opener.start()
        opener.join(seconds)
        assert not opener.is_alive(), "the batch never reached its hold"


def _generate_parser():
    """The parser of ``rrtpso generate`` (its flags are derived from the declared options)."""
    import argparse

    from rrtpso_ompl.cli.main import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices["generate"]


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


# -- wheels and trajectories (tests/kinematics) ---------------------------------------------
#: The paper's robot: wheels, track, speed and sample time.
PAPER_ROBOT = Robot(radius=28.5, wheel_radius=7.6, track_width=38.0, speed=20.0, sample_time=0.15)
#: Their 500 x 500 cm workspace.
BOUNDS = ((0.0, 0.0), (500.0, 500.0))


def arc_curve(radius: float, angle: float, n: int = 2000) -> ReferenceCurve:
    """An exact circular arc, counter-clockwise, sampled by arc length."""
    phi = np.linspace(0.0, angle, n)
    s = radius * phi
    return ReferenceCurve(
        s=s, x=250 + radius * np.sin(phi), y=250 - radius * np.cos(phi), theta=phi,
        kappa=np.full(n, 1.0 / radius), turns=np.zeros(n), kind="spline", knots=np.zeros((0, 2)),
    )  # fmt: skip


# -- occupancy maps (tests/model, tests/cli) -------------------------------------------------
def _pgm(path, img: np.ndarray, binary: bool = True, maxval: int = 255) -> None:
    h, w = img.shape
    if binary:
        dtype = ">u2" if maxval > 255 else "u1"
        path.write_bytes(f"P5\n# c\n{w} {h}\n{maxval}\n".encode() + img.astype(dtype).tobytes())
    else:
        rows = "\n".join(" ".join(str(int(v)) for v in row) for row in img)
        path.write_text(f"P2\n# comment\n{w} {h}\n# another\n{maxval}\n{rows}\n")


def _map(tmp_path, img, name="m", image=None, **keys) -> str:
    """A map YAML next to its image (a PGM unless ``image`` names one already written)."""
    if image is None:
        image = f"{name}.pgm"
        _pgm(tmp_path / image, img)
    doc = {"image": image, "resolution": 0.5, "origin": [0.0, 0.0, 0.0], "negate": 0,
           "occupied_thresh": 0.65, "free_thresh": 0.196, **keys}  # fmt: skip
    path = tmp_path / f"{name}.yaml"
    path.write_text(json.dumps(doc))  # JSON is YAML
    return str(path)


def turned_copy(tmp_path, name: str, yaw: float, pivot=(0.0, 0.0), **problem):
    """A copy of ``problems/maps/<name>.yaml`` whose map is turned by ``yaw`` radians about
    ``pivot``: its YAML's origin becomes ``[*pivot, yaw]`` (the image's lower-left corner moves
    to ``pivot``), and the start and goal move and turn with it. Returns the problem file and
    the move (a function of ``(..., 2)`` points: ``pivot + R(yaw) (p - old origin)``)."""
    import yaml

    src = PROBLEMS / "maps" / f"{name}.yaml"
    doc = yaml.safe_load(src.read_text())
    map_yaml = src.parent / doc["map"]
    grid = yaml.safe_load(map_yaml.read_text())
    shutil.copy(map_yaml.parent / grid["image"], tmp_path / grid["image"])
    old = np.array(grid["origin"][:2], dtype=float)
    grid["origin"] = [float(pivot[0]), float(pivot[1]), float(yaw)]
    (tmp_path / f"{name}_map.yaml").write_text(json.dumps(grid))
    c, s = np.cos(yaw), np.sin(yaw)

    def move(p):
        d = np.asarray(p, dtype=float) - old
        return np.asarray(pivot) + np.stack([c * d[..., 0] - s * d[..., 1],
                                             s * d[..., 0] + c * d[..., 1]], axis=-1)  # fmt: skip

    doc.update({"map": f"{name}_map.yaml", "start": move(doc["start"]).tolist(),
                "goal": move(doc["goal"]).tolist(), **problem})  # fmt: skip
    path = tmp_path / f"{name}.yaml"
    path.write_text(json.dumps(doc))
    return path, move


def map_shapes(problem, cells: bool = False):
    """What a map problem's map blocks, as one shapely geometry in the map frame, built
    independently of the world's checks: its blocked cells (``cells``: each cell's square, else
    the merged boxes) turned by shapely about the origin, and, when unknown space blocks, the
    bounds outside the map's turned rectangle."""
    import shapely
    from shapely import affinity

    m = problem.map
    if cells:
        rows, cols = np.nonzero(m.blocked)
        boxes = np.array([m.cell_box(i, j) for i, j in zip(rows, cols, strict=True)])
    else:
        boxes = m.boxes
    blocked = shapely.union_all(shapely.box(*boxes.T)) if len(boxes) else shapely.Polygon()
    (x0, y0), (x1, y1) = m.extent
    rect = shapely.box(x0, y0, x1, y1)
    blocked = affinity.rotate(blocked, m.yaw, origin=m.origin, use_radians=True)
    rect = affinity.rotate(rect, m.yaw, origin=m.origin, use_radians=True)
    if m.unknown_blocks:
        (bx0, by0), (bx1, by1) = problem.bounds
        outside = shapely.box(bx0, by0, bx1, by1).difference(rect)
        # Round-off slivers (a map turned by pi/2 in its own bounding box) are no unknown space:
        # an opening by 1e-9 drops them and keeps the rest (mitred, its corners stay sharp).
        outside = outside.buffer(-1e-9, join_style="mitre").buffer(1e-9, join_style="mitre")
        blocked = blocked.union(outside)
    return blocked


def _corridor(tmp_path, **problem) -> str:
    """A 20 x 10-cell map at 0.5 m: walls around, a wall with a gap in the middle, an unknown
    patch."""
    img = np.full((10, 20), 254, dtype=np.uint8)
    img[[0, -1], :] = 0
    img[:, [0, -1]] = 0
    img[0:7, 10] = 0  # wall from the top, gap at the bottom
    img[1:3, 14:17] = 205  # unknown
    _map(tmp_path, img, name="corridor")
    doc = {"map": "corridor.yaml", "start": [2.0, 3.0], "goal": [8.0, 2.5],
           "robot": {"radius": 0.3}, **problem}  # fmt: skip
    path = tmp_path / "prob.yaml"
    path.write_text(json.dumps(doc))
    return str(path)


#: Runs the command line in a subprocess whose PYTHONPATH holds an installed plugin.
CLI_CODE = "import sys; from rrtpso_ompl.cli.main import main; sys.exit(main(sys.argv[1:]))"


def install_plugin(tmp_path: Path, name: str, source: str, group: str,
                   entry_points: dict[str, str]) -> dict[str, str]:  # fmt: skip
    """Build the one-module package ``name`` (``source``, with ``entry_points`` in the entry-point
    ``group``) and really install it, offline, into a target folder; the environment of a
    subprocess that sees it (run :data:`CLI_CODE` with it)."""
    import subprocess
    import sys
    import textwrap

    pkg = tmp_path / name
    (pkg / name).mkdir(parents=True)
    (pkg / name / "__init__.py").write_text(source)
    lines = "\n".join(f'{k} = "{v}"' for k, v in entry_points.items())
    (pkg / "pyproject.toml").write_text(textwrap.dedent(f"""
        [build-system]
        requires = ["setuptools"]
        build-backend = "setuptools.build_meta"
        [project]
        name = "{name}"
        version = "0.1"
        [project.entry-points."{group}"]
    """) + lines + "\n")  # fmt: skip
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
                    "--no-build-isolation", "--target", str(target), str(pkg)],
                   check=True, capture_output=True)  # fmt: skip
    return {"PYTHONPATH": str(target), "PATH": str(Path(sys.executable).parent)}


#: A wall at x = 4.8..5.2 with a door 0.8 wide at y = 4.6..5.4 (robot radius 0.2, inflation
#: radius 0.6: the door is narrower than 2 x 0.6 but wider than 2 x 0.2), and a pillar.
INFLATED_DOOR = {
    "bounds": [[0, 0], [10, 10]], "start": [1, 8], "goal": [9, 2],
    "robot": {"radius": 0.2, "inflation_radius": 0.6, "cost_scaling_factor": 3.0},
    "obstacles": [{"type": "rectangle", "min": [4.8, 0], "max": [5.2, 4.6]},
                  {"type": "rectangle", "min": [4.8, 5.4], "max": [5.2, 10]},
                  {"type": "circle", "center": [7.5, 3.5], "radius": 0.5}],
}  # fmt: skip


def exact_length(world, start, goal) -> float:
    """The exact optimum's length between two points of a World (no problem file: the few
    fields :func:`~rrtpso_ompl.groundtruth.optimum.shortest_path` reads)."""
    import math

    from rrtpso_ompl.groundtruth.optimum import shortest_path

    class P:
        pass

    p = P()
    p.start, p.goal, p.goal_tolerance, p.name, p.source = start, goal, 0.0, "t", "t"
    p.bounds = world.bounds
    return shortest_path(p, world, upper_bound=math.inf).length


def cells_world(blocked: np.ndarray, radius: float = 0.0):
    """A world of a grid's blocked unit cells (rows from the bottom; boxes on the lattice, as a
    map's), its bounds the grid, for a robot of ``radius`` cells."""
    from rrtpso_ompl.model import World

    rows, cols = np.nonzero(blocked)
    boxes = np.column_stack([cols, rows, cols + 1, rows + 1]).astype(float)
    ny, nx = blocked.shape
    return World(((0.0, 0.0), (float(nx), float(ny))), boxes=boxes, robot_radius=radius)


def assert_same_optimum_without(world, queries, monkeypatch, patch) -> int:
    """For each ``(start, goal)``: the exact optimum is the one found with ``patch(m)`` applied
    (to a ``monkeypatch`` context ``m``: a part of the search turned off), to 1e-9, and its
    path is valid; both or neither find one. Returns how many had a path."""
    import pytest

    from rrtpso_ompl.groundtruth.optimum import shortest_path_in_world

    checked = 0
    for start, goal in queries:
        new = shortest_path_in_world(world, start, goal)
        with monkeypatch.context() as m:
            patch(m)
            old = shortest_path_in_world(world, start, goal)
        if old.length is None:
            assert new.length is None
            continue
        checked += 1
        assert new.length == pytest.approx(old.length, rel=1e-9)
        assert world.path_valid(new.valid_polyline(world))
    return checked
