"""The Python API refuses arguments of the wrong kind with the project's errors (issue 22):
one message saying what goes there, never an AttributeError from deep inside."""

from __future__ import annotations

import logging

import pytest
from helpers import PROBLEMS, SINGLE_CIRCLE
from ompl import base as ob

from rrtpso_ompl.errors import ArgumentError, ProblemError, RrtpsoError, UsageError
from rrtpso_ompl.harness import make_tasks
from rrtpso_ompl.model import load_problem, problem_from_dict
from rrtpso_ompl.planners import default_registry, resolve, solve

FILE = PROBLEMS / "static" / "single_circle.yaml"
PROBLEM = load_problem(FILE)


@pytest.mark.parametrize(
    ("args", "kwargs", "words"),
    [
        ((str(FILE), "RRTstar"), {"time_limit": 0.1}, "load the file first: solve(load_problem("),
        ((FILE,), {}, "problem must be a Problem"),
        ((None,), {}, "problem must be a Problem"),
        ((PROBLEM, 3), {}, "planner must be a planner name"),
        ((PROBLEM, "RRTstar"), {"params": "a=1"}, "params must be a mapping"),
        ((PROBLEM, "RRTstar"), {"params": {1: 2}}, "parameter names are strings"),
        ((PROBLEM, "RRTstar"), {"post": 3}, "post must be step names"),
        ((PROBLEM, "RRTstar"), {"world": "w"}, "world must be the problem's World"),
    ],
    ids=["path", "pathlib", "none", "planner-int", "params-str", "params-key", "post", "world"],
)
def test_solve_refuses_arguments_of_the_wrong_kind(args, kwargs, words):
    with pytest.raises(ArgumentError) as exc:
        solve(*args, **kwargs)
    assert words in str(exc.value)
    assert isinstance(exc.value, RrtpsoError) and isinstance(exc.value, TypeError)


def test_only_the_problem_and_the_planner_are_positional():
    """``solve(problem, planner, *, time_limit=..., seed=..., ...)``: a number in third place
    could be read as a time limit or a seed, so it is refused."""
    with pytest.raises(TypeError, match="positional"):
        solve(PROBLEM, "RRTstar", 0.1)


def test_a_request_is_solved_as_resolved_and_not_with_other_arguments():
    request = resolve(PROBLEM, "RRTConnect", time_limit=0.2, seed=1)
    with pytest.raises(ArgumentError, match=r"not both .*time_limit"):
        solve(request, time_limit=0.5)
    with pytest.raises(ArgumentError, match="without a problem"):
        solve(resolve(None, "RRTConnect"))
    result = solve(request)
    assert result.solved and result.planner == "RRTConnect" and result.time_limit == 0.2


def test_post_may_be_a_comma_list_as_on_the_command_line():
    result = solve(PROBLEM, "RRTConnect", time_limit=0.2, seed=1, post="simplify")
    assert [s["step"] for s in result.stages["post"]] == ["simplify"]


def test_a_quoted_number_in_the_file_s_planner_params_is_text():
    """YAML values are typed everywhere in a file: ``swarm_size: '30'`` is refused as
    ``radius: '30'`` is; the same text from ``--param`` or Python's ``params`` is converted."""
    doc = {**SINGLE_CIRCLE, "planner": {"params": {"swarm_size": "30"}}}
    quoted = problem_from_dict(doc, "q.yaml")
    with pytest.raises(ProblemError) as exc:
        solve(quoted, "RRTstarPSO", time_limit=0.1)
    assert exc.value.source == "q.yaml" and exc.value.key == "planner.params.swarm_size"
    assert "a number in quotes is text" in str(exc.value)
    doc["planner"]["params"]["swarm_size"] = 30
    plain = problem_from_dict(doc, "q.yaml")
    result = solve(plain, "RRTstarPSO", time_limit=0.1, seed=1, params={"iterations": "5"})
    assert result.params["swarm_size"] == 30


@pytest.mark.parametrize("name", ["RRTstarPSO", "PSO"])
def test_solving_without_a_problem_definition_is_one_error_line(name, caplog):
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(ob.AllValidStateValidityChecker(si))
    si.setup()
    planner = default_registry().get(name).make(si)
    with caplog.at_level(logging.ERROR):
        status = planner.solve(0.1)
    assert status.getStatus() == ob.PlannerStatus.ABORT
    assert len(caplog.records) == 1 and caplog.records[0].exc_info is None
    assert "no problem definition" in caplog.records[0].getMessage()


def test_a_batch_of_too_many_runs_is_refused_before_its_tasks_are_built():
    with pytest.raises(UsageError, match=r"--runs: .* got runs 4,294,967,295 x 1 planner x 1 file"):
        make_tasks([str(FILE)], ["RRTstar"], runs=2**32 - 1)
