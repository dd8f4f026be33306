"""OMPL's process-wide state: its random seed (applied before each seeded solve) and its log
level (warnings from the moment this package loads OMPL, unless asked for more)."""

from __future__ import annotations

from ompl import util as ou

__all__ = ["seed_ompl", "set_ompl_log_level"]


def seed_ompl(seed: int | None) -> bool:
    """Seed OMPL's random numbers: every OMPL generator made from now on (a planner's, a
    sampler's) draws its own seed from a sequence that ``seed`` starts.

    OMPL derives each generator's seed from one process-wide seed generator. Its
    ``RNG::setSeed`` restarts that sequence whenever it is called, and only complains ("Random
    number generation already started") because generators that exist already keep their state.
    A solve builds its planner, samplers and space information afresh after this call, so a solve
    with a seed gives the same path in a fresh process and after any number of other solves in
    this one (``tests/ompl_setup/test_process.py``); the complaint is muted.

    OMPL refuses seed 0 (it takes 1 in a fresh process and ignores 0 afterwards), so 0 is
    applied as 1 in every case: seeds 0 and 1 give the same runs.

    Parameters
    ----------
    seed : int or None
        In ``[0, 2**32 - 1]``; None leaves OMPL's sequence where it is (an unseeded run).

    Returns
    -------
    bool
        Whether a seed was applied.
    """
    if seed is None:
        return False
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)
    try:
        ou.RNG.setSeed(max(int(seed), 1))
    finally:
        ou.setLogLevel(level)
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
