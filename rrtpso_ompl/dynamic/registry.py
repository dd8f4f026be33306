"""Strategies by name, as planners are (:mod:`rrtpso_ompl.planners.registry`).

Where strategies come from, in this order:

1. the first-party strategies of :mod:`rrtpso_ompl.dynamic.strategies`: ``contour``, ``global``,
   ``none`` and ``dwa``;
2. third-party packages, through the entry-point group ``rrtpso_ompl.strategies``. An entry point
   loads to a strategy class (see :class:`~rrtpso_ompl.dynamic.strategies.base.Strategy`) or an
   iterable of them.

A name that is already taken is refused (a plugin cannot shadow a built-in strategy); a broken
third-party plugin is reported in a warning and skipped, so it cannot break the tool, whatever it
raises while it loads (``sys.exit()`` included).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from functools import lru_cache
from importlib.metadata import entry_points
from typing import Any

from ..errors import RrtpsoError, did_you_mean, shown
from ..foreign import contained
from .strategies import FIRST_PARTY, Strategy

__all__ = [
    "STRATEGY_ENTRY_POINT_GROUP",
    "StrategyRegistry",
    "UnknownStrategyError",
    "default_strategies",
]

log = logging.getLogger(__name__)

STRATEGY_ENTRY_POINT_GROUP = "rrtpso_ompl.strategies"


class UnknownStrategyError(RrtpsoError, ValueError):
    """No strategy of that name is registered."""


class StrategyRegistry:
    """Name -> strategy class. Names are case-sensitive."""

    def __init__(self) -> None:
        self._classes: dict[str, type[Strategy]] = {}
        #: Which plugin registered each name.
        self.sources: dict[str, str] = {}

    def register(self, cls: type[Strategy], source: str = "") -> type[Strategy]:
        """Add a strategy class; ``ValueError`` when its name is taken, ``TypeError`` when it is
        not a strategy (a class with a ``name``, ``options`` and a ``simulate`` method)."""
        name = getattr(cls, "name", None)
        opts = getattr(cls, "options", False)
        if not (isinstance(cls, type) and isinstance(name, str) and name.strip()
                and callable(getattr(cls, "simulate", None))):  # fmt: skip
            raise TypeError(f"expected a strategy class with a name and simulate(), got {cls!r}")
        if opts is not None and not hasattr(opts, "PARAMS"):
            raise TypeError(f"strategy '{name}': options must be a declared option set or None")
        if name in self._classes:
            owner = self.sources.get(name) or "another plugin"
            raise ValueError(f"strategy name '{name}' is already registered by {owner}")
        self._classes[name] = cls
        self.sources[name] = source
        return cls

    def get(self, name: str) -> type[Strategy]:
        """The class of strategy ``name``; :class:`UnknownStrategyError` otherwise."""
        try:
            return self._classes[name]
        except KeyError:
            known = ", ".join(self._classes)
            raise UnknownStrategyError(
                f"no strategy '{shown(name)}'{did_you_mean(str(name), self._classes)} "
                f"(known: {known})"
            ) from None

    def make(self, name: str, values: Mapping[str, Any] | None = None) -> Strategy:
        """Strategy ``name`` with option ``values`` (validated by its option set)."""
        cls = self.get(name)
        if not values:
            return cls()
        if cls.options is None:
            raise UnknownStrategyError(f"strategy '{name}' takes no options, got {dict(values)}")
        converted = cls.options.PARAMS.validate(values, owner=f"strategy '{name}'")
        return cls(cls.options(**converted))

    def __contains__(self, name: object) -> bool:
        return name in self._classes

    def names(self) -> list[str]:
        """The names, first-party ones first, in the order they were registered."""
        return list(self._classes)

    def description(self, name: str) -> str:
        """The first paragraph of the strategy's docstring, on one line."""
        doc = (self.get(name).__doc__ or "").strip().split("\n\n")[0]
        return " ".join(doc.split())

    def load_first_party(self) -> None:
        """Register the strategies of :mod:`rrtpso_ompl.dynamic.strategies`."""
        for cls in FIRST_PARTY:
            self.register(cls, source=cls.__module__)

    def load_entry_points(self, group: str = STRATEGY_ENTRY_POINT_GROUP) -> None:
        """Register third-party strategies from the entry-point group; warn about broken ones."""
        for ep in entry_points(group=group):
            source = f"entry point '{ep.name} = {ep.value}'"
            # Whatever it raises (sys.exit() included; a real Ctrl-C still stops the command).
            with contained() as box:
                obj = ep.load()
                for cls in [obj] if isinstance(obj, type) else list(obj):
                    self.register(cls, source=source)
            if box.error is not None:
                log.warning("skipping strategy plugin %s: %s", source, box.message)


@lru_cache(maxsize=1)
def default_strategies() -> StrategyRegistry:
    """The process-wide registry: first-party strategies, then entry points (built once)."""
    reg = StrategyRegistry()
    reg.load_first_party()
    reg.load_entry_points()
    return reg
