"""Reading YAML safely: malformed, binary, missing and directory files, alias bombs."""

from __future__ import annotations

import pytest

from rrtpso_ompl.model.problem import ProblemError, load_problem

MALFORMED = [
    (
        "unclosed-bracket",
        "bounds: [[0, 0], [1, 1]\nstart: [0, 0]\n",
        "malformed YAML at line 2, column 1",
    ),
    ("bad-indent", "robot:\n  radius: 1\n   speed: 2\n", "malformed YAML at line 3, column 9"),
    ("tab", "robot:\n\tradius: 1\n", "malformed YAML at line 2, column 1"),
    (
        "bad-date",
        "name: x\nunits: 2020-13-45\n",
        "at line 2, column 8: cannot read the value '2020-13-45'",
    ),
    (
        "bad-int-tag",
        "goal_tolerance: !!int abc\n",
        "at line 1, column 17: cannot read the value 'abc'",
    ),
    ("python-tag", "start: !!python/tuple [1, 2]\n", "malformed YAML at line 1, column 8"),
    ("two-documents", "a: 1\n---\nb: 2\n", "malformed YAML at line 2, column 1"),
    (
        "duplicate-key",
        "robot:\n  radius: 1\n  radius: 2\n",
        "line 3, column 3: duplicate key 'radius' (first",
    ),
    ("too-deep", "start: " + "[" * 3000 + "]" * 3000 + "\n", "nested too deeply"),
    ("control-character", "name: \x07\n", "malformed YAML"),
    ("empty", "", "the file is empty"),
    ("only-comment", "# nothing here\n", "the file is empty"),
    ("list", "- just\n- a list\n", "the file must be a mapping"),
    ("scalar", "42\n", "the file must be a mapping"),
]


@pytest.mark.parametrize("text,fragment", [m[1:] for m in MALFORMED], ids=[m[0] for m in MALFORMED])
def test_malformed_files(tmp_path, text, fragment):
    path = tmp_path / "m.yaml"
    path.write_text(text)
    with pytest.raises(ProblemError) as info:
        load_problem(path)
    assert str(info.value).startswith(f"{path}: ") and info.value.key == ""
    assert fragment in str(info.value)


def test_missing_binary_and_directory_files(tmp_path):
    with pytest.raises(ProblemError, match="no such file"):
        load_problem(tmp_path / "absent.yaml")
    blob = tmp_path / "blob.yaml"
    blob.write_bytes(b"\xff\xfe\x00\x01")
    with pytest.raises(ProblemError, match="cannot read"):
        load_problem(blob)
    with pytest.raises(ProblemError, match="is a directory, not a regular file"):
        load_problem(tmp_path)


def test_billion_laughs_is_cheap(tmp_path):
    """Aliases to aliases build a huge structure by reference; the message stays short."""
    lines = ["a0: &a0 [1, 1, 1, 1, 1, 1, 1, 1, 1]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    text = "\n".join(lines).replace("a0:", "start:", 1) + "\n"
    path = tmp_path / "laughs.yaml"
    path.write_text(text)
    with pytest.raises(ProblemError) as info:
        load_problem(path)
    assert len(str(info.value)) < 400
