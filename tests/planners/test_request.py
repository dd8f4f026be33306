"""Request resolution in one place (planners.request.resolve): the order of the sources, the
budget rule, the post-passes' parameters, and errors that say where each value came from."""

from __future__ import annotations

import pickle
import subprocess

import pytest
from helpers import PROBLEMS, SINGLE_CIRCLE, rrtpso_exe

from rrtpso_ompl.errors import ParameterError, ProblemError, UnknownPlannerError
from rrtpso_ompl.model.problem import problem_from_dict
from rrtpso_ompl.planners import DEFAULT_PLANNER, DEFAULT_TIME_LIMIT, resolve
from rrtpso_ompl.planners.request import command_line

PLANNER = {"type": "RRTstar", "time_limit": 0.5, "seed": 4, "params": {"range": 30}}
FILED = problem_from_dict({**SINGLE_CIRCLE, "planner": PLANNER}, "p.yaml")
PLAIN = problem_from_dict(SINGLE_CIRCLE, "q.yaml")


def test_the_caller_over_the_file_over_the_defaults_and_where_each_came_from():
    request = resolve(FILED, params={"goal_bias": "0.1"}, seed=9, sources=command_line("p.yaml"))
    assert request.entry.name == "RRTstar" and request.time_limit == 0.5 and request.seed == 9
    assert dict(request.params) == {"range": 30.0, "goal_bias": 0.1}  # text converted
    assert dict(request.origins) == {
        "planner": "p.yaml: planner.type",
        "time_limit": "p.yaml: planner.time_limit",
        "seed": "p.yaml: --seed",
        "params.range": "p.yaml: planner.params.range",
        "params.goal_bias": "p.yaml: --param goal_bias",
    }
    over = resolve(FILED, "RRTConnect", params={"range": 5}, time_limit=0.2)
    assert (over.entry.name, over.time_limit, over.params["range"]) == ("RRTConnect", 0.2, 5.0)
    bare = resolve(PLAIN)
    assert (bare.entry.name, bare.time_limit, bare.seed) == (DEFAULT_PLANNER, DEFAULT_TIME_LIMIT,
                                                             None)  # fmt: skip
    assert bare.origins["planner"] == bare.origins["time_limit"] == "default"


def test_the_budget_rule():
    """A planner that splits its time gets the time limit, less the post-passes' share; the
    seed goes to a planner that takes one; what the caller or file gave is kept."""
    assert resolve(PLAIN, "RRTstarPSO", time_limit=2.0, seed=3).values["budget"] == 2.0
    spec = resolve(PLAIN, "RRTstarPSO+pso", time_limit=2.0, seed=3)
    assert spec.planner_time == pytest.approx(1.6) and spec.values["budget"] == pytest.approx(1.6)
    assert spec.values["seed"] == 3
    assert spec.origins["params.budget"] == "time_limit (the planner's share)"
    half = resolve(PLAIN, "RRTstarPSO", post="pso", params={"post_fraction": 0.5}, time_limit=2.0)
    assert half.values["budget"] == 1.0 and half.label == "RRTstarPSO" and half.post == ("pso",)
    kept = resolve(PLAIN, "RRTstarPSO+pso", params={"budget": 0.3}, time_limit=2.0)
    assert kept.values["budget"] == 0.3
    assert "budget" not in resolve(PLAIN, "RRTConnect+pso").values  # it takes none


def test_post_pass_parameters_go_to_the_post_passes_from_the_file_too():
    problem = problem_from_dict({**SINGLE_CIRCLE, "planner": {"params": {"swarm_size": 20}}},
                                "s.yaml")  # fmt: skip
    request = resolve(problem, "RRTConnect+simplify+pso", params={"post_fraction": "0.3"})
    assert dict(request.post_params) == {"swarm_size": 20, "post_fraction": 0.3}
    assert request.spec_post == request.post == ("simplify", "pso")
    assert request.label == "RRTConnect+simplify+pso" and request.takes("swarm_size")
    with pytest.raises(ProblemError) as exc:  # no post-passes: the planner's own check names it
        resolve(problem, "RRTConnect")
    assert str(exc.value).startswith("s.yaml: planner.params.swarm_size: planner 'RRTConnect'")


@pytest.mark.parametrize(
    ("kwargs", "error", "text"),
    [
        ({"spec": "RRTstra"}, UnknownPlannerError, "planner: unknown planner 'RRTstra' (did you"),
        ({"spec": " "}, ParameterError, "planner: give a planner name"),
        ({"spec": "RRT+zap"}, ParameterError, "planner: unknown post-pass 'zap'"),
        ({"post": "pso,smooth"}, ParameterError, "post: unknown post-pass 'smooth'"),
        ({"time_limit": 0}, ParameterError, "time_limit: a time in seconds must be > 0"),
        ({"seed": 2**32}, ParameterError, "seed: the seed must be <="),
        ({"params": {"swarm_siz": 3}}, ParameterError,
         "params['swarm_siz']: planner 'RRTstarPSO' has no parameter 'swarm_siz' (did you mean"),
        ({"params": {"c1": 3, "c2": "1.5"}}, ParameterError,
         "params['c1'] and params['c2']: parameters of RRTstarPSO must satisfy c1 + c2 < 4"),
        ({"params": {"c1": 3}}, ParameterError, "params['c1'] and the default of c2: "),
        ({"spec": "RRT+pso", "params": {"post_fractio": 0.3}}, ParameterError,
         "(did you mean 'post_fraction'?)"),
    ],
    ids=["planner", "empty", "spec-step", "post", "time", "seed", "param", "rule", "rule-default",
         "post-param"],
)  # fmt: skip
def test_errors_name_where_the_value_came_from(kwargs, error, text):
    with pytest.raises(error) as exc:
        resolve(PLAIN, **kwargs)
    assert text in str(exc.value)
    copy = pickle.loads(pickle.dumps(exc.value))  # a worker sends its errors to its parent
    assert str(copy) == str(exc.value) and type(copy) is type(exc.value)


def test_the_file_s_planner_type_is_named_as_the_file_s():
    problem = problem_from_dict({**SINGLE_CIRCLE, "planner": {"type": "Nope"}}, "n.yaml")
    with pytest.raises(UnknownPlannerError) as exc:
        resolve(problem)
    assert str(exc.value).startswith("n.yaml: planner.type: unknown planner 'Nope'")
    assert exc.value.origin == "n.yaml: planner.type"


def test_rules_over_post_pass_parameters_are_checked_before_planning():
    """``c1 + c2 < 4`` holds for the swarm of a post-pass too: refused when resolving (the
    command line exits 2 before any run), not by each run after its planner has used its time
    (before, a batch wrote one error row per run)."""
    with pytest.raises(ParameterError, match=r"parameters of post-pass must satisfy c1 \+ c2"):
        resolve(PLAIN, "RRTConnect+pso", params={"c1": 3.0})
    proc = subprocess.run([*rrtpso_exe(), "batch", str(PROBLEMS / "static" / "single_circle.yaml"),
                           "--planner", "RRTConnect+pso", "--param", "c1=3", "--time", "0.1",
                           "--out", "-"], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert proc.returncode == 2 and "--param c1 and the default of c2" in proc.stderr
    assert proc.stdout == ""
