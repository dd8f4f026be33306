"""A disc robot's path round wall corners: the funnel through portals shrunk by the radius, its
bends replaced by polygons circumscribed about arcs of the radius round the corners, so that no
segment comes closer than the radius to a corner."""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from ....model.raster import Lattice
from .funnel import (
    FunnelEnds,
    away_from_walls,
    channel_portals,
    free_rectangles,
    funnel,
    rectangle_channel,
)
from .routes import channel

#: Most rounds of :func:`wrapped_funnel` adding a wall corner its path passed without a bend, or
#: releasing one the string no longer wraps.
WRAP_REPAIRS = 32


def wrapped_funnel(model, lat: Lattice, free, route, ends: FunnelEnds, terminate=None):
    """A disc robot's path on a map through the same route, closer to the walls than the wholly
    free cells allow (they lose up to a cell along every wall).

    The funnel runs through the cells no obstacle enters, with each portal's end moved the
    robot's radius in where a blocked cell touches it; every wall corner the funnel bends round
    then becomes a circle of the robot's radius, and the path the taut string round those
    circles (:func:`_round_corners`). Checked; None when it fails (a gap narrower than the
    robot, a corner passed without a bend) or the world is not a map."""
    point = model.point_free_cells(lat) if hasattr(model, "point_free_cells") else None
    r = float(model.robot_radius) + 16.0 * model.tol
    if point is None:
        return None
    # The cells along the walls next to the wholly free ones (and no others: a band stays a band).
    point &= ndimage.binary_dilation(free, iterations=math.ceil(r / lat.h) + 1)
    rects, label = free_rectangles(point)
    seq = rectangle_channel(channel(route), label)
    # Lattice points a blocked cell (or the lattice's edge) touches.
    pad = np.zeros((lat.nx + 2, lat.ny + 2), dtype=bool)
    pad[1:-1, 1:-1] = point
    walled = ~(pad[:-1, :-1] & pad[1:, :-1] & pad[:-1, 1:] & pad[1:, 1:])
    wall_portals = _wall_portals(
        channel_portals(seq, rects, lat, 0.0), lat, walled, r, 16.0 * model.tol
    )
    if wall_portals is None:
        return None  # narrower than the robot
    portals, corner_of = wall_portals
    inner = funnel(ends.a, ends.b, portals)
    corners = _sided([corner_of.get((float(x), float(y))) for x, y in inner[1:-1]], inner)
    (ox, oy), h = lat.origin, lat.h
    walls = np.column_stack([ox + h * np.nonzero(walled)[0], oy + h * np.nonzero(walled)[1]])
    for _ in range(WRAP_REPAIRS):
        if terminate is not None and terminate():
            return None
        rounded = _round_corners(inner, corners, r)
        if rounded is None:
            return None
        if isinstance(rounded, int):  # a corner the string no longer wraps: released
            inner = np.delete(inner, rounded, axis=0)
            del corners[rounded - 1]
            continue
        rounded, owner = rounded
        candidate = ends.path(rounded)
        if model.path_valid(candidate):
            return candidate
        # A wall corner the string passes without wrapping it (a side of the channel that is
        # free space, not wall, let the funnel pass it without a bend): it becomes a circle too.
        blamed = _blamed_corner(model, rounded, owner, inner, corners, walls, r)
        if blamed is None:
            return None
        k, at, corner = blamed
        side = _wall_side(corner, rounded[k + 1] - rounded[k], rounded[k], lat, point)
        inner = np.insert(inner, at, corner, axis=0)
        corners.insert(at - 1, (corner, side))
    return None


def _blamed_corner(model, rounded, owner, inner, corners, walls, r: float):
    """``(segment, insert at, wall corner)`` for the first segment of ``rounded`` that fails the
    check with a wall corner within ``r`` of it that is not one of the circles it runs between
    (such a circle was passed on the wrong side: not to be added again); None when there is
    none (the hops to the end points failed, or no corner is to blame)."""
    bad = np.flatnonzero(model.segment_violation(rounded[:-1], rounded[1:]) > 0.0)
    for k in bad.tolist():
        corner = _nearest_wall(rounded[k], rounded[k + 1], walls, r)
        at = int(owner[k]) + 1  # after the circle the segment leaves
        if corner is not None and not any(
            corners[i - 1] is not None and np.array_equal(corner, corners[i - 1][0])
            for i in (at - 1, at)
            if 0 < i < len(inner) - 1
        ):
            return k, at, corner
    return None


def _wall_side(corner: np.ndarray, d: np.ndarray, a: np.ndarray, lat: Lattice, point) -> float:
    """The side (+1 left, -1 right) of a path through ``a`` in direction ``d`` that the wall
    corner ``corner`` is to be passed on: the side it lies on, or, for a corner on the path's
    line (a path along a wall, touching it), the side of the blocked cells at it (their mean
    centre), not one by chance."""
    h = lat.h
    mass = -away_from_walls(corner, lat, point)  # towards the blocked cells' mean centre
    e = corner - a
    cross = d[0] * e[1] - d[1] * e[0]
    if abs(cross) <= 1e-9 * float(np.hypot(*d)) * h:  # on the line: the wall's side decides
        cross = d[0] * mass[1] - d[1] * mass[0]
    return 1.0 if cross > 0.0 else -1.0


def _sided(corners, path: np.ndarray):
    """``corners`` (one per interior vertex of ``path``: a wall corner or None) with the side
    each is passed on, ``(corner, +1)`` where the path turns left there, ``(corner, -1)`` right,
    None where it does not turn: fixed from the funnel's own path, so that a corner inserted by
    a repair cannot flip the sides of those around it."""
    out = []
    for k, corner in enumerate(corners, start=1):
        d_in, d_out = path[k] - path[k - 1], path[k + 1] - path[k]
        turn = d_in[0] * d_out[1] - d_in[1] * d_out[0]
        out.append(None if corner is None or turn == 0.0 else
                   (np.asarray(corner, dtype=float), 1.0 if turn > 0 else -1.0))  # fmt: skip
    return out


def _wall_portals(portals, lat: Lattice, walled: np.ndarray, r: float, tol: float):
    """``portals`` with each end moved ``r`` towards the other where a wall touches it
    (``walled``: the lattice points a blocked cell touches), ``tol`` elsewhere; and, for every
    end moved ``r``, the wall corner it came from (keyed by the moved end). None when a portal
    is narrower than that."""
    (ox, oy), h = lat.origin, lat.h
    out, corner_of = [], {}
    for left, right in portals:
        pair = [np.asarray(left, dtype=float), np.asarray(right, dtype=float)]
        width = float(np.hypot(*(pair[1] - pair[0])))
        moved = []
        for e, other in ((pair[0], pair[1]), (pair[1], pair[0])):
            wall = walled[round((e[0] - ox) / h), round((e[1] - oy) / h)]
            step = r if wall else tol
            if 2.0 * step >= width:
                return None
            q = e + step * (other - e) / width
            if wall:
                corner_of[(float(q[0]), float(q[1]))] = e
            moved.append((float(q[0]), float(q[1])))
        out.append((moved[0], moved[1]))
    return out, corner_of


def _nearest_wall(a: np.ndarray, b: np.ndarray, walls: np.ndarray, r: float):
    """The point of ``walls`` nearest the segment ``a b`` if closer than ``r``, else None."""
    lo, hi = np.minimum(a, b) - r, np.maximum(a, b) + r
    near = walls[np.all((walls >= lo) & (walls <= hi), axis=1)]
    if not len(near):
        return None
    d = b - a
    f = np.clip(((near - a) @ d) / max(float(d @ d), 1e-300), 0.0, 1.0)
    dist = np.hypot(*(a + f[:, None] * d - near).T)
    k = int(np.argmin(dist))
    return near[k] if dist[k] < r else None


def _round_corners(path: np.ndarray, corners, r: float):
    """The taut string from ``path[0]`` to ``path[-1]`` round circles of radius ``r`` at the
    ``corners`` (one per interior vertex: a point passed on the side the path turns to there,
    a ``(point, side)`` pair, side +1 for a corner on the left, or None for a vertex kept as a
    point); every arc replaced by the polygon circumscribed about it (:func:`round_circles`), so
    no segment comes closer than ``r`` to a corner. Also returns, for every vertex, the index
    of the path vertex whose circle it lies on. None when two circles on opposite sides overlap;
    the index ``k`` of the first path vertex whose arc would turn back (the string, pulled
    round the others, no longer touches that circle: it is to be released)."""
    centres, side = [path[0]], [0.0]
    for k, corner in enumerate(corners, start=1):
        d_in, d_out = path[k] - path[k - 1], path[k + 1] - path[k]
        turn = d_in[0] * d_out[1] - d_in[1] * d_out[0]
        if isinstance(corner, tuple):  # a corner given with its side
            centres.append(np.asarray(corner[0], dtype=float))
            side.append(corner[1])
        elif corner is None or turn == 0.0:
            centres.append(path[k])
            side.append(0.0)
        else:  # turning left: the corner is on the left, the path passes to its right
            centres.append(np.asarray(corner, dtype=float))
            side.append(1.0 if turn > 0 else -1.0)
    centres.append(path[-1])
    side.append(0.0)
    return round_circles(np.asarray(centres), np.full(len(centres), r), np.asarray(side))


def round_circles(c: np.ndarray, radii: np.ndarray, s: np.ndarray, piece: float = 0.25 * math.pi,
                  every_back: bool = False):  # fmt: skip
    """The taut string from ``c[0]`` to ``c[-1]`` round the circles of centres ``c[1:-1]`` and
    ``radii`` (a radius per centre; the ends' are not used), each passed on its side ``s`` (+1:
    the circle on the left; 0: the centre is a vertex of the string).

    Every arc is replaced by the polygon circumscribed about it, in pieces of at most ``piece``
    radians with vertices at ``r / cos(delta / 2)``: its edges are tangent to the circle, and it
    is longer than the arc by ``tan(piece / 2) / (piece / 2) - 1`` (5.5 % at 45 degrees, 0.06 %
    at 5; a corner's arc at the robot's radius is short, a circle's may not be).

    Returns ``(path, owner)`` (for every vertex, the index of the centre whose circle it lies
    on); None when two circles on opposite sides overlap (or two centres coincide); or the index
    ``k`` of the first centre whose arc would turn back by more than half a turn (the string,
    pulled round the others, no longer touches that circle; with ``every_back``, the indices of
    all such centres, an array).
    """
    r = np.where(s != 0.0, radii, 0.0)
    d = np.diff(c, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    if not np.all(length > 0.0):
        return None
    u = d / length[:, None]
    # The common tangent of consecutive circles: travel t at angle phi to the line of centres,
    # sin(phi) = (s_k r_k - s_k+1 r_k+1) / L; the tangent points lie s r along t's right normal.
    sin_phi = (s[:-1] * r[:-1] - s[1:] * r[1:]) / length
    if np.any(np.abs(sin_phi) >= 1.0):
        return None
    t = np.sqrt(1.0 - sin_phi**2)[:, None] * u + sin_phi[:, None] * np.column_stack(
        [-u[:, 1], u[:, 0]]
    )
    m = np.column_stack([t[:, 1], -t[:, 0]])
    leave = c[:-1] + (s[:-1] * r[:-1])[:, None] * m
    arrive = c[1:] + (s[1:] * r[1:])[:, None] * m
    # Every arc at once: from the tangent point arriving at circle k to the one leaving it.
    inner = np.arange(1, len(c) - 1)
    wrapped = inner[s[inner] != 0.0]
    e_in, e_out = arrive[wrapped - 1] - c[wrapped], leave[wrapped] - c[wrapped]
    a_in = np.arctan2(e_in[:, 1], e_in[:, 0])
    sweep = (np.arctan2(e_out[:, 1], e_out[:, 0]) - a_in) % (2.0 * math.pi)
    sweep = np.where(s[wrapped] < 0, sweep - 2.0 * math.pi, sweep)
    back = np.flatnonzero(np.abs(sweep) > math.pi)
    if len(back):  # more than half a turn: the string would turn back
        return wrapped[back] if every_back else int(wrapped[back[0]])
    pieces = np.maximum(1, np.ceil(np.abs(sweep) / piece)).astype(np.int64)
    delta = sweep / pieces
    arc_of = np.repeat(np.arange(len(wrapped)), pieces)
    within = np.arange(len(arc_of)) - np.repeat(np.cumsum(pieces) - pieces, pieces)
    ang = a_in[arc_of] + (within + 0.5) * delta[arc_of]
    rho = (r[wrapped] / np.cos(0.5 * delta))[arc_of]
    arcs = c[wrapped][arc_of] + rho[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    # Each centre's vertices in order: the arc's polygon, or the centre itself (side 0).
    owner_of = np.concatenate([[0], np.repeat(inner, np.where(s[inner] != 0.0, 0, 1)),
                               wrapped[arc_of], [len(c) - 1]])  # fmt: skip
    points = np.vstack([c[:1], c[inner][s[inner] == 0.0], arcs, c[-1:]])
    order = np.argsort(owner_of, kind="stable")
    return points[order], owner_of[order]


def circumscribe_corners(path: np.ndarray, lat: Lattice, free: np.ndarray, r: float) -> np.ndarray:
    """Replace each interior vertex that lies on a lattice corner with the polygon
    circumscribed about the arc of radius ``r`` round that corner, from the normal of the
    segment coming in to that of the segment going out (vertices at ``r / cos(delta / 2)``,
    ``delta`` at most 45 degrees): each of its segments is tangent to the circle, so none comes
    closer than ``r`` to the corner."""
    (ox, oy), h = lat.origin, lat.h
    out = [path[0]]
    for k in range(1, len(path) - 1):
        v, u, w = path[k], path[k - 1], path[k + 1]
        corner = np.array([ox + h * round((v[0] - ox) / h), oy + h * round((v[1] - oy) / h)])
        d_in, d_out = v - u, w - v
        n_in, n_out = np.hypot(*d_in), np.hypot(*d_out)
        if n_in == 0.0 or n_out == 0.0 or np.hypot(*(v - corner)) > 0.25 * h:
            out.append(v)
            continue
        turn = math.atan2(d_in[0] * d_out[1] - d_in[1] * d_out[0], float(d_in @ d_out))
        side = -math.copysign(1.0, turn)  # the path turns round the corner on this side
        # Normals pointing away from the corner, on the outside of the turn.
        a_in = math.atan2(d_in[1], d_in[0]) + side * 0.5 * math.pi
        pieces = max(1, math.ceil(abs(turn) / (0.25 * math.pi)))
        delta = turn / pieces
        rho = r / math.cos(0.5 * delta)
        for i in range(pieces):
            ang = a_in + (i + 0.5) * delta
            out.append(corner + rho * np.array([math.cos(ang), math.sin(ang)]))
    out.append(path[-1])
    return np.asarray(out)
