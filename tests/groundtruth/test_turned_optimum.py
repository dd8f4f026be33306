"""The exact optimum on turned maps (issue 26 item 3): a map turned with its start, goal and
obstacles has the same shortest path, turned (a rotation keeps lengths)."""

from __future__ import annotations

import itertools
import json
import math
import os

import numpy as np
import pytest
import shapely
from helpers import PROBLEMS, map_shapes, turned_copy

from rrtpso_ompl.groundtruth.optimum import shortest_path
from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.planners.solve import solve

#: Extra obstacles in the unturned office corridor: a circle in the corridor and a rectangle
#: at the door the optimum takes, so that the path bends round shapes as well as map cells.
_CIRCLE = {"type": "circle", "center": [15.0, 10.0], "radius": 0.4}
_RECT = ((19.0, 9.0), (19.6, 9.8))


def _pair(tmp_path, name, yaw, pivot, shapes=False, **problem):
    """The problem as shipped (with ``problem`` keys) and its turned copy: (flat, turned, move)."""
    flat_path = tmp_path / "flat.yaml"
    turned_path, move = turned_copy(tmp_path, name, yaw, pivot, **problem)
    flat = json.loads(turned_path.read_text())
    src = load_problem(PROBLEMS / "maps" / f"{name}.yaml")
    grid = os.path.abspath(src.map.source)
    flat.update(map={**problem["map"], "file": grid} if "map" in problem else grid,
                start=list(src.start), goal=list(src.goal))  # fmt: skip
    turned = json.loads(turned_path.read_text())
    if shapes:
        (x0, y0), (x1, y1) = _RECT
        corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
        flat["obstacles"] = [_CIRCLE, {"type": "rectangle", "min": [x0, y0], "max": [x1, y1]}]
        turned["obstacles"] = [
            {**_CIRCLE, "center": move(_CIRCLE["center"]).tolist()},
            {"type": "polygon", "points": move(corners).tolist()},
        ]
    flat_path.write_text(json.dumps(flat))
    turned_path.write_text(json.dumps(turned))
    return load_problem(flat_path), load_problem(turned_path), move


@pytest.mark.parametrize(("name", "yaw", "pivot", "shapes"), [
    ("office_corridor", 0.3, (0.0, 0.0), True),
    ("office_rooms", -2.0, (10.0, 5.0), False),
    ("lab_clutter", math.pi / 2, (3.0, -1.0), False),
    ("lab_diagonal", 0.3, (-4.0, 2.0), False),
])  # fmt: skip
def test_the_optimum_of_a_turned_map_is_the_unturned_optimum_turned(
    tmp_path, name, yaw, pivot, shapes
):
    flat, turned, _ = _pair(tmp_path, name, yaw, pivot, shapes)
    assert turned.map_frame is not None and turned.map_frame.confined is not None
    a, b = shortest_path(flat), shortest_path(turned)
    assert a.found and b.found and a.exact and b.exact
    assert b.length == pytest.approx(a.length, abs=1e-6)
    if shapes:  # the shapes are in the way: the optimum is longer than the shipped one's
        shipped = shortest_path(load_problem(PROBLEMS / "maps" / f"{name}.yaml"))
        assert a.length > shipped.length + 0.01
    # Its pieces are the world's (turned back from grid coordinates): they join start to goal,
    # each arc's ends lie on its circle, and the polyline keeps the radius from every turned
    # cell and shape, as shapely sees them.
    pieces = b.pieces
    assert pieces[0].start == pytest.approx(tuple(turned.start), abs=1e-9)
    assert pieces[-1].end == pytest.approx(tuple(turned.goal), abs=1e-9)
    for p, q in itertools.pairwise(pieces):
        assert p.end == pytest.approx(q.start, abs=1e-9)
    for p in (p for p in pieces if p.kind == "arc"):
        assert math.dist(p.start, p.center) == pytest.approx(p.radius, abs=1e-9)
        angle = math.atan2(p.start[1] - p.center[1], p.start[0] - p.center[0])
        assert math.remainder(angle - p.angle, 2 * math.pi) == pytest.approx(0.0, abs=1e-9)
    world = World.from_problem(turned)
    path = b.valid_polyline(world)
    assert world.path_valid(path)
    blocked = map_shapes(turned)
    if shapes:
        blocked = blocked.union(
            shapely.Point(turned.obstacles[0].center).buffer(
                turned.obstacles[0].radius, quad_segs=256
            )
        )
        blocked = blocked.union(shapely.Polygon(turned.obstacles[1].points))
    d = shapely.distance(blocked, shapely.linestrings(np.stack([path[:-1], path[1:]], axis=1)))
    assert d.min() >= turned.robot.radius - 1e-6  # the circle is a 1024-gon inside it


def test_a_turned_map_whose_free_space_is_not_confined_to_it_is_solved_exactly_too(tmp_path):
    """``unknown: free``: the robot may leave the map, so grid coordinates have no box bounds;
    the turned cells are searched as polygons, to the same length."""
    flat, turned, _ = _pair(tmp_path, "lab_clutter", 0.3, (1.0, 1.0),
                            map={"file": "lab_clutter_map.yaml", "unknown": "free"})  # fmt: skip
    assert not flat.map.unknown_blocks and turned.map_frame.confined is None
    a, b = shortest_path(flat), shortest_path(turned)
    assert b.length == pytest.approx(a.length, abs=1e-6)
    assert World.from_problem(turned).path_valid(b.valid_polyline(World.from_problem(turned)))


def test_the_exact_planner_solves_a_turned_map_to_the_optimum(tmp_path):
    flat, turned, _ = _pair(tmp_path, "office_corridor", 0.3, (2.0, -1.0))
    r = solve(turned, "Exact", time_limit=10.0)
    assert r.solved and r.length == pytest.approx(shortest_path(flat).length, rel=1e-4)
    assert World.from_problem(turned).path_valid(np.array(r.path))


class _AdversarialNumpy:
    """numpy, but ``np.empty`` returns memory holding ``fill`` (what it held before is
    whatever the process left there)."""

    def __init__(self, fill: float) -> None:
        self.fill = fill

    def __getattr__(self, name):
        return getattr(np, name)

    def empty(self, shape, dtype=float):
        return np.full(shape, self.fill, dtype)


@pytest.mark.parametrize("fill", [7.0, 3.0, -1.0, 1e300])
def test_polygons_cast_no_shadow_whatever_unset_memory_holds(tmp_path, monkeypatch, fill):
    """The tangent filter's shadows come from the discs of circles and boxes near a circle; a
    polygon's index items have none (their rows are never set). Its interiors used to be read
    anyway: unset memory made the optimum of this turned map 13.09 m instead of 12.63 m in
    some runs (a polygon world's, generally). Here unset memory is made to hold ``fill``."""
    from rrtpso_ompl.groundtruth.optimum import shadows

    flat, turned, _ = _pair(tmp_path, "lab_diagonal", 0.3, (-4.0, 2.0))
    assert len(World.from_problem(turned).polygons) == 4  # the unknown corners
    want = shortest_path(flat).length
    monkeypatch.setattr(shadows, "np", _AdversarialNumpy(fill))
    assert shortest_path(turned).length == pytest.approx(want, abs=1e-6)
