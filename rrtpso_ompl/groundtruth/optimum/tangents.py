"""Common tangents of circles, and the cones of free directions at polygon vertices.

Two circles ``i`` and ``j`` (centres ``c``, radii ``rho``; a point has radius 0) have up to four
common tangents: two outer, whose normals make the angle ``acos((rho_i - rho_j) / d)`` with the
line of centres, and two inner, ``acos((rho_i + rho_j) / d)``, with the normal reversed on
circle ``j`` (LaValle, *Planning Algorithms*, 2006, section 6.2.4). A path along a tangent wraps
each circle in a sense: +1 counter-clockwise, -1 clockwise. Angles are in radians, lengths in
the problem's unit.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["ANGLE_TOL", "TWO_PI", "Tangents", "cone_pos", "tangents_from"]

#: A whole turn, radians.
TWO_PI = 2.0 * math.pi
#: Round-off allowed on angles at a cone's ends, radians: a tangent along a polygon's edge leaves
#: and reaches its end vertices exactly at their cones' ends, and which side of them its computed
#: angles fall on is chance. (A tangent that far outside a cone comes nearer the edge by
#: ``rho (1 - cos(1e-7))``, about ``5e-15 rho``: far below the touch tolerance.)
ANGLE_TOL = 1e-7


def cone_pos(angle: Any, lo: Any) -> Any:
    """Angle from the start of a circle's free arc, counter-clockwise.

    Parameters
    ----------
    angle, lo : float or ndarray
        Angles of the points and of the free arc's start, radians.

    Returns
    -------
    float or ndarray
        Radians, in ``[-ANGLE_TOL, 2 pi - ANGLE_TOL)``: an angle a hair before the start stays
        a hair before it (a plain ``mod`` puts it a whole turn ahead, outside every cone, and
        the search refused the tangents along half of the polygons' edges).
    """
    return np.mod(angle - lo + ANGLE_TOL, TWO_PI) - ANGLE_TOL


class Tangents:
    """The common tangents from one circle to many: arrays of the same length.

    ``q`` is where each tangent ends (its tangent point, or where it enters the goal disc);
    ``pos_i`` is the tangent point's angle from the start of circle i's free arc; ``seg``, ``h``
    and ``node`` (the tangent's length, the lower bound from its end to the goal, and the node
    it reaches, -1 before it is reached) are filled in by the search.
    """

    _FIELDS = ("i", "j", "t", "p", "q", "angle_i", "angle_j", "sense_i", "sense_j", "pos_i",
               "seg", "h", "node")  # fmt: skip

    def __init__(self, i, j, t, p, q, angle_i, angle_j, sense_i, sense_j) -> None:
        self.i, self.j, self.t, self.p, self.q = i, j, t, p, q
        self.angle_i, self.angle_j = angle_i, angle_j
        self.sense_i, self.sense_j = sense_i, sense_j
        self.pos_i = self.seg = self.h = self.node = None

    def take(self, idx: np.ndarray) -> Tangents:
        out = Tangents.__new__(Tangents)
        for name in self._FIELDS:
            value = getattr(self, name)
            setattr(out, name, None if value is None else value[idx])
        return out


def tangents_from(circles: np.ndarray, i: np.ndarray, j: np.ndarray) -> Tangents:
    """Every common tangent from circle ``i[k]`` to circle ``j[k]``, for each pair, with the sense
    in which a path along it wraps each circle (+1 counter-clockwise, -1 clockwise, 0 for a
    point)."""
    c = circles
    i = np.asarray(i, dtype=np.intp)
    j = np.asarray(j, dtype=np.intp)
    ri, rj = c[i, 2], c[j, 2]
    d_vec = c[j, :2] - c[i, :2]
    d = np.hypot(*d_vec.T)
    base = np.arctan2(d_vec[:, 1], d_vec[:, 0])
    parts = []
    # Outer tangents: normal at angle base +- acos((ri - rj) / d) on both circles. Inner ones:
    # base +- acos((ri + rj) / d), with the normal reversed on circle j. A radius of 0 makes
    # the inner tangents repeat the outer ones, and two points have one tangent.
    for t, (inner, sign) in enumerate(((False, 1.0), (False, -1.0), (True, 1.0), (True, -1.0))):
        if inner:
            ok = (ri > 0) & (rj > 0) & (d > ri + rj)
            cos_a = np.divide(ri + rj, d, out=np.ones_like(d), where=d > 0)
        else:
            ok = d > np.abs(ri - rj)
            if sign < 0:
                ok &= (ri > 0) | (rj > 0)
            cos_a = np.divide(ri - rj, d, out=np.ones_like(d), where=d > 0)
        ang = base + sign * np.arccos(np.clip(cos_a, -1.0, 1.0))
        n = np.column_stack([np.cos(ang), np.sin(ang)])
        p = c[i, :2] + ri[:, None] * n
        q = c[j, :2] + (-1.0 if inner else 1.0) * rj[:, None] * n
        aj = ang + math.pi if inner else ang
        parts.append((i[ok], j[ok], np.full(int(ok.sum()), t), p[ok], q[ok], ang[ok], aj[ok]))
    ii, jj, tt, p, q, ai, aj = (np.concatenate(x) for x in zip(*parts, strict=True))
    direction = q - p
    sense_i = np.where(c[ii, 2] > 0, _sense(direction, c[ii, :2] - p), 0)
    sense_j = np.where(c[jj, 2] > 0, _sense(direction, c[jj, :2] - q), 0)
    return Tangents(ii, jj, tt, p, q, np.mod(ai, TWO_PI), np.mod(aj, TWO_PI), sense_i,
                     sense_j)  # fmt: skip


def _sense(direction: np.ndarray, to_center: np.ndarray) -> np.ndarray:
    """+1 when the centre lies to the left of the direction of travel (counter-clockwise)."""
    z = direction[:, 0] * to_center[:, 1] - direction[:, 1] * to_center[:, 0]
    return np.where(z > 0, 1, -1)
