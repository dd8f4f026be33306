"""``none``: the baseline that never replans."""

from __future__ import annotations

from ..replanning import ReplanningStrategy

__all__ = ["NoReplanning"]


class NoReplanning(ReplanningStrategy):
    """Never replan: drive the static path blindly (a baseline)."""

    name = "none"
    policy = None
