"""The measured figures in the docs are the benchmark's own output, not numbers typed by hand."""

from __future__ import annotations

import pytest
from helpers import REPO as ROOT

from rrtpso_ompl.harness.bench import overview_markdown, read_report_csv

DOCS = ROOT / "docs"


def _overview() -> list[str]:
    return overview_markdown(read_report_csv(DOCS / "bench" / "report.csv")).splitlines()


def test_committed_report_opens_with_the_overview_of_its_csv():
    assert "\n".join(_overview()) in (DOCS / "bench" / "report.md").read_text()


def test_benchmarking_guide_quotes_the_overview_verbatim():
    guide = {line.strip() for line in (DOCS / "benchmarking.md").read_text().splitlines()}
    quoted = [line for line in _overview() if line.startswith(("|", "- "))]
    assert len(quoted) > 20  # both tables and the list of cells
    missing = [line for line in quoted if line not in guide]
    assert not missing, f"docs/benchmarking.md differs from docs/bench/report.csv: {missing}"


def test_readme_table_is_the_overview_table():
    overview = _overview()
    first = overview.index(next(line for line in overview if line.startswith("| planner")))
    table = overview[first : overview.index("", first)]
    assert "\n".join(table) in (ROOT / "README.md").read_text()


def test_dynamic_guide_quotes_the_dynamic_benchmark():
    """docs/dynamic.md repeats the target table of docs/dynamic-benchmark.md (written by
    benchmarks/dynamic.py): contour against global per family and named scenario, verbatim."""
    generated = (DOCS / "dynamic-benchmark.md").read_text().splitlines()
    first = generated.index(next(line for line in generated if line.startswith("| cases | n |")))
    table = generated[first : generated.index("", first)]
    assert len(table) >= 2 + 3 + 7  # header, rule, three families, the named scenarios
    assert "\n".join(table) in (DOCS / "dynamic.md").read_text()


def test_benchmarking_guide_quotes_the_family_report_verbatim():
    """docs/benchmarking.md repeats every per-family table of docs/families.md (written by
    benchmarks/families.py), and the report's rows are the runs it summarises."""
    import json

    report = (DOCS / "families.md").read_text()
    guide = (DOCS / "benchmarking.md").read_text()
    tables = [block for block in report.split("\n\n") if block.startswith("| family |")]
    assert len(tables) == 3  # 0.25, 1 and 4 s
    for table in tables:
        assert table in guide
    rows = [json.loads(line) for line in (DOCS / "families.jsonl").read_text().splitlines()]
    assert {r["budget"] for r in rows} == {0.25, 1.0, 4.0}
    assert not [r for r in rows if r["solved"] and not r["valid"]]


def test_benchmarking_guide_quotes_the_inflation_report_verbatim():
    """docs/benchmarking.md repeats the 1 s tables of docs/inflation.md (written by
    benchmarks/inflation.py); every path of its runs was valid and none failed."""
    import json

    report = (DOCS / "inflation.md").read_text()
    guide = (DOCS / "benchmarking.md").read_text()
    one_second = report[report.index("## 1 s") : report.index("## 4 s")]
    tables = [b for b in one_second.split("\n\n") if b.startswith("| family |")]
    assert len(tables) == 2
    for table in tables:
        assert table in guide
    rows = [json.loads(line) for line in (DOCS / "inflation.jsonl").read_text().splitlines()]
    assert {r["budget"] for r in rows} == {0.25, 1.0, 4.0}
    assert not [r for r in rows if r.get("solved") and not r.get("valid")]
    assert not [r for r in rows if r.get("error")]


def test_the_published_json_schema_is_the_declared_format_and_accepts_the_library():
    import json

    import jsonschema
    import yaml

    from rrtpso_ompl.model.format import schema_text

    text = (DOCS / "problem.schema.json").read_text()
    assert text == schema_text(), "regenerate with python benchmarks/problem_schema.py"
    schema = json.loads(text)
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    files = sorted((ROOT / "problems").glob("*/*.yaml"))
    assert files
    for path in files:
        errors = [e.message for e in validator.iter_errors(yaml.safe_load(path.read_text()))]
        assert not errors, (path.name, errors[:2])
    # and refuses what the loader refuses for the same reasons
    bad = {"bounds": [[0, 0], [10, 10]], "start": [1, 1], "goal": [2, 2],
           "robot": {"radius": -1}, "colour": "red"}  # fmt: skip
    messages = " ".join(e.message for e in validator.iter_errors(bad))
    assert "colour" in messages and "-1" in messages


def test_the_readme_python_snippet_prints_only_its_result():
    """The README's Python example, run as a user would (a fresh process in the checkout): its
    one print is all that appears; OMPL's Info and Debug lines stay quiet unless asked for."""
    import re
    import subprocess
    import sys

    readme = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", readme, flags=re.S)
    assert len(blocks) == 1
    proc = subprocess.run([sys.executable, "-c", blocks[0]], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert re.fullmatch(r"\d+\.\d+\n", proc.stdout), proc.stdout[:500]
    assert proc.stderr == "", proc.stderr[:500]
    assert 600 < float(proc.stdout) < 700  # paper_static's optimum is 620.72


def test_ompl_messages_come_back_when_asked_for():
    import subprocess
    import sys

    code = ("from rrtpso_ompl.ompl_setup import set_ompl_log_level\n"
            "from ompl import util as ou\n"
            "assert ou.getLogLevel() == ou.LOG_WARN\n"
            "set_ompl_log_level(1)\n"
            "assert ou.getLogLevel() == ou.LOG_INFO\n")  # fmt: skip
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)  # fmt: skip
    assert proc.returncode == 0, proc.stderr


def test_the_turned_maps_report_finds_the_unturned_optimum_on_every_turned_map():
    """docs/turned-maps.md (benchmarks/turned_maps.py): each map problem's exact optimum turned
    by 0.3 rad, with unknown space blocked and free, is the unturned one's to the printed digits;
    and its own figures are quoted in problem-format.md only through the link."""
    lines = (DOCS / "turned-maps.md").read_text().splitlines()
    first = lines.index(next(line for line in lines if line.startswith("## Exact optimum")))
    table = lines[first + 2 : lines.index("", first + 2)]
    assert len(table) == 2 + 6  # header, rule, the six map problems
    for row in table[2:]:
        cells = [c.strip().split(" ")[0] for c in row.strip("|").split("|")[1:]]
        assert cells[0] == cells[1] and cells[2] == cells[3], row
    assert "(turned-maps.md)" in (DOCS / "problem-format.md").read_text()


@pytest.mark.parametrize("name", ["real-maps", "real-maps-fresh"])
def test_benchmarking_guide_quotes_the_real_map_reports_verbatim(name):
    """docs/benchmarking.md repeats the pooled tables of docs/real-maps*.md (written by
    benchmarks/real_maps.py, issue 37); every path of their runs was valid and none failed."""
    import json

    report = (DOCS / f"{name}.md").read_text()
    guide = (DOCS / "benchmarking.md").read_text()
    tables = [b for b in report.split("\n\n") if b.startswith("| planner |")]
    assert len(tables) == 2  # 1 s and 0.1 s
    for table in tables:
        assert table in guide
    rows = [json.loads(line) for line in (DOCS / f"{name}.jsonl").read_text().splitlines()]
    assert {r["budget"] for r in rows} == {1.0, 0.1}
    assert not [r for r in rows if r["solved"] and not r["valid"]]
    assert not [r for r in rows if r.get("error")]
