"""A car-like robot's problem as OMPL objects: Dubins or Reeds-Shepp curves over the exact world.

A problem whose robot has a ``turning_radius`` is planned in ``ob.DubinsStateSpace(rho)`` (or
``ob.ReedsSheppStateSpace(rho)`` with ``robot.reverse``), a state ``(x, y, yaw)``, with the
problem's bounds on ``(x, y)``. A state is valid when the robot's disc there is free (the
world's exact point check). A motion is the space's own curve, arcs of radius ``rho`` and
straight lines, checked by :class:`CurveMotionValidator` soundly against the exact world:

* the curve is cut by the space's own interpolation into pieces of arc length at most
  ``step = sqrt(8 * sagitta * rho)``; a piece whose curvature is at most ``1 / rho`` lies within
  ``step^2 / (8 rho) = sagitta`` of its chord (the chord's sagitta bound, which holds for any
  curve of bounded curvature, not only for one arc);
* a Reeds-Shepp cusp (the car stops and backs) inside a piece is found by its chord being
  shorter than any chord of that arc length and curvature could be; that piece is halved
  around the cusp until its chord is within ``sagitta`` of the curve too (a point of a piece of
  arc length ``s`` is within ``s / 2`` of its chord's nearer end).

A curve passes when each of its points keeps the robot's radius ``r`` plus a margin ``m`` (the
sagitta, and a cusp's ``step^3 / (24 rho^2)``, below 1e-7 rho) from every obstacle and ``m``
inside the bounds. Then any chords of it no longer than ``step`` lie within ``m`` of it and keep
``r``: the polyline a solve reports as ``path`` is valid as the file format defines a path, and
the solve's final check is the format's own (:meth:`CurveMotionValidator.polyline_valid`).

The check: a coarse pass first (poses every ``16 step`` of arc, their exact clearance and their
distance inside the bounds): a point that hits refuses the curve at once, and a piece whose ends
both have half its arc length of room beyond ``r + m`` is free as it is (each of its points is
that close to an end); the other pieces are halved, and tested so, down to two steps; only those
still in doubt are cut into chords of at most ``step``, each checked exactly with the radius
``r + 2 m`` (circles as circles, polygons' edges, the map's cells), so that the curve within
``m`` of it keeps ``r + m``. A curve accepted is never a collision; one within ``2 m`` of contact
may be refused. ``sagitta`` is :data:`SAGITTA` of the turning radius.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from ompl import base as ob
from ompl import geometric as og

from ..model.problem_types import Problem
from ..model.world import World
from .space import centre_bounds

__all__ = [
    "SAGITTA",
    "CarModel",
    "CarValidityChecker",
    "CurveMotionValidator",
    "car_space",
]

#: The chord check's margin, as a share of the turning radius (0.25 mm for a 1 m radius).
SAGITTA = 2.5e-4
#: Halvings of a piece around a cusp, at most (a cusp's piece is halved to twice the sagitta in
#: about log2(step / sagitta), 7 halvings).
_CUSP_HALVINGS = 40


@dataclass(frozen=True)
class CarModel:
    """A car-like robot's curves: the space, its turning radius and the chord spacing.

    Attributes
    ----------
    space : ob.DubinsStateSpace or ob.ReedsSheppStateSpace
    rho : float
        The turning radius (problem units).
    reverse : bool
        Whether the car may back (Reeds-Shepp).
    sagitta : float
        How far a curve may lie from its chords (problem units).
    step : float
        The arc length of a chord, at most (problem units).
    """

    space: object
    rho: float
    reverse: bool
    sagitta: float
    step: float

    @classmethod
    def of(cls, problem: Problem) -> CarModel:
        rho = float(problem.robot.turning_radius)
        sagitta = SAGITTA * rho
        return cls(car_space(problem), rho, bool(problem.robot.reverse), sagitta,
                   math.sqrt(8.0 * sagitta * rho))  # fmt: skip

    def samples(self, a, b, out=None, t0: float = 0.0, t1: float = 1.0) -> np.ndarray:
        """Poses ``(x, y, yaw)`` along the curve from state ``a`` to state ``b`` (between the
        shares ``t0`` and ``t1`` of it, both included): pieces of arc length at most
        :attr:`step`, pieces around a cusp halved until their chord is within :attr:`sagitta`
        of the curve."""
        space = self.space
        length = space.distance(a, b)
        n = max(1, math.ceil(length * (t1 - t0) / self.step))
        s = out if out is not None else space.allocState()
        ts = np.linspace(t0, t1, n + 1)
        poses = self.at(a, b, ts, s)
        if self.reverse:
            poses = self._split_cusps(a, b, poses, ts, length, s)
        return poses

    @property
    def coarse_step(self) -> float:
        """The arc spacing of a motion check's first pass: ``16 step`` (its pieces are halved
        where they are near an obstacle)."""
        return 16.0 * self.step

    def at(self, a, b, ts: np.ndarray, s) -> np.ndarray:
        """The poses at the shares ``ts`` of the curve (the ends exactly as given)."""
        interpolate = self.space.interpolate
        rows = []
        for t in ts.tolist():
            if t <= 0.0:
                rows.append(_pose(a))
            elif t >= 1.0:
                rows.append(_pose(b))
            else:
                interpolate(a, b, t, s)
                rows.append(_pose(s))
        return np.array(rows)

    def _split_cusps(self, a, b, poses, ts, length, s) -> np.ndarray:
        """Poses with the pieces that hold a cusp halved around it (see the module docstring)."""
        suspect = self._cusp_test(length * (ts[1] - ts[0]))
        out = [poses[:1]]
        for k in range(len(poses) - 1):
            if suspect(poses[k], poses[k + 1]):
                out.append(self._halve(a, b, (ts[k], poses[k]), (ts[k + 1], poses[k + 1]),
                                       length, s, _CUSP_HALVINGS))  # fmt: skip
            out.append(poses[k + 1 : k + 2])
        return np.vstack(out)

    def _cusp_test(self, piece: float):
        """Whether a piece of arc length ``piece`` between two poses may hold a cusp: its chord
        is shorter than any chord of a curve of curvature at most ``1 / rho`` could be."""
        shortest = 2.0 * self.rho * math.sin(min(piece / (2.0 * self.rho), 0.5 * math.pi))

        def suspect(p, q) -> bool:
            return math.hypot(q[0] - p[0], q[1] - p[1]) < shortest * (1.0 - 1e-9) - 1e-12

        return suspect

    def _halve(self, a, b, lo, hi, length: float, s, depth: int) -> np.ndarray:
        """The poses strictly between ``lo`` and ``hi`` (each ``(t, pose)``) that cut a piece
        which may hold a cusp into pieces within the sagitta: halved, and each half that may
        still hold one halved again, until a half's arc length is at most twice the sagitta."""
        (t0, p0), (t1, p1) = lo, hi
        piece = 0.5 * length * (t1 - t0)  # each half's arc length
        if depth == 0 or length * (t1 - t0) <= 2.0 * self.sagitta:
            return np.empty((0, 3))
        tm = 0.5 * (t0 + t1)
        self.space.interpolate(a, b, float(tm), s)
        pm = np.array(_pose(s))
        suspect = self._cusp_test(piece)
        out = []
        if suspect(p0, pm):
            out.append(self._halve(a, b, lo, (tm, pm), length, s, depth - 1))
        out.append(pm[None])
        if suspect(pm, p1):
            out.append(self._halve(a, b, (tm, pm), hi, length, s, depth - 1))
        return np.vstack(out)

    def polyline(self, rows: np.ndarray) -> np.ndarray:
        """The chords' poses of a whole path of waypoint poses ``rows`` ``(k, 3)``: the curve
        sampled as :meth:`samples` does, each waypoint once."""
        space = self.space
        a, b, s = space.allocState(), space.allocState(), space.allocState()
        out = [np.asarray(rows[:1], dtype=float)]
        for r0, r1 in itertools.pairwise(rows):
            _assign(a, r0)
            _assign(b, r1)
            out.append(self.samples(a, b, s)[1:])
        return np.vstack(out)

    def path_poses(self, path: og.PathGeometric) -> np.ndarray:
        """The waypoint poses of an OMPL path of this space, ``(k, 3)``."""
        return np.array([_pose(s) for s in path.getStates()], dtype=float).reshape(-1, 3)


def _pose(s) -> tuple[float, float, float]:
    return (s.getX(), s.getY(), s.getYaw())


def _assign(state, row) -> None:
    state.setXY(float(row[0]), float(row[1]))
    state.setYaw(float(row[2]))


def car_space(problem: Problem):
    """``ob.DubinsStateSpace(rho)`` or ``ob.ReedsSheppStateSpace(rho)`` bounded by the problem's
    bounds (the robot's centre)."""
    rho = float(problem.robot.turning_radius)
    space = ob.ReedsSheppStateSpace(rho) if problem.robot.reverse else ob.DubinsStateSpace(rho)
    space.setBounds(centre_bounds(problem.bounds))
    return space


class CarValidityChecker(ob.StateValidityChecker):
    """A pose is valid when its position lies in the bounds and the robot's disc there is free
    (the heading does not matter to a disc)."""

    def __init__(self, si: ob.SpaceInformation, world: World) -> None:
        super().__init__(si)
        self.world = world

    def isValid(self, state) -> bool:
        x, y = state.getX(), state.getY()
        return self.world.in_bounds(x, y) and self.world.point_free(x, y)


class CurveMotionValidator(ob.MotionValidator):
    """The space's curve from one pose to another, checked soundly (the module docstring): a
    curve passes when every point of it keeps the robot's radius plus :attr:`margin` from every
    obstacle and :attr:`margin` inside the bounds. Then chords of it no longer than ``step``
    (which lie within ``margin`` of it), the polyline a solve reports, keep the robot's radius:
    valid as the file format defines a path.

    ``exact = True`` tells :class:`~rrtpso_ompl.planners.pso.space_path.MotionChecker` that no
    finer samples are needed: nothing lies between this check's chords.
    """

    exact = True

    def __init__(self, si: ob.SpaceInformation, world: World, car: CarModel) -> None:
        super().__init__(si)
        self.car = car
        self.world = world
        #: How far a curve may lie from its chords: the sagitta, and what a cusp within a step's
        #: ``step^3 / (48 rho^2)`` of a chord's end (unseen by the cusp test) adds, doubled.
        self.margin = car.sagitta + car.step**3 / (24.0 * car.rho**2)
        #: The world for the check's chords: a chord that keeps the radius plus twice the margin
        #: leaves its curve the radius plus the margin.
        self.chord_world = world.with_robot_radius(world.robot_radius + 2.0 * self.margin)
        self._s = car.space.allocState()

    def checkMotion(self, s1, s2, *last_valid) -> bool:
        if not self.world.in_bounds(s2.getX(), s2.getY()):
            return False
        car, s = self.car, self._s
        length = car.space.distance(s1, s2)
        ts = np.linspace(0.0, 1.0, max(1, math.ceil(length / car.coarse_step)) + 1)
        room = self._room(car.at(s1, s2, ts, s))
        if (room < -self.margin).any():  # a point of the curve itself hits, or is out
            return False
        piece = length / (len(ts) - 1)  # arc length of each piece
        lo = ts[:-1]
        # Every point of a piece is within half its arc length of one of its ends (along the
        # curve, so also in the plane): a piece whose ends both have that much room is free.
        doubt = np.minimum(room[:-1], room[1:]) < 0.5 * piece
        lo, room_lo, room_hi = lo[doubt], room[:-1][doubt], room[1:][doubt]
        while len(lo) and piece > 2.0 * car.step:  # halve the doubtful pieces
            piece *= 0.5
            dt = piece / length
            mid = self._room(car.at(s1, s2, lo + dt, s))
            if (mid < -self.margin).any():
                return False
            lo = np.concatenate([lo, lo + dt])
            left, right = np.minimum(room_lo, mid), np.minimum(mid, room_hi)
            keep = np.concatenate([left, right]) < 0.5 * piece
            room_hi = np.concatenate([mid, room_hi])[keep]
            room_lo = np.concatenate([room_lo, mid])[keep]
            lo = lo[keep]
        for t0 in lo.tolist():  # the rest: their chords, with twice the margin
            xy = car.samples(s1, s2, s, t0, min(1.0, t0 + piece / length))[:, :2]
            if not (self._inside(xy, 2.0 * self.margin)
                    and self.chord_world.segments_free(xy[:-1], xy[1:]).all()):  # fmt: skip
                return False
        return True

    def _room(self, poses: np.ndarray) -> np.ndarray:
        """How far each pose's position may move and keep the robot's radius plus the margin
        from obstacles and the margin inside the bounds (below ``-margin``: not valid there)."""
        xy = poses[:, :2]
        (xmin, ymin), (xmax, ymax) = self.world.bounds
        edge = np.minimum.reduce([xy[:, 0] - xmin, xmax - xy[:, 0], xy[:, 1] - ymin,
                                  ymax - xy[:, 1]])  # fmt: skip
        r = self.world.robot_radius
        clear = self.world.point_clearance(xy, cap=r + self.car.coarse_step) - r
        tol = self.world.tol  # the world's touching allowance: an end state may touch
        raw = np.where((clear < 0) & (clear > -tol), 0.0, np.minimum(clear, edge))
        return raw - self.margin

    def _inside(self, xy: np.ndarray, m: float) -> bool:
        """Whether the points keep ``m`` inside the bounds."""
        (xmin, ymin), (xmax, ymax) = self.world.bounds
        return bool(((xy[:, 0] >= xmin + m) & (xy[:, 0] <= xmax - m) & (xy[:, 1] >= ymin + m)
                     & (xy[:, 1] <= ymax - m)).all())  # fmt: skip

    def polyline_valid(self, xy: np.ndarray) -> bool:
        """Whether a chord polyline (``(n, 2)``, from :meth:`CarModel.polyline`) is a valid path
        as the file format defines one (the robot's radius, the bounds): every motion this
        validator passed gives one."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        return len(xy) > 1 and bool(self.world.path_valid(xy))
