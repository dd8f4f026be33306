"""What to run, resolved in one place: a problem, a planner spec and the caller's choices become
one typed, frozen :class:`PlannerRequest`.

Every caller resolves through :func:`resolve`: :func:`~rrtpso_ompl.planners.solve` (Python),
``rrtpso solve`` and ``rrtpso simulate`` (with the problem file), ``rrtpso batch`` and
``rrtpso bench`` (each planner spec with the ``--param`` values, before any file is loaded). It
decides, in this order:

1. the planner: the caller's spec (``"BITstar+simplify+pso"``: a registered name and the
   post-passes after it), else the file's ``planner.type``, else :data:`DEFAULT_PLANNER`;
2. the post-passes: the spec's, then the caller's ``post``;
3. the time limit and the seed: the caller's, else the file's, else the defaults;
4. the parameters: the file's ``planner.params`` under the caller's, each converted and checked
   by its declaration; with post-passes, a parameter the planner does not take goes to them when
   they declare it (:data:`POST_PARAMS`, the swarm's and the path optimiser's); then the rules
   over several (``c1 + c2 < 4``) on both sets;
5. the budget rule: a planner that takes ``budget`` (it splits its time) gets the time limit,
   less the post-passes' share ``post_fraction`` when post-passes follow; one that takes ``seed``
   gets the seed. Values the caller or the file gave are kept.

The request records where every value came from (:attr:`PlannerRequest.origins`), and every
error names it: ``"p.yaml: planner.params.swarm_size: ..."`` (a
:class:`~rrtpso_ompl.errors.ProblemError`: the file is wrong), ``"p.yaml: --param swarm_size:
..."`` or ``"params['swarm_size']: ..."`` (a :class:`~rrtpso_ompl.errors.ParameterError` whose
``origin`` says so), ``"--planner: unknown planner ..."`` (an
:class:`~rrtpso_ompl.errors.UnknownPlannerError`). :class:`Sources` says how the caller's
arguments are named: as Python arguments (:data:`PYTHON`) or as command-line flags
(:func:`command_line`). The command line only turns these errors into its exit status 2.

Nothing here imports OMPL (the registry loads the planners' modules when first asked).
"""

from __future__ import annotations

import dataclasses
import functools
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from ..errors import (
    ArgumentError,
    ParameterError,
    ProblemError,
    UnknownPlannerError,
    UnsupportedSpaceError,
    did_you_mean,
    shown,
)
from ..model.problem_types import PlannerConfig, Problem
from ..params import ParamSpec, ParamTable
from ..validation import check_seconds, check_seed, describe
from .pso.path_optimizer import PathOptimizerOptions
from .registry import PlannerEntry, PlannerRegistry, default_registry

__all__ = [
    "COMMAND_LINE",
    "DEFAULT_PLANNER",
    "DEFAULT_TIME_LIMIT",
    "POST_PARAMS",
    "POST_STEPS",
    "PYTHON",
    "PlannerRequest",
    "Sources",
    "check_arguments",
    "command_line",
    "parse_steps",
    "post_table",
    "resolve",
    "split_spec",
]

DEFAULT_PLANNER = "RRTstarPSO"
#: Seconds.
DEFAULT_TIME_LIMIT = 1.0

#: The post-passes, in the order a spec may name them: OMPL's simplifier and the swarm.
POST_STEPS = ("simplify", "pso")

#: The harness's parameters of the post-passes.
POST_PARAMS = ParamTable(
    ParamSpec("post_fraction", float, 0.2,
              "Share of the time budget kept for the post-passes after the planner (the planner "
              "gets the rest); only used when post-passes are asked for.", low=0.0, high=0.9),
    ParamSpec("simplify_share", float, 0.5,
              "Most of the post-pass time OMPL's simplifier may take when the swarm follows it.",
              low=0.0, high=1.0),
)  # fmt: skip


@functools.cache
def post_table() -> ParamTable:
    """Every parameter the post-passes take: :data:`POST_PARAMS`, the swarm's and the path
    optimiser's."""
    return POST_PARAMS + PathOptimizerOptions.PARAMS


def parse_steps(items: Iterable[str], origin: str = "post") -> tuple[str, ...]:
    """Post-pass names, checked; a :class:`ParameterError` from ``origin`` naming the known ones
    otherwise."""
    steps = tuple(s.strip() for s in items)
    for step in steps:
        if step not in POST_STEPS:
            known = ", ".join(POST_STEPS)
            raise ParameterError(
                f"unknown post-pass '{shown(step)}' (known: {known})", step, origin
            )
    return steps


def split_spec(spec: str, origin: str = "") -> tuple[str, tuple[str, ...]]:
    """``"BITstar+simplify+pso"`` -> ``("BITstar", ("simplify", "pso"))``; steps checked."""
    name, *steps = spec.split("+")
    return name.strip(), parse_steps(steps, origin or f"planner '{shown(spec)}'")


# ----------------------------------------------------------------------------------------------
# How the caller's arguments are named
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Sources:
    """How messages name the values a caller gives (a file's values are named by the file).

    Attributes
    ----------
    planner, post, time_limit, seed : str
        The labels of those arguments.
    param : str
        The label of one parameter, a format with ``{name}``.
    prefix : str
        Put before every label (the problem file, for flags given with it); empty for none.
    """

    planner: str = "planner"
    post: str = "post"
    time_limit: str = "time_limit"
    seed: str = "seed"
    param: str = "params[{name!r}]"
    prefix: str = ""

    def label(self, what: str, name: str = "") -> str:
        """The origin text of the caller's ``what`` (``"param"`` with its ``name``)."""
        text = self.param.format(name=shown(name)) if what == "param" else getattr(self, what)
        return f"{self.prefix}: {text}" if self.prefix else text


#: Python's names: ``solve(problem, planner, time_limit=..., seed=..., params={...})``.
PYTHON = Sources()
#: The command line's flags, without a problem file (batch, bench).
COMMAND_LINE = Sources("--planner", "--post", "--time", "--seed", "--param {name}")


def command_line(src: str = "") -> Sources:
    """The command line's flags, given with the problem file ``src`` (named before them)."""
    return dataclasses.replace(COMMAND_LINE, prefix=src)


DEFAULT = "default"


# ----------------------------------------------------------------------------------------------
# The request
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PlannerRequest:
    """A planner, its post-passes, parameters, time limit and seed, resolved for one problem
    (or for none: a batch checks its flags before it loads any file). Build it with
    :func:`resolve`.

    Attributes
    ----------
    problem : Problem or None
        The problem whose ``planner`` section was read.
    entry : PlannerEntry
        The registered planner.
    post : tuple of str
        Every post-pass after the planner, in order: the spec's, then the caller's.
    spec_post : tuple of str
        The post-passes the spec named (``BITstar+pso``): part of the planner's label.
    params : mapping
        The planner's parameters as given (the file's under the caller's), converted.
    post_params : mapping
        The post-passes' parameters as given, converted (empty without post-passes).
    time_limit : float
        Seconds, for the planner and its post-passes together.
    seed : int or None
        OMPL's seed (and the planner's numpy seed when it takes one and none was given).
    origins : mapping
        Where each value came from, as messages name it: keys ``"planner"``, ``"post"``,
        ``"time_limit"``, ``"seed"`` and ``"params.NAME"`` (the planner's, the filled ``budget``
        and ``seed`` included, and the post-passes'); values such as ``"p.yaml:
        planner.params.swarm_size"``, ``"--param swarm_size"`` or ``"default"``.
    """

    problem: Problem | None
    entry: PlannerEntry
    post: tuple[str, ...] = ()
    spec_post: tuple[str, ...] = ()
    params: Mapping[str, Any] = field(default_factory=dict)
    post_params: Mapping[str, Any] = field(default_factory=dict)
    time_limit: float = DEFAULT_TIME_LIMIT
    seed: int | None = None
    origins: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("params", "post_params", "origins"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))

    @property
    def label(self) -> str:
        """The planner as asked: the name with the spec's post-passes (``BITstar+pso``), a
        configuration of its own in benchmarks; the caller's ``post`` are not part of it."""
        return self.entry.name + "".join(f"+{step}" for step in self.spec_post)

    @property
    def post_fraction(self) -> float:
        """The share of the time limit the post-passes get (0 without any)."""
        if not self.post:
            return 0.0
        return float(self.post_params.get("post_fraction", POST_PARAMS["post_fraction"].default))

    @property
    def planner_time(self) -> float:
        """The planner's own time limit, seconds: the rest after the post-passes' share."""
        return self.time_limit * (1.0 - self.post_fraction)

    def param_names(self) -> list[str]:
        """Every parameter the request may be given: the planner's, then its post-passes'."""
        return [*self.entry.params.names(), *(post_table().names() if self.post else [])]

    def takes(self, name: str) -> bool:
        """Whether the planner or its post-passes take a parameter ``name``."""
        return self.entry.takes(name) or (bool(self.post) and name in post_table())

    @property
    def values(self) -> dict[str, Any]:
        """What the planner is made with: :attr:`params`, plus ``budget`` (the planner's time)
        and ``seed`` for a planner that takes them and was not given them."""
        values = dict(self.params)
        # Planners that split their time (RRTstarPSO) need to know it: OMPL's termination
        # condition does not say how much is left.
        if self.entry.takes("budget") and "budget" not in values:
            values["budget"] = self.planner_time
        if self.seed is not None and self.entry.takes("seed") and "seed" not in values:
            values["seed"] = self.seed
        return values


def resolve(
    problem: Problem | None = None,
    spec: str | None = None,
    *,
    params: Mapping[str, Any] | None = None,
    time_limit: float | None = None,
    seed: int | None = None,
    post: Sequence[str] | str = (),
    registry: PlannerRegistry | None = None,
    sources: Sources = PYTHON,
) -> PlannerRequest:
    """Resolve what to run: the caller's choices over the problem's ``planner`` section over
    the defaults (see the module's docstring for the order and the budget rule).

    Parameters
    ----------
    problem : Problem, optional
        Its ``planner`` section gives what the caller leaves out; without one, the defaults do.
    spec : str, optional
        A planner name or alias, with post-passes after ``+`` (``"BITstar+simplify+pso"``).
    params, time_limit, seed, post
        Parameters by name (text is converted, as from the command line); seconds for the
        planner and its post-passes; OMPL's and the planner's seed; post-passes after the
        spec's (a string is a comma list).
    registry : PlannerRegistry, optional
        The default registry when omitted.
    sources : Sources
        How messages name the caller's arguments: :data:`PYTHON` or :func:`command_line`.

    Returns
    -------
    PlannerRequest

    Raises
    ------
    ArgumentError
        For an argument of the wrong kind.
    UnknownPlannerError, ParameterError
        For a planner, post-pass, parameter, time limit or seed that cannot be honoured, its
        ``origin`` naming where it came from.
    ProblemError
        For a value of the problem's ``planner.params`` its planner cannot take.
    """
    post = check_arguments("resolve", problem, spec, params, post)
    cfg = problem.planner if problem is not None else PlannerConfig()
    src = problem.source if problem is not None else ""
    origins: dict[str, str] = {}
    entry, spec_post = _planner(spec, cfg, src, registry or default_registry(), sources, origins)
    _check_space(problem, entry, origins)
    steps = tuple(dict.fromkeys((*spec_post, *parse_steps(post, sources.label("post")))))
    if post:
        origins["post"] = sources.label("post")
    limit = _time_limit(time_limit, cfg, src, sources, origins)
    seed = _seed(seed, cfg, src, sources, origins)
    planner_params, post_params = _params(entry, steps, cfg, src, params or {}, sources, origins)
    request = PlannerRequest(
        problem, entry, steps, spec_post, planner_params, post_params, limit, seed, origins
    )
    _check_rules(request, origins)
    return request


def _check_space(problem: Problem | None, entry: PlannerEntry, origins: Mapping[str, str]) -> None:
    """Refuse a planner of the plane only for a car-like robot's problem, before planning."""
    if problem is not None and problem.car and not entry.capabilities.car_spaces:
        raise UnsupportedSpaceError(
            f"{origins.get('planner', entry.name)}: {entry.name} plans in the plane only; a "
            f"car-like robot (robot.turning_radius of {problem.source}) is planned in OMPL's "
            f"Dubins or Reeds-Shepp space: use RRTstarPSO or one of OMPL's planners"
        )


def check_arguments(
    caller: str, problem: Any, spec: Any, params: Any, post: Any, problem_required: bool = False
) -> tuple[str, ...]:
    """Refuse arguments of :func:`resolve` (or of ``caller``, which takes the same) of the wrong
    kind with an :class:`ArgumentError` that says what goes there (a wrong *value* is the
    planners' business); returns ``post`` as a tuple of step names."""
    if (problem is not None or problem_required) and not isinstance(problem, Problem):
        hint = ""
        if isinstance(problem, str | os.PathLike):
            hint = f"; load the file first: {caller}(load_problem({str(problem)!r}), ...)"
        raise ArgumentError(f"{caller}: problem must be a Problem (from load_problem or "
                            f"problem_from_dict), got {describe(problem)}{hint}")  # fmt: skip
    if spec is not None and not isinstance(spec, str):
        raise ArgumentError(f"{caller}: planner must be a planner name such as 'RRTstarPSO' (see "
                            f"'rrtpso planners'), got {describe(spec)}")  # fmt: skip
    if params is not None:
        if not isinstance(params, Mapping):
            raise ArgumentError(f"{caller}: params must be a mapping of parameter names to "
                                f"values, such as {{'range': 2.0}}, "
                                f"got {describe(params)}")  # fmt: skip
        for key in params:
            if not isinstance(key, str):
                raise ArgumentError(f"{caller}: params: parameter names are strings, got "
                                    f"{describe(key)}")  # fmt: skip
    if isinstance(post, str):
        post = [s for s in post.split(",") if s.strip()]
    if not isinstance(post, Sequence) or not all(isinstance(s, str) for s in post):
        raise ArgumentError(f"{caller}: post must be step names such as ('simplify', 'pso'), "
                            f"got {describe(post)}")  # fmt: skip
    return tuple(post)


def _planner(
    spec: str | None,
    cfg: PlannerConfig,
    src: str,
    registry: PlannerRegistry,
    sources: Sources,
    origins: dict[str, str],
) -> tuple[PlannerEntry, tuple[str, ...]]:
    """The registered planner and the spec's post-passes: the caller's spec, else the file's
    ``planner.type``, else the default."""
    if spec is not None:
        origin = sources.label("planner")
        if not spec.strip():
            raise ParameterError("give a planner name (see 'rrtpso planners')", "planner", origin)
    elif cfg.type:
        spec, origin = cfg.type, f"{src}: planner.type"
    else:
        spec, origin = DEFAULT_PLANNER, DEFAULT
    origins["planner"] = origin
    name, steps = split_spec(spec, origin)
    try:
        return registry.get(name), steps
    except UnknownPlannerError as exc:
        raise UnknownPlannerError(exc.name, exc.known, exc.reason, origin) from None


def _origin(name: str, given, from_file, src: str, sources: Sources, default):
    """The value of ``name`` and where it came from: the caller's (``sources`` labels it), the
    problem file's ``planner`` section, else ``default``."""
    if given is not None:
        return given, sources.label(name)
    if from_file is not None:
        return from_file, f"{src}: planner.{name}"
    return default, DEFAULT


def _time_limit(
    given: float | None, cfg: PlannerConfig, src: str, sources: Sources, origins: dict[str, str]
) -> float:
    value, origins["time_limit"] = _origin(
        "time_limit", given, cfg.time_limit, src, sources, DEFAULT_TIME_LIMIT
    )
    try:
        return check_seconds(value)
    except ValueError as exc:
        raise ParameterError(
            f"a time in seconds {exc}", "time_limit", origins["time_limit"]
        ) from None


def _seed(
    given: int | None, cfg: PlannerConfig, src: str, sources: Sources, origins: dict[str, str]
) -> int | None:
    value, origins["seed"] = _origin("seed", given, cfg.seed, src, sources, None)
    if value is None:
        return None
    try:
        return check_seed(value)
    except ValueError as exc:
        raise ParameterError(f"the seed {exc}", "seed", origins["seed"]) from None


def _params(
    entry: PlannerEntry,
    steps: tuple[str, ...],
    cfg: PlannerConfig,
    src: str,
    given: Mapping[str, Any],
    sources: Sources,
    origins: dict[str, str],
) -> tuple[dict[str, Any], dict[str, Any]]:
    """``(planner's, post-passes')`` parameters, each converted by its declaration: the file's
    (typed YAML: ``"30"`` in quotes is text there, as everywhere in it) under the caller's (text
    is converted, as from the command line)."""
    table = post_table() if steps else ParamTable()
    planner_params: dict[str, Any] = {}
    post_params: dict[str, Any] = {}
    for text, values in ((False, cfg.params), (True, given)):
        for key, value in values.items():
            label = shown(key)
            origin = sources.label("param", key) if text else f"{src}: planner.params.{label}"
            try:
                if entry.takes(key) or key not in table:
                    planner_params[key] = _spec(entry, table, key).convert(value, entry.name, text)
                else:
                    post_params[key] = table[key].convert(value, "post-pass", text)
            except ParameterError as exc:
                if not text:
                    raise ProblemError(src, f"planner.params.{label}", str(exc)) from None
                raise ParameterError(exc.detail, exc.name, origin) from None
            origins[f"params.{key}"] = origin
    if entry.takes("budget") and "budget" not in planner_params:
        share = " (the planner's share)" if steps else ""
        origins["params.budget"] = origins["time_limit"] + share
    if entry.takes("seed") and "seed" not in planner_params:
        origins["params.seed"] = origins["seed"]
    return planner_params, post_params


def _spec(entry: PlannerEntry, post: ParamTable, key: str) -> ParamSpec:
    """The planner's spec of ``key``; for a name neither the planner nor its post-passes take,
    a :class:`ParameterError` listing the planner's (and suggesting among both)."""
    if entry.takes(key):
        return entry.param(key)
    if not len(post):
        return entry.param(key)  # raises, naming the planner's parameters
    known = ", ".join(entry.params.names()) or "none"
    hint = did_you_mean(key, [*entry.params.names(), *post.names()])
    raise ParameterError(f"planner '{entry.name}' has no parameter '{shown(key)}'{hint} (known: "
                         f"{known}; the post-passes': {', '.join(post.names())})", key)  # fmt: skip


def _check_rules(request: PlannerRequest, origins: Mapping[str, str]) -> None:
    """The rules over several parameters (``c1 + c2 < 4``), on the planner's values and on the
    post-passes', naming where the values involved came from."""
    checks = [(request.entry.params, request.values, request.entry.name)]
    if request.post:
        checks.append((post_table(), dict(request.post_params), "post-pass"))
    for table, values, owner in checks:
        try:
            table.validate(values, owner=owner)
        except ParameterError as exc:
            names = exc.name.split(" + ")
            texts = [origins.get(f"params.{n}", f"the default of {n}") for n in names]
            raise ParameterError(exc.detail, exc.name, _joint(texts)) from None


def _joint(origins: Sequence[str]) -> str:
    """Several origins as one: ``"p.yaml: --param c1 and planner.params.c2"`` (a shared file
    named once)."""
    texts = list(dict.fromkeys(origins))
    heads = {t.partition(": ")[0] for t in texts if ": " in t}
    if len(heads) == 1 and all(": " in t for t in texts):
        head = heads.pop()
        return f"{head}: " + " and ".join(t.partition(": ")[2] for t in texts)
    return " and ".join(texts)
