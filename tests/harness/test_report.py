"""Markdown tables: one helper for the bench report and every benchmark script."""

from __future__ import annotations

import pytest

from rrtpso_ompl.harness.report import markdown_table, write_markdown


def test_a_table_is_header_rule_and_rows():
    text = markdown_table(["planner", "0.5 s", "1 s"], [["RRT", 1.5, "+2 %"], ["PSO", "", 3]],
                          align="-rc")  # fmt: skip
    assert text.splitlines() == [
        "| planner | 0.5 s | 1 s |",
        "|---|---:|:---:|",
        "| RRT | 1.5 | +2 % |",
        "| PSO |  | 3 |",
    ]
    assert markdown_table(["a"], [], align="l") == "| a |\n|:---|"


def test_a_cell_cannot_break_the_table():
    text = markdown_table(["file", "error"], [["a|b.yaml", "line one\nline two"]])
    assert text.splitlines()[2] == r"| a\|b.yaml | line one line two |"


@pytest.mark.parametrize(
    ("rows", "align", "message"),
    [([["x"]], None, "row 0 has 1 cells, the header 2"), ([], "r", "align must be 2 characters"),
     ([], "rx", "align must be 2 characters")],
)  # fmt: skip
def test_a_ragged_table_is_refused(rows, align, message):
    with pytest.raises(ValueError, match=message):
        markdown_table(["a", "b"], rows, align=align)


def test_a_report_is_written_and_printed_or_only_printed(tmp_path, capsys):
    out = tmp_path / "r.md"
    write_markdown(["# Title", "| a |"], out)
    assert out.read_text() == "# Title\n| a |\n"
    assert capsys.readouterr().out == "# Title\n| a |\n\n"  # print() adds its own newline
    write_markdown(["only printed"], "-")
    assert capsys.readouterr().out == "only printed\n\n" and not (tmp_path / "-").exists()
