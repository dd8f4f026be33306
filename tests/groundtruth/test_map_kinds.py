"""The occupancy-grid map kinds of ``rrtpso generate`` (rooms_map, maze_map, ...): seeded, checked,
certified, written as three files all or nothing."""

from __future__ import annotations

import contextlib
import json
import math
import os
import subprocess

import numpy as np
import pytest
import yaml
from helpers import rrtpso_exe

from rrtpso_ompl.errors import GenerationError
from rrtpso_ompl.groundtruth import generate, generate_to_file, map_kinds, shortest_path
from rrtpso_ompl.groundtruth.generate import GENERATORS, generate_map
from rrtpso_ompl.groundtruth.map_kinds import MapKindOptions
from rrtpso_ompl.model import load_problem
from rrtpso_ompl.model.occupancy import load_map
from rrtpso_ompl.model.world import World

MAP_KINDS = [k for k, c in GENERATORS.items() if issubclass(c, MapKindOptions)]
#: Small maps: quick tests.
SMALL = {"cells": 48}
#: One out-of-range option per kind, and the name the message must give.
BAD = {
    "rooms_map": ({"door": (5, 2)}, "door"),
    "maze_map": ({"corridor": 0}, "corridor"),
    "city_map": ({"plazas": 1.5}, "plazas"),
    "warehouse_map": ({"aisle": (0, 3)}, "aisle"),
    "caves_map": ({"fill": 0.95}, "fill"),
    "random_map": ({"density": -0.1}, "density"),
}


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*rrtpso_exe(), *args], capture_output=True, text=True, timeout=120)


def three(out):
    return map_kinds.map_output_paths(out)


def test_the_six_map_kinds_are_registered():
    assert MAP_KINDS == ["rooms_map", "maze_map", "city_map", "warehouse_map", "caves_map",
                         "random_map"]  # fmt: skip
    assert set(BAD) == set(MAP_KINDS)


@pytest.mark.parametrize("kind", MAP_KINDS)
def test_same_seed_same_bytes_other_seed_other_map(kind, tmp_path):
    a = generate_to_file(kind, 3, tmp_path / "a" / "p.yaml", **SMALL)
    b = generate_to_file(kind, 3, tmp_path / "b" / "p.yaml", **SMALL)
    for x, y in zip(three(a), three(b), strict=True):
        assert x.read_bytes() == y.read_bytes(), x.name
    c = generate_to_file(kind, 4, tmp_path / "c" / "p.yaml", **SMALL)
    assert three(c)[2].read_bytes() != three(a)[2].read_bytes()  # another map
    # The problem names its map relatively, the map its image: the folder can move.
    doc = yaml.safe_load(a.read_text())
    assert doc["map"] == "p_map.yaml" and "bounds" not in doc and doc["units"] == "m"
    assert yaml.safe_load(three(a)[1].read_text())["image"] == "p_map.pgm"


@pytest.mark.parametrize("kind", MAP_KINDS)
def test_a_bad_option_is_one_generation_error_naming_it(kind):
    options, name = BAD[kind]
    with pytest.raises(GenerationError, match=name):
        generate(kind, 1, **SMALL, **options)


def test_map_kinds_refuse_what_does_not_apply_to_them():
    with pytest.raises(GenerationError, match="resolution"):
        generate("rooms_map", 1, resolution=0.5)
    with pytest.raises(GenerationError, match="does not apply"):
        generate("rooms_map", 1, corridor=2)  # a maze_map option
    with pytest.raises(GenerationError, match="corridor"):
        generate("maze_map", 1, cells=16, corridor=12, wall_cells=4)


@pytest.mark.parametrize("kind", MAP_KINDS)
def test_the_problem_is_valid_and_certified_and_the_exact_optimum_agrees(kind, tmp_path):
    out = generate_to_file(kind, 5, tmp_path / "p.yaml", **SMALL)
    problem = load_problem(out)
    grid = load_map(three(out)[1])
    assert grid.shape == (48, 48) and math.isclose(grid.resolution, 100.0 / 48)
    assert problem.map is not None and set(np.unique(grid.state)) <= {0, 1}
    world = World.from_problem(problem)
    assert world.point_free(*problem.start) and world.point_free(*problem.goal)
    assert math.dist(problem.start, problem.goal) >= 50.0  # half the map side
    # The default robot is a quarter of a cell (rounded down to the file's decimals).
    assert 0.24 * grid.resolution < problem.robot.radius <= 0.25 * grid.resolution
    best = shortest_path(problem, world)
    assert best.found
    certified = float(problem.description.split("path of length ")[1].split()[0])
    assert best.length <= certified * (1 + 1e-9)


def test_a_real_rrtpso_solve_finds_a_valid_path_on_a_generated_map(tmp_path):
    out = tmp_path / "rooms.yaml"
    proc = run("generate", "rooms_map", "--seed", "2", "--cells", "40", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    result = tmp_path / "r.json"
    proc = run("solve", str(out), "--time", "0.5", "--planner", "RRTstar", "--json", str(result))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(result.read_text())
    problem = load_problem(out)
    assert data["solved"] and World.from_problem(problem).path_valid(np.array(data["path"]))


def test_one_cell_corridors_stay_passable_with_the_default_robot():
    data = generate("maze_map", 7, cells=41, corridor=1, wall_cells=1, loops=0.1)
    assert "collision-free path of length" in data["description"]


def test_query_moves_start_and_goal_not_the_map(tmp_path):
    a = generate_map("caves_map", 9, **SMALL)
    b = generate_map("caves_map", 9, query=1, **SMALL)
    assert np.array_equal(a.blocked, b.blocked)
    assert (a.problem["start"], a.problem["goal"]) != (b.problem["start"], b.problem["goal"])
    # On file too: the map's bytes are the same.
    pa = generate_to_file("caves_map", 9, tmp_path / "a.yaml", **SMALL)
    pb = generate_to_file("caves_map", 9, tmp_path / "b.yaml", query=1, **SMALL)
    assert three(pa)[2].read_bytes() == three(pb)[2].read_bytes()
    assert "--query 1" in pb.read_text().splitlines()[0]


def test_generate_returns_the_problem_and_generate_map_the_map_too():
    data = generate("warehouse_map", 2, **SMALL)
    assert data["map"] == "warehouse_map_2_map.yaml"
    m = generate_map("warehouse_map", 2, **SMALL)
    assert m.problem == data
    assert m.image.dtype == np.uint8 and set(np.unique(m.image)) == {0, 254}
    assert np.array_equal(m.image == 0, m.blocked)
    assert m.pgm_bytes().startswith(b"P5\n48 48\n255\n") and len(m.pgm_bytes()) == 13 + 48 * 48
    with pytest.raises(GenerationError, match="not a map kind"):
        generate_map("circles", 1)


def test_exact_states_the_exact_length():
    data = generate("rooms_map", 4, exact=True, **SMALL)
    assert "(exact, rrtpso optimum)" in data["description"]


def test_a_robot_that_fits_nowhere_is_refused():
    with pytest.raises(GenerationError, match=r"robot fits nowhere|no two cells"):
        generate("maze_map", 1, cells=16, robot_radius=30.0, max_attempts=2)


def test_the_header_command_regenerates_the_three_files(tmp_path):
    import shlex

    first = generate_to_file("maze_map", 3, tmp_path / "a" / "p.yaml", cells=24, corridor=1,
                             exact=True)  # fmt: skip
    command = first.read_text().splitlines()[0].removeprefix("# Generated by: ")
    assert command == "rrtpso generate maze_map --seed 3 --cells 24 --exact --corridor 1 --out FILE"
    proc = run(*shlex.split(command)[1:-1], str(tmp_path / "b" / "p.yaml"))
    assert proc.returncode == 0, proc.stderr
    # The command says it wrote the map's two files too, naming them.
    b = tmp_path / "b"
    assert f"wrote {b / 'p.yaml'} and its map, {b / 'p_map.yaml'} and {b / 'p_map.pgm'}" in (
        proc.stderr)  # fmt: skip
    for x, y in zip(three(first), three(tmp_path / "b" / "p.yaml"), strict=True):
        assert x.read_bytes() == y.read_bytes()


# ----------------------------------------------------------------------------------------------
# The three files follow the output rules
# ----------------------------------------------------------------------------------------------
# Each case runs the command (a second each): the quick run keeps one (pytest.mark.slow).
@pytest.mark.parametrize(
    "which", [0, pytest.param(1, marks=pytest.mark.slow), pytest.param(2, marks=pytest.mark.slow)]
)
def test_any_existing_file_is_refused_without_overwrite_and_nothing_is_written(which, tmp_path):
    out = tmp_path / "p.yaml"
    paths = three(out)
    paths[which].write_text("mine\n")
    proc = run("generate", "random_map", "--seed", "1", "--cells", "32", "--out", str(out))
    assert proc.returncode == 2 and "--overwrite" in proc.stderr and "Traceback" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [paths[which].name]
    assert paths[which].read_text() == "mine\n"
    proc = run("generate", "random_map", "--seed", "1", "--cells", "32", "--out", str(out),
               "--overwrite")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert load_problem(out).map is not None


@contextlib.contextmanager
def read_only(folder):
    """``folder`` made unwritable: by its mode, and for root (whom modes do not stop) by the
    immutable attribute (skipped where chattr cannot set it)."""
    folder.chmod(0o500)
    immutable = False
    try:
        if os.geteuid() == 0:
            done = subprocess.run(["chattr", "+i", str(folder)], capture_output=True, check=False)
            if done.returncode != 0:
                pytest.skip("root writes into read-only folders and chattr +i is not available")
            immutable = True
        yield folder
    finally:
        if immutable:
            subprocess.run(["chattr", "-i", str(folder)], capture_output=True, check=False)
        folder.chmod(0o700)


def test_a_read_only_folder_is_refused_and_nothing_is_left(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    with read_only(folder):
        proc = run("generate", "rooms_map", "--seed", "1", "--cells", "32", "--out",
                   str(folder / "p.yaml"))  # fmt: skip
        assert proc.returncode == 2, proc.stderr
        assert "Traceback" not in proc.stderr and "p.yaml" in proc.stderr
        assert list(folder.iterdir()) == []


def test_a_write_that_fails_midway_leaves_nothing_behind(tmp_path, monkeypatch):
    """The pgm and the map YAML are in place when the problem's rename fails: both are removed,
    as is the temporary folder and the folder made for the files."""
    from rrtpso_ompl import outputs

    real = outputs.publish
    problem = tmp_path / "new" / "p.yaml"
    published = []

    def failing(tmp, target):
        if target == problem:  # the last of the three, into place (not inside the scratch folder)
            raise OSError(28, "No space left on device")
        real(tmp, target)
        published.append(target)

    monkeypatch.setattr(outputs, "publish", failing)
    with pytest.raises(GenerationError, match="No space left"):
        generate_to_file("rooms_map", 1, problem, cells=32)
    assert set(three(problem)[1:]) <= set(published)  # the map's two files were in place
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "what",
    [pytest.param(w, marks=pytest.mark.slow) for w in ("link", "directory")] + ["fifo", "stdout"],
)
def test_links_folders_fifos_and_stdout_are_refused(what, tmp_path):
    out = tmp_path / "p.yaml"
    target = three(out)[1]  # the map YAML's place
    if what == "link":
        (tmp_path / "elsewhere.yaml").write_text("x\n")
        target.symlink_to(tmp_path / "elsewhere.yaml")
    elif what == "directory":
        target.mkdir()
    elif what == "fifo":
        os.mkfifo(target)
    before = sorted(p.name for p in tmp_path.iterdir())
    name = "-" if what == "stdout" else str(out)
    with pytest.raises(GenerationError):
        generate_to_file("random_map", 1, name, cells=32)
    proc = run("generate", "random_map", "--seed", "1", "--cells", "32", "--out", name,
               "--overwrite")  # fmt: skip
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    if what == "link":
        assert (tmp_path / "elsewhere.yaml").read_text() == "x\n"


def test_options_of_the_same_name_have_one_type_across_kinds():
    """One flag serves every kind declaring an option (cells: maze and the map kinds): a name
    declared as a number by one kind and a range by another would break it."""
    seen: dict[str, tuple] = {}
    for kind, cls in GENERATORS.items():
        for spec in cls.PARAMS:
            shape = (spec.type, spec.length)
            assert seen.setdefault(spec.name, shape) == shape, (kind, spec.name)
