"""The corridor stage: lattices, which cells are free, routes and the funnel."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely
from helpers import exact_length

from rrtpso_ompl.model import World
from rrtpso_ompl.model.geometry import path_length
from rrtpso_ompl.model.raster import Lattice, MapRaster
from rrtpso_ompl.planners.rrtstar_pso.corridor import channel, corridor_path, funnel, lattice_route


def _map_world(blocked_image, radius=0.0, res=1.0, origin=(0.0, 0.0), bounds=None):
    from rrtpso_ompl.model.occupancy import merge_cells

    img = np.asarray(blocked_image, dtype=bool)
    raster = MapRaster.from_image(img, origin, res)
    h, w = img.shape
    bounds = bounds or ((origin[0], origin[1]), (origin[0] + w * res, origin[1] + h * res))
    boxes = merge_cells(img, res, origin)
    return World(bounds, robot_radius=radius, boxes=boxes, raster=raster, raster_boxes=len(boxes))


def _brute_free(world: World, lat: Lattice) -> np.ndarray:
    """A cell is free when shapely finds no blocked square within the radius of it."""
    r = world.robot_radius
    squares = [shapely.box(*b) for b in world.boxes]
    union = shapely.union_all(squares) if squares else shapely.Polygon()
    out = np.zeros((lat.nx, lat.ny), dtype=bool)
    ox, oy = lat.origin
    for i in range(lat.nx):
        for j in range(lat.ny):
            cell = shapely.box(ox + i * lat.h, oy + j * lat.h, ox + (i + 1) * lat.h,
                               oy + (j + 1) * lat.h)  # fmt: skip
            if r > 0:
                out[i, j] = cell.distance(union) >= r - 1e-12
            else:
                out[i, j] = cell.intersection(union).area == 0.0
    return out


@pytest.mark.parametrize("radius", [0.0, 0.3, 1.0, 2.2])
@pytest.mark.parametrize("sub", [0.5, 1.0, 2.0])
def test_free_cells_of_a_map_agree_with_shapely(radius, sub):
    rng = np.random.default_rng(int(radius * 10 + sub * 3))
    img = rng.random((12, 15)) < 0.2
    world = _map_world(img, radius)
    lat = Lattice.over(world.bounds, 1.0 / sub, world.raster.origin)
    got = world.free_cells(lat)
    want = _brute_free(world, lat)
    if sub >= 1.0:
        assert np.array_equal(got, want)
    else:  # a coarser lattice than the map: conservative
        assert not (got & ~want).any()


def test_free_cells_of_circles_are_conservative():
    world = World(((0, 0), (50, 40)), circles=[(10, 10, 4), (30, 25, 6), (40, 8, 2.5)],
                  robot_radius=1.5)  # fmt: skip
    lat = world.lattice(900)
    got = world.free_cells(lat)
    assert got.sum() > 0.5 * got.size
    ox, oy = lat.origin
    for i, j in zip(*np.nonzero(got), strict=True):
        # the whole cell (its corners and centre) is free
        xs = ox + lat.h * np.array([i, i + 1, i, i + 1, i + 0.5])
        ys = oy + lat.h * np.array([j, j, j + 1, j + 1, j + 0.5])
        assert (world.point_clearance(np.column_stack([xs, ys])) >= world.threshold).all()


def test_funnel_pulls_the_string_round_the_inner_corner():
    # an L-shaped channel of unit cells: along the bottom row, then up the right column
    cells = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2)]
    from rrtpso_ompl.planners.rrtstar_pso.corridor.funnel import channel_portals

    lat = Lattice((0.0, 0.0), 1.0, 3, 3)
    rects = np.array([(i, i + 1, j, j + 1) for i, j in cells])
    path = funnel((0.5, 0.5), (2.5, 2.5), channel_portals(list(range(5)), rects, lat, 0.0))
    assert np.allclose(path, [[0.5, 0.5], [2.0, 1.0], [2.5, 2.5]])


def test_channel_cells_share_edges():
    route = [(0, 0), (1, 1), (3, 2), (4, 4), (3, 3), (1, 2)]
    cells = channel(route)
    for (i0, j0), (i1, j1) in itertools.pairwise(cells):
        assert abs(i1 - i0) + abs(j1 - j0) == 1


def test_a_one_cell_maze_gives_the_exact_shortest_path():
    # a zig-zag corridor one cell wide, point robot: the taut path touches the corners
    img = np.array(
        [
            [1, 1, 1, 1, 1, 1, 1],
            [1, 0, 0, 0, 0, 0, 1],
            [1, 1, 1, 1, 1, 0, 1],
            [1, 0, 0, 0, 0, 0, 1],
            [1, 0, 1, 1, 1, 1, 1],
            [1, 0, 0, 0, 0, 0, 1],
            [1, 1, 1, 1, 1, 1, 1],
        ]
    )
    world = _map_world(img)
    start, goal = (1.5, 5.5), (5.5, 1.5)  # top-left corridor to bottom-right
    res = corridor_path(world, start, goal, 10_000)
    assert res.path is not None and world.path_valid(res.path)
    exact = exact_length(world, start, goal)  # the exact optimum of the same world
    assert res.length == pytest.approx(exact, rel=1e-4)
    assert res.length >= exact * (1 - 1e-9)


def test_no_route_is_reported_honestly():
    img = np.zeros((6, 6), dtype=bool)
    img[:, 3] = True  # a wall splits the map
    world = _map_world(img)
    res = corridor_path(world, (1.0, 3.0), (5.0, 3.0), 1000)
    assert res.path is None and "no route" in res.reason


def test_routes_prefer_the_shorter_door():
    img = np.zeros((20, 20), dtype=bool)
    img[10, :] = True
    img[10, 2:4] = False  # a door far to the left
    img[10, 12:14] = False  # a door right above the goal's column
    world = _map_world(img, radius=0.4)
    res = corridor_path(world, (12.5, 2.5), (13.5, 17.5), 10_000)
    assert res.path is not None and world.path_valid(res.path)
    assert res.length < 16.0  # through the near door: about 15, via the far one over 28


def test_lattice_route_is_none_between_walled_off_cells():
    free = np.ones((5, 5), dtype=bool)
    free[2, :] = False
    assert lattice_route(free, (0, 0), (4, 4)) is None
    route = lattice_route(np.ones((5, 5), dtype=bool), (0, 0), (4, 4))
    assert route[0] == (0, 0) and route[-1] == (4, 4) and len(route) == 5
    assert path_length(np.array(route, float)) == pytest.approx(4 * math.sqrt(2))


@pytest.mark.parametrize("radius", [0.1, 0.24, 0.45])
def test_a_disc_robot_on_a_map_is_pulled_round_the_door_jambs(radius):
    # Rooms 10 cells wide joined by doors 2 cells wide at different heights: the wholly free
    # lattice cells lose a cell along every wall, so their funnel swings wide round each jamb;
    # the wrapped funnel bends round the jambs at the robot's radius, as the optimum does.
    img = np.zeros((12, 34), dtype=bool)
    img[0, :] = img[-1, :] = img[:, 0] = img[:, -1] = True
    for col, door in ((11, 2), (22, 8)):
        img[:, col] = True
        img[door : door + 2, col] = False
    world = _map_world(img, radius=radius)
    start, goal = (1.5, 1.5), (32.5, 1.5)
    res = corridor_path(world, start, goal, 10_000)
    assert res.path is not None and world.path_valid(res.path)
    exact = exact_length(world, start, goal)
    assert exact * (1 - 1e-9) <= res.length <= exact * 1.002


def _detailed_world() -> World:
    """A gear of 20,000 vertices across the straight line: marking a lattice among its edges
    is slow enough to matter at a real-time budget."""
    k = np.arange(20_000)
    rad = np.where(k % 2, 23.0, 20.0)
    ang = 2 * np.pi * k / len(k)
    gear = np.column_stack([50 + rad * np.cos(ang), 50 + rad * np.sin(ang)])
    return World(((0.0, 0.0), (100.0, 100.0)), [], [gear], 1.0)


def test_the_corridor_stage_stops_marking_cells_when_terminated():
    """The stage's termination condition reaches into a lattice marking: fired at its fifth
    look (whatever the clock says), the stage ends without a path and says why."""
    from rrtpso_ompl.planners.rrtstar_pso.corridor import find_corridor_path

    looks = []

    def terminate() -> bool:
        looks.append(1)
        return len(looks) >= 5

    result = find_corridor_path(
        _detailed_world(), (5.0, 5.0), (95.0, 95.0), 1e6, terminate=terminate
    )
    assert result.path is None and result.reason == "out of time marking the lattice's cells"
    assert len(looks) == 5


def test_obstacles_too_detailed_to_mark_in_time_end_the_stage_at_once():
    """The probe that measures the cost of marking is cut at its share of the time: with none
    (a budget of 0 s) the stage gives up before any lattice."""
    from rrtpso_ompl.planners.rrtstar_pso.corridor import find_corridor_path

    result = find_corridor_path(_detailed_world(), (5.0, 5.0), (95.0, 95.0), 0.0)
    assert result.path is None and "too slow" in result.reason and result.lattice is None


def test_a_wall_corner_passed_on_the_line_between_two_bends_is_pushed_off_too():
    """Three wall corners on one line, the walls on alternate sides (a zig-zag of zero
    clearance, common among random blocked cells): the funnel bends at the outer two only.
    Pushed apart, their segment would cross the middle corner exactly (it touches the wall,
    which counts as entering); the middle corner becomes a vertex pushed off its own wall."""
    from rrtpso_ompl.planners.rrtstar_pso.corridor.funnel import push_off_corners

    free = np.ones((5, 4), dtype=bool)
    free[3, 1] = free[1, 2] = False  # A below the line y = 2, right; B above it, left
    lat = Lattice((0.0, 0.0), 1.0, 5, 4)
    # round A's top-left corner (3, 2), along y = 2 past B's bottom-right corner (2, 2), round
    # B's bottom-left corner (1, 2)
    path = np.array([(4.5, 2.5), (3.0, 2.0), (1.0, 2.0), (0.5, 1.5)])
    pushed = push_off_corners(path, lat, free, 1e-3)
    walls = shapely.union_all([shapely.box(3, 1, 4, 2), shapely.box(1, 2, 2, 3)])
    assert shapely.LineString(pushed).distance(walls) > 1e-4
    assert len(pushed) == 5  # the middle corner inserted
    assert path_length(pushed) == pytest.approx(path_length(path), abs=1e-2)


def test_among_shapes_a_stage_with_no_route_tries_the_coarse_lattice_again(monkeypatch):
    """The first coarse tries among shapes have half the stage's time; when they and the route
    through free cell centres find nothing, the coarse lattice is tried again while the no-route
    time lasts (among 10,000 circles one run in ten went unsolved without it). The first try and
    the centre route are made to fail; no clock decides (the deadlines are far ahead)."""
    from rrtpso_ompl.planners.rrtstar_pso.corridor import search

    world = World(((0, 0), (20, 10)), circles=[(6, 5.2, 2.0), (13, 4.6, 1.5)], robot_radius=0.2)
    real, calls = search._shape_corridors, []

    def first_fails(*args, **kwargs):
        calls.append(args[1])
        if len(calls) == 1:
            return search.CorridorResult(None, reason="no route through the lattice")
        return real(*args, **kwargs)

    monkeypatch.setattr(search, "_shape_corridors", first_fails)
    monkeypatch.setattr(search, "lattice_route", lambda *a: None)  # no taut string of a route
    monkeypatch.setattr(search, "centre_route",
                        lambda *a, **k: search.CorridorResult(None, reason="none"))  # fmt: skip
    found = search.find_corridor_path(world, (1.0, 5.0), (19.0, 5.0), 100.0, max_cells=4096,
                                      no_route_seconds=1000.0)  # fmt: skip
    assert len(calls) == 2 and found.path is not None and world.path_valid(found.path)
