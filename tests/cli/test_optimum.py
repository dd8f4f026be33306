"""``rrtpso optimum``: the JSON contract, the plot and bad input."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest
from helpers import PROBLEMS, rrtpso_exe

pytestmark = pytest.mark.slow


def test_cli_writes_the_contract(tmp_path):
    out = tmp_path / "opt.json"
    png = tmp_path / "opt.png"
    problem = PROBLEMS / "static" / "single_circle.yaml"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(problem), "--json", str(out),
                           "--plot", str(png)], capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert list(data)[:2] == ["length", "path"]
    assert data["length"] == pytest.approx(647.4596, abs=1e-4)
    path = np.array(data["path"])
    assert np.allclose(path[0], (20, 20)) and np.allclose(path[-1], (450, 450))
    assert png.stat().st_size > 1000


def test_cli_bad_file_exit_2(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("bounds: [[0, 0], [10, 10]]\nstart: [1, 1]\n")
    out = tmp_path / "opt.json"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(bad), "--json", str(out)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 2
    assert str(bad) in proc.stderr and "goal" in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()


#: A wall across x = 5 with a door 0.8 m wide; the robot's inflation (1 m) reaches across it.
DOOR = """\
name: door
units: m
bounds: [[0, 0], [10, 10]]
start: [1, 2]
goal: [9, 2]
robot: {radius: 0.2%s}
obstacles:
  - {type: rectangle, min: [4.9, -1], max: [5.1, 4.6]}
  - {type: rectangle, min: [4.9, 5.4], max: [5.1, 11]}
"""


def test_cost_writes_the_grid_reference_of_the_objective(tmp_path):
    from rrtpso_ompl.model import World, load_problem
    from rrtpso_ompl.model.objective import InflationCost

    problem = tmp_path / "door.yaml"
    problem.write_text(DOOR % ", inflation_radius: 1.0")
    out, png = tmp_path / "ref.json", tmp_path / "ref.png"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(problem), "--cost", "--resolution",
                           "0.1", "--json", str(out), "--plot", str(png)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "grid reference J=" in proc.stderr and "h=0.1," in proc.stderr
    data = json.loads(out.read_text())
    assert list(data)[:3] == ["length", "path", "cost"]
    loaded = load_problem(problem)
    world = World.from_problem(loaded)
    path = np.array(data["path"])
    assert world.path_valid(path)
    assert data["cost"] == pytest.approx(InflationCost.of(loaded.robot).path_cost(world, path))
    assert data["grid"]["resolution"] == pytest.approx(0.1) and data["grid"]["edges"] > 0
    assert data["cost"] <= data["grid"]["cost"]
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_cost_without_inflation_is_the_exact_shortest_path(tmp_path):
    problem = tmp_path / "door.yaml"
    problem.write_text(DOOR % "")
    out = tmp_path / "opt.json"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(problem), "--cost", "--json", str(out)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "no inflation: J is the length" in proc.stderr
    data = json.loads(out.read_text())
    assert list(data)[:3] == ["length", "path", "cost"] and data["cost"] == data["length"]
    assert data["exact"] is True and data["pieces"]


@pytest.mark.parametrize(
    "flags,needle",
    [
        (["--resolution", "0.1"], "--resolution: only with --cost"),
        (["--cost", "--resolution", "0"], "--resolution: must be a positive number"),
        (["--cost", "--resolution", "0.001"], "at most 2,000,000"),
    ],
)
def test_cost_bad_resolution_exit_2_without_output(tmp_path, flags, needle):
    problem = tmp_path / "door.yaml"
    problem.write_text(DOOR % ", inflation_radius: 1.0")
    out = tmp_path / "ref.json"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(problem), *flags, "--json", str(out)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 2
    assert needle in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not out.exists()


#: A wall across the whole workspace: no path exists.
WALLED = """\
name: walled
bounds: [[0, 0], [10, 10]]
start: [1, 1]
goal: [9, 9]
robot: {radius: 0.2}
obstacles:
  - {type: rectangle, min: [4.9, -1], max: [5.1, 11]}
"""


@pytest.mark.parametrize(
    ("problem", "flags", "status", "needle"),
    [
        (PROBLEMS / "static" / "single_circle.yaml", [], 0, "optimum length=647.45"),
        (PROBLEMS / "static" / "maze.yaml", ["--plot", "o.png"], 0, "optimum length="),
        (PROBLEMS / "maps" / "office_rooms.yaml", [], 0, "optimum length=34.77"),
        (PROBLEMS / "static" / "single_circle.yaml", ["--cost"], 0, "J is the length"),
        (PROBLEMS / "static" / "single_circle.yaml", ["--path-out", "p.yaml"], 0, "length="),
        ("walled.yaml", ["--plot", "o.png"], 1, "no path exists"),
        ("walled.yaml", ["--path-out", "p.yaml"], 1, "no path exists"),
    ],
    ids=["plain", "plot-only", "map", "cost-plain", "path-out-only", "none-plot", "none-path"],
)  # fmt: skip
def test_optimum_without_json_reports_and_writes_what_was_asked(
    tmp_path, problem, flags, status, needle
):
    """The result is built whatever the outputs ask for (issue 32, item 7: these crashed with
    'NoneType' object is not subscriptable)."""
    (tmp_path / "walled.yaml").write_text(WALLED)
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(problem), *flags],
                          capture_output=True, text=True, cwd=tmp_path)  # fmt: skip
    assert proc.returncode == status, proc.stderr
    assert needle in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    if "--plot" in flags:
        assert (tmp_path / "o.png").read_bytes()[:4] == b"\x89PNG"
    if "--path-out" in flags:  # written only when there is a path
        assert (tmp_path / "p.yaml").exists() == (status == 0)
