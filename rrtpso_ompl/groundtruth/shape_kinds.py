"""Generated shape problems of the families planners are usually compared on
(``rrtpso generate slabs|combs|spiral|rooms``): obstacles as shapes in the problem file, certified
as the other kinds are (:mod:`.kinds`).

* ``slabs``: thin slanted rectangles (polygons) in rows across the workspace, gaps between them:
  the point-robot "slanted slabs" family (:class:`SlabsOptions`);
* ``combs``: two interleaved combs of long thin teeth, from the bottom and from the top, so the
  path zig-zags between them (:class:`CombsOptions`);
* ``spiral``: a square spiral of walls, start outside and goal in the centre, or the reverse
  (:class:`SpiralOptions`);
* ``rooms``: a grid of rooms whose walls are rectangles, doors in random places over a spanning
  tree plus extra doors (:class:`RoomsOptions`).

Sizes are fractions of ``size`` unless given, in metres (the files say ``units: m``); every random
choice comes from the generator's one seeded stream.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import GenerationError
from ..params import Rule, declared, param
from .certify import GRID_POINTS
from .kinds import GeneratorOptions, register_kind

__all__ = ["CombsOptions", "RoomsOptions", "SlabsOptions", "SpiralOptions"]


def _rect(x0: float, y0: float, x1: float, y1: float) -> dict[str, Any]:
    return {"type": "rectangle", "min": [float(min(x0, x1)), float(min(y0, y1))],
            "max": [float(max(x0, x1)), float(max(y0, y1))]}  # fmt: skip


def _fraction_range(name: str) -> Rule:
    return Rule((name,), lambda v: v is None or 0 < v[0] <= v[1], f"0 < {name} min <= max")


class _ShapeOptions(GeneratorOptions):
    """What the shape kinds share: a default robot radius of 0.005 size and a certificate grid
    fine enough for the narrowest passage the kind makes (:meth:`passage`)."""

    robot_radius: float | None = param(
        None, "Robot radius (0: a point robot). Default: 0.005 size.", unit="length", low=0.0
    )

    def passage(self, robot: float) -> float:
        """The narrowest free width the robot's centre gets, for the certificate's grid."""
        raise NotImplementedError

    def _resolve_shapes(self, **values: Any):
        robot = 0.005 * self.size if self.robot_radius is None else self.robot_radius
        free = self.passage(robot)
        if free <= 0:
            raise GenerationError(
                f"the robot (radius {robot:g}) does not fit the narrowest passage of {self.KIND}; "
                "use a smaller robot_radius or wider gaps"
            )
        return self._resolve(min(self.size / GRID_POINTS, free / 4.0), robot_radius=robot,
                             **values)  # fmt: skip


@register_kind
@declared(
    rules=(
        _fraction_range("length"),
        _fraction_range("gaps"),
        Rule(("angle",), lambda a: a[0] <= a[1], "angle min <= max"),
    )
)
class SlabsOptions(_ShapeOptions):
    """Rows of thin slanted slabs (``rrtpso generate slabs``)."""

    KIND: ClassVar[str] = "slabs"

    rows: int = param(6, "Rows of slabs, between start (bottom) and goal (top).", low=1, high=200)
    length: tuple[float, float] | None = param(
        None, "Least and largest slab length. Default: (0.06 size, 0.14 size).", unit="length",
        low=0.0,
    )  # fmt: skip
    thickness: float | None = param(None, "Slab thickness. Default: 0.008 size.", unit="length",
                                    low=0.0)  # fmt: skip
    angle: tuple[float, float] = param(
        (20.0, 70.0), "Least and largest slant from the horizontal, degrees (either way).",
        low=0.0, high=90.0,
    )  # fmt: skip
    gaps: tuple[float, float] | None = param(
        None,
        "Least and largest free gap between neighbouring slabs of a row (between their bounding "
        "boxes). Default: (0.02 size, 0.05 size).",
        unit="length",
        low=0.0,
    )

    def passage(self, robot: float) -> float:
        gaps = self.gaps or (0.02 * self.size, 0.05 * self.size)
        return gaps[0] - 2.0 * robot

    def resolved(self) -> SlabsOptions:
        s = self.size
        return self._resolve_shapes(
            length=self.length or (0.06 * s, 0.14 * s),
            thickness=self.thickness or 0.008 * s,
            gaps=self.gaps or (0.02 * s, 0.05 * s),
        )

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([0.5, 0.03]) * self.size, np.array([0.5, 0.97]) * self.size

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        s, t = self.size, self.thickness
        ys = np.linspace(0.15 * s, 0.85 * s, self.rows) if self.rows > 1 else np.array([0.5 * s])
        out = []
        for y in ys.tolist():
            x = float(rng.uniform(0.0, self.gaps[1]))
            for _ in range(10_000):  # bounded: each slab advances x by at least the least gap
                length = rng.uniform(*self.length)
                theta = math.radians(rng.uniform(*self.angle)) * (1 if rng.random() < 0.5 else -1)
                u = np.array([math.cos(theta), math.sin(theta)]) * 0.5 * length
                v = np.array([-math.sin(theta), math.cos(theta)]) * 0.5 * t
                half_w = abs(u[0]) + abs(v[0])
                half_h = abs(u[1]) + abs(v[1])
                cx = x + half_w
                if cx + half_w > s:
                    break
                c = np.array([cx, y])
                pts = np.array([c - u - v, c + u - v, c + u + v, c - u + v])
                # Keep slabs off start and goal.
                if min(abs(y - 0.03 * s), abs(y - 0.97 * s)) > half_h + 0.02 * s:
                    out.append({"type": "polygon", "points": pts.tolist()})
                x = cx + half_w + rng.uniform(*self.gaps)
        return out

    def describe(self) -> str:
        return (
            f"{self.rows} rows of thin slanted slabs (length {self.length[0]:.3g}-"
            f"{self.length[1]:.3g}, thickness {self.thickness:.3g}, slant {self.angle[0]:g}-"
            f"{self.angle[1]:g} degrees either way, free gaps {self.gaps[0]:.3g}-"
            f"{self.gaps[1]:.3g} between them) in a {self.size:g} x {self.size:g} workspace; "
            f"robot radius {self.robot_radius:g}, start at the bottom, goal at the top."
        )


@register_kind
@declared(rules=(_fraction_range("reach"),))
class CombsOptions(_ShapeOptions):
    """Two interleaved combs (``rrtpso generate combs``)."""

    KIND: ClassVar[str] = "combs"

    teeth: int = param(10, "Teeth of each comb.", low=1, high=10_000)
    reach: tuple[float, float] = param(
        (0.6, 0.8), "Least and largest tooth length, as a share of the workspace's height "
        "(above 0.5 the combs interleave).", low=0.0, high=0.95,
    )  # fmt: skip
    thickness: float | None = param(None, "Tooth thickness. Default: 0.008 size.", unit="length",
                                    low=0.0)  # fmt: skip

    def _pitch(self) -> float:
        """Distance between neighbouring teeth (one comb's and the other's)."""
        return 0.84 * self.size / (2 * self.teeth)

    def passage(self, robot: float) -> float:
        t = self.thickness or 0.008 * self.size
        return 0.8 * self._pitch() - t - 2.0 * robot  # teeth jitter by 0.1 pitch either way

    def resolved(self) -> CombsOptions:
        return self._resolve_shapes(thickness=self.thickness or 0.008 * self.size)

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([0.03, 0.5]) * self.size, np.array([0.97, 0.5]) * self.size

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        s, t = self.size, self.thickness
        pitch = self._pitch()
        n = 2 * self.teeth
        xs = 0.08 * s + pitch * (np.arange(n) + 0.5) + rng.uniform(-0.1, 0.1, n) * pitch
        reach = rng.uniform(*self.reach, n) * s
        out = []
        for k, (x, r) in enumerate(zip(xs.tolist(), reach.tolist(), strict=True)):
            if k % 2 == 0:  # from the bottom
                out.append(_rect(x - t / 2, 0.0, x + t / 2, r))
            else:  # from the top
                out.append(_rect(x - t / 2, s - r, x + t / 2, s))
        return out

    def describe(self) -> str:
        return (
            f"Two interleaved combs of {self.teeth} teeth each (thickness {self.thickness:.3g}, "
            f"reaching {self.reach[0]:.0%}-{self.reach[1]:.0%} of the height from the bottom and "
            f"from the top) in a {self.size:g} x {self.size:g} workspace, so the path zig-zags "
            f"between them; robot radius {self.robot_radius:g}, start left, goal right."
        )


@register_kind
@declared
class SpiralOptions(_ShapeOptions):
    """A square spiral of walls (``rrtpso generate spiral``)."""

    KIND: ClassVar[str] = "spiral"

    turns: int = param(5, "Turns of the spiral.", low=1, high=1000)
    thickness: float | None = param(
        None, "Wall thickness. Default: a fifth of the spacing of the loops.", unit="length",
        low=0.0,
    )  # fmt: skip
    reverse: bool = param(False, "Start in the centre, goal outside (default: the other way).")

    def _spacing(self) -> float:
        """Distance between neighbouring loops (wall centre to wall centre)."""
        return 0.9 * self.size / (2 * self.turns + 1)

    def passage(self, robot: float) -> float:
        w = self._spacing()
        return w - (self.thickness or 0.2 * w) - 2.0 * robot

    def resolved(self) -> SpiralOptions:
        return self._resolve_shapes(thickness=self.thickness or 0.2 * self._spacing())

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        outside = np.array([0.025, 0.025]) * self.size
        centre = np.array([0.5, 0.5]) * self.size
        return (centre, outside) if self.reverse else (outside, centre)

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        s, t, w = self.size, self.thickness, self._spacing()
        m = 0.05 * s
        length = s - 2 * m
        p = np.array([m, m])
        directions = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
        segments = []
        for k in range(4 * self.turns + 4):
            seg = length - (k // 2) * w  # L, L, L - w, L - w, ...: loops w apart
            if seg <= 0.5 * w:
                break
            q = p + directions[k % 4] * seg
            segments.append((p, q))
            p = q
        # A random one of the square's eight symmetries (about the centre): which corner the
        # spiral starts in and which way it turns.
        flip = rng.random() < 0.5
        quarter = int(rng.integers(4))
        centre = np.array([0.5 * s, 0.5 * s])
        rot = np.array([[0.0, -1.0], [1.0, 0.0]])
        out = []
        h = 0.5 * t
        for a, b in segments:
            ends = []
            for pt in (a, b):
                d = pt - centre
                if flip:
                    d = d * np.array([-1.0, 1.0])
                for _ in range(quarter):
                    d = rot @ d
                ends.append(centre + d)
            (x0, y0), (x1, y1) = ends
            out.append(_rect(min(x0, x1) - h, min(y0, y1) - h, max(x0, x1) + h, max(y0, y1) + h))
        return out

    def describe(self) -> str:
        where = "start in the centre, goal outside" if self.reverse else (
            "start outside, goal in the centre")  # fmt: skip
        return (
            f"A square spiral of walls with {self.turns} turns (loops {self._spacing():.3g} apart, "
            f"walls {self.thickness:.3g} thick) in a {self.size:g} x {self.size:g} workspace; "
            f"robot radius {self.robot_radius:g}, {where}."
        )


@register_kind
@declared(rules=(_fraction_range("door_width"),))
class RoomsOptions(_ShapeOptions):
    """Rooms joined by doors, walls as rectangles (``rrtpso generate rooms``)."""

    KIND: ClassVar[str] = "rooms"

    rooms: int = param(4, "Rooms per side.", low=1, high=100)
    thickness: float | None = param(None, "Wall thickness. Default: 0.01 size.", unit="length",
                                    low=0.0)  # fmt: skip
    door_width: tuple[float, float] | None = param(
        None, "Least and largest door width. Default: (0.25, 0.4) of a room's side.",
        unit="length", low=0.0,
    )  # fmt: skip
    extra_doors: float = param(
        0.3,
        "Share of the walls between two rooms that get a door beyond those of a spanning tree "
        "(0: one route between any two rooms).",
        low=0.0,
        high=1.0,
    )

    def _cell(self) -> float:
        return self.size / self.rooms

    def passage(self, robot: float) -> float:
        door = self.door_width or (0.25 * self._cell(), 0.4 * self._cell())
        return door[0] - 2.0 * robot

    def resolved(self) -> RoomsOptions:
        c = self._cell()
        door = self.door_width or (0.25 * c, 0.4 * c)
        t = self.thickness or 0.01 * self.size
        if door[1] > 0.6 * c - t:
            raise GenerationError(
                f"door_width {door[1]:g} must be at most 0.6 of a room's side minus the wall "
                f"thickness ({0.6 * c - t:g})"
            )
        return self._resolve_shapes(thickness=t, door_width=door)

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        c = self._cell()
        return np.array([0.5 * c, 0.5 * c]), np.array([self.size - 0.5 * c, self.size - 0.5 * c])

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        n, c, t, s = self.rooms, self._cell(), self.thickness, self.size
        h = 0.5 * t
        # Interior wall lines, each moved by up to 0.15 of a room.
        lines = c * np.arange(1, n) + rng.uniform(-0.15, 0.15, (2, n - 1)) * c
        xs = np.concatenate([[0.0], lines[0], [s]])
        ys = np.concatenate([[0.0], lines[1], [s]])
        walls = [(i, j, i + 1, j) for i in range(n - 1) for j in range(n)]  # above room (i, j)
        walls += [(i, j, i, j + 1) for i in range(n) for j in range(n - 1)]  # right of it
        parent = list(range(n * n))

        def find(x: int) -> int:
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        door_of: dict[int, tuple[float, float]] = {}
        for k in rng.permutation(len(walls)).tolist():
            i, j, a, b = walls[k]
            ra, rb = find(i * n + j), find(a * n + b)
            if ra == rb and rng.random() >= self.extra_doors:
                continue
            parent[ra] = rb
            lo, hi = (xs[j], xs[j + 1]) if a != i else (ys[i], ys[i + 1])
            w = rng.uniform(*self.door_width)
            start = rng.uniform(lo + h + 0.1 * c, hi - h - 0.1 * c - w)
            door_of[k] = (start, start + w)
        out = []
        for k, (i, j, a, _b) in enumerate(walls):
            if a != i:  # horizontal wall at y = ys[i + 1] from xs[j] to xs[j + 1]
                y = ys[i + 1]
                lo, hi = xs[j] - h, xs[j + 1] + h
                pieces = [(lo, hi)] if k not in door_of else [(lo, door_of[k][0]),
                                                              (door_of[k][1], hi)]  # fmt: skip
                out += [_rect(p, y - h, q, y + h) for p, q in pieces]
            else:  # vertical wall at x = xs[j + 1] from ys[i] to ys[i + 1]
                x = xs[j + 1]
                lo, hi = ys[i] - h, ys[i + 1] + h
                pieces = [(lo, hi)] if k not in door_of else [(lo, door_of[k][0]),
                                                              (door_of[k][1], hi)]  # fmt: skip
                out += [_rect(x - h, p, x + h, q) for p, q in pieces]
        return out

    def describe(self) -> str:
        return (
            f"{self.rooms} x {self.rooms} rooms (walls {self.thickness:.3g} thick, doors "
            f"{self.door_width[0]:.3g}-{self.door_width[1]:.3g} wide in random places over a "
            f"spanning tree plus {self.extra_doors:.0%} extra doors) in a {self.size:g} x "
            f"{self.size:g} workspace; robot radius {self.robot_radius:g}, start and goal in "
            "opposite corner rooms."
        )
