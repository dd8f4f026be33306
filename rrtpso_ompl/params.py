"""Planner parameters, each declared once.

OMPL declares a planner parameter in one line, ``declareParam<double>("range", this,
&RRTstar::setRange, &RRTstar::getRange, "0.:1.:10000.")``, and everything else (benchmark logs,
MoveIt's configuration) reads that declaration back. ``Planner.params()`` is not usable from the
OMPL 2.0 Python bindings, so the declarations live here instead, one :class:`ParamSpec` per
parameter (name, type, default, unit, range, documentation and, for OMPL's own planners, the
setter and getter), gathered in a :class:`ParamTable` with the rules that tie several parameters
together (``c1 + c2 < 4``).

Option sets that algorithms take as one object (the swarm's, the path optimiser's, the dynamic
simulation's, the DWA's, the generator's) are ordinary frozen, keyword-only dataclasses whose
fields are declared with :func:`param` and whose class is decorated with :func:`declared`:
editors and type checkers see their fields, and the decorator derives the :class:`ParamTable`
(``cls.PARAMS``), validation on construction and ``from_values`` from the same declarations.

Everything else is derived from the tables: the validation of YAML ``planner.params``,
``--param`` and Python keyword arguments (:meth:`ParamTable.validate`, one
:class:`~rrtpso_ompl.errors.ParameterError` for every violation, as scikit-learn's
``_parameter_constraints`` do), the listing of ``rrtpso planners`` and the tables in
``docs/planners.md``. Defaults therefore agree everywhere by construction.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from .errors import ParameterError, did_you_mean, shown
from .validation import check_integer, check_number, describe, number_hint

__all__ = ["ParamSpec", "ParamTable", "Rule", "declared", "param"]

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
        For OMPL planners: the setter method to call (``"setRange"``).
    getter : str or None
        For OMPL planners: the matching getter, used to check defaults against OMPL.
    optional : bool
        Whether None is a value: "not given", resolved by the owner from other values (the
        ``doc`` says how), such as a radius that defaults to a fraction of a size.
    length : int or None
        For a tuple of values of ``type`` (such as a range ``(min, max)``): how many; ``low``,
        ``high`` and ``choices`` apply to each. None for one value.
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
    optional: bool = False
    length: int | None = None

    def convert(self, value: Any, owner: str = "", text: bool = True) -> Any:
        """Validate ``value`` (a Python value or a command-line string) and convert it.

        Parameters
        ----------
        value : Any
            The value as given (``"50"`` from the command line, ``50`` from YAML or Python).
        owner : str
            The planner, named in the message.
        text : bool
            Whether a string may stand for a number or a boolean (command-line text). A YAML
            file's values are typed: there ``"50"`` in quotes is text, refused for a number, as
            every quoted number of a problem file is.

        Raises
        ------
        ParameterError
            Naming the parameter, the expected type and range, and the value given.
        """
        try:
            if value is None and self.optional:
                return None
            if self.length is not None:
                return self._convert_tuple(value, text)
            return self._convert_one(value, text)
        except ValueError as exc:
            of = f" of {owner}" if owner else ""
            raise ParameterError(f"parameter '{self.name}'{of} {exc}", self.name) from None

    def _convert_one(self, value: Any, text: bool) -> Any:
        if not text and isinstance(value, str) and self.type is not str:
            kind = {bool: "a boolean", int: "an integer"}.get(self.type, "a number")
            raise ValueError(f"must be {kind}, got {describe(value)}{number_hint(value)}")
        return self._convert(self._parse(value))

    def _convert_tuple(self, value: Any, text: bool) -> tuple[Any, ...]:
        """``length`` values, from a sequence (or, on the command line, ``"2 6"`` or ``"2,6"``)."""
        if text and isinstance(value, str):
            value = value.replace(",", " ").split()
        if isinstance(value, str) or not isinstance(value, Sequence) or len(value) != self.length:
            shape = "a pair" if self.length == 2 else f"{self.length} values"
            raise ValueError(f"must be {shape} of {self.type.__name__}, got {describe(value)}")
        return tuple(self._convert_one(v, text) for v in value)

    def _parse(self, value: Any) -> Any:
        """A command-line string to a Python value of the declared type."""
        if not isinstance(value, str) or self.type is str:
            return value
        text = value.strip()
        if self.type is bool:
            if text.lower() in _TRUE:
                return True
            if text.lower() in _FALSE:
                return False
            raise ValueError(f"must be a boolean (true/false), got '{shown(value)}'")
        try:
            number = float(text)
        except ValueError:
            raise ValueError(f"must be {'an integer' if self.type is int else 'a number'}, "
                             f"got '{shown(value)}'") from None  # fmt: skip
        if self.type is int and math.isfinite(number) and "." not in text and "e" not in text:
            return int(text)  # exact, also beyond 2**53
        return number

    def _convert(self, v: Any) -> Any:
        if self.type is dict:
            # A mapping of named values handed on as they are (a planner's parameters, which
            # the planner's own table validates).
            if not isinstance(v, Mapping) or not all(isinstance(k, str) for k in v):
                raise ValueError(f"must be a mapping of names to values, got {describe(v)}")
            return v
        if self.type is bool:
            if isinstance(v, bool):
                return v
            if isinstance(v, int) and v in (0, 1):
                return bool(v)
            raise ValueError(f"must be a boolean, got {describe(v)}")
        if self.type in (int, float):
            x = check_integer(v) if self.type is int else check_number(v)
            if (self.low is not None and x < self.low) or (self.high is not None and x > self.high):
                raise ValueError(f"must be in {self.range_text()}, got {shown(x)}")
            return x
        if not isinstance(v, str):
            raise ValueError(f"must be a string, got {describe(v)}")
        if self.choices is not None and v not in self.choices:
            raise ValueError(f"must be one of {list(self.choices)}, got '{shown(v)}'")
        return v

    def range_text(self) -> str:
        """The allowed range as text, e.g. ``[0, 1]``."""
        if self.choices is not None:
            return "{" + ", ".join(map(str, self.choices)) + "}"
        if self.type is str:
            return "any text"
        if self.type is dict:
            return "names to values"
        if self.type is bool:
            return "{false, true}"

        def text(x: float) -> str:
            return str(int(x)) if self.type is int else f"{x:g}"

        lo = "-inf" if self.low is None else text(self.low)
        hi = "inf" if self.high is None else text(self.high)
        return f"[{lo}, {hi}]" + (" each" if self.length is not None else "")

    def type_text(self) -> str:
        """The type as listings show it: ``float``, ``(int, int)``, ``float or None``."""
        name = self.type.__name__
        if self.length is not None:
            name = "(" + ", ".join([name] * self.length) + ")"
        return f"{name} or None" if self.optional else name


@dataclass(frozen=True)
class Rule:
    """A constraint over several parameters that no single value reveals.

    Parameters
    ----------
    names : tuple of str
        The parameters involved, in the order ``holds`` takes them.
    holds : callable
        ``holds(*values) -> bool``.
    text : str
        The rule as users read it, e.g. ``"c1 + c2 < 4 (paper Table 2)"``.
    """

    names: tuple[str, ...]
    holds: Callable[..., bool]
    text: str


class ParamTable:
    """The declared parameters of a planner (or of one stage of it), with their rules.

    Parameters
    ----------
    *params : ParamSpec
        The parameters, in the order listings show them; names must be unique.
    rules : iterable of Rule
        Constraints over several parameters.
    """

    def __init__(self, *params: ParamSpec, rules: Iterable[Rule] = (),
                 groups: Mapping[str, tuple[str, bool]] | None = None) -> None:  # fmt: skip
        self._params = {p.name: p for p in params}
        if len(self._params) != len(params):
            raise ValueError("a parameter table declares a parameter twice")
        self.rules = tuple(r for r in rules if set(r.names) <= set(self._params))
        # Each parameter's stage and whether it is worth tuning first, for listings; kept beside
        # the specs so that a planner shares another's declarations (the same objects).
        self._groups = {n: g for n, g in (groups or {}).items() if n in self._params}
        for spec in params:
            spec.convert(spec.default)  # a default outside its own range is a declaration bug

    # -- a sequence of specs ---------------------------------------------------------------------
    def __iter__(self) -> Iterator[ParamSpec]:
        return iter(self._params.values())

    def __len__(self) -> int:
        return len(self._params)

    def __contains__(self, name: object) -> bool:
        return name in self._params

    def __getitem__(self, name: str) -> ParamSpec:
        """The spec of ``name``; :class:`ParameterError` listing the known names otherwise."""
        try:
            return self._params[name]
        except KeyError:
            known = ", ".join(self._params) or "none"
            hint = did_you_mean(name, self._params)
            raise ParameterError(
                f"no parameter '{shown(name)}'{hint} (known: {known})", name
            ) from None

    def names(self) -> list[str]:
        """Parameter names in declaration order."""
        return list(self._params)

    def defaults(self) -> dict[str, Any]:
        """Every parameter at its default."""
        return {p.name: p.default for p in self}

    # -- composition -----------------------------------------------------------------------------
    def __add__(self, other: ParamTable) -> ParamTable:
        """Both tables' parameters (and rules); a name in both is a declaration bug."""
        return ParamTable(*self, *other, rules=(*self.rules, *other.rules),
                          groups={**self._groups, **other._groups})  # fmt: skip

    def group_of(self, name: str) -> tuple[str, bool]:
        """``(stage, worth tuning first)`` of a parameter, as :meth:`grouped` set it (``("",
        False)`` when it has none)."""
        return self._groups.get(name, ("", False))

    def with_defaults(self, **defaults: Any) -> ParamTable:
        """The same parameters with other defaults (a planner that sets its own)."""
        return self.replace(**{k: {"default": v} for k, v in defaults.items()})

    def replace(self, **changes: Mapping[str, Any]) -> ParamTable:
        """The same table with fields of some specs replaced: ``replace(iterations={...})``."""
        for name in changes:
            self[name]  # raises ParameterError for an unknown name
        specs = [dataclasses.replace(p, **changes[p.name]) if p.name in changes else p
                 for p in self]  # fmt: skip
        return ParamTable(*specs, rules=self.rules, groups=self._groups)

    def grouped(self, group: str, key: Iterable[str] = ()) -> ParamTable:
        """The same table with every parameter in ``group`` and those of ``key`` marked as worth
        tuning first (for listings: ``rrtpso planners NAME``)."""
        key = set(key)
        for name in key:
            self[name]  # raises ParameterError for an unknown name
        return ParamTable(*self, rules=self.rules,
                          groups={p.name: (group, p.name in key) for p in self})  # fmt: skip

    def subset(self, *names: str) -> ParamTable:
        """A table of some of the parameters (and the rules among them), in the order given."""
        return ParamTable(*(self[n] for n in names), rules=self.rules, groups=self._groups)

    def without(self, *names: str) -> ParamTable:
        """The table without some parameters (and the rules that involve them)."""
        return ParamTable(*(p for p in self if p.name not in names), rules=self.rules,
                          groups=self._groups)  # fmt: skip

    # -- validation ------------------------------------------------------------------------------
    def validate(self, values: Mapping[str, Any] | None, owner: str = "") -> dict[str, Any]:
        """Check names and values; return the converted values (only those given).

        The rules are checked on the given values over the defaults, so that a value that breaks
        a rule only together with a default is refused too.

        Raises
        ------
        ParameterError
            For an unknown name, a wrong value or a broken rule.
        """
        of = f" of {owner}" if owner else ""
        converted = {}
        for key, value in (values or {}).items():
            if key not in self._params:
                known = ", ".join(self._params) or "none"
                hint = did_you_mean(str(key), self._params)
                raise ParameterError(f"{owner or 'the planner'} has no parameter "
                                     f"'{shown(key)}'{hint} (known: {known})", key)  # fmt: skip
            converted[key] = self._params[key].convert(value, owner)
        merged = {**self.defaults(), **converted}
        for rule in self.rules:
            if not rule.holds(*(merged[n] for n in rule.names)):
                given = ", ".join(f"{n} = {shown(repr(merged[n]))}" for n in rule.names)
                raise ParameterError(f"parameters{of} must satisfy {rule.text}, got {given}",
                                     " + ".join(rule.names))  # fmt: skip
        return converted

    # -- derived text ------------------------------------------------------------------------------
    def markdown(self) -> str:
        """The table as markdown (name, type, default, unit, range, meaning), as in the docs."""
        rows = ["| name | type | default | unit | range | meaning |", "|---|---|---|---|---|---|"]
        for p in self:
            rows.append(
                f"| `{p.name}` | {p.type_text()} | {p.default} | {p.unit or '–'} | "
                f"{p.range_text()} | {p.doc} |"
            )
        return "\n".join(rows)

    def numpydoc(self) -> str:
        """A numpydoc ``Parameters`` section of the table."""
        lines = ["Parameters", "----------"]
        for p in self:
            unit = f", in {p.unit}" if p.unit else ""
            lines.append(f"{p.name} : {p.type_text()}, default {p.default!r}")
            lines.append(f"    {p.doc} Range {p.range_text()}{unit}.")
        return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# Option sets as dataclasses: one declaration per field
# ----------------------------------------------------------------------------------------------
_PARAM_KEY = "rrtpso_param"
_TYPES = {"int": int, "float": float, "bool": bool, "str": str}
_T = TypeVar("_T")


def param(
    default: Any,
    doc: str,
    *,
    unit: str = "",
    low: float | None = None,
    high: float | None = None,
    choices: tuple[Any, ...] | None = None,
) -> Any:
    """Declare one field of an option set (see :func:`declared`): its default, what it does,
    its unit and its range. The name and type come from the field itself."""
    spec = {"doc": doc, "unit": unit, "low": low, "high": high, "choices": choices}
    if isinstance(default, dict):
        # A mapping field (such as a planner's parameters): each instance gets its own copy.
        return dataclasses.field(default_factory=lambda: dict(default), metadata={_PARAM_KEY: spec})
    return dataclasses.field(default=default, metadata={_PARAM_KEY: spec})


def _field_type(hint: Any, where: str) -> tuple[type, bool, int | None]:
    """``(type, optional, length)`` of a field's annotation: ``float``, ``float | None``,
    ``tuple[int, int]``, ``tuple[float, float] | None``."""
    optional = False
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        rest = [a for a in typing.get_args(hint) if a is not type(None)]
        if len(rest) != 1 or len(typing.get_args(hint)) != 2:
            raise TypeError(f"{where}: a field is one type, or one type or None")
        hint, optional = rest[0], True
    length = None
    if typing.get_origin(hint) is tuple:
        items = typing.get_args(hint)
        if not items or Ellipsis in items or len(set(items)) != 1:
            raise TypeError(f"{where}: a tuple field holds values of one type, a fixed number")
        hint, length = items[0], len(items)
    if typing.get_origin(hint) in (dict, Mapping) or hint in (dict, Mapping):
        return dict, optional, None
    return (_TYPES.get(hint, hint) if isinstance(hint, str) else hint), optional, length


def _validate_fields(self: Any) -> None:
    """``__post_init__`` of every option set: its values against its table."""
    klass = type(self)
    values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}  # not copied
    klass.PARAMS.validate(values, owner=klass.__name__)


def _dataclass_transform(**kwargs: Any) -> Callable[[_T], _T]:
    """``typing.dataclass_transform`` (Python 3.11+): tells type checkers that :func:`declared`
    makes a dataclass; a no-op before."""
    transform = getattr(typing, "dataclass_transform", None)
    return transform(**kwargs) if transform else (lambda f: f)


@_dataclass_transform(kw_only_default=True, frozen_default=True, field_specifiers=(param,))
def declared(cls: type[_T] | None = None, *, rules: Iterable[Rule] = ()) -> Any:
    """Make a class of :func:`param` fields a frozen, keyword-only dataclass and an option set.

    Adds ``PARAMS`` (the :class:`ParamTable` of its fields, in order, with ``rules`` and the
    rules of the option sets it extends), validation on construction (one
    :class:`~rrtpso_ompl.errors.ParameterError` naming the field), ``from_values(mapping)``
    (its own fields out of a larger mapping, such as a planner's values) and a numpydoc
    ``Parameters`` section appended to the docstring. An option set may extend another
    (subclass it): its table holds the base's fields first.

    Examples
    --------
    >>> @declared
    ... class Options:
    ...     size: int = param(3, "How many.", low=1)
    >>> Options(size=4).size
    4
    """

    def build(klass: Any) -> Any:
        if "__post_init__" not in klass.__dict__:
            klass.__post_init__ = _validate_fields
        klass = dataclasses.dataclass(frozen=True, kw_only=True)(klass)
        hints = typing.get_type_hints(klass)
        inherited: list[Rule] = []
        for base in klass.__mro__[1:]:
            table = base.__dict__.get("PARAMS")
            if isinstance(table, ParamTable):
                inherited.extend(table.rules)
        specs = []
        for f in dataclasses.fields(klass):
            meta = f.metadata.get(_PARAM_KEY)
            if meta is None:
                raise TypeError(f"{klass.__name__}.{f.name}: declare it with param(...)")
            kind, optional, length = _field_type(hints[f.name], f"{klass.__name__}.{f.name}")
            default = f.default_factory() if f.default is dataclasses.MISSING else f.default
            specs.append(ParamSpec(f.name, kind, default, **meta, optional=optional,
                                   length=length))  # fmt: skip
        table = ParamTable(*specs, rules=(*dict.fromkeys(inherited), *rules))

        def from_values(k: Any, values: Mapping[str, Any]) -> Any:
            return k(**{n: values[n] for n in k.PARAMS.names() if n in values})

        klass.PARAMS = table
        klass.from_values = classmethod(from_values)
        klass.__doc__ = f"{(klass.__doc__ or '').rstrip()}\n\n{table.numpydoc()}"
        return klass

    return build if cls is None else build(cls)
