"""The taut string of a path's homotopy among circles (corridor/taut.py): exact against the
optimum where the homotopy is the optimum's, valid, passing circles on the reference's side."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from helpers import exact_length

from rrtpso_ompl.model import World
from rrtpso_ompl.model.geometry import path_length
from rrtpso_ompl.planners.rrtstar_pso.corridor import search
from rrtpso_ompl.planners.rrtstar_pso.corridor.corners import round_circles
from rrtpso_ompl.planners.rrtstar_pso.corridor.taut import TAUT_PIECE, sides_along, taut_string

#: The polygon of a 5-degree piece is this much longer than its arc.
PIECE_EXCESS = math.tan(0.5 * TAUT_PIECE) / (0.5 * TAUT_PIECE) - 1.0


@pytest.mark.parametrize("robot", [0.0, 0.4])
def test_the_string_round_circles_is_the_optimum_in_the_optimums_homotopy(robot):
    world = World(((0, 0), (20, 10)), circles=[(6, 5.2, 2.0), (13, 4.6, 1.5), (9, 1.0, 0.8)],
                  robot_radius=robot)  # fmt: skip
    start, goal = (1.0, 5.0), (19.0, 5.0)
    best = exact_length(world, start, goal)
    # Detours above the two large circles and below them (above the small one): the optimum
    # takes one of the two homotopies; its string is the optimum.
    above = np.array([start, (6, 9.5), (13, 9.5), goal])
    below = np.array([start, (3, 2.8), (6, 2.6), (9, 2.3), (13, 2.5), goal])
    lengths = []
    for reference in (above, below):
        assert world.path_valid(reference)
        string = taut_string(world, reference)
        assert string is not None and world.path_valid(string)
        lengths.append(path_length(string))
    assert lengths and min(lengths) >= best * (1 - 1e-9)
    assert min(lengths) <= best * (1 + PIECE_EXCESS + 1e-6)


def test_the_string_keeps_the_reference_side_of_every_obstacle():
    world = World(((0, 0), (20, 10)), circles=[(10, 5, 2.0)], robot_radius=0.25)
    start, goal = (1.0, 5.2), (19.0, 5.2)
    for reference, side in ((np.array([start, (10, 9), goal]), 1.0),
                            (np.array([start, (10, 1), goal]), -1.0)):  # fmt: skip
        string = taut_string(world, reference)
        assert world.path_valid(string)
        # the circle lies right of a path above it (-1), left of one below (+1)
        assert sides_along(string, np.array([[10.0, 5.0]]))[1][0] == -side
        assert path_length(string) < path_length(reference)


def test_worlds_with_boxes_or_polygons_are_declined():
    """A segment may cross a polygon far from its corners (no anchor entered): such worlds keep
    the funnel path."""
    world = World(((0, 0), (10, 10)), boxes=[(4, 0, 5, 6)], circles=[(7, 7, 1.0)])
    reference = np.array([(1.0, 1.0), (2, 7.5), (5.5, 7.5), (5.5, 3.0), (9.0, 1.0)])
    assert world.path_valid(reference)
    assert taut_string(world, reference) is None


def test_round_circles_with_radii_of_their_own():
    """Two circles of different radii passed on opposite sides: the inner tangent, of length
    sqrt(L^2 - (r1 + r2)^2), joins them; the polygons stay outside both circles."""
    c = np.array([(0.0, 0.0), (3.0, 0.0), (9.0, 0.0), (12.0, 0.0)])
    path, owner = round_circles(c, np.array([0.0, 1.0, 2.0, 0.0]), np.array([0.0, 1.0, -1.0, 0.0]),
                                TAUT_PIECE)  # fmt: skip
    assert owner[0] == 0 and owner[-1] == 3 and np.all(np.diff(owner) >= 0)
    for centre, radius in ((c[1], 1.0), (c[2], 2.0)):
        assert shapely.LineString(path).distance(shapely.Point(centre)) >= radius - 1e-9
    # The polygons' vertices lie on the tangents at the arcs' ends, a piece's half beyond them:
    # the longest segment is the inner tangent so lengthened.
    seg = np.hypot(*np.diff(path, axis=0).T).max()
    tangent = math.sqrt(6.0**2 - 3.0**2)
    assert tangent <= seg <= tangent + 3.0 * math.tan(0.5 * TAUT_PIECE) + 1e-9
    # A circle off the line, on the side it would have to be wrapped the long way round.
    back = round_circles(np.array([(0.0, 0.0), (5.0, 3.0), (10.0, 0.0)]), np.array([0, 1.0, 0]),
                         np.array([0, 1.0, 0]), every_back=True)  # fmt: skip
    assert list(back) == [1]
    assert round_circles(np.array([(0.0, 0.0), (5.0, 3.0), (10.0, 0.0)]), np.array([0, 1.0, 0]),
                         np.array([0, 1.0, 0])) == 1  # fmt: skip


def test_routes_start_from_an_open_cell_joined_to_the_goals():
    """The nearest open cell to the start may be walled in (a diagonal needs the cells beside
    it): the ends are the nearest pair the lattice joins."""
    opened = np.ones((6, 6), dtype=bool)
    opened[1, 0] = opened[0, 1] = False  # (0, 0) walled in: its diagonal needs (1, 0), (0, 1)
    opened[1, 1] = False
    opened[0, 0] = True
    ends = search._joined_ends(opened, (0, 0), (5, 5))
    assert ends is not None and ends[0] != (0, 0) and ends[1] == (5, 5)
    walled = np.zeros((6, 6), dtype=bool)
    walled[0, 0] = walled[5, 5] = True
    assert search._joined_ends(walled, (0, 0), (5, 5)) is None


def _circle_field(n: int, seed: int, robot: float) -> World:
    """``n`` x ``n`` circles on a jittered lattice in 100 x 100 (the scaling benchmark's worlds,
    smaller): many corridors of nearly equal length."""
    rng = np.random.default_rng(seed)
    cell = 100.0 / n
    centres = (np.stack(np.meshgrid(np.arange(n), np.arange(n)), -1).reshape(-1, 2) + 0.5) * cell
    centres += rng.uniform(-0.2, 0.2, centres.shape) * cell
    radii = rng.uniform(0.2, 0.3, len(centres)) * cell
    return World(((0, 0), (100, 100)), circles=np.column_stack([centres, radii]),
                 robot_radius=robot * cell)  # fmt: skip


@pytest.mark.parametrize(("seed", "robot"), [(1, 0.0), (2, 0.05)])
def test_among_circles_alone_the_stage_pulls_taut_the_route_of_a_fine_lattice(seed, robot):
    """Among circles alone the stage's path is the taut string of the shortest route on the
    lattice of free centres (no bands), valid and within 1 % of the optimum on a field of 400
    circles."""
    world = _circle_field(20, seed, robot)
    start, goal = (0.5, 0.5), (99.5, 99.5)
    result = search.find_corridor_path(world, start, goal, None, max_cells=65_536)
    assert "taut_routes" in result.stages and result.routes == 1
    assert result.lattice.n_cells <= 65_536 and result.path is not None
    assert world.path_valid(result.path)
    best = exact_length(world, start, goal)
    assert best * (1 - 1e-9) <= result.length <= best * 1.01


def test_without_a_string_of_a_route_the_bands_take_over(monkeypatch):
    world = _circle_field(10, 3, 0.05)
    start, goal = (0.5, 0.5), (99.5, 99.5)
    monkeypatch.setattr(search, "lattice_route", lambda *a: None)
    result = search.find_corridor_path(world, start, goal, None, max_cells=16_384)
    assert result.path is not None and world.path_valid(result.path)
    assert result.routes >= 1 and "funnel" in result.stages


def test_worlds_with_boxes_go_through_the_bands():
    world = World(((0, 0), (20, 10)), boxes=[(9, 0, 10, 6)], circles=[(5, 5, 1.0)])
    result = search.find_corridor_path(world, (1.0, 2.0), (19.0, 2.0), None, max_cells=16_384)
    assert result.path is not None and world.path_valid(result.path)
    assert "taut_routes" not in result.stages
