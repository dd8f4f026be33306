"""Planners by name: the registry, its entries and their parameters.

A planner is registered as a :class:`PlannerEntry`: a name (plus aliases such as MoveIt's
``geometric::RRTstar``), a factory ``factory(si) -> ob.Planner`` and a table of
:class:`ParamSpec` (name, type, default, unit, range, documentation and how to apply it). The table
is ours because ``Planner.params()`` cannot be used from the OMPL 2.0 Python bindings.

Where planners come from, in this order:

1. the first-party plugins, the modules of ``rrtpso_ompl.plugins`` (the ``plugins/`` folder of the
   source tree): RRTstarPSO, the PSO baseline and every geometric planner of the OMPL wheel;
2. third-party packages, through the entry-point group ``rrtpso_ompl.planners``. An entry point may
   load to a :class:`PlannerEntry`, an iterable of them, or a callable returning either.

A name that is already taken is refused (a third-party plugin cannot shadow a built-in planner); a
broken third-party plugin is reported in a warning and skipped, so it cannot break the tool.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import math
import sys
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

__all__ = [
    "ENTRY_POINT_GROUP",
    "ParamSpec",
    "PlannerEntry",
    "PlannerRegistry",
    "UnknownPlannerError",
    "default_registry",
]

log = logging.getLogger(__name__)

ENTRY_POINT_GROUP = "rrtpso_ompl.planners"
FIRST_PARTY_PLUGINS = ("rrtstar_pso", "pso", "ompl_geometric")

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"0", "false", "no", "off"}


@dataclass(frozen=True)
class ParamSpec:
    """One planner parameter.

    Parameters
    ----------
    name : str
        snake_case name; OMPL's name where OMPL has one (``range``, ``goal_bias``).
    type : type
        ``float``, ``int``, ``bool`` or ``str``.
    default : Any
        Default value (as the planner itself uses it).
    doc : str
        What the parameter does to the search.
    unit : str
        Unit of the value ("" for dimensionless), e.g. ``"length"`` for the problem's unit, ``"s"``.
    low, high : float or None
        Inclusive range of numeric values; None for unbounded.
    choices : tuple or None
        Allowed values of a ``str`` parameter.
    setter : str or None
        For stock OMPL planners: the setter method to call (``"setRange"``).
    getter : str or None
        For stock OMPL planners: the matching getter, used to check defaults against OMPL.
    """

    name: str
    type: type
    default: Any
    doc: str
    unit: str = ""
    low: float | None = None
    high: float | None = None
    choices: tuple[Any, ...] | None = None
    setter: str | None = None
    getter: str | None = None

    def convert(self, value: Any) -> Any:
        """Validate ``value`` (a Python value or a command-line string) and convert it.

        Raises
        ------
        ValueError
            With a message naming the parameter, the expected type and range.
        """
        v = value
        if isinstance(v, str) and self.type is not str:
            v = v.strip()
            if self.type is bool:
                if v.lower() in _TRUE:
                    v = True
                elif v.lower() in _FALSE:
                    v = False
                else:
                    raise ValueError(f"parameter '{self.name}' expects a boolean, got '{value}'")
            else:
                try:
                    v = self.type(float(v)) if self.type is int and "." not in v else self.type(v)
                except ValueError:
                    raise ValueError(
                        f"parameter '{self.name}' expects {self.type.__name__}, got '{value}'"
                    ) from None
        if self.type is bool:
            if not isinstance(v, bool):
                if isinstance(v, int) and v in (0, 1):
                    v = bool(v)
                else:
                    raise ValueError(f"parameter '{self.name}' expects a boolean, got {value!r}")
        elif self.type is int:
            if isinstance(v, bool) or not isinstance(v, int | float) or v != int(v):
                raise ValueError(f"parameter '{self.name}' expects an integer, got {value!r}")
            v = int(v)
        elif self.type is float:
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ValueError(f"parameter '{self.name}' expects a finite number, got {value!r}")
            v = float(v)
        elif self.type is str and not isinstance(v, str):
            raise ValueError(f"parameter '{self.name}' expects a string, got {value!r}")
        if (self.low is not None and v < self.low) or (self.high is not None and v > self.high):
            raise ValueError(f"parameter '{self.name}' must be in {self.range_text()}, got {v!r}")
        if self.choices is not None and v not in self.choices:
            raise ValueError(f"parameter '{self.name}' must be one of {list(self.choices)}")
        return v

    def range_text(self) -> str:
        """The allowed range as text, e.g. ``[0, 1]``."""
        if self.choices is not None:
            return "{" + ", ".join(map(str, self.choices)) + "}"
        if self.type is bool:
            return "{false, true}"
        lo = "-inf" if self.low is None else f"{self.low:g}"
        hi = "inf" if self.high is None else f"{self.high:g}"
        return f"[{lo}, {hi}]"


@dataclass(frozen=True)
class PlannerEntry:
    """A planner that can be selected by name.

    Parameters
    ----------
    name : str
        The name users type (``"RRTstarPSO"``).
    factory : callable
        ``factory(si) -> ob.Planner``.
    params : tuple of ParamSpec
        The parameters the planner accepts by name.
    description : str
        One line for listings.
    aliases : tuple of str
        Other names (e.g. MoveIt's ``"geometric::RRTstar"``).
    optimizing : bool
        Whether the planner improves its path with more time (for reports).
    configure : callable, optional
        ``configure(planner, values)`` applies validated parameter values; by default each value
        goes to the ``setter`` method named in its ParamSpec, or to ``planner.set_param(name, v)``.
    check : callable, optional
        ``check(values)`` with every parameter (defaults filled in) raises ``ValueError`` for
        combinations that no single value reveals (e.g. ``c1 + c2 < 4``).
    source : str
        Which plugin registered it (filled by the registry).
    """

    name: str
    factory: Callable[[Any], Any]
    params: tuple[ParamSpec, ...] = ()
    description: str = ""
    aliases: tuple[str, ...] = ()
    optimizing: bool = False
    configure: Callable[[Any, Mapping[str, Any]], None] | None = None
    check: Callable[[dict[str, Any]], None] | None = None
    source: str = field(default="", compare=False)

    def param(self, name: str) -> ParamSpec:
        """The spec of parameter ``name``; ``KeyError`` listing the known names otherwise."""
        for p in self.params:
            if p.name == name:
                return p
        known = ", ".join(p.name for p in self.params) or "none"
        raise KeyError(f"planner '{self.name}' has no parameter '{name}' (known: {known})")

    def validate(self, values: Mapping[str, Any] | None) -> dict[str, Any]:
        """Check names and values; return the converted values (``KeyError``/``ValueError``)."""
        converted = {k: self.param(k).convert(v) for k, v in (values or {}).items()}
        if self.check is not None:
            self.check({**{p.name: p.default for p in self.params}, **converted})
        return converted

    def make(self, si: Any, values: Mapping[str, Any] | None = None) -> Any:
        """Create the planner for ``si`` and apply the parameter ``values``."""
        converted = self.validate(values)
        planner = self.factory(si)
        if converted:
            if self.configure is not None:
                self.configure(planner, converted)
            else:
                for k, v in converted.items():
                    spec = self.param(k)
                    if spec.setter:
                        getattr(planner, spec.setter)(v)
                    else:
                        planner.set_param(k, v)
        return planner


class UnknownPlannerError(KeyError):
    """No usable planner of that name; the message lists the known names (and says why a
    planner that exists but is excluded cannot be used)."""

    def __init__(self, name: str, known: Iterable[str], reason: str = "") -> None:
        self.name = name
        self.known = sorted(known, key=str.lower)
        self.reason = reason
        super().__init__(name)

    def __str__(self) -> str:
        known = ", ".join(self.known)
        if self.reason:
            return f"planner '{self.name}' is unavailable ({self.reason}); known planners: {known}"
        return f"unknown planner '{self.name}'; known planners: {known}"


class PlannerRegistry:
    """Name -> :class:`PlannerEntry`, with aliases. Names are case-sensitive, as in OMPL."""

    def __init__(self) -> None:
        self._entries: dict[str, PlannerEntry] = {}
        self._lookup: dict[str, str] = {}
        #: Names that exist but cannot be used, with the reason (reported on selection).
        self.unavailable: dict[str, str] = {}

    def register(self, entry: PlannerEntry, source: str = "") -> PlannerEntry:
        """Add ``entry``; ``ValueError`` when its name or an alias is taken or it is malformed."""
        if not isinstance(entry, PlannerEntry):
            raise TypeError(f"expected a PlannerEntry, got {type(entry).__name__}")
        if not entry.name or not callable(entry.factory):
            raise ValueError("a PlannerEntry needs a name and a callable factory")
        names = [p.name for p in entry.params]
        if len(set(names)) != len(names):
            raise ValueError(f"planner '{entry.name}' declares a parameter twice")
        for spec in entry.params:
            spec.convert(spec.default)  # a default outside its own range is a plugin bug
        for n in (entry.name, *entry.aliases):
            if n in self._lookup:
                owner = self._entries[self._lookup[n]]
                raise ValueError(
                    f"planner name '{n}' is already registered by "
                    f"{owner.source or 'another plugin'}"
                )
        if source:
            entry = _with_source(entry, source)
        self._entries[entry.name] = entry
        for n in (entry.name, *entry.aliases):
            self._lookup[n] = entry.name
        return entry

    def get(self, name: str) -> PlannerEntry:
        """The entry for ``name`` (or an alias); :class:`UnknownPlannerError` otherwise."""
        try:
            return self._entries[self._lookup[name]]
        except KeyError:
            reason = self.unavailable.get(name.removeprefix("geometric::"), "")
            raise UnknownPlannerError(name, self._entries, reason) from None

    def __contains__(self, name: object) -> bool:
        return name in self._lookup

    def names(self) -> list[str]:
        """Primary names, sorted case-insensitively."""
        return sorted(self._entries, key=str.lower)

    def entries(self) -> list[PlannerEntry]:
        """All entries, sorted by name."""
        return [self._entries[n] for n in self.names()]

    def register_plugin(self, obj: Any, source: str) -> list[PlannerEntry]:
        """Register what a plugin provides: an entry, an iterable of entries, or a callable
        returning either."""
        if callable(obj) and not isinstance(obj, PlannerEntry):
            obj = obj()
        items = [obj] if isinstance(obj, PlannerEntry) else list(obj)
        return [self.register(e, source) for e in items]

    def load_first_party(self) -> None:
        """Register the planners of ``rrtpso_ompl.plugins`` (each module's ``PLANNERS``)."""
        for mod_name in FIRST_PARTY_PLUGINS:
            module = _import_first_party(mod_name)
            self.register_plugin(module.PLANNERS, source=f"rrtpso_ompl.plugins.{mod_name}")
            self.unavailable.update(getattr(module, "UNAVAILABLE", {}))

    def load_entry_points(self, group: str = ENTRY_POINT_GROUP) -> None:
        """Register third-party planners from the entry-point group; warn about broken ones."""
        for ep in entry_points(group=group):
            source = f"entry point '{ep.name} = {ep.value}'"
            try:
                self.register_plugin(ep.load(), source=source)
            except Exception as exc:  # a broken plugin must not break the tool: report and skip
                log.warning("skipping planner plugin %s: %s", source, exc)


def _import_first_party(mod_name: str) -> Any:
    """Import ``rrtpso_ompl.plugins.<mod_name>``.

    An installed package has the ``plugins/`` folder as its subpackage ``rrtpso_ompl.plugins``; a
    source tree that was never installed has it beside the package, so map it there.
    """
    if "rrtpso_ompl.plugins" not in sys.modules:
        try:
            importlib.import_module("rrtpso_ompl.plugins")
        except ModuleNotFoundError as exc:
            if exc.name != "rrtpso_ompl.plugins":
                raise
            folder = Path(__file__).resolve().parents[2] / "plugins"
            spec = importlib.util.spec_from_file_location(
                "rrtpso_ompl.plugins",
                folder / "__init__.py",
                submodule_search_locations=[str(folder)],
            )
            if spec is None or spec.loader is None:
                raise
            package = importlib.util.module_from_spec(spec)
            sys.modules["rrtpso_ompl.plugins"] = package
            spec.loader.exec_module(package)
    return importlib.import_module(f"rrtpso_ompl.plugins.{mod_name}")


def _with_source(entry: PlannerEntry, source: str) -> PlannerEntry:
    from dataclasses import replace

    return replace(entry, source=source)


@lru_cache(maxsize=1)
def default_registry() -> PlannerRegistry:
    """The process-wide registry: first-party plugins, then entry points (built once)."""
    reg = PlannerRegistry()
    reg.load_first_party()
    reg.load_entry_points()
    return reg
