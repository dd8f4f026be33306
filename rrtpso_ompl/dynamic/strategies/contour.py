"""``contour``: the paper's method (section 4.2)."""

from __future__ import annotations

from ..manager import ReplanPolicy
from ..replanning import ReplanningStrategy

__all__ = ["Contour"]


class Contour(ReplanningStrategy):
    """Detours up and down around the collision zone, or a wait (the paper's method).

    The candidates are verified and chosen by predicted arrival; the rest of the plan is
    shortcut once the obstacle has passed (``DynamicOptions.reshorten``).
    """

    name = "contour"
    policy = ReplanPolicy(kind="contour", sides=("up", "down"), wait=True)
    reshortens = True
