"""Planning on turned maps (issue 26 item 3): RRT*PSO solves a turned copy of a shipped map
and its path keeps the robot's radius from every turned cell, as shapely measures it."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from helpers import map_shapes, turned_copy

from rrtpso_ompl.model import World, load_problem
from rrtpso_ompl.planners.solve import solve


@pytest.mark.parametrize(("name", "yaw", "pivot"), [
    ("office_corridor", 0.3, (2.0, -1.0)),
    ("lab_clutter", math.pi / 2, (0.0, 0.0)),
])  # fmt: skip
def test_rrtstar_pso_solves_a_turned_map_and_its_path_is_exact(tmp_path, name, yaw, pivot):
    problem = load_problem(turned_copy(tmp_path, name, yaw, pivot)[0])
    world = World.from_problem(problem)
    # A turned map has no lattice view (its cells are no lattice of the world's axes): the
    # corridor stage runs on generic cells, measured by the exact clearance.
    assert world.raster is None and world.box_frame is not None
    r = solve(problem, "RRTstarPSO", time_limit=0.5, seed=2)
    assert r.solved
    assert r.stages["corridor_cells"] > 0 and not r.stages["corridor_reason"]
    path = np.asarray(r.path)
    assert path[0] == pytest.approx(problem.start) and path[-1] == pytest.approx(problem.goal)
    (x0, y0), (x1, y1) = problem.bounds
    assert ((path >= [x0, y0]) & (path <= [x1, y1])).all()
    d = shapely.distance(map_shapes(problem),
                         shapely.linestrings(np.stack([path[:-1], path[1:]], axis=1)))  # fmt: skip
    assert d.min() >= problem.robot.radius - world.tol
