"""A planning problem as plain data: frozen dataclasses, no OMPL, no matplotlib.

A problem is one planning query for a disc-shaped differential-drive robot in the plane: the
bounds of the robot's centre, start and goal, the robot, static obstacles (circles, polygons),
optional moving obstacles (paper eqs. 14-15), an optional occupancy map and planner defaults.
:func:`~rrtpso_ompl.model.problem.load_problem` builds one from a file and validates every value.

Also here: the workspace's round-off allowance (:func:`touch_tolerance`) and the clearance that
still counts as free (:func:`clearance_threshold`), which the loader and the world share, and
the parts of the bounds outside a map, which block the robot when unknown space does.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from types import MappingProxyType
from typing import Any

import numpy as np

from .format import ROBOT
from .geometry import GridFrame
from .objective import InflationCost
from .occupancy import OccupancyMap

__all__ = [
    "Circle",
    "MovingObstacle",
    "Obstacle",
    "PlannerConfig",
    "Point",
    "Polygon",
    "Problem",
    "Robot",
    "clearance_threshold",
    "normalise_degrees",
    "outside_boxes",
    "outside_polygons",
    "touch_tolerance",
]

Point = tuple[float, float]


@dataclass(frozen=True)
class Circle:
    """A static circular obstacle. Clearance to it is computed exactly (never on a polygon)."""

    center: Point
    radius: float
    kind: str = field(default="circle", init=False)


@dataclass(frozen=True)
class Polygon:
    """A static polygonal obstacle (a ``rectangle`` from the file is stored as its 4 corners).

    ``points`` is a simple (non-self-intersecting) ring of at least 3 vertices with non-zero area,
    in counter-clockwise order, without the closing repeat of the first vertex.
    """

    points: tuple[Point, ...]
    kind: str = "polygon"  # "polygon" or "rectangle": how it was written in the file


#: A static obstacle.
Obstacle = Circle | Polygon


@dataclass(frozen=True)
class MovingObstacle:
    """A disc moving at constant velocity (paper eqs. 14-15).

    Parameters
    ----------
    radius : float
        Radius of the obstacle's disc (its safety zone SO), in problem units.
    start : (float, float)
        Centre at t = 0.
    speed : float
        Speed in problem units per second, >= 0.
    heading_deg : float
        Direction of motion in degrees, counter-clockwise from +x.
    """

    radius: float
    start: Point
    speed: float
    heading_deg: float

    @property
    def velocity(self) -> np.ndarray:
        """Velocity vector (vx, vy) in units per second."""
        h = math.radians(self.heading_deg)
        return np.array([self.speed * math.cos(h), self.speed * math.sin(h)])

    def position(self, t: float | np.ndarray) -> np.ndarray:
        """Centre at time(s) ``t`` in seconds: eqs. 14-15 in closed form, shape ``(..., 2)``."""
        t = np.asarray(t, dtype=float)
        return np.asarray(self.start, dtype=float) + t[..., None] * self.velocity


def _robot_class() -> type:
    """The :class:`Robot` dataclass, its fields derived from the format's robot keys
    (:data:`~rrtpso_ompl.model.format.ROBOT`): a robot key is declared once, there, with its
    kind, unit and meaning, and is a field here at once (``radius`` required, the others
    ``None`` when not given)."""
    fields: list[Any] = []
    for key in ROBOT.keys:
        if key.required:
            fields.append((key.name, float))
        elif key.kind == "bool":
            fields.append((key.name, bool, field(default=False)))
        else:
            fields.append((key.name, float | None, field(default=None)))
    cls = dataclasses.make_dataclass("Robot", fields, frozen=True)
    cls.__module__ = __name__  # pickled with the problem (batch workers): found by this name
    cls.__doc__ = """The robot: a disc of radius ``radius`` (the safety zone SR) plus drive
    parameters, one field per key of the format's ``robot`` section (docs/problem-format.md).

    Attributes are in problem units (lengths), units per second (speeds), seconds
    (sample_time); the drive parameters are None until given, and needed only for velocities
    and simulations, the inflation keys only for the clearance cost.
    """
    return cls


#: The robot (:func:`_robot_class`): ``Robot(radius=0.2, speed=0.5, ...)``.
Robot = _robot_class()


@dataclass(frozen=True)
class PlannerConfig:
    """Optional planner defaults from the file; command-line flags override them."""

    type: str | None = None
    time_limit: float | None = None
    seed: int | None = None
    params: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))


@dataclass(frozen=True)
class Problem:
    """One validated planning problem. Build it with :func:`load_problem`.

    Lengths are in the problem's ``units``; ``goal_yaw`` is the heading wanted at the goal in
    degrees, counter-clockwise from +x, normalised to (-180, 180] (None: any heading), and
    ``start_yaw`` a car-like robot's heading at the start (None: towards the goal).
    """

    name: str
    bounds: tuple[Point, Point]
    start: Point
    goal: Point
    robot: Robot
    obstacles: tuple[Obstacle, ...] = ()
    moving_obstacles: tuple[MovingObstacle, ...] = ()
    goal_tolerance: float = 0.0
    goal_yaw: float | None = None
    start_yaw: float | None = None
    planner: PlannerConfig = field(default_factory=PlannerConfig)
    description: str = ""
    units: str = ""
    source: str = "<dict>"
    map: OccupancyMap | None = field(default=None, compare=False)

    @cached_property
    def objective(self) -> InflationCost:
        """The objective every planner, post-pass and reference of this problem minimises:
        the path length plus, when the robot has an ``inflation_radius``, the inflation cost
        near obstacles (:class:`~rrtpso_ompl.model.objective.InflationCost`; its ``active`` says
        whether it has one). Built once, here, from the robot's declared keys."""
        return InflationCost.of(self.robot)

    @property
    def car(self) -> bool:
        """Whether the robot is car-like (``robot.turning_radius``): its path is Dubins or
        Reeds-Shepp curves, planned in OMPL's space of them (:mod:`rrtpso_ompl.ompl_setup.car`)."""
        return self.robot.turning_radius is not None

    def end_yaws(self) -> tuple[float, float]:
        """A car-like robot's headings at the start and the goal, radians in ``[-pi, pi)`` (as
        OMPL's ``SO2StateSpace`` bounds them: a yaw of ``pi`` is out of its bounds): the
        file's, else the direction from the start to the goal."""
        toward = math.atan2(self.goal[1] - self.start[1], self.goal[0] - self.start[0])
        yaws = (toward if deg is None else math.radians(deg)
                for deg in (self.start_yaw, self.goal_yaw))  # fmt: skip
        return tuple((y + math.pi) % (2.0 * math.pi) - math.pi for y in yaws)

    @property
    def map_boxes(self) -> np.ndarray | None:
        """(k, 4) boxes ``(xmin, ymin, xmax, ymax)`` blocked by the map, in its grid coordinates
        (:attr:`map_frame`; the map frame's for a map that is not turned): its merged blocked
        cells and, for a map that is not turned when unknown cells block, the parts of the bounds
        outside the map (a turned map's are :attr:`map_outside`); None without a map."""
        if self.map is None:
            return None
        boxes = self.map.boxes
        if not self.map.unknown_blocks or self.map.frame is not None:
            return boxes
        outside = outside_boxes(self.bounds, self.map.extent)
        return np.vstack([boxes, outside]) if len(outside) else boxes

    @property
    def map_frame(self) -> GridFrame | None:
        """The grid frame of a turned map (None without one): :attr:`map_boxes` are in its
        coordinates. Its ``confined`` is the map's rectangle when every free configuration lies
        in it (unknown space blocks, and the map lies within the bounds)."""
        if self.map is None or self.map.frame is None:
            return None
        frame = self.map.frame
        (bx0, by0), (bx1, by1) = self.bounds
        tol = touch_tolerance(self.bounds)
        c = self.map.corners
        inside = (c[:, 0] >= bx0 - tol) & (c[:, 0] <= bx1 + tol)
        inside &= (c[:, 1] >= by0 - tol) & (c[:, 1] <= by1 + tol)
        if self.map.unknown_blocks and inside.all():
            (x0, y0), (x1, y1) = self.map.extent
            frame = replace(frame, confined=(x0, y0, x1, y1))
        return frame

    @property
    def map_outside(self) -> tuple[Polygon, ...]:
        """The parts of the bounds outside a turned map, as convex polygons in the map frame,
        when unknown space blocks (there the robot's disc may not go); none otherwise (a map that
        is not turned has them among :attr:`map_boxes`). Parts thinner than the round-off
        allowance are left out: a disc reaching into them is within it anyway."""
        if self.map is None or self.map.frame is None or not self.map.unknown_blocks:
            return ()
        return outside_polygons(self.bounds, self.map.corners, touch_tolerance(self.bounds))

    @property
    def inputs(self) -> tuple[str, ...]:
        """The files the problem was read from, resolved (absolute, links followed): the problem
        file, and its map's YAML and image; none for a problem built from a mapping. No output
        may be one of them (the command line refuses it before planning)."""
        files = [] if self.source.startswith("<") else [self.source]
        if self.map is not None:
            files += [self.map.source, self.map.image]
        return tuple(dict.fromkeys(os.path.realpath(f) for f in files))


def normalise_degrees(angle: float) -> float:
    """``angle`` (degrees) as the same direction in (-180, 180], exactly (``math.remainder``
    rounds nothing, even for 1e300)."""
    a = math.remainder(angle, 360.0)
    return 180.0 if a == -180.0 else a + 0.0  # + 0.0: no -0.0 in outputs


def touch_tolerance(bounds: tuple[Point, Point]) -> float:
    """Round-off allowance for "touching is allowed" comparisons in a workspace.

    ``1e-9`` of the workspace's scale: the larger of its sides and of its coordinates'
    magnitudes (float spacing grows with both). Relative at every scale, so a workspace 1e-6
    wide is checked as exactly as one of 500 cm; far below any physical clearance, well above
    float round-off in the distance formulas.
    """
    (xmin, ymin), (xmax, ymax) = bounds
    scale = max(xmax - xmin, ymax - ymin, abs(xmin), abs(ymin), abs(xmax), abs(ymax))
    return 1e-9 * scale


def clearance_threshold(robot_radius: float, tol: float) -> float:
    """The smallest distance to an obstacle that still counts as free.

    ``robot_radius - tol``: touching at exactly the radius is allowed, up to round-off. For a point
    robot (radius 0) that would let a segment *enter* an obstacle (its distance is then 0, like a
    touch), so the threshold never drops below ``+tol``: still within the round-off tolerance of
    the radius, and every penetration is caught. The loader (free start and goal) and
    :class:`~rrtpso_ompl.model.World` share this rule, so a start accepted here is never refused
    by a planner.
    """
    return max(robot_radius - tol, tol)


def outside_boxes(bounds: tuple[Point, Point], extent: tuple[Point, Point]) -> np.ndarray:
    """(k <= 4, 4) boxes covering the part of ``bounds`` outside the map's ``extent``."""
    (bx0, by0), (bx1, by1) = bounds
    (mx0, my0), (mx1, my1) = extent
    boxes = [
        (bx0, by0, min(mx0, bx1), by1),  # left of the map
        (max(mx1, bx0), by0, bx1, by1),  # right
        (max(mx0, bx0), by0, min(mx1, bx1), min(my0, by1)),  # below, between left and right
        (max(mx0, bx0), max(my1, by0), min(mx1, bx1), by1),  # above
    ]
    out = np.array([b for b in boxes if b[2] > b[0] and b[3] > b[1]], dtype=float)
    return out.reshape(-1, 4)


def outside_polygons(bounds: tuple[Point, Point], corners: np.ndarray, tol: float):
    """Convex polygons covering the part of ``bounds`` outside the turned rectangle ``corners``
    ((4, 2), counter-clockwise): the part beyond its first side, then what is left beyond its
    second side, and so on (a convex polygon clipped by half-planes each time). A vertex within
    ``tol`` of a side's line counts as on it (so that round-off makes no sliver or repeated
    vertex), and parts that reach no more than ``tol`` beyond their side are left out."""
    (bx0, by0), (bx1, by1) = bounds
    rest = [(bx0, by0), (bx1, by0), (bx1, by1), (bx0, by1)]
    pieces = []
    for k in range(4):
        (ax, ay), (cx, cy) = corners[k].tolist(), corners[(k + 1) % 4].tolist()
        ex, ey = cx - ax, cy - ay
        n = math.hypot(ex, ey)

        def inward(p, ax=ax, ay=ay, ex=ex, ey=ey, n=n) -> float:
            """Signed distance of ``p`` into the rectangle's side of the line (left of it),
            0 within ``tol``."""
            d = (ex * (p[1] - ay) - ey * (p[0] - ax)) / n
            return 0.0 if abs(d) <= tol else d

        beyond = _clip_convex(rest, inward, -1.0, tol)
        rest = _clip_convex(rest, inward, 1.0, tol)
        if len(beyond) >= 3 and min(inward(p) for p in beyond) < 0.0:
            pieces.append(Polygon(tuple(beyond)))
        if len(rest) < 3:
            break
    return tuple(pieces)


def _clip_convex(ring: list[Point], side: Callable[[Point], float], sign: float, tol: float):
    """The part of a convex ring where ``sign * side`` is >= 0 (one Sutherland-Hodgman step);
    counter-clockwise stays counter-clockwise; vertices within ``tol`` of the one before merge."""
    out: list[Point] = []
    for i, p in enumerate(ring):
        q = ring[(i + 1) % len(ring)]
        sp, sq = sign * side(p), sign * side(q)
        if sp >= 0.0:
            out.append(p)
        if (sp > 0.0 > sq) or (sp < 0.0 < sq):
            t = sp / (sp - sq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    kept: list[Point] = []
    for p in out:
        if not kept or math.dist(p, kept[-1]) > tol:
            kept.append(p)
    while len(kept) > 1 and math.dist(kept[0], kept[-1]) <= tol:
        kept.pop()
    return kept
