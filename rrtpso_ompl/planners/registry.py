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
broken plugin is reported in a warning and skipped, so it cannot break the tool, whatever it
raises while it loads (``sys.exit()`` included).
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

from ..errors import ParameterError, UnknownPlannerError, did_you_mean, shown
from ..foreign import contained
from ..params import ParamSpec, ParamTable

__all__ = [
    "ENTRY_POINT_GROUP",
    "Capabilities",
    "ParamSpec",
    "ParamTable",
    "PlannerEntry",
    "PlannerRegistry",
    "UnknownPlannerError",
    "default_registry",
]

log = logging.getLogger(__name__)

ENTRY_POINT_GROUP = "rrtpso_ompl.planners"
FIRST_PARTY_PLUGINS = ("rrtstar_pso", "pso", "exact", "ompl_geometric")


@dataclass(frozen=True)
class Capabilities:
    """What the harness may ask of a planner (OMPL's ``PlannerSpecs``, which Python cannot read).

    Parameters
    ----------
    optimizing : bool
        The planner improves its path with more time (asymptotically optimal or anytime).
    progress_polling : bool
        It has ``bestCost()`` and evaluates its termination condition only in the planning
        thread, so a Python condition may sample its best cost while it runs. (PRM and PRM*
        evaluate it in a second thread as well, which would wait for the GIL forever.) Planners
        of this package report their own progress instead.
    simplify_in_benchmark : bool
        Benchmarks follow it with OMPL's path simplifier, as OMPL's ``Benchmark`` does for its
        planners; the planners of this package optimise their own paths.
    car_spaces : bool
        It plans in OMPL's Dubins and Reeds-Shepp spaces, a car-like robot's problem
        (``robot.turning_radius``); False for planners of the plane only, which such a problem
        refuses before planning.
    """

    optimizing: bool = False
    progress_polling: bool = False
    simplify_in_benchmark: bool = False
    car_spaces: bool = True


@dataclass(frozen=True)
class PlannerEntry:
    """A planner that can be selected by name.

    Parameters
    ----------
    name : str
        The name users type (``"RRTstarPSO"``).
    factory : callable
        ``factory(si) -> ob.Planner``.
    params : ParamTable or sequence of ParamSpec
        The parameters the planner accepts by name (a sequence is made a table).
    description : str
        One line for listings.
    aliases : tuple of str
        Other names (e.g. MoveIt's ``"geometric::RRTstar"``).
    capabilities : Capabilities
        What the harness may ask of it.
    stats : callable, optional
        ``stats(planner) -> PlannerStats`` after a solve; by default the planner's own
        ``last_stats`` (planners of this package), else the figures every planner has.
    configure : callable, optional
        ``configure(planner, values)`` applies validated parameter values; by default they go
        to ``planner.set_params(**values)`` when the planner has it (scikit-learn's form, as
        :class:`~rrtpso_ompl.planners.base.PythonPlanner`), else each to the ``setter`` method
        named in its ParamSpec, or to ``planner.set_param(name, v)``.
    source : str
        Which plugin registered it (filled by the registry).
    """

    name: str
    factory: Callable[[Any], Any]
    params: ParamTable = field(default_factory=ParamTable)
    description: str = ""
    aliases: tuple[str, ...] = ()
    capabilities: Capabilities = field(default_factory=Capabilities)
    stats: Callable[[Any], Any] | None = None
    configure: Callable[[Any, Mapping[str, Any]], None] | None = None
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.params, ParamTable):
            object.__setattr__(self, "params", ParamTable(*self.params))

    @property
    def optimizing(self) -> bool:
        """Whether the planner improves its path with more time."""
        return self.capabilities.optimizing

    def takes(self, name: str) -> bool:
        """Whether the planner has a parameter ``name`` (such as ``budget`` or ``seed``)."""
        return name in self.params

    def param(self, name: str) -> ParamSpec:
        """The spec of parameter ``name``; :class:`~rrtpso_ompl.errors.ParameterError` otherwise."""
        if name not in self.params:
            known = ", ".join(self.params.names()) or "none"
            hint = did_you_mean(name, self.params.names())
            raise ParameterError(
                f"planner '{self.name}' has no parameter '{shown(name)}'{hint} (known: {known})",
                name,
            )
        return self.params[name]

    def validate(self, values: Mapping[str, Any] | None) -> dict[str, Any]:
        """Check names, values and rules; return the converted values (``ParameterError``)."""
        for key in values or {}:
            self.param(key)
        return self.params.validate(values, owner=self.name)

    def make(self, si: Any, values: Mapping[str, Any] | None = None) -> Any:
        """Create the planner for ``si`` and apply the parameter ``values``."""
        converted = self.validate(values)
        planner = self.factory(si)
        if converted:
            if self.configure is not None:
                self.configure(planner, converted)
            elif callable(getattr(planner, "set_params", None)):
                planner.set_params(**converted)
            else:
                for k, v in converted.items():
                    spec = self.params[k]
                    if spec.setter:
                        getattr(planner, spec.setter)(v)
                    else:
                        planner.set_param(k, v)
        return planner

    def collect_stats(self, planner: Any) -> Any:
        """The figures of the planner's last solve (a :class:`~rrtpso_ompl.planners.base.
        PlannerStats`)."""
        from .base import PlannerStats

        if self.stats is not None:
            return self.stats(planner)
        own = getattr(planner, "last_stats", None)
        return own if isinstance(own, PlannerStats) else PlannerStats()


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
        """Register the planners of ``rrtpso_ompl.plugins`` (each module's ``PLANNERS``); a
        module that fails to load is reported and skipped, as a third-party one is."""
        for mod_name in FIRST_PARTY_PLUGINS:
            source = f"rrtpso_ompl.plugins.{mod_name}"
            with contained() as box:
                module = _import_first_party(mod_name)
                self.register_plugin(module.PLANNERS, source=source)
                self.unavailable.update(getattr(module, "UNAVAILABLE", {}))
            if box.error is not None:
                log.warning("skipping planner plugin %s: %s", source, box.message)

    def load_entry_points(self, group: str = ENTRY_POINT_GROUP) -> None:
        """Register third-party planners from the entry-point group; warn about broken ones.

        Whatever a plugin raises while it loads is reported and the plugin skipped, so that it
        cannot break the tool: ``sys.exit()`` and a ``KeyboardInterrupt`` of its own included
        (a real Ctrl-C still stops the command, :func:`~rrtpso_ompl.foreign.contained`).
        """
        # Here, not at the top: importing importlib.metadata and scanning the installed
        # distributions is for the commands that look a planner up (docs/design.md, "Start-up").
        from importlib.metadata import entry_points

        for ep in entry_points(group=group):
            source = f"entry point '{ep.name} = {ep.value}'"
            with contained() as box:
                self.register_plugin(ep.load(), source=source)
            if box.error is not None:
                log.warning("skipping planner plugin %s: %s", source, box.message)


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
    return replace(entry, source=source)


@lru_cache(maxsize=1)
def default_registry() -> PlannerRegistry:
    """The process-wide registry: first-party plugins, then entry points (built once)."""
    reg = PlannerRegistry()
    reg.load_first_party()
    reg.load_entry_points()
    return reg
