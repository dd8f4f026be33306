"""The first-party strategies, one module each: ``contour`` (:class:`Contour`), ``global``
(:class:`WholePath`), ``none`` (:class:`NoReplanning`) and ``dwa`` (:class:`DWA`), all
:class:`Strategy` classes (see :mod:`.base`)."""

from .base import Strategy
from .contour import Contour
from .dwa import DWA, DWAOptions
from .no_replanning import NoReplanning
from .whole_path import WholePath

#: The first-party strategies, in the order listings show them.
FIRST_PARTY = (Contour, WholePath, NoReplanning, DWA)

__all__ = ["DWA", "FIRST_PARTY", "Contour", "DWAOptions", "NoReplanning", "Strategy", "WholePath"]
