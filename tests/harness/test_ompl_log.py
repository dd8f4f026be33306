"""OMPL benchmark logs: written by :mod:`rrtpso_ompl.harness.ompl_log`, read back by OMPL."""

from __future__ import annotations

import math
import sqlite3
from pathlib import Path

import pytest

from rrtpso_ompl import __version__
from rrtpso_ompl.harness.ompl_log import (
    STATUS_ENUM,
    Experiment,
    PlannerRuns,
    build_database,
    format_log,
    status_code,
    write_log,
)

PSO_PROPS = [
    ("time", "REAL"),
    ("solved", "BOOLEAN"),
    ("status", "ENUM"),
    ("solution length", "REAL"),
    ("simplified solution length", "REAL"),
    ("simplification time", "REAL"),
]
RRT_PROPS = [
    ("time", "REAL"),
    ("solved", "BOOLEAN"),
    ("status", "ENUM"),
    ("solution length", "REAL"),
]
PROGRESS_PROPS = [("time", "REAL"), ("best cost", "REAL")]

# Values chosen so that a short decimal rendering would not round-trip.
PSO_RUNS = [
    {
        "time": 0.1 + 0.2,
        "solved": True,
        "status": "Exact solution",
        "solution length": 1 / 3 + 700,
        "simplified solution length": 647.4512345678901,
        "simplification time": 0.012345678901234567,
    },
    {
        "time": 1.0000000000000002,
        "solved": False,
        "status": "none",
        "solution length": None,
        "simplified solution length": None,
        "simplification time": float("nan"),
    },
    {
        "time": 2.5,
        "solved": True,
        "status": 5,
        "solution length": 812.0,
        "simplified solution length": 700.25,
        # "simplification time" left out: an empty field
    },
]
RRT_RUNS = [
    {"time": 0.75, "solved": True, "status": "exact", "solution length": 701.125},
    {"time": 1.5, "solved": False, "status": "Timeout", "solution length": None},
    {"time": 0.5, "solved": True, "status": 6, "solution length": 1e-300},
]
PSO_PROGRESS = [
    [(0.05, 13.1), (0.1, 12.5)],
    [(0.05, float("inf")), (0.1, float("inf"))],
    [(0.05, 900.5), (0.1, 850.0), (0.15, 812.0)],
]
RRT_PROGRESS = [[(0.05, 750.0)], [(0.05, None)], [(0.05, 1e-300), (0.1, 1e-300 / 3)]]


def make_experiment(name: str = "single_circle", **kwargs) -> Experiment:
    planners = [
        PlannerRuns(
            name="RRTstarPSO",
            settings={"range": 25.0, "goal_bias": 0.05, "delay_collision_checking": True},
            run_properties=PSO_PROPS,
            runs=PSO_RUNS,
            progress_properties=PROGRESS_PROPS,
            progress=PSO_PROGRESS,
        ),
        PlannerRuns(
            name="RRTstar",
            settings={"range": 30},
            run_properties=RRT_PROPS,
            runs=RRT_RUNS,
            progress_properties=PROGRESS_PROPS,
            progress=RRT_PROGRESS,
        ),
    ]
    defaults = {
        "time_limit": 5.0,
        "run_count": 3,
        "seed": 42,
        "total_time": 12.25,
        "host": "testhost",
        "date": "2026-11-22 17:49:20",
        "setup": "problem: single_circle\nplanners: RRTstarPSO, RRTstar",
        "cpuinfo": "2 cores",
        "properties": {"num_obstacles": 1, "goal tolerance": 0.5, "dynamic": False, "units": "cm"},
    }
    defaults.update(kwargs)
    return Experiment(name=name, planners=planners, **defaults)


def query(db: Path, sql: str, *args) -> list[tuple]:
    conn = sqlite3.connect(db)
    try:
        return conn.execute(sql, args).fetchall()
    finally:
        conn.close()


def columns(db: Path, table: str) -> list[str]:
    return [row[1] for row in query(db, f"PRAGMA table_info({table})")]


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> tuple[Path, Path]:
    tmp = tmp_path_factory.mktemp("ompl_log")
    log = write_log(make_experiment(), tmp / "exp.log")
    db = build_database([log], tmp / "bench.db")
    return log, db


def test_format_shape() -> None:
    text = format_log(make_experiment())
    lines = text.splitlines()
    assert lines[0] == f"rrtpso-ompl version {__version__}"
    assert lines[1] == "Experiment single_circle"
    assert "1 enum type" in lines
    assert "status|" + "|".join(STATUS_ENUM) in lines
    assert "geometric_RRTstarPSO" in lines and "geometric_RRTstar" in lines
    assert "delay_collision_checking = 1" in lines
    assert "0.05,13.1,;0.1,12.5,;" in lines
    assert (
        "0.30000000000000004; 1; 6; 700.3333333333334; 647.4512345678901; 0.012345678901234567; "
        in lines
    )
    assert text.endswith(".\n")


def test_experiment_row(built) -> None:
    _, db = built
    rows = query(
        db,
        "SELECT name, runcount, timelimit, memorylimit, totaltime, version, hostname, seed, "
        "date, setup, cpuinfo, num_obstacles, goaltolerance, dynamic, units FROM experiments",
    )
    assert rows == [
        (
            "single_circle",
            3,
            5.0,
            4096.0,
            12.25,
            f"rrtpso-ompl {__version__}",
            "testhost",
            "42",
            "2026-11-22 17:49:20",
            "problem: single_circle\nplanners: RRTstarPSO, RRTstar\n",
            "2 cores\n",
            1,
            0.5,
            0,
            "cm",
        )
    ]


def test_planner_configs(built) -> None:
    _, db = built
    configs = dict(query(db, "SELECT name, settings FROM plannerConfigs"))
    assert set(configs) == {"geometric_RRTstarPSO", "geometric_RRTstar"}
    pso = configs["geometric_RRTstarPSO"]
    assert "range = 25.0" in pso and "goal_bias = 0.05" in pso
    assert "delay_collision_checking = 1" in pso
    assert "range = 30" in configs["geometric_RRTstar"]


def test_runs_round_trip(built) -> None:
    _, db = built
    cols = columns(db, "runs")
    for col in ("solution_length", "simplified_solution_length", "simplification_time"):
        assert col in cols
    sql = (
        "SELECT r.time, r.solved, r.status, r.solution_length, r.simplified_solution_length, "
        "r.simplification_time FROM runs r JOIN plannerConfigs p ON r.plannerid = p.id "
        "WHERE p.name = ? ORDER BY r.id"
    )
    pso = query(db, sql, "geometric_RRTstarPSO")
    assert pso == [
        (0.1 + 0.2, 1, 6, 1 / 3 + 700, 647.4512345678901, 0.012345678901234567),
        (1.0000000000000002, 0, 4, None, None, None),
        (2.5, 1, 5, 812.0, 700.25, None),
    ]
    rrt = query(db, sql, "geometric_RRTstar")
    assert rrt == [
        (0.75, 1, 6, 701.125, None, None),
        (1.5, 0, 4, None, None, None),
        (0.5, 1, 6, 1e-300, None, None),
    ]
    types = query(db, "SELECT typeof(time), typeof(status) FROM runs")
    assert set(types) == {("real", "integer")}


def test_enums(built) -> None:
    _, db = built
    rows = query(db, "SELECT value, description FROM enums WHERE name = 'status' ORDER BY value")
    assert rows == list(enumerate(STATUS_ENUM))


def test_progress(built) -> None:
    _, db = built
    assert "best_cost" in columns(db, "progress")
    rows = query(
        db,
        "SELECT p.name, g.time, g.best_cost FROM progress g JOIN runs r ON g.runid = r.id "
        "JOIN plannerConfigs p ON r.plannerid = p.id ORDER BY g.runid, g.time",
    )
    pso = [(t, c) for n, t, c in rows if n == "geometric_RRTstarPSO"]
    rrt = [(t, c) for n, t, c in rows if n == "geometric_RRTstar"]
    assert pso == [
        (0.05, 13.1),
        (0.1, 12.5),
        (0.05, None),
        (0.1, None),
        (0.05, 900.5),
        (0.1, 850.0),
        (0.15, 812.0),
    ]
    assert rrt == [(0.05, 750.0), (0.05, None), (0.05, 1e-300), (0.1, 1e-300 / 3)]


def test_in_process_parser(tmp_path) -> None:
    tools = pytest.importorskip("ompl.tools")
    log = write_log(make_experiment(), tmp_path / "a.log")
    db = tmp_path / "inproc.db"
    tools.readBenchmarkLog(str(db), [str(log)], False)
    assert query(db, "SELECT name, version FROM experiments") == [
        ("single_circle", f"rrtpso-ompl {__version__}")
    ]
    assert query(db, "SELECT count(*) FROM runs") == [(6,)]


def test_two_experiments(tmp_path) -> None:
    log_a = write_log(make_experiment("problem_a"), tmp_path / "a.log")
    log_b = write_log(make_experiment("problem_b", version="9.9"), tmp_path / "b.log")
    # both logs in one call
    db = build_database([log_a, log_b], tmp_path / "both.db")
    assert query(db, "SELECT name, version FROM experiments ORDER BY id") == [
        ("problem_a", f"rrtpso-ompl {__version__}"),
        ("problem_b", "rrtpso-ompl 9.9"),
    ]
    assert query(db, "SELECT count(*) FROM runs") == [(12,)]
    # the same planner configuration is shared between experiments
    assert query(db, "SELECT count(*) FROM plannerConfigs") == [(2,)]

    # appending, and replacing without append
    db2 = tmp_path / "append.db"
    build_database([log_a], db2)
    build_database([log_b], db2, append=True)
    assert query(db2, "SELECT name FROM experiments ORDER BY id") == [
        ("problem_a",),
        ("problem_b",),
    ]
    build_database([log_b], db2)
    assert query(db2, "SELECT name FROM experiments") == [("problem_b",)]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_build_database_failure(tmp_path) -> None:
    bad = tmp_path / "bad.log"
    bad.write_text("rrtpso-ompl version 1\nExperiment x\nnonsense\n")
    db = tmp_path / "keep.db"
    build_database([write_log(make_experiment(), tmp_path / "ok.log")], db)
    with pytest.raises(RuntimeError, match="converter failed"):
        build_database([bad], db, append=True)
    # the existing database is untouched, no temporary file is left behind
    assert query(db, "SELECT count(*) FROM experiments") == [(1,)]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    with pytest.raises(FileNotFoundError):
        build_database([tmp_path / "missing.log"], db)


def test_write_log_is_atomic_and_validates_first(tmp_path) -> None:
    path = write_log(make_experiment(), tmp_path / "sub" / "x.log")
    before = path.read_text()
    bad = make_experiment()
    bad.planners[0].name = "RRT star"
    with pytest.raises(ValueError):
        write_log(bad, path)
    assert path.read_text() == before
    assert [p.name for p in path.parent.iterdir()] == ["x.log"]


@pytest.mark.parametrize("name", ["RRT star", "RRT|star", "", "RRT\tstar"])
def test_bad_planner_name(name: str) -> None:
    exp = make_experiment()
    exp.planners[0].name = name
    with pytest.raises(ValueError, match="planner name"):
        format_log(exp)


def test_prefixed_planner_name_kept() -> None:
    exp = make_experiment()
    exp.planners[1].name = "control_KPIECE1"
    lines = format_log(exp).splitlines()
    assert "control_KPIECE1" in lines and "geometric_control_KPIECE1" not in lines


@pytest.mark.parametrize(
    "props",
    [
        [("time;x", "REAL")],
        [("a,b", "REAL")],
        [("time", "STRING")],
        [("time", "REAL"), ("time", "REAL")],
        [("plannerid", "INTEGER")],
        [("bad(name)", "REAL")],
    ],
)
def test_bad_run_properties(props) -> None:
    exp = make_experiment()
    exp.planners[1].run_properties = props
    exp.planners[1].runs = []
    exp.planners[1].progress = []
    with pytest.raises(ValueError):
        format_log(exp)


def test_bad_values() -> None:
    exp = make_experiment()
    exp.planners[1].runs = [{"time": "fast"}]
    with pytest.raises(ValueError, match="real number"):
        format_log(exp)
    exp.planners[1].runs = [{"undeclared": 1.0}]
    with pytest.raises(ValueError, match="not declared"):
        format_log(exp)
    exp = make_experiment()
    exp.planners[1].progress = [[(0.1, 2.0, 3.0)]]
    with pytest.raises(ValueError, match="values"):
        format_log(exp)
    with pytest.raises(ValueError, match="experiment name"):
        format_log(make_experiment("two words"))
    with pytest.raises(ValueError, match="clashes"):
        format_log(make_experiment(properties={"seed": 1}))


def test_value_formatting() -> None:
    exp = make_experiment()
    exp.planners[1].run_properties = [
        ("a", "REAL"),
        ("b", "REAL"),
        ("c", "REAL"),
        ("d", "INTEGER"),
        ("e", "BOOLEAN"),
        ("status", "ENUM"),
    ]
    exp.planners[1].runs = [
        {"a": float("nan"), "b": float("inf"), "c": -math.inf, "d": 7.0, "e": 0, "status": 9}
    ]
    exp.planners[1].progress = []
    text = format_log(exp)
    assert "nan; inf; ; 7; 0; 9; " in text.splitlines()


def test_experiment_property_types() -> None:
    exp = make_experiment(
        properties={
            "count": 5,
            "ratio": 0.25,
            "flag": True,
            "label": "hello",
            "obstacle-count": 3,
            "level": (2, "ENUM"),
        }
    )
    lines = format_log(exp).splitlines()
    start = lines.index("6 experiment properties")
    assert lines[start + 1 : start + 7] == [
        "count INTEGER = 5",
        "ratio REAL = 0.25",
        "flag BOOLEAN = 1",
        "label TEXT = hello",
        "obstacle-count INTEGER = 3",
        "level ENUM = 2",
    ]
    bads = [
        {"a;b": 1},
        {"x": "a = b"},
        {"x": "two\nlines"},
        {"name": "x"},
        {"x": None},
        {"x": ""},
        {"x": float("nan")},
        {"x": (1, "NOT A TYPE")},
    ]
    for bad in bads:
        with pytest.raises(ValueError):
            format_log(make_experiment(properties=bad))


def test_experiment_properties_in_db(tmp_path) -> None:
    props = {"obstacle-count": 3, "level": (2, "ENUM"), "robot radius": 28.5, "label": "a b"}
    exp = make_experiment(properties=props)
    db = build_database([write_log(exp, tmp_path / "p.log")], tmp_path / "p.db")
    rows = query(db, "SELECT obstacle_count, level, robotradius, label FROM experiments")
    assert rows == [(3, 2, 28.5, "a b")]


def test_defaults() -> None:
    exp = Experiment(name="x", planners=[], time_limit=1, run_count=0)
    lines = format_log(exp).splitlines()
    assert lines[0] == f"rrtpso-ompl version {__version__}"
    assert lines[2] == "0 experiment properties"
    assert lines[3].startswith("Running on ") and len(lines[3].split()) == 3
    assert lines[4].startswith("Starting at 2")
    assert lines[5:7] == ["<<<|", "|>>>"]
    assert lines[7] == "0 is the random seed"
    assert lines[-1] == "0 planners"


def test_status_code() -> None:
    assert len(STATUS_ENUM) == 10
    assert STATUS_ENUM[6] == "Exact solution" and STATUS_ENUM[4] == "Timeout"
    for code, text in enumerate(STATUS_ENUM):
        assert status_code(text) == code
        assert status_code(text.upper().replace(" ", "_")) == code
    assert status_code("exact") == 6
    assert status_code("approximate") == 5
    assert status_code("none") == 4
    assert status_code("EXACT_SOLUTION") == 6
    assert status_code("bogus") == 0
    assert status_code(7) == 7
    assert status_code(42) == 0
    assert status_code(None) == 0


def test_status_code_matches_ompl() -> None:
    ob = pytest.importorskip("ompl.base")
    ps = ob.PlannerStatus
    names = [
        "UNKNOWN",
        "INVALID_START",
        "INVALID_GOAL",
        "UNRECOGNIZED_GOAL_TYPE",
        "TIMEOUT",
        "APPROXIMATE_SOLUTION",
        "EXACT_SOLUTION",
        "CRASH",
        "ABORT",
        "INFEASIBLE",
    ]
    for code, name in enumerate(names):
        value = getattr(ps, name)
        assert value.value == code
        assert status_code(name) == code
        if code < 8:  # OMPL 2.0.1 calls ABORT and INFEASIBLE "Unknown status"
            assert status_code(ps(value)) == code
