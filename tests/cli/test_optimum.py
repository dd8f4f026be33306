"""``rrtpso optimum``: the JSON contract, the plot and bad input."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest
from helpers import PROBLEMS, rrtpso_exe

pytestmark = pytest.mark.slow


def test_cli_writes_the_contract(tmp_path):
    out = tmp_path / "opt.json"
    png = tmp_path / "opt.png"
    problem = PROBLEMS / "static" / "single_circle.yaml"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(problem), "--json", str(out),
                           "--plot", str(png)], capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert list(data)[:2] == ["length", "path"]
    assert data["length"] == pytest.approx(647.4596, abs=1e-4)
    path = np.array(data["path"])
    assert np.allclose(path[0], (20, 20)) and np.allclose(path[-1], (450, 450))
    assert png.stat().st_size > 1000


def test_cli_bad_file_exit_2(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("bounds: [[0, 0], [10, 10]]\nstart: [1, 1]\n")
    out = tmp_path / "opt.json"
    proc = subprocess.run([*rrtpso_exe(), "optimum", str(bad), "--json", str(out)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 2
    assert str(bad) in proc.stderr and "goal" in proc.stderr and "Traceback" not in proc.stderr
    assert not out.exists()
