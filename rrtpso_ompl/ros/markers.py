"""A problem's obstacles as ``visualization_msgs/msg/MarkerArray``: what RViz2 and Foxglove draw.

``/obstacles`` (:func:`obstacle_markers`) starts with a ``DELETEALL`` marker (so a replayed bag
clears what an earlier one drew), then one marker per shape, by namespace:

- ``circles``: a ``CYLINDER`` per circle, diameter ``2 r``, :data:`HEIGHT` tall, opaque grey;
- ``polygons``: a ``LINE_STRIP`` outline per polygon (and rectangle) and ``polygon_fill``, a
  ``TRIANGLE_LIST`` filling it;
- ``safety``: the robot's safety zone around each obstacle, translucent: where the robot's centre
  may not go (the obstacle grown by ``robot.radius``), a flat cylinder for a circle, a filled
  outline for a polygon;
- ``inflation``: the same grown by ``robot.inflation_radius`` when the problem has one (Nav2's
  inflation layer), fainter;
- ``robot``: the robot's disc (``robot.radius``) at the start and at the goal, translucent.

The map's cells are not markers: ``/map`` carries them. ``/moving_obstacles``
(:func:`moving_markers`) draws the moving obstacles of a simulation at one instant: a cylinder of
their radius (the safety zone SO) and, translucent, the contact zone ``SO + SR`` in which the
robot's centre would touch them. All lengths are metres (times the frame's scale).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from .messages import Messages

__all__ = ["HEIGHT", "MAX_OBSTACLES", "check_marker_count", "moving_markers", "obstacle_markers"]

#: Most static obstacles ``/obstacles`` draws (an input-driven allocation): 100,000 obstacles
#: make about 200,000 markers, some 25 s and 600 MB to build and write.
MAX_OBSTACLES = 100_000

#: Height of an obstacle's cylinder or prism, metres (the plan is 2-D; a little height makes
#: obstacles stand out from the flat zones in a 3-D view).
HEIGHT = 0.3
#: Thickness of the flat safety and inflation zones, metres.
FLAT = 0.01
#: Colours, RGBA.
GREY = (0.25, 0.25, 0.25, 1.0)
SAFETY = (1.0, 0.55, 0.0, 0.3)
INFLATION = (1.0, 0.85, 0.2, 0.12)
ROBOT = (0.1, 0.4, 1.0, 0.35)
MOVING = (0.85, 0.1, 0.1, 0.9)
CONTACT = (1.0, 0.3, 0.3, 0.25)


def check_marker_count(problem: Any) -> None:
    """Refuse (ValueError) a problem with more static obstacles than :data:`MAX_OBSTACLES`."""
    n = len(problem.obstacles)
    if n > MAX_OBSTACLES:
        raise ValueError(
            f"the problem has {n:,} obstacles, more than the {MAX_OBSTACLES:,} a bag's "
            "/obstacles markers hold"
        )


def obstacle_markers(
    msgs: Messages, problem: Any, scale: float, line_width: float, t: float = 0.0
) -> Any:
    """The ``MarkerArray`` of ``problem``'s static obstacles and the robot's zones.

    Parameters
    ----------
    msgs : Messages
    problem : Problem
    scale : float
        Metres per problem unit.
    line_width : float
        Width of the outlines, metres.
    t : float
        Stamp, seconds.
    """
    from ..model.problem_types import Circle

    b = _Builder(msgs, t, line_width)
    b.delete_all()
    robot_r = problem.robot.radius
    inflation = getattr(problem.robot, "inflation_radius", None)
    circles = [o for o in problem.obstacles if isinstance(o, Circle)]
    polygons = [o for o in problem.obstacles if not isinstance(o, Circle)]
    for c in circles:
        centre = np.asarray(c.center, dtype=float) * scale
        b.cylinder("circles", centre, c.radius * scale, HEIGHT, GREY)
        b.cylinder("safety", centre, (c.radius + robot_r) * scale, FLAT, SAFETY)
        if inflation:
            b.cylinder("inflation", centre, (c.radius + inflation) * scale, FLAT / 2, INFLATION)
    for poly in polygons:
        ring = np.asarray(poly.points, dtype=float) * scale
        b.line_strip("polygons", ring, GREY)
        b.fill("polygon_fill", _shape(ring), GREY, z=HEIGHT)
        grown = _shape(ring).buffer(robot_r * scale, quad_segs=8)
        b.outline_and_fill("safety", grown, SAFETY)
        if inflation:
            b.outline_and_fill(
                "inflation", _shape(ring).buffer(inflation * scale, quad_segs=8), INFLATION
            )
    for end in (problem.start, problem.goal):
        b.cylinder("robot", np.asarray(end, dtype=float) * scale, robot_r * scale, FLAT, ROBOT)
    return msgs.MarkerArray(markers=b.markers)


def moving_markers(
    msgs: Messages,
    centres: np.ndarray,
    radii: Sequence[float],
    robot_radius: float,
    scale: float,
    t: float,
) -> Any:
    """The ``MarkerArray`` of the moving obstacles at time ``t``.

    Parameters
    ----------
    centres : (k, 2) ndarray
        Their centres, problem units.
    radii : sequence of float
        Their radii SO, problem units.
    robot_radius : float
        The robot's SR, problem units.
    scale : float
        Metres per problem unit.
    """
    b = _Builder(msgs, t, 0.0)
    for centre, r in zip(np.asarray(centres, dtype=float) * scale, radii, strict=True):
        b.cylinder("moving", centre, r * scale, HEIGHT, MOVING)
        b.cylinder("contact", centre, (r + robot_radius) * scale, FLAT, CONTACT)
    return msgs.MarkerArray(markers=b.markers)


def _shape(ring: np.ndarray) -> Any:
    import shapely

    return shapely.Polygon(ring)


class _Builder:
    """Markers of one array: ids counted per namespace, one header, one line width."""

    def __init__(self, msgs: Messages, t: float, line_width: float) -> None:
        self.msgs = msgs
        self.header = msgs.header(t)
        self.line_width = float(line_width)
        self.markers: list[Any] = []
        self._ids: dict[str, int] = {}

    def _marker(
        self,
        ns: str,
        kind: int,
        pose: Any,
        size: Iterable[float],
        color: Sequence[float],
        points: Sequence[Any] = (),
        action: int = 0,
    ) -> None:
        m = self.msgs
        marker_id = self._ids.get(ns, 0)
        self._ids[ns] = marker_id + 1
        self.markers.append(
            m.Marker(
                header=self.header,
                ns=ns,
                id=marker_id,
                type=kind,
                action=action,
                pose=pose,
                scale=m.vector3(*size),
                color=m.ColorRGBA(r=color[0], g=color[1], b=color[2], a=color[3]),
                lifetime=m.Duration(sec=0, nanosec=0),  # forever
                frame_locked=False,
                points=list(points),
                colors=[],
                texture_resource="",
                texture=m.CompressedImage(
                    header=m.header(0.0, ""), format="", data=np.zeros(0, dtype=np.uint8)
                ),
                uv_coordinates=[],
                text="",
                mesh_resource="",
                mesh_file=m.MeshFile(filename="", data=np.zeros(0, dtype=np.uint8)),
                mesh_use_embedded_materials=False,
            )
        )

    def delete_all(self) -> None:
        """``DELETEALL``: clears every marker of the display before the new ones."""
        self._marker(
            "",
            self.msgs.Marker.CYLINDER,
            self.msgs.pose(0, 0),
            (1, 1, 1),
            (0, 0, 0, 0),
            action=self.msgs.Marker.DELETEALL,
        )

    def cylinder(
        self, ns: str, centre: Any, radius: float, height: float, color: Sequence[float]
    ) -> None:
        """An upright cylinder standing on z = 0 (a marker's pose is its centre)."""
        d = 2.0 * radius
        pose = self.msgs.pose(centre[0], centre[1], 0.0, z=0.5 * height)
        self._marker(ns, self.msgs.Marker.CYLINDER, pose, (d, d, height), color)

    def line_strip(self, ns: str, ring: np.ndarray, color: Sequence[float]) -> None:
        """A closed outline of ``ring`` ((n, 2) metres) at the obstacle's top."""
        pts = [self.msgs.point(x, y, HEIGHT) for x, y in np.vstack([ring, ring[:1]]).tolist()]
        self._marker(
            ns,
            self.msgs.Marker.LINE_STRIP,
            self.msgs.pose(0, 0),
            (self.line_width, 0, 0),
            color,
            pts,
        )

    def fill(self, ns: str, shape: Any, color: Sequence[float], z: float) -> bool:
        """A ``TRIANGLE_LIST`` covering ``shape`` (holes too); False (nothing drawn) when this
        shapely has no constrained triangulation (before 2.1)."""
        import shapely

        if shape.is_empty or not hasattr(shapely, "constrained_delaunay_triangles"):
            return False
        triangles = shapely.get_parts(shapely.constrained_delaunay_triangles(shape))
        coords = [np.asarray(tri.exterior.coords)[:3] for tri in triangles]
        if not coords:
            return False
        pts = [self.msgs.point(x, y, z) for x, y in np.concatenate(coords).tolist()]
        self._marker(
            ns, self.msgs.Marker.TRIANGLE_LIST, self.msgs.pose(0, 0), (1, 1, 1), color, pts
        )
        return True

    def outline_and_fill(self, ns: str, shape: Any, color: Sequence[float]) -> None:
        """A flat translucent zone: filled, or its outlines when it cannot be filled."""
        if self.fill(ns, shape, color, z=FLAT):
            return
        import shapely

        for poly in shapely.get_parts(shape):
            for ring in (poly.exterior, *poly.interiors):
                pts = [self.msgs.point(x, y, FLAT) for x, y in np.asarray(ring.coords).tolist()]
                self._marker(
                    ns,
                    self.msgs.Marker.LINE_STRIP,
                    self.msgs.pose(0, 0),
                    (max(self.line_width, 1e-3), 0, 0),
                    color,
                    pts,
                )
