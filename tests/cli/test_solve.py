"""``rrtpso solve`` as a user runs it: real processes, real files, exit codes, JSON."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
import yaml
from helpers import PROBLEMS, SINGLE_CIRCLE, rrtpso_exe, run

pytestmark = pytest.mark.slow

CONTRACT_KEYS = {"problem", "planner", "status", "solved", "length", "time", "seed", "path"}


@pytest.fixture
def circle_file(tmp_path: Path) -> Path:
    path = tmp_path / "single_circle.yaml"
    path.write_text(yaml.safe_dump(SINGLE_CIRCLE))
    return path


def test_solve_writes_contract_json_and_plot(circle_file, tmp_path):
    out, png = tmp_path / "r.json", tmp_path / "p.png"
    proc = run(
        "solve",
        str(circle_file),
        "--time",
        "0.3",
        "--seed",
        "3",
        "--json",
        str(out),
        "--plot",
        str(png),
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data.keys() >= CONTRACT_KEYS
    assert data["status"] == "exact" and data["solved"] is True
    assert data["planner"] == "RRTstarPSO" and data["seed"] == 3
    assert data["path"][0] == [20, 20] and data["path"][-1] == [450, 450]
    assert data["length"] == pytest.approx(647.45, rel=0.01)
    assert data["stages"]["pso_length"] <= data["stages"]["rrt_length"]
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # Quiet by default: no OMPL Info/Debug lines, no nanobind leak report.
    assert "Info:" not in proc.stdout + proc.stderr
    assert "leaked" not in proc.stderr


def test_verbose_shows_ompl_info(circle_file):
    proc = run("solve", str(circle_file), "--time", "0.1", "--planner", "RRTstar", "-v")
    assert "Info:" in proc.stdout + proc.stderr


def test_unsolved_exit_1_still_writes_json(tmp_path):
    problem = {
        "bounds": [[0, 0], [500, 500]],
        "start": [50, 50],
        "goal": [380, 380],
        "robot": {"radius": 10},
        "obstacles": [
            {"type": "rectangle", "min": [300, 300], "max": [460, 310]},
            {"type": "rectangle", "min": [300, 450], "max": [460, 460]},
            {"type": "rectangle", "min": [300, 300], "max": [310, 460]},
            {"type": "rectangle", "min": [450, 300], "max": [460, 460]},
        ],
    }
    f = tmp_path / "boxed.yaml"
    f.write_text(yaml.safe_dump(problem))
    out = tmp_path / "r.json"
    proc = run("solve", str(f), "--time", "0.2", "--planner", "RRTstar", "--json", str(out))
    assert proc.returncode == 1, proc.stderr
    data = json.loads(out.read_text())
    assert data["solved"] is False and data["status"] in ("none", "approximate")


BAD_INPUT = {
    "unknown-planner": (["--planner", "NoSuchPlanner"], "NoSuchPlanner"),
    "zero-time": (["--time", "0"], "--time"),
    "negative-time": (["--time", "-1"], "--time"),
    "unknown-param": (["--param", "no_such=1"], "no_such"),
    "bad-param-value": (["--param", "goal_bias=2"], "goal_bias"),
    "malformed-param": (["--param", "swarm_size"], "--param"),
    "c1-plus-c2": (["--param", "c1=3", "--param", "c2=1.5"], "c1"),
    "excluded-planner": (["--planner", "AORRTC"], "unavailable"),
    "plot-unknown-suffix": (["--plot", "out.xyz"], "--plot"),
    "plot-clearance-unknown-suffix": (["--plot-clearance", "out.xyz"], "--plot-clearance"),
}


@pytest.mark.parametrize("flags,needle", BAD_INPUT.values(), ids=BAD_INPUT.keys())
def test_bad_flags_exit_2_without_output(circle_file, tmp_path, flags, needle):
    out = tmp_path / "r.json"
    proc = run("solve", str(circle_file), *flags, "--json", str(out))
    assert proc.returncode == 2
    assert needle in proc.stderr
    if not any(f.startswith("--plot") for f in flags):  # planning errors name the problem
        assert circle_file.name in proc.stderr
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_bad_file_exit_2_names_file_and_key(tmp_path):
    bad = dict(SINGLE_CIRCLE, robot={"radius": -3})
    f = tmp_path / "neg.yaml"
    f.write_text(yaml.safe_dump(bad))
    out = tmp_path / "r.json"
    proc = run("solve", str(f), "--json", str(out))
    assert proc.returncode == 2
    assert "neg.yaml" in proc.stderr and "robot.radius" in proc.stderr
    assert "Traceback" not in proc.stderr and not out.exists()


def test_unknown_planner_in_file_names_the_key(tmp_path):
    f = tmp_path / "p.yaml"
    f.write_text(yaml.safe_dump(dict(SINGLE_CIRCLE, planner={"type": "Nope"})))
    proc = run("solve", str(f))
    assert proc.returncode == 2 and "planner.type" in proc.stderr and "RRTstarPSO" in proc.stderr


def test_output_into_a_directory_is_refused_before_planning(circle_file, tmp_path):
    proc = run("solve", str(circle_file), "--json", str(tmp_path))
    assert proc.returncode == 2 and "is a directory" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_missing_file_exit_2(tmp_path):
    proc = run("solve", str(tmp_path / "nope.yaml"))
    assert proc.returncode == 2 and "nope.yaml" in proc.stderr and "Traceback" not in proc.stderr


def test_same_seed_same_path_iteration_bounded(circle_file, tmp_path):
    """Reproducibility across processes, as docs/benchmarking.md states it: OMPL is seeded once
    per process, so each run is its own process; bounded by iterations (RRT*'s and the swarm's)
    under a time limit it never reaches, two processes with the same seed, running at the same
    time on a loaded machine, give the same result in every field but the clock's."""
    args = ["--time", "30", "--param", "rrt_max_iterations=600", "--param", "iterations=30",
            "--param", "refine_rounds=0", "--param", "polish_rounds=0"]  # fmt: skip
    procs = []
    for i, seed in enumerate((11, 11, 12)):
        cmd = [*rrtpso_exe(), "solve", str(circle_file), "--seed", str(seed), *args, "--json",
               str(tmp_path / f"r{i}.json")]  # fmt: skip
        procs.append(subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True))
    for proc in procs:
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 0, err
    rows = [json.loads((tmp_path / f"r{i}.json").read_text()) for i in range(3)]
    assert rows[0]["stages"]["rrt_iterations"] == 600  # the bound, not the clock, stopped RRT*
    texts = [json.dumps(_without_times(r), sort_keys=True) for r in rows]
    assert texts[0] == texts[1]
    # Another seed grows another tree (the returned path may agree: among circles the corridor
    # stage's path is the taut string of its corridor, the same for every seed).
    assert rows[0]["stages"]["rrt_path"] != rows[2]["stages"]["rrt_path"]


def _without_times(value):
    """A result without what the clock measured (times, and the progress's time stamps)."""
    if isinstance(value, dict):
        clock = ("time", "progress")
        return {k: _without_times(v) for k, v in value.items()
                if k not in clock and not k.endswith(("_time", " time"))}  # fmt: skip
    return value


#: The shipped problems with a drive (wheel radius, track width, speed, sample time).
DRIVEN = [p for p in sorted(PROBLEMS.glob("static/*.yaml")) if "wheel_radius" in p.read_text()]


@pytest.mark.parametrize("path", [*DRIVEN, PROBLEMS / "dynamic" / "paper_dynamic.yaml"],
                         ids=lambda p: p.stem)  # fmt: skip
def test_every_driven_problem_solves_and_drives(path, tmp_path):
    out, csv_out = tmp_path / "r.json", tmp_path / "t.csv"
    proc = run("solve", str(path), "--time", "0.5", "--seed", "1", "--json", str(out),
               "--trajectory", str(csv_out))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["solved"]
    assert data["kinematics"]["open_loop_max_error"] <= 0.02 * data["length"]
    assert csv_out.read_text().startswith("t,x,y,theta,v,omega,v_right,v_left,")


def test_output_files_get_normal_permissions(circle_file, tmp_path):
    out, png = tmp_path / "r.json", tmp_path / "p.png"
    proc = run("solve", str(circle_file), "--time", "0.1", "--json", str(out), "--plot", str(png))
    assert proc.returncode == 0, proc.stderr
    for f in (out, png):
        assert f.stat().st_mode & 0o044, f"{f.name} is readable by its owner only"
    assert not list(tmp_path.glob(".*"))  # no temporary file left behind
