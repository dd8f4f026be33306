"""outputs.atomic_files: files that belong together (a problem and its map) appear together, in
the order given, or not at all; nothing is left behind when a step fails."""

from __future__ import annotations

import pytest

from rrtpso_ompl import outputs
from rrtpso_ompl.errors import OutputError
from rrtpso_ompl.outputs import atomic_files


def test_the_files_appear_together_and_read_each_other_in_the_scratch_folder(tmp_path):
    folder = tmp_path / "new" / "deeper"
    data, index = folder / "data.txt", folder / "index.txt"
    with atomic_files([data, index]) as (tmp_data, tmp_index):
        assert tmp_data.parent == tmp_index.parent != folder  # one scratch folder beside them
        assert (tmp_data.name, tmp_index.name) == ("data.txt", "index.txt")
        tmp_data.write_text("42\n")
        tmp_index.write_text("data.txt\n")
        # A file names its sibling relatively: it is found where it is written.
        assert (tmp_index.parent / tmp_index.read_text().strip()).read_text() == "42\n"
        assert not data.exists() and not index.exists()  # nothing in place before the end
    assert data.read_text() == "42\n" and index.read_text() == "data.txt\n"
    assert sorted(p.name for p in folder.iterdir()) == ["data.txt", "index.txt"]


def test_a_failing_block_leaves_nothing_and_keeps_what_was_there(tmp_path):
    old = tmp_path / "a.txt"
    old.write_text("mine\n")
    with (
        pytest.raises(RuntimeError, match="drawing failed"),
        atomic_files([old, tmp_path / "b.txt"]) as (a, _),
    ):
        a.write_text("new\n")
        raise RuntimeError("drawing failed")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]
    assert old.read_text() == "mine\n"
    made = tmp_path / "x" / "y"
    with pytest.raises(RuntimeError), atomic_files([made / "c.txt"]) as (c,):
        c.write_text("c\n")
        raise RuntimeError("no")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]  # x/y removed again


def test_a_publish_that_fails_removes_the_files_already_published(tmp_path, monkeypatch):
    real = outputs.publish
    first, last = tmp_path / "out" / "map.pgm", tmp_path / "out" / "p.yaml"
    published = []

    def failing(tmp, target):
        if target == last:
            raise OSError(28, "No space left on device")
        real(tmp, target)
        published.append(target)

    monkeypatch.setattr(outputs, "publish", failing)
    with (
        pytest.raises(OutputError, match="No space left") as err,
        atomic_files([first, last]) as (a, b),
    ):
        a.write_bytes(b"P5")
        b.write_text("map: map.pgm\n")
    assert published == [first]  # in the order given: it was in place, then removed
    assert err.value.reason == "No space left on device" and err.value.path == str(last)
    assert list(tmp_path.iterdir()) == []


def test_files_in_two_folders_are_refused(tmp_path):
    with (
        pytest.raises(ValueError, match="one folder"),
        atomic_files([tmp_path / "a.txt", tmp_path / "sub" / "b.txt"]),
    ):
        pass
    assert list(tmp_path.iterdir()) == []
