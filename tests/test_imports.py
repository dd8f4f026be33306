"""OMPL is imported only where it is used: the pure stages load without it."""

from __future__ import annotations

import subprocess
import sys


def test_the_pure_stages_import_no_ompl():
    code = (
        "import rrtpso_ompl.planners.swarm, rrtpso_ompl.planners.params, rrtpso_ompl.plotting, "
        "rrtpso_ompl.groundtruth; import sys; assert 'ompl' not in sys.modules"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr


def test_the_planners_package_loads_ompl_on_first_use_of_a_planner_class():
    code = ("import sys, rrtpso_ompl.planners as p; assert 'ompl' not in sys.modules; "
            "p.RRTstarPSO; assert 'ompl' in sys.modules; "
            "from rrtpso_ompl.planners import solve; assert callable(solve)")  # fmt: skip
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
