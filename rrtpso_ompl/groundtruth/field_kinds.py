"""Random fields of non-overlapping obstacles (``rrtpso generate circles|polygons``).

* ``circles``: random non-overlapping circles (:class:`CirclesOptions`);
* ``polygons``: random non-overlapping convex polygons (:class:`PolygonsOptions`).

Start and goal are in opposite corners, at ``(0.05 size, 0.05 size)`` and its mirror image;
obstacles keep at least ``max(2 robot_radius, 0.03 size)`` away from both. The discs (circles,
or the polygons' circumcircles) are placed by rejection sampling against a k-d tree of those
placed so far; every random choice comes from the generator's one seeded stream
(:mod:`.kinds`).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np

from ..errors import GenerationError
from ..params import Rule, declared, param
from .certify import GRID_POINTS
from .kinds import GeneratorOptions, register_kind

__all__ = ["MAX_OBSTACLES", "CirclesOptions", "PolygonsOptions"]

#: Most obstacles of a circle or polygon field: the bound of every loop and allocation.
MAX_OBSTACLES = 100_000


#: The radii of circles and polygons: 0 < min <= max < size / 2.
_RADII_RULE = Rule(
    ("radius_range", "size"),
    lambda r, size: r is None or 0 < r[0] <= r[1] < size / 2,
    "0 < radius_range min <= max < size / 2",
)


@declared(
    rules=(
        Rule(("robot_radius", "size"), lambda r, size: r is None or r < 0.05 * size,
             "robot_radius < 0.05 size (the start's inset from the corner)"),
    )
)  # fmt: skip
class _FieldOptions(GeneratorOptions):
    """Random non-overlapping obstacles, start and goal in opposite corners (circles and
    polygons: each kind declares ``n``, ``radius_range`` and ``gap`` and draws its shapes)."""

    #: Default radii (circumradii) as fractions of ``size``, for the default number of obstacles.
    RADII: ClassVar[tuple[float, float]] = (0.0, 0.0)

    robot_radius: float | None = param(
        None,
        "Robot radius (0: a point robot), less than 0.05 size (the start's inset from the "
        "corner). Default: 0.01 size, shrunk as the radii beyond 100 obstacles.",
        unit="length",
        low=0.0,
    )

    # Each kind declares n, radius_range and gap (their defaults and docs differ).

    def resolved(self) -> _FieldOptions:
        default_n = self.PARAMS["n"].default
        shrink = _shrink(self.n, default_n)
        radius_range = self.radius_range
        if radius_range is None:
            lo, hi = self.RADII
            radius_range = (lo * self.size * shrink, hi * self.size * shrink)
        robot = 0.01 * self.size * shrink if self.robot_radius is None else self.robot_radius
        return self._resolve(self.size / GRID_POINTS, radius_range=radius_range,
                             robot_radius=robot)  # fmt: skip

    def start_goal(self) -> tuple[np.ndarray, np.ndarray]:
        inset = 0.05 * self.size
        return np.array([inset, inset]), np.array([self.size - inset, self.size - inset])

    def draw(self, rng: np.random.Generator) -> list[dict[str, Any]]:
        centres, radii = self._place(rng)
        return self._shapes(rng, centres, radii)

    def _shapes(self, rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray
                ) -> list[dict[str, Any]]:  # fmt: skip
        """The obstacles in the circles ``(centres, radii)``."""
        raise NotImplementedError

    def _place(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """n non-overlapping discs by rejection sampling: ``(centres, radii)``.

        Candidates come in batches of 256, each tested against the obstacles placed so far that
        a k-d tree of their centres names within reach (``r + hi + gap``), then accepted in
        order, each also tested against those accepted before it in the same batch. The cost
        per batch grows as ``log n``, not ``n``: 10,000 obstacles take a second or two. The
        stream is consumed batch by batch, so the result depends on the seed only.
        """
        lo, hi = self.radius_range
        centres = np.empty((self.n, 2))
        radii = np.empty(self.n)
        ends = np.array(self.start_goal())
        # Obstacles keep off start and goal: the robot must be able to turn away from them.
        keep_out = max(2.0 * self.robot_radius, 0.03 * self.size)
        placed = 0
        budget = max(200 * self.n, 10_000)
        batch = 256
        for _ in range(0, budget, batch):
            r = rng.uniform(lo, hi, size=batch)
            c = rng.uniform(r[:, None], self.size - r[:, None], size=(batch, 2))
            clear_ends = (
                np.hypot(c[:, None, 0] - ends[None, :, 0], c[:, None, 1] - ends[None, :, 1])
                - r[:, None]
            )
            ok = np.all(clear_ends >= keep_out, axis=1)
            if placed:
                ok &= _clear_of(c, r, centres[:placed], radii[:placed], hi, self.gap)
            first_new = placed
            for k in np.flatnonzero(ok).tolist():
                new = slice(first_new, placed)  # accepted earlier in this batch
                if placed > first_new and np.any(
                    np.hypot(*(centres[new] - c[k]).T) < radii[new] + r[k] + self.gap
                ):
                    continue
                centres[placed], radii[placed] = c[k], r[k]
                placed += 1
                if placed == self.n:
                    break
            if placed == self.n:
                break
        else:
            raise GenerationError(
                f"generate {self.KIND}: placed only {placed} of {self.n} non-overlapping "
                f"obstacles (radius {lo:g}-{hi:g}, gap {self.gap:g}) in {budget} tries; "
                "use fewer or smaller obstacles or a larger size"
            )
        return centres, radii

    def _where(self) -> str:
        return (
            f"in a {self.size:g} x {self.size:g} workspace, robot radius "
            f"{self.robot_radius:g}, start and goal in opposite corners."
        )


@register_kind
@declared(rules=(_RADII_RULE,))
class CirclesOptions(_FieldOptions):
    """Random non-overlapping circles (``rrtpso generate circles``)."""

    KIND: ClassVar[str] = "circles"
    RADII: ClassVar[tuple[float, float]] = (0.02, 0.06)

    n: int = param(30, "Number of circles.", low=1, high=MAX_OBSTACLES)
    radius_range: tuple[float, float] | None = param(
        None,
        "Least and largest radius, 0 < min <= max < size / 2. Default: (0.02 size, 0.06 "
        "size), shrunk by sqrt(30 / n) beyond 100 circles.",
        unit="length",
        low=0.0,
    )
    gap: float = param(0.0, "Least free distance between two circles (0: they may touch).",
                       unit="length", low=0.0)  # fmt: skip

    def _shapes(self, rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray
                ) -> list[dict[str, Any]]:  # fmt: skip
        return [
            {"type": "circle", "center": c.tolist(), "radius": float(r)}
            for c, r in zip(centres, radii, strict=True)
        ]

    def describe(self) -> str:
        lo, hi = self.radius_range
        return (
            f"{self.n} random non-overlapping circles of radius {lo:.3g}-{hi:.3g} {self._where()}"
        )


@register_kind
@declared(
    rules=(
        _RADII_RULE,
        Rule(("vertices",), lambda v: v[0] <= v[1], "vertices min <= max"),
    )
)
class PolygonsOptions(_FieldOptions):
    """Random non-overlapping convex polygons (``rrtpso generate polygons``)."""

    KIND: ClassVar[str] = "polygons"
    RADII: ClassVar[tuple[float, float]] = (0.03, 0.08)

    n: int = param(20, "Number of polygons.", low=1, high=MAX_OBSTACLES)
    radius_range: tuple[float, float] | None = param(
        None,
        "Least and largest circumradius, 0 < min <= max < size / 2. Default: (0.03 size, "
        "0.08 size), shrunk by sqrt(20 / n) beyond 100 polygons.",
        unit="length",
        low=0.0,
    )
    vertices: tuple[int, int] = param((3, 8), "Least and most vertices of a polygon.", low=3)
    gap: float = param(
        0.0,
        "Least free distance between the circumscribed circles of two polygons (0: they may "
        "touch).",
        unit="length",
        low=0.0,
    )

    def _shapes(self, rng: np.random.Generator, centres: np.ndarray, radii: np.ndarray
                ) -> list[dict[str, Any]]:  # fmt: skip
        return [
            {"type": "polygon", "points": _convex_polygon(rng, c, r, self.vertices).tolist()}
            for c, r in zip(centres, radii, strict=True)
        ]

    def describe(self) -> str:
        lo, hi = self.radius_range
        return (
            f"{self.n} random non-overlapping convex polygons with {self.vertices[0]}-"
            f"{self.vertices[1]} vertices and circumradius {lo:.3g}-{hi:.3g} {self._where()}"
        )


#: Up to this many obstacles the default radii are fixed fractions of the size (the files of
#: problems/ were made so); beyond it they shrink.
_SHRINK_FROM = 100


def _shrink(n: int, default_n: int) -> float:
    """Factor of the default radii (and robot radius) for ``n`` obstacles: 1 up to
    :data:`_SHRINK_FROM`, then ``sqrt(default_n / n)``, so that the obstacles cover the share of
    the workspace the default count covers (about 15 % for circles) and the world stays
    feasible: 10,000 circles in a 100 x 100 world have radii 0.11-0.33 and a robot of radius
    0.055."""
    return 1.0 if n <= _SHRINK_FROM else math.sqrt(default_n / n)


def _clear_of(c, r, centres, radii, hi: float, gap: float) -> np.ndarray:
    """Whether each candidate disc ``(c[k], r[k])`` keeps ``gap`` from every placed disc: only the
    placed discs a k-d tree finds within ``r[k] + hi + gap`` can be too close."""
    from scipy.spatial import cKDTree

    ok = np.ones(len(c), dtype=bool)
    near = cKDTree(centres).query_ball_point(c, r + hi + gap)
    for k, idx in enumerate(near):
        if idx:
            d = np.hypot(*(centres[idx] - c[k]).T)
            ok[k] = bool(np.all(d >= radii[idx] + r[k] + gap))
    return ok


def _convex_polygon(
    rng: np.random.Generator, centre: np.ndarray, radius: float, vertices: tuple[int, int]
) -> np.ndarray:
    """A random convex polygon inscribed in the circle (centre, radius).

    Vertices at jittered, increasing angles on an ellipse (a random squash and rotation of the
    circle): points on an ellipse in angular order are always a strictly convex polygon, and the
    jitter keeps every angular step at least 40% of the even one, so there are no slivers.
    """
    k = int(rng.integers(vertices[0], vertices[1] + 1))
    theta0 = rng.uniform(0.0, 2.0 * math.pi)
    jitter = rng.uniform(-0.3, 0.3, size=k)
    angles = theta0 + 2.0 * math.pi * (np.arange(k) + jitter) / k
    aspect = rng.uniform(0.5, 1.0)
    phi = rng.uniform(0.0, math.pi)
    unit = np.column_stack([np.cos(angles), aspect * np.sin(angles)])
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    return centre + radius * unit @ rot.T
