"""The first-party strategies, one module each: ``contour`` (:class:`Contour`), ``global``
(:class:`Global`), ``none`` (:class:`Blind`) and ``dwa`` (:class:`DWA`), all
:class:`Strategy` classes (see :mod:`.base`)."""

from .base import Strategy
from .contour import Contour
from .dwa import DWA, DWAOptions
from .global_ import Global
from .none import Blind

#: The first-party strategies, in the order listings show them.
FIRST_PARTY = (Contour, Global, Blind, DWA)

__all__ = ["DWA", "FIRST_PARTY", "Blind", "Contour", "DWAOptions", "Global", "Strategy"]
