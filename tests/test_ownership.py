"""Recognising the files of this program that no other output replaces, and publishing that
never replaces them (issue 32, item 4): real files, real locks (a results file held open by
:class:`ResultsFile`, the way a running batch holds it)."""

from __future__ import annotations

import json
import os
import socket

import pytest

from rrtpso_ompl.errors import OutputError, UsageError
from rrtpso_ompl.harness.record import RunRecord
from rrtpso_ompl.harness.results_file import ResultsFile
from rrtpso_ompl.outputs import link_new, write_json_atomic, write_text_atomic
from rrtpso_ompl.ownership import (
    ABSENT,
    BENCH_LOG_MARK,
    HEAD_BYTES,
    describe,
    inspected,
    is_bench_log,
)


def _row(seed: int = 1, **kw) -> RunRecord:
    return RunRecord(file="p.yaml", planner="RRTConnect", seed=seed, run=seed - 1,
                     status="error", error="x", **kw)  # fmt: skip


def _results(path, n: int = 2):
    with ResultsFile(path) as results:
        for seed in range(1, n + 1):
            results.append(_row(seed))
    return path


def test_a_results_file_is_recognised_and_counted(tmp_path):
    owned = describe(_results(tmp_path / "res.jsonl", 3))
    assert owned.kind == "results"
    assert "a results file of rrtpso batch or bench (3 rows)" in owned.what
    # A torn last line is a row too (a batch killed mid-write), and so is one longer than what is
    # read of a first line: judged by how a row begins.
    torn = tmp_path / "torn.jsonl"
    torn.write_bytes(b'{"file": "p.yaml", "plan')
    assert describe(torn).kind == "results"
    long = tmp_path / "long.jsonl"
    path = [[float(i), 0.0] for i in range(HEAD_BYTES // 8)]
    long.write_text(json.dumps(_row(path=path).to_json()) + "\n")
    assert long.stat().st_size > HEAD_BYTES
    assert describe(long).kind == "results"


@pytest.mark.parametrize(
    "content",
    [b"", b"notes\n", b'{\n  "problem": "p",\n  "status": "exact"\n}\n', b'{"keep": 1}\n',
     b"\x89PNG\r\n\x1a\n\0\0", b"\n\n"],
    ids=["empty", "text", "solve-json", "other-json", "binary", "blank-lines"],
)  # fmt: skip
def test_other_files_are_not_ours(tmp_path, content):
    p = tmp_path / "f"
    p.write_bytes(content)
    assert describe(p) is None
    assert describe(tmp_path / "missing") is None
    assert describe(tmp_path) is None


def test_a_fifo_and_a_socket_are_never_read(tmp_path):
    """Opening a fifo to read it would wait for a writer: it is looked at without reading."""
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    assert describe(fifo) is None  # returns at once: nobody writes the fifo
    sock = socket.socket(socket.AF_UNIX)
    try:
        sock.bind(str(tmp_path / "s"))
        assert describe(tmp_path / "s") is None
    finally:
        sock.close()


def test_a_file_a_batch_holds_is_locked_even_before_its_first_row(tmp_path):
    out = tmp_path / "res.jsonl"
    with ResultsFile(out) as results:  # a batch that has started: the file is empty and locked
        assert out.stat().st_size == 0
        owned = describe(out)
        assert owned.kind == "locked" and "locked by another process" in owned.what
        results.append(_row())
        assert "1 row so far" in describe(out).what
        results.append(_row(2))  # looking took nothing from the batch
    assert describe(out).kind == "results"  # finished: rows, no lock
    assert len(out.read_text().splitlines()) == 2


def test_publishing_never_replaces_a_results_file(tmp_path):
    """The last look, just before the rename: a running batch's file (locked), a finished one,
    each is left as it was, with nothing left behind."""
    out = tmp_path / "res.jsonl"
    with ResultsFile(out) as results:
        results.append(_row())
        inode = out.stat().st_ino
        locked = r"res\.jsonl: cannot write: it is a results file locked"
        with pytest.raises(OutputError, match=locked):
            write_json_atomic({"a": 1}, out)
        results.append(_row(2))  # the batch goes on writing the file at its name
    assert out.stat().st_ino == inode and len(out.read_text().splitlines()) == 2
    before = out.read_bytes()
    finished = r"it is a results file of rrtpso batch or bench \(2 rows\)"
    with pytest.raises(OutputError, match=finished):
        write_text_atomic("x", out)
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res.jsonl"]  # no temporary file left


def test_publishing_replaces_other_files_and_makes_new_ones(tmp_path):
    plain = tmp_path / "plain.json"
    plain.write_text("old")
    os.chmod(plain, 0o640)
    write_json_atomic({"a": 1}, plain)
    assert json.loads(plain.read_text()) == {"a": 1}
    assert plain.stat().st_mode & 0o777 == 0o640  # it keeps its permissions
    new = tmp_path / "new.json"
    write_json_atomic({"b": 2}, new)
    assert json.loads(new.read_text()) == {"b": 2}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.json", "plain.json"]


def test_a_new_file_is_never_put_over_one_made_meanwhile(tmp_path):
    """Where nothing was, the result is linked into place: a file made in between (a batch's new
    results file) is not renamed over; publish looks again."""
    tmp, target = tmp_path / "tmp", tmp_path / "res.jsonl"
    tmp.write_text("ours")
    target.write_text("made meanwhile")
    assert link_new(tmp, target) is False
    assert target.read_text() == "made meanwhile" and tmp.exists()
    target.unlink()
    assert link_new(tmp, target) is True
    assert target.read_text() == "ours" and not tmp.exists()


def test_a_batch_cannot_take_a_file_while_it_is_being_published_over(tmp_path):
    """Publishing holds a shared lock across its last look and the rename: a batch starting on
    the file in between is refused (and loses nothing: it never had the file)."""
    out = tmp_path / "r.jsonl"
    out.write_text("an earlier output\n")
    with inspected(out) as found:
        assert found is None  # not ours: it may be replaced
        with pytest.raises(UsageError, match="another rrtpso batch or bench is writing"),\
                ResultsFile(out, overwrite=True):  # fmt: skip
            pass
    with inspected(tmp_path / "none") as found:
        assert found == ABSENT


def test_a_bench_folder_is_recognised_by_its_files(tmp_path):
    bench = tmp_path / "b"
    bench.mkdir()
    runs = _results(bench / "runs.jsonl")
    assert describe(runs).kind == "results"  # alone, it may be any batch's results file
    (bench / "report.md").write_text("# Benchmark report\n")
    (bench / "benchmark.db").write_bytes(b"SQLite format 3\0")
    log = bench / "p_1s.log"
    log.write_text(f"rrtpso-ompl version 0.1.0\n...\n{BENCH_LOG_MARK}\n")
    assert is_bench_log(log)
    for name, what in [("runs.jsonl", "the results file of the rrtpso bench in"),
                       ("report.md", "the report.md of the rrtpso bench in"),
                       ("benchmark.db", "the benchmark.db of the rrtpso bench in"),
                       ("p_1s.log", "an OMPL benchmark log written by rrtpso bench")]:  # fmt: skip
        owned = describe(bench / name)
        assert owned.kind == "bench" and what in owned.what, name
    assert str(bench) in describe(bench / "report.md").what
    # Through a link, the folder named is the bench's.
    (tmp_path / "link.md").symlink_to(bench / "report.md")
    assert f"in '{bench}'" in describe(tmp_path / "link.md").what
    # Without the results file, the names alone are nobody's.
    runs.unlink()
    assert describe(bench / "report.md") is None and describe(bench / "benchmark.db") is None
    other = tmp_path / "notes.log"
    other.write_text("a log of something else\n")
    assert not is_bench_log(other) and describe(other) is None
