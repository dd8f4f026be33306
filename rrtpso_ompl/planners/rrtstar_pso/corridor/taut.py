"""The taut string of a path's homotopy among circles: the shortest path that passes every
circle on the same side as the path does, its arcs replaced by circumscribed polygons.

The corridor stage's funnel path runs through cells wholly free, which lose up to a cell along
every circle: among 10,000 circles it was 3 % over the optimum in the right corridor. The string
here starts straight from start to goal; every circle a segment of it enters becomes an anchor,
wrapped on the side the reference path passes it (the homotopy); the string is pulled round the
anchors in their order along it (:func:`.corners.round_circles`), anchors it no longer touches
are released, and the round repeats until the exact check passes.

Worlds with boxes or polygons are declined (None): a segment may cross a polygon far from every
corner, so no anchor would be entered there; their corridors keep the funnel path, whose cells
follow straight edges without loss.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from .corners import round_circles

#: Most rounds of anchoring the obstacles the string enters (each round one exact check of
#: the string and one pull).
TAUT_ROUNDS = 64

#: The longest piece of a circumscribed arc, radians (its polygon 0.06 % longer than the arc).
TAUT_PIECE = math.radians(5.0)

#: Most point-segment pairs :func:`sides_along` holds at once (memory: a few arrays of them).
PAIRS = 1 << 20

#: Most points along a segment at which the circles near it are looked up.
SEGMENT_SAMPLES = 4096

#: Most releases of anchors the string no longer touches, per round.
TAUT_RELEASES = 256


class Anchors:
    """The circles a string may wrap: of their radius plus the robot's, a few round-offs wider
    so that the string passes the check; a spatial index over their centres."""

    def __init__(self, world) -> None:
        margin = world.threshold + 16.0 * world.tol
        self.centres = world.circles[:, :2]
        self.radii = world.circles[:, 2] + margin
        self.tree = cKDTree(self.centres) if len(self.centres) else None
        self.reach = float(self.radii.max()) if len(self.radii) else 0.0

    def entered(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Indices of the anchors whose circle the segment ``a b`` enters."""
        if self.tree is None:
            return np.empty(0, dtype=np.int64)
        d = b - a
        length = float(np.hypot(*d))
        # Points along the segment ``spacing`` apart (about a reach, at most SEGMENT_SAMPLES of
        # them): every centre within reach of the segment is within reach + spacing / 2 of one.
        n = min(SEGMENT_SAMPLES, max(2, math.ceil(length / max(self.reach, 1e-300)) + 1))
        pts = a + np.linspace(0.0, 1.0, n)[:, None] * d
        radius = self.reach + 0.5 * length / (n - 1) + 1e-9 * (1.0 + length)
        near = np.unique(np.concatenate(
            [np.asarray(x, dtype=np.int64) for x in self.tree.query_ball_point(pts, radius)]
            + [np.empty(0, dtype=np.int64)]))  # fmt: skip
        if not len(near):
            return near
        f = np.clip(((self.centres[near] - a) @ d) / max(float(d @ d), 1e-300), 0.0, 1.0)
        dist = np.hypot(*(a + f[:, None] * d - self.centres[near]).T)
        return near[dist < self.radii[near]]


def sides_along(reference: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each point, the arc length along ``reference`` of its nearest point there and the side
    it lies on (+1 left, -1 right of the direction of travel). Points by segments at once, in
    chunks of at most :data:`PAIRS` pairs."""
    a, b = reference[:-1], reference[1:]
    d = b - a
    dd = np.maximum((d * d).sum(axis=1), 1e-300)
    start = np.concatenate([[0.0], np.cumsum(np.sqrt(dd))])[:-1]
    s_out, side = np.empty(len(points)), np.empty(len(points))
    step = max(1, PAIRS // max(len(a), 1))
    for lo in range(0, len(points), step):
        p = points[lo : lo + step, None, :]
        f = np.clip(((p - a) * d).sum(axis=2) / dd, 0.0, 1.0)
        q = a + f[..., None] * d
        k = np.argmin(((q - p) ** 2).sum(axis=2), axis=1)
        rows = np.arange(len(k))
        e = p[:, 0] - q[rows, k]
        cross = d[k, 0] * e[:, 1] - d[k, 1] * e[:, 0]
        s_out[lo : lo + step] = start[k] + f[rows, k] * np.sqrt(dd[k])
        side[lo : lo + step] = np.where(cross > 0.0, 1.0, -1.0)
    return s_out, side


def taut_string(world, reference: np.ndarray, terminate=None) -> np.ndarray | None:
    """The taut string of ``reference``'s homotopy in ``world``, checked exactly; None when it
    does not converge within :data:`TAUT_ROUNDS` rounds, ``terminate()`` says stop, or the
    world is not one of circles alone (no map, boxes or polygons).

    Each round anchors the obstacles the string enters on the side ``reference`` passes them,
    orders every anchor by where it lies along the string (the string is nearer the answer
    than the reference: ordered along the reference, two neighbouring circles traded places
    and were anchored and released in turn), and pulls the string round them.
    """
    if not circles_alone(world):
        return None
    anchors = Anchors(world)
    start, goal = reference[0], reference[-1]
    string = np.array([start, goal], dtype=float)
    side: dict[int, float] = {}  # anchor -> side
    for _ in range(TAUT_ROUNDS):
        if terminate is not None and terminate():
            return None
        bad = np.flatnonzero(world.segment_violation(string[:-1], string[1:]) > 0.0)
        if not len(bad):
            return string if world.path_valid(string) else None
        new = np.unique(np.concatenate([anchors.entered(string[k], string[k + 1]) for k in bad]))
        new = np.array([i for i in new.tolist() if i not in side], dtype=np.int64)
        if not len(new):
            return None  # entered an anchor already wrapped, or an obstacle that is none
        side.update(zip(new.tolist(), sides_along(reference, anchors.centres[new])[1].tolist(),
                        strict=True))  # fmt: skip
        chosen = np.array(list(side), dtype=np.int64)
        along = sides_along(string, anchors.centres[chosen])[0]
        string = _pulled(start, goal, anchors, side, chosen[np.argsort(along, kind="stable")])
        if string is None:
            return None
    return None


def circles_alone(world) -> bool:
    """Whether ``world`` is a World whose obstacles are circles only (where :func:`taut_string`
    applies)."""
    if getattr(world, "raster", None) is not None or not hasattr(world, "circles"):
        return False
    return len(world.circles) > 0 and not len(world.boxes) and not world.polygons


def _pulled(start, goal, anchors: Anchors, side: dict, order: np.ndarray) -> np.ndarray | None:
    """The string from ``start`` to ``goal`` round the anchors ``order`` (on their ``side``),
    those it does not touch released (removed from ``side``); None when two anchors on
    opposite sides overlap."""
    order = order.tolist()
    for _ in range(TAUT_RELEASES):
        idx = np.array(order, dtype=np.int64)
        centres = np.vstack([start[None], anchors.centres[idx], goal[None]])
        radii = np.concatenate([[0.0], anchors.radii[idx], [0.0]])
        sides = np.concatenate([[0.0], [side[i] for i in order], [0.0]])
        out = round_circles(centres, radii, sides, TAUT_PIECE, every_back=True)
        if out is None or isinstance(out, tuple):
            return None if out is None else out[0]
        # Arcs that would turn back: the string no longer wraps those anchors (all at once; one
        # wrongly released is entered again and anchored in the next round).
        for k in sorted(out.tolist(), reverse=True):
            del side[order.pop(k - 1)]
    return None
