"""One query in one line (issue 36, item 1): ``--map``, ``--start``, ``--goal`` and the robot, for
``solve``, ``optimum`` and ``simulate``, with or without a problem file; validated as a file is,
the messages naming the flag."""

from __future__ import annotations

import json

import pytest
import yaml
from helpers import PROBLEMS, run

pytestmark = pytest.mark.slow

MAP = str(PROBLEMS / "maps" / "grids" / "office.yaml")
QUERY = ("--map", MAP, "--start", "2", "17.5", "--goal", "27.5", "3", "--radius", "0.3")
#: Iteration-bounded: the same path on any machine.
BOUNDED = ("--time", "60", "--seed", "4", "--param", "rrt_max_iterations=300",
           "--param", "iterations=20")  # fmt: skip


def test_the_direct_form_plans_what_the_same_file_plans(tmp_path):
    doc = {"map": MAP, "start": [2, 17.5], "goal": [27.5, 3], "robot": {"radius": 0.3}}
    (tmp_path / "office.yaml").write_text(yaml.safe_dump(doc))
    direct, filed = tmp_path / "direct.json", tmp_path / "filed.json"
    one = run("solve", *QUERY, *BOUNDED, "--json", str(direct))
    two = run("solve", str(tmp_path / "office.yaml"), *BOUNDED, "--json", str(filed))
    assert one.returncode == 0 and two.returncode == 0, one.stderr + two.stderr
    a, b = json.loads(direct.read_text()), json.loads(filed.read_text())
    assert a["solved"] and a["path"] == b["path"] and a["problem"] == "office"
    assert a["path"][0] == [2.0, 17.5] and a["path"][-1] == [27.5, 3.0]


def test_flags_override_a_problem_file_and_a_wrong_value_names_its_flag():
    proc = run("solve", str(PROBLEMS / "maps" / "office_rooms.yaml"), "--radius", "0.35",
               "--goal", "27", "3.5")  # fmt: skip
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert "office_rooms.yaml: --goal: the robot disc (radius 0.35) at (27, 3.5)" in proc.stderr


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("--map", MAP, "--start", "2", "17.5"), "missing: --goal, --radius"),
        ((*QUERY, "--start", "1"), "--start: give X Y or X Y YAW, got 1 numbers"),
        ((*QUERY, "--start", "2", "17.5", "45"), "--start: a heading (YAW) at the start applies "
                                                 "to a car-like robot only"),
        ((*QUERY, "--start", "0.1", "0.1"), "command line: --start: (0.1, 0.1) lies in the "
                                            "unknown map cell"),
        ((*QUERY, "--reverse"), "--reverse: applies to a car-like robot only"),
    ],
)  # fmt: skip
def test_a_bad_query_is_one_message_and_exit_2(args, words):
    proc = run("solve", *args)
    assert proc.returncode == 2 and words in proc.stderr and "Traceback" not in proc.stderr


def test_optimum_and_a_car_take_the_direct_form(tmp_path):
    out = tmp_path / "o.json"
    proc = run("optimum", *QUERY, "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    assert json.loads(out.read_text())["length"] == pytest.approx(34.774087, abs=1e-5)
    car = tmp_path / "car.json"
    proc = run("solve", "--map", MAP, "--start", "2", "17.5", "90", "--goal", "27.5", "3", "0",
               "--radius", "0.3", "--turning-radius", "0.6", "--time", "0.3", "--json",
               str(car))  # fmt: skip
    assert proc.returncode in (0, 1), proc.stderr  # time-bounded: solved or not, an answer
    stages = json.loads(car.read_text())["stages"]
    assert stages["space"] == "Dubins" and stages["stages"][0] == "corridor"  # a car's solve


def test_simulate_takes_the_direct_form_over_its_file():
    proc = run("simulate", str(PROBLEMS / "dynamic" / "paper_dynamic.yaml"), "--goal", "-5", "0")
    assert proc.returncode == 2 and "--goal: " in proc.stderr and "outside" in proc.stderr
