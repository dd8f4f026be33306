"""Parameters declared once: tables, rules, derived options classes and docs."""

from __future__ import annotations

import dataclasses

import pytest

from rrtpso_ompl.errors import ParameterError, RrtpsoError
from rrtpso_ompl.params import ParamSpec, ParamTable, Rule
from rrtpso_ompl.planners import PathOptimizerOptions, PSOOptions, default_registry
from rrtpso_ompl.planners.pso.path_optimizer import OPTIMIZER_PARAMS
from rrtpso_ompl.planners.pso.swarm import SWARM_PARAMS

TABLE = ParamTable(
    ParamSpec("a", float, 1.0, "first", low=0.0, high=3.0),
    ParamSpec("b", float, 1.0, "second", low=0.0, high=3.0),
    ParamSpec("n", int, 4, "count", low=1),
    ParamSpec("on", bool, False, "flag"),
    ParamSpec("mode", str, "x", "mode", choices=("x", "y")),
    rules=[Rule(("a", "b"), lambda a, b: a + b < 4, "a + b < 4")],
)


@pytest.mark.parametrize(
    ("given", "expected"),
    [
        ({"a": "2.5"}, {"a": 2.5}),
        ({"n": "12"}, {"n": 12}),
        ({"n": 12.0}, {"n": 12}),
        ({"n": "1e2"}, {"n": 100}),
        ({"on": "yes"}, {"on": True}),
        ({"on": 1}, {"on": True}),
        ({"mode": "y"}, {"mode": "y"}),
    ],
)
def test_values_are_converted(given, expected):
    assert TABLE.validate(given) == expected


@pytest.mark.parametrize(
    ("given", "words"),
    [
        ({"a": 3.5}, "parameter 'a' of P must be in [0, 3], got 3.5"),
        ({"a": -1}, "must be in [0, 3]"),
        ({"a": "inf"}, "finite"),
        ({"a": True}, "must be a number"),
        ({"n": 2.5}, "must be an integer"),
        ({"n": "two"}, "must be an integer"),
        ({"n": 0}, "must be in [1, inf], got 0"),
        ({"on": "maybe"}, "boolean"),
        ({"mode": "z"}, "one of"),
        ({"zzz": 1}, "P has no parameter 'zzz' (known: a, b, n, on, mode)"),
        ({"a": 2.5, "b": 2.0}, "parameters of P must satisfy a + b < 4, got a = 2.5, b = 2.0"),
        ({"a": 3.0}, "a + b < 4"),  # breaks the rule together with b's default
    ],
)
def test_every_violation_is_one_parameter_error(given, words):
    with pytest.raises(ParameterError, match=None) as info:
        TABLE.validate(given, owner="P")
    assert words in str(info.value)
    assert isinstance(info.value, RrtpsoError) and isinstance(info.value, ValueError)


def test_a_declaration_bug_is_caught_when_the_table_is_built():
    with pytest.raises(ParameterError):
        ParamTable(ParamSpec("x", float, 5.0, "default out of range", low=0, high=1))
    with pytest.raises(ValueError, match="twice"):
        ParamTable(ParamSpec("x", float, 0.0, ""), ParamSpec("x", float, 0.0, ""))


def test_options_classes_take_fields_and_defaults_from_the_tables():
    fields = {f.name: f.default for f in dataclasses.fields(PathOptimizerOptions)}
    assert fields == {**SWARM_PARAMS.defaults(), **OPTIMIZER_PARAMS.defaults()}
    assert {f.name for f in dataclasses.fields(PSOOptions)} == set(SWARM_PARAMS.names())
    # ... validate with the same rules, and document every parameter.
    with pytest.raises(ParameterError, match="c1 \\+ c2 < 4"):
        PathOptimizerOptions(c1=2.0, c2=2.0)
    assert all(f"{name} : " in PathOptimizerOptions.__doc__ for name in fields)
    # from_values picks its own fields out of a planner's values.
    values = default_registry().get("RRTstarPSO").params.defaults()
    assert PSOOptions.from_values({**values, "swarm_size": 7}).swarm_size == 7


def test_planners_share_declarations_instead_of_copying_them():
    reg = default_registry()
    rrt, ours = reg.get("RRTstar").params, reg.get("RRTstarPSO").params
    for name in ("range", "goal_bias", "rewire_factor", "informed_sampling", "tree_pruning"):
        assert ours[name] is rrt[name]  # the inner RRT*'s parameters are OMPL's declarations
    baseline = reg.get("PSO").params
    assert baseline["c1"] is ours["c1"] and baseline["iterations"].default == 200
    assert "v_max_fraction" not in baseline  # its clamp is relative to the workspace instead
    assert baseline.rules and ours.rules  # the c1 + c2 rule travels with the swarm's table


def test_markdown_lists_every_parameter_in_order():
    lines = TABLE.markdown().splitlines()
    assert lines[0].startswith("| name | type | default")
    assert [line.split("`")[1] for line in lines[2:]] == TABLE.names()


def test_declared_option_sets_are_dataclasses_with_one_declaration_per_field():
    from rrtpso_ompl.params import Rule, declared, param

    @declared(rules=[Rule(("lo", "hi"), lambda lo, hi: lo <= hi, "lo <= hi")])
    class Window:
        """A window."""

        lo: float = param(0.0, "Lower end.", unit="s", low=0.0)
        hi: float = param(1.0, "Upper end.", unit="s", low=0.0)

    @declared
    class Named(Window):
        """A named window."""

        label: str = param("w", "Its name.")

    assert Window.PARAMS.names() == ["lo", "hi"] and Window.PARAMS["lo"].type is float
    assert Named.PARAMS.names() == ["lo", "hi", "label"] and Named.PARAMS.rules  # inherited
    with pytest.raises(ParameterError, match="lo <= hi"):
        Named(lo=2.0)
    with pytest.raises(ParameterError, match="'lo' of Window must be in"):
        Window(lo=-1.0)
    with pytest.raises(TypeError):
        Window(0.5, 0.6)  # keyword-only
    with pytest.raises(dataclasses.FrozenInstanceError):
        Window().lo = 3.0
    assert Named.from_values({"hi": 3.0, "label": "x", "other": 1}) == Named(hi=3.0, label="x")
    assert "lo : float, default 0.0" in Window.__doc__

    with pytest.raises(TypeError, match="param"):

        @declared
        class Bad:
            x: int = 3


def test_declared_fields_may_be_optional_or_fixed_tuples():
    """A default that depends on other values is None (the doc says what it stands for), and a
    range is a pair, each value checked against the declared range (issue 23: the generator's
    radius_range and vertices)."""
    from rrtpso_ompl.params import declared, param

    @declared
    class Field:
        """A field of obstacles."""

        radius: float | None = param(None, "A radius. Default: a tenth of the size.", low=0.0)
        span: tuple[int, int] = param((3, 8), "Least and most corners.", low=3)

    assert Field().radius is None and Field(radius=2.0).radius == 2.0
    span = Field.PARAMS["span"]
    assert (span.length, span.type, Field.PARAMS["radius"].optional) == (2, int, True)
    assert span.convert("4 6") == (4, 6) == span.convert("4,6") == span.convert([4.0, 6])
    with pytest.raises(ParameterError, match="'span' of Field must be a pair of int, got int 3"):
        Field(span=3)
    with pytest.raises(ParameterError, match=r"'span' of Field must be in \[3, inf\] each, got 2"):
        Field(span=(2, 5))
    with pytest.raises(ParameterError, match="must be an integer, got str '4'"):
        span.convert(["4", "6"], text=False)  # a YAML file's values are typed
    with pytest.raises(ParameterError, match=r"'radius' of Field must be in \[0, inf\]"):
        Field(radius=-1.0)
    table = Field.PARAMS.markdown()
    assert "| `radius` | float or None | None |" in table
    assert "| `span` | (int, int) | (3, 8) | – | [3, inf] each |" in table
    assert "radius : float or None, default None" in Field.__doc__

    with pytest.raises(TypeError, match="one type, or one type or None"):

        @declared
        class Either:
            x: int | str = param(3, "Either.")


def test_rrtstar_pso_s_parameters_are_listed_by_stage_with_the_few_to_tune_first():
    """``rrtpso planners RRTstarPSO`` (issue 36): a header per stage, the few worth tuning first
    marked, every column aligned however long a name is."""
    from rrtpso_ompl.cli.planners import _param_lines

    table = default_registry().get("RRTstarPSO").params
    keys = {n for n in table.names() if table.group_of(n)[1]}
    assert keys == {"budget", "corridor_fraction", "rrt_time_fraction", "rrt_max_iterations",
                    "swarm_size", "iterations", "smoothness_weight"}  # fmt: skip
    assert all(table.group_of(n)[0] for n in table.names())  # every one has a stage
    lines = _param_lines(table, docs=False)
    headers = [line.strip() for line in lines if line.endswith(":")]
    assert headers == ["the run:", "the corridor stage:", "RRT* and OMPL's simplifier:",
                       "the swarm (eqs. 4-5):",
                       "the swarm over the path: rounds, polish, costs:"]  # fmt: skip
    rows = [line for line in lines if " default " in line]
    assert len(rows) == len(table) and len({row.index(" default ") for row in rows}) == 1
    assert sum(row.startswith("  * ") for row in rows) == len(keys)
    # The grouping is the listing's: the specs stay the declarations they were.
    assert table["range"] is default_registry().get("RRTstar").params["range"]
