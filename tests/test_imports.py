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


def test_every_subpackage_is_installed_by_a_non_editable_install():
    """pyproject.toml lists the packages explicitly (plugins/ is installed as a subpackage): a
    new subpackage missing from the list works in the editable checkout and is absent from a
    wheel (CI installs one)."""
    import tomllib
    from helpers import REPO

    listed = set(tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
                 ["packages"])  # fmt: skip
    found = {".".join(p.parent.relative_to(REPO).parts)
             for p in (REPO / "rrtpso_ompl").rglob("__init__.py")}  # fmt: skip
    assert found <= listed, f"missing from pyproject.toml's packages: {sorted(found - listed)}"
