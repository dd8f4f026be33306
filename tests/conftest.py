"""Shared fixtures: small real problems, built through the public API as a user would."""

from __future__ import annotations

import shutil

import pytest
from helpers import PROBLEMS, SINGLE_CIRCLE

from rrtpso_ompl.model.problem import Problem, problem_from_dict


@pytest.fixture
def single_circle() -> Problem:
    return problem_from_dict(SINGLE_CIRCLE, source="single_circle")


@pytest.fixture
def folder(tmp_path):
    """Two good problems and a bad one."""
    d = tmp_path / "problems"
    d.mkdir()
    shutil.copy(PROBLEMS / "static" / "single_circle.yaml", d / "a_circle.yaml")
    shutil.copy(PROBLEMS / "static" / "narrow_passage.yaml", d / "b_passage.yaml")
    (d / "c_bad.yaml").write_text("bounds: [[0, 0], [10, 10]]\nstart: [1, 1]\ngoal: [9, 9]\n")
    return d
