"""``global``: the baseline of whole-path replanning (issue 14)."""

from __future__ import annotations

from ..manager import ReplanPolicy
from ..replanning import ReplanningStrategy

__all__ = ["WholePath"]


class WholePath(ReplanningStrategy):
    """Replan the whole remaining path to the goal at each predicted collision (a baseline).

    One plan, no wall, no wait candidate, no re-shortening; the same prediction, sweeps,
    verification and fallbacks as ``contour``.
    """

    name = "global"
    policy = ReplanPolicy(kind="global", sides=(None,), wait=False, rejoin_at_goal=True)
