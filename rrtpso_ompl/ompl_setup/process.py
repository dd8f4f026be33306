"""OMPL's process-wide state: its random seed (once per process) and its log level (warnings
from the moment this package loads OMPL, unless asked for more)."""

from __future__ import annotations

import logging

from ompl import util as ou

__all__ = ["seed_ompl", "set_ompl_log_level"]

log = logging.getLogger(__name__)

_seeded: int | None = None


def seed_ompl(seed: int | None) -> bool:
    """Seed OMPL's global RNG, once per process, before any OMPL object samples.

    OMPL derives every planner's and sampler's seed from one process-wide generator, and refuses a
    new seed once that generator has started. So the first call wins; later calls with another
    seed return False (and log a warning) instead of silently pretending to reseed.

    Returns
    -------
    bool
        Whether OMPL now runs with ``seed``.
    """
    global _seeded
    if seed is None:
        return _seeded is None
    if _seeded is None:
        ou.RNG.setSeed(int(seed))
        _seeded = int(seed)
        return True
    if _seeded != seed:
        log.warning(
            "OMPL was already seeded with %d in this process; seed %d cannot take effect "
            "(run each seed in its own process for reproducible results)",
            _seeded,
            seed,
        )
        return False
    return True


def set_ompl_log_level(verbose: int = 0) -> None:
    """OMPL's own log level: errors only (-1, the command line's ``-q``), warnings (0, the
    default from importing this package), Info (1) or Debug (2+)."""
    if verbose < 0:
        level = ou.LOG_ERROR
    else:
        level = {0: ou.LOG_WARN, 1: ou.LOG_INFO}.get(verbose, ou.LOG_DEBUG)
    ou.setLogLevel(level)


# OMPL starts at Debug, so a library user's first solve would print dozens of Info and Debug
# lines (one per planner setup, per solve, per sampler). Keep it to warnings unless asked: a
# level the user chose before importing us (anything but OMPL's start level) stays, and
# set_ompl_log_level(1 or 2) or ompl.util.setLogLevel after the import turns the detail back on.
if ou.getLogLevel() == ou.LOG_DEBUG:
    set_ompl_log_level(0)
