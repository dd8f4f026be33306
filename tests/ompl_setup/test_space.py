"""The one state space this package's planners plan in, and why any other is refused (issue 32);
the path converters refuse other spaces rather than read or write two coordinates of them."""

from __future__ import annotations

import numpy as np
import pytest
from ompl import base as ob
from ompl import geometric as og

from rrtpso_ompl.errors import UnsupportedSpaceError
from rrtpso_ompl.ompl_setup import (
    array_to_path,
    describe_space,
    path_to_array,
    plane_space_problem,
    require_plane_space,
)


class MyPlane(ob.RealVectorStateSpace):
    """A user's own subclass of the plane."""

    def __init__(self):
        super().__init__(2)


def _compound_with_a_plane():
    space = ob.CompoundStateSpace()
    space.addSubspace(ob.RealVectorStateSpace(2), 1.0)
    return space


def test_the_plane_is_accepted_as_a_space_or_a_space_information():
    plane = ob.RealVectorStateSpace(2)
    assert plane_space_problem(plane) is None
    assert plane_space_problem(ob.SpaceInformation(plane)) is None
    assert plane_space_problem(MyPlane()) is None
    require_plane_space(plane, "me")  # no exception


@pytest.mark.parametrize(
    ("make", "kind"),
    [
        (lambda: ob.RealVectorStateSpace(1), "(ob.RealVectorStateSpace(1))"),
        (lambda: ob.RealVectorStateSpace(3), "(ob.RealVectorStateSpace(3))"),
        (lambda: ob.RealVectorStateSpace(6), "(ob.RealVectorStateSpace(6))"),
        (ob.SE2StateSpace, "(ob.SE2StateSpace, 3 dimensions)"),
        (lambda: ob.DubinsStateSpace(1.0), "(ob.DubinsStateSpace, 3 dimensions)"),
        (lambda: ob.ReedsSheppStateSpace(1.0), "(ob.ReedsSheppStateSpace, 3 dimensions)"),
        (ob.SO2StateSpace, "(ob.SO2StateSpace, 1 dimension)"),
        (ob.SE3StateSpace, "(ob.SE3StateSpace, 6 dimensions)"),
        (ob.TimeStateSpace, "(ob.TimeStateSpace)"),  # its dimension is not bound
        (_compound_with_a_plane, "(ob.CompoundStateSpace, 2 dimensions)"),
    ],
)
def test_every_other_space_is_refused_by_name(make, kind):
    space = make()
    said = plane_space_problem(ob.SpaceInformation(space))
    assert said == (f"the state space {space.getName()!r} {kind} is not "
                    f"ob.RealVectorStateSpace(2), the only space this package's planners plan "
                    f"in for now")  # fmt: skip
    assert describe_space(space) == f"{space.getName()!r} {kind}"
    with pytest.raises(UnsupportedSpaceError, match=r"^Thing: the state space ") as exc:
        require_plane_space(space, "Thing")
    assert isinstance(exc.value, ValueError)


def test_array_to_path_refuses_a_space_whose_other_coordinates_it_would_leave_unset():
    space = ob.RealVectorStateSpace(3)
    space.setBounds(0.0, 10.0)
    si = ob.SpaceInformation(space)
    with pytest.raises(UnsupportedSpaceError, match=r"array_to_path: .*RealVectorStateSpace\(3\)"):
        array_to_path(si, np.array([[1.0, 1.0], [9.0, 9.0]]))


def test_path_to_array_refuses_states_that_are_not_real_vectors():
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    a, b = space.allocState(), space.allocState()
    a.setXY(1.0, 1.0)
    b.setXY(9.0, 9.0)
    path = og.PathGeometric(si, a, b)
    with pytest.raises(UnsupportedSpaceError, match="SE2StateType, not 2-D real vectors"):
        path_to_array(path)


def test_the_plane_still_converts_both_ways():
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 10.0)
    xy = np.array([[1.0, 2.0], [3.5, 4.25], [9.0, 9.0]])
    assert np.array_equal(path_to_array(array_to_path(ob.SpaceInformation(space), xy)), xy)
