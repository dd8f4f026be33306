"""Writing problem files: key order, the header, validity after rounding."""

from __future__ import annotations

import pytest

from rrtpso_ompl.groundtruth.generate import write_problem
from rrtpso_ompl.model.problem import Circle, ProblemError, load_problem


# ----------------------------------------------------------------------------------------------
# write_problem
# ----------------------------------------------------------------------------------------------
def test_write_problem_orders_keys_and_keeps_the_header(tmp_path):
    data = {
        "planner": {"seed": 1, "type": "RRTstarPSO"},
        "obstacles": [{"radius": 1.0, "center": [5.0, 5.0], "type": "circle"}],
        "robot": {"track_width": 0.4, "radius": 0.25},
        "goal": [9, 9],
        "start": [1, 1],
        "bounds": [[0, 0], [10, 10]],
        "units": "m",
        "name": "ordered",
    }
    path = write_problem(data, tmp_path / "o.yaml", header="first line\nsecond line")
    text = path.read_text()
    assert text.startswith("# first line\n# second line\nname: ordered\nunits: m\nbounds:")
    assert "robot:\n  radius: 0.25\n  track_width: 0.4\n" in text
    assert "  - {type: circle, center: [5.0, 5.0], radius: 1.0}\n" in text
    assert "planner:\n  type: RRTstarPSO\n  seed: 1\n" in text
    assert load_problem(path).obstacles == (Circle((5.0, 5.0), 1.0),)


def test_write_problem_rechecks_validity_after_rounding(tmp_path):
    data = {
        "bounds": [[0, 0], [10, 10]],
        "start": [1, 1],
        "goal": [9, 9],
        "robot": {"radius": 0},
        # Valid as written; rounded to 3 decimals its apex lands on the base: zero area.
        "obstacles": [{"type": "polygon", "points": [[4, 5], [5, 5.0004], [6, 5]]}],
    }
    write_problem(data, tmp_path / "fine.yaml")  # default decimals for a side of 10: 4
    with pytest.raises(ValueError, match=r"after rounding to 3 decimals .*obstacles\[0\]"):
        write_problem(data, tmp_path / "bad.yaml", decimals=3)
    assert not (tmp_path / "bad.yaml").exists()
    with pytest.raises(ProblemError, match=r"robot\.radius"):
        write_problem({**data, "robot": {"radius": -1}}, tmp_path / "bad.yaml")
