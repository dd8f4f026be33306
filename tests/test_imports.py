"""OMPL is imported only where it is used: the pure stages load without it."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from helpers import PROBLEMS


def test_the_pure_stages_import_no_ompl():
    code = (
        "import rrtpso_ompl.planners.pso.swarm, rrtpso_ompl.params, rrtpso_ompl.plotting, "
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


# ----------------------------------------------------------------------------------------------
# Start-up: what each command imports (issue 33; docs/design.md, "Start-up")
# ----------------------------------------------------------------------------------------------
#: Runs ``rrtpso ARGS`` (its ``main``, as the console script does) in this fresh interpreter,
#: then writes the modules it holds, the exit status and, with WATCH set, every call of
#: ``importlib.metadata.entry_points`` (how plugins are found) to the file ``sys.argv[1]``.
_RUN = """
import json, os, sys
calls = []
if os.environ.get("WATCH"):
    import importlib.metadata as md
    real = md.entry_points
    md.entry_points = lambda *a, **k: calls.append(k.get("group")) or real(*a, **k)
from rrtpso_ompl.cli import main
try:
    status = main(sys.argv[2:])
except SystemExit as exc:  # --help, --version
    status = exc.code
with open(sys.argv[1], "w") as fh:
    json.dump({"status": status, "modules": sorted(sys.modules), "entry_points": calls}, fh)
"""

#: "Heavy": the numeric and drawing libraries, OMPL, and the package's stages. ``rrtpso
#: --version`` and the help of any command need none of them (numpy and yaml included: nothing
#: there reads a number or a file); ``importlib.metadata`` is how plugins are found.
HEAVY = ("numpy", "yaml", "scipy", "shapely", "matplotlib", "ompl", "PIL", "tqdm", "rosbags",
         "importlib.metadata")  # fmt: skip
STAGES = tuple(f"rrtpso_ompl.{s}" for s in ("model", "planners", "groundtruth", "dynamic",
               "harness", "ompl_setup", "ros", "kinematics", "plotting"))  # fmt: skip


def _run(tmp_path, *args: str, watch: bool = False) -> dict:
    out = tmp_path / "run.json"
    env = {**os.environ, "WATCH": "1" if watch else ""}
    proc = subprocess.run([sys.executable, "-c", _RUN, str(out), *args], capture_output=True,
                          text=True, timeout=120, env=env, cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    data["stdout"] = proc.stdout
    return data


def _bare_modules() -> set[str]:
    """What the interpreter holds before running anything (a site hook may import more)."""
    code = "import json, sys; print(json.dumps(sorted(sys.modules)))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=True)  # fmt: skip
    return set(json.loads(proc.stdout))


def _among(modules, names) -> list[str]:
    """The modules that are one of ``names`` or inside one of them."""
    return sorted(m for m in modules if any(m == n or m.startswith(n + ".") for n in names))


@pytest.mark.parametrize("args", [["--version"], ["--help"], ["solve", "--help"]])
def test_version_and_help_import_nothing_heavy(tmp_path, args):
    run = _run(tmp_path, *args)
    assert run["status"] == 0
    assert "rrtpso" in run["stdout"]  # it did print the version or the help
    loaded = set(run["modules"]) - _bare_modules()
    assert _among(loaded, HEAVY + STAGES) == []


def test_the_help_still_lists_every_command_and_the_solve_flags(tmp_path):
    """Built lazily, the help says what it said: every command, and solve's own flags."""
    from rrtpso_ompl.cli.main import COMMANDS

    top = _run(tmp_path, "--help")["stdout"]
    assert all(f"    {name} " in top for name in COMMANDS)
    solve = _run(tmp_path, "solve", "--help")["stdout"]
    assert all(flag in solve for flag in ("--planner", "--json", "--plot", "--post", "--bag"))


def test_optimum_and_generate_import_no_ompl_and_no_matplotlib(tmp_path):
    problem = PROBLEMS / "static" / "paper_static.yaml"  # 12 obstacles, no map
    optimum = _run(tmp_path, "optimum", str(problem), "--json", "-")
    assert optimum["status"] == 0
    assert json.loads(optimum["stdout"])["length"] > 0
    # Nor the planners, the dynamic stage or the harness; and for a raster this small the
    # optimum's breadth-first searches need no scipy (groundtruth.free_grid).
    unused = ("ompl", "matplotlib", "scipy", "rrtpso_ompl.planners", "rrtpso_ompl.dynamic",
              "rrtpso_ompl.harness", "rrtpso_ompl.plotting")  # fmt: skip
    assert _among(optimum["modules"], unused) == []
    generate = _run(tmp_path, "generate", "circles", "--seed", "1", "--out", "g.yaml")
    assert generate["status"] == 0 and (tmp_path / "g.yaml").is_file()
    assert _among(generate["modules"], ("ompl", "matplotlib", "rrtpso_ompl.dynamic",
                                        "rrtpso_ompl.plotting")) == []  # fmt: skip


def test_solve_imports_no_matplotlib_unless_it_draws(tmp_path):
    problem = PROBLEMS / "static" / "single_circle.yaml"
    solve = _run(tmp_path, "solve", str(problem), "--json", "-", "--time", "0.1", "--seed", "1")
    assert solve["status"] in (0, 1) and json.loads(solve["stdout"])["planner"]
    assert "ompl" in solve["modules"]
    assert _among(solve["modules"], ("matplotlib", "rrtpso_ompl.plotting",
                                     "rrtpso_ompl.dynamic")) == []  # fmt: skip
    drawn = _run(tmp_path, "optimum", str(problem), "--plot", "o.png")
    assert drawn["status"] == 0 and "matplotlib" in drawn["modules"]  # the control


def test_plugin_entry_points_are_read_only_when_a_planner_is_looked_up(tmp_path):
    problem = str(PROBLEMS / "static" / "single_circle.yaml")
    for args in (["--version"], ["--help"], ["solve", "--help"], ["optimum", problem]):
        assert _run(tmp_path, *args, watch=True)["entry_points"] == [], args
    solve = _run(tmp_path, "solve", problem, "--time", "0.05", "--seed", "1", watch=True)
    assert "rrtpso_ompl.planners" in solve["entry_points"]  # the control: the hook sees it


def test_the_package_exports_its_names_lazily():
    code = (
        "import sys, rrtpso_ompl as r; assert 'numpy' not in sys.modules, 'numpy'; "
        "assert r.__version__ and 'importlib.metadata' not in sys.modules; "
        "from rrtpso_ompl import load_problem, World, solve, RRTstarPSO, RrtpsoError; "
        "assert all(hasattr(r, n) for n in r.__all__) and set(r.__all__) <= set(dir(r)); "
        # A submodule imported after its package keeps the package's same-named function.
        "import rrtpso_ompl.groundtruth as g, rrtpso_ompl.planners as p; "
        "import rrtpso_ompl.groundtruth.generate, rrtpso_ompl.planners.solve; "
        "assert callable(g.generate) and not isinstance(g.generate, type(sys)), g.generate; "
        "assert callable(p.solve) and not isinstance(p.solve, type(sys)), p.solve; "
        "from rrtpso_ompl.groundtruth import map_kinds; assert isinstance(map_kinds, type(sys))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
