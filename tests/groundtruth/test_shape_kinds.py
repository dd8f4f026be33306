"""The shape kinds of ``rrtpso generate`` added in issue 25 (slabs, combs, spiral, rooms): seeded,
checked, certified."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from rrtpso_ompl.errors import GenerationError
from rrtpso_ompl.groundtruth import generate, generate_to_file, shortest_path
from rrtpso_ompl.groundtruth.generate import GENERATORS
from rrtpso_ompl.groundtruth.shape_kinds import CombsOptions, RoomsOptions, SlabsOptions
from rrtpso_ompl.model import load_problem
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.model.world import World

SHAPE_KINDS = ["slabs", "combs", "spiral", "rooms"]
#: Small problems: quick tests.
SMALL = {"slabs": {"rows": 3}, "combs": {"teeth": 4}, "spiral": {"turns": 2},
         "rooms": {"rooms": 3}}  # fmt: skip
BAD = {
    "slabs": ({"angle": (70.0, 20.0)}, "angle"),
    "combs": ({"reach": (0.0, 0.7)}, "reach"),
    "spiral": ({"turns": 0}, "turns"),
    "rooms": ({"extra_doors": 1.5}, "extra_doors"),
}


def test_the_kinds_are_registered():
    assert set(SHAPE_KINDS) <= set(GENERATORS)


@pytest.mark.parametrize("kind", SHAPE_KINDS)
def test_same_seed_same_bytes_other_seed_other_problem(kind, tmp_path):
    a = generate_to_file(kind, 3, tmp_path / "a.yaml", **SMALL[kind])
    b = generate_to_file(kind, 3, tmp_path / "sub" / "a.yaml", **SMALL[kind])
    c = generate_to_file(kind, 4, tmp_path / "c.yaml", **SMALL[kind])
    assert a.read_bytes() == b.read_bytes()
    assert load_problem(a).obstacles != load_problem(c).obstacles


@pytest.mark.parametrize("kind", SHAPE_KINDS)
def test_a_bad_option_is_one_generation_error_naming_it(kind):
    options, name = BAD[kind]
    with pytest.raises(GenerationError, match=name):
        generate(kind, 1, **{**SMALL[kind], **options})


@pytest.mark.parametrize("kind", SHAPE_KINDS)
def test_certified_and_the_exact_optimum_agrees(kind, tmp_path):
    problem = load_problem(generate_to_file(kind, 5, tmp_path / "p.yaml", **SMALL[kind]))
    assert problem.units == "m"
    world = World.from_problem(problem)
    assert world.point_free(*problem.start) and world.point_free(*problem.goal)
    stated = float(re.search(r"path of length ([0-9.]+) exists", problem.description)[1])
    best = shortest_path(problem, world)
    assert best.found and best.length <= stated * (1 + 1e-9)


@pytest.mark.parametrize(("kind", "low", "high"),
                         [("slabs", 30, 120), ("combs", 20, 20), ("rooms", 24, 48)])  # fmt: skip
def test_defaults_give_a_few_dozen_obstacles(kind, low, high):
    options = {"slabs": SlabsOptions, "combs": CombsOptions, "rooms": RoomsOptions}[kind]()
    data = options.resolved()
    obstacles = data.draw(np.random.default_rng(0))
    assert low <= len(obstacles) <= high


def test_slabs_are_slanted_thin_polygons_with_free_gaps():
    data = generate("slabs", 2, rows=3, angle=(30.0, 40.0))
    for o in data["obstacles"]:
        pts = np.array(o["points"])
        sides = np.hypot(*np.diff(np.vstack([pts, pts[:1]]), axis=0).T)
        assert o["type"] == "polygon" and len(pts) == 4
        assert sides.min() == pytest.approx(0.8, abs=0.01)  # 0.008 size
        edge = pts[1] - pts[0]
        slant = math.degrees(math.atan2(abs(edge[1]), abs(edge[0])))
        assert 29.9 <= slant <= 40.1


def test_combs_interleave_so_the_straight_line_is_blocked():
    problem = problem_from_dict(generate("combs", 1, teeth=3))
    world = World.from_problem(problem)
    assert not world.motion_free(*problem.start, *problem.goal)
    assert len(problem.obstacles) == 6
    best = shortest_path(problem, world)
    assert best.length > 3 * 100 * 0.6  # zig-zags around at least three teeth reaching 60 %


def test_spiral_reverse_swaps_start_and_goal():
    a = generate("spiral", 1, turns=2)
    b = generate("spiral", 1, turns=2, reverse=True)
    assert (a["start"], a["goal"]) == (b["goal"], b["start"])
    assert a["goal"] == [50.0, 50.0] and a["obstacles"] == b["obstacles"]


def test_rooms_without_extra_doors_have_a_spanning_tree_of_doors():
    n = 3
    data = generate("rooms", 4, rooms=n, extra_doors=0.0)
    walls = 2 * n * (n - 1)
    doors = n * n - 1  # each door splits its wall into two rectangles
    assert len(data["obstacles"]) == walls + doors


def test_a_robot_too_large_for_the_passages_is_refused():
    with pytest.raises(GenerationError, match="does not fit"):
        generate("spiral", 1, turns=20, robot_radius=2.0)
