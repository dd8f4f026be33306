"""The ``rrtpso`` command: :mod:`.main` builds the parser from one module per subcommand
(:mod:`.solve`, :mod:`.simulate`, :mod:`.batch`, :mod:`.generate`, :mod:`.optimum`,
:mod:`.bench`, :mod:`.planners`); :mod:`.common` holds what they share."""

from .main import main

__all__ = ["main"]
