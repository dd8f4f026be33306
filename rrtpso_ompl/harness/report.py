"""Markdown for reports: one way to write a table, for the bench report and every benchmark script.

The benchmark scripts of ``benchmarks/`` write their measurements into ``docs/`` as markdown, and
``rrtpso bench`` writes ``report.md``; all of their tables come from :func:`markdown_table`, so
a table is escaped and aligned the same way everywhere.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["markdown_table", "write_markdown"]

#: The rule under a column's header for each alignment character of :func:`markdown_table`.
_RULES = {"-": "---", "l": ":---", "r": "---:", "c": ":---:"}


def markdown_table(
    header: Sequence[object],
    rows: Iterable[Sequence[object]],
    align: str | None = None,
) -> str:
    """A GitHub-flavoured markdown table, one line per row, without a final newline.

    Parameters
    ----------
    header : sequence
        The column titles.
    rows : iterable of sequences
        The cells of each row, as many as ``header`` has. A cell is written as ``str(cell)``
        (format numbers before); a ``|`` in it is escaped and a line break becomes a space, so
        no cell breaks the table. An empty cell is written as two spaces between its bars.
    align : str, optional
        One character per column: ``"-"`` no alignment (``---``), ``"l"`` left (``:---``),
        ``"r"`` right (``---:``), ``"c"`` centred (``:---:``). Default: none for every column.

    Returns
    -------
    str
        ``| a | b |``, then ``|---|---:|``, then the rows.

    Raises
    ------
    ValueError
        When a row or ``align`` has another number of columns than ``header``, or ``align``
        holds another character.

    Examples
    --------
    >>> print(markdown_table(["planner", "length"], [["RRT", "650.2"]], align="-r"))
    | planner | length |
    |---|---:|
    | RRT | 650.2 |
    """
    n = len(header)
    align = "-" * n if align is None else align
    if len(align) != n or not set(align) <= set(_RULES):
        raise ValueError(f"align must be {n} characters of {''.join(_RULES)}, got {align!r}")
    lines = [_line(header), "|" + "".join(_RULES[a] + "|" for a in align)]
    for k, row in enumerate(rows):
        if len(row) != n:
            raise ValueError(f"row {k} has {len(row)} cells, the header {n}")
        lines.append(_line(row))
    return "\n".join(lines)


def _line(cells: Sequence[object]) -> str:
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


def _cell(value: object) -> str:
    text = str(value)
    return text.replace("|", r"\|").replace("\r\n", " ").replace("\n", " ").replace("\r", " ")


def write_markdown(lines: Iterable[str], out: str | Path) -> None:
    """Join ``lines`` into one markdown document (ending in a newline), write it to ``out``
    unless ``out`` is ``"-"``, and print it: how a benchmark script publishes its report."""
    text = "\n".join(lines) + "\n"
    if str(out) != "-":
        Path(out).write_text(text)
    print(text)
