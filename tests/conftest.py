"""Shared fixtures: small real problems, built through the public API as a user would."""

from __future__ import annotations

import pytest
from helpers import SINGLE_CIRCLE

from rrtpso_ompl.model.problem import Problem, problem_from_dict


@pytest.fixture
def single_circle() -> Problem:
    return problem_from_dict(SINGLE_CIRCLE, source="single_circle")
