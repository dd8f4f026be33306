"""Reading YAML safely: the C parser when present, positions in every message, no duplicate keys,
and bounded size and alias expansion.

Every YAML file the package reads (problems, maps) goes through :func:`read_yaml_file`, which
reports each way a file can be unreadable as one :class:`~rrtpso_ompl.errors.ProblemError` naming
the file (and the line and column where it knows them).

Caps, so that no input can make the reader run out of time or memory:

- a file holds at most :data:`MAX_FILE_BYTES` (64 MiB: about a million obstacles);
- lists and mappings nest at most :data:`MAX_DEPTH` levels deep;
- aliases may expand the document to at most :data:`MAX_EXPANDED_NODES` values (a "billion
  laughs" file of ten nested aliases would expand to 10**10); recursive aliases are refused;
- messages echo at most a few dozen characters of a value.

Only regular files are read (:func:`open_input`, also for map images): a fifo would block the
reader forever, a device such as ``/dev/zero`` never ends, and a directory cannot be read; each
is refused with a message that says what it is.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path
from typing import Any, BinaryIO

import yaml

from ..errors import ProblemError
from ..gc_pause import cyclic_gc_paused
from ..validation import short_repr

__all__ = [
    "MAX_EXPANDED_NODES",
    "MAX_FILE_BYTES",
    "file_kind",
    "load_yaml",
    "open_input",
    "read_yaml_file",
]

#: Largest YAML file read, bytes.
MAX_FILE_BYTES = 64 * 2**20
#: Largest number of values a document may expand to through its aliases.
MAX_EXPANDED_NODES = 5_000_000
#: Deepest nesting of lists and mappings (a problem needs four levels).
MAX_DEPTH = 100

#: libyaml's parser when PyYAML was built with it (tens of times faster on big files); the
#: constructor stays Python's, so values and messages are the same.
_BaseLoader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
#: Most plain scalars' tags one loader remembers (a bound on its memory).
_TAG_MEMORY = 4096


def file_kind(mode: int) -> str:
    """What a file of ``st_mode`` is, in words (``a fifo``, ``a directory``, ...)."""
    for test, kind in (
        (stat.S_ISREG, "a regular file"),
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a fifo (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "not a regular file"


def open_input(path: str | Path) -> BinaryIO:
    """Open an input file for reading, if it is a regular file.

    Opened without blocking, then checked: a fifo is refused without waiting for a writer, a
    device or a directory without reading it.

    Raises
    ------
    ValueError
        Saying why not, in words for a message after the file's name: ``no such file``, ``is a
        fifo (named pipe), not a regular file``, ``is a symbolic link loop``, ``its name holds a
        NUL byte``, ``cannot read it: Permission denied``.
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except ValueError:  # os.open's "embedded null byte"
        raise ValueError("its name holds a NUL byte") from None
    except FileNotFoundError:
        raise ValueError("no such file") from None
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ValueError("is a symbolic link loop") from None
        if exc.errno == errno.EISDIR:
            raise ValueError("is a directory, not a regular file") from None
        raise ValueError(f"cannot read it: {exc.strerror or exc}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise ValueError(f"is {file_kind(mode)}, not a regular file")
    if hasattr(os, "set_blocking"):
        os.set_blocking(fd, True)
    return os.fdopen(fd, "rb")


def read_yaml_file(path: str | Path) -> Any:
    """The parsed document of a YAML file (UTF-8); ProblemError for anything unreadable."""
    path = Path(path)
    source = str(path)
    try:
        with open_input(path) as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
    except ValueError as exc:
        raise ProblemError(source, "", str(exc)) from None
    except OSError as exc:
        raise ProblemError(source, "", f"cannot read the file: {exc.strerror or exc}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ProblemError(
            source, "", f"the file is larger than {MAX_FILE_BYTES // 2**20} MiB, the most read"
        )
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ProblemError(source, "", f"cannot read the file: not UTF-8 text ({exc})") from None
    try:
        return load_yaml(text)
    except yaml.YAMLError as exc:
        if "maximum nesting depth" in str(getattr(exc, "problem", "")):
            # libyaml (PyYAML >= 6.0.3 wheels) has a nesting limit of its own, met before ours.
            exc.problem = f"lists or mappings nested too deeply (more than {MAX_DEPTH} levels)"
        raise ProblemError(source, "", f"malformed YAML{_yaml_message(exc)}") from None
    except RecursionError:
        raise ProblemError(
            source, "", "malformed YAML: lists or mappings nested too deeply"
        ) from None


class _SafeLoader(_BaseLoader):
    """A safe loader whose value errors carry the line and column of the value.

    PyYAML's constructors raise plain ``ValueError``, ``KeyError`` and others for values such as
    ``2020-13-45`` or ``!!int abc``. Converting them here, where the node (and so its position in
    the file) is known, turns them into ordinary YAML errors with a location.
    """

    def __init__(self, stream: str) -> None:
        self._tags: dict[str, str] = {}
        super().__init__(stream)

    def resolve(self, kind: type, value: str, implicit: tuple[bool, bool]) -> str:
        """The tag of a node; a plain scalar's depends on its text alone (no path resolvers),
        and a large document repeats its keys and words thousands of times: remembered (up to
        :data:`_TAG_MEMORY` texts)."""
        if kind is not yaml.ScalarNode or not implicit[0] or self.yaml_path_resolvers:
            return super().resolve(kind, value, implicit)
        tag = self._tags.get(value)
        if tag is None:
            tag = super().resolve(kind, value, implicit)
            if len(self._tags) < _TAG_MEMORY:
                self._tags[value] = tag
        return tag

    def construct_object(self, node: yaml.Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep=deep)
        except (yaml.YAMLError, RecursionError):
            raise
        except Exception as exc:
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"cannot read the value {short_repr(node.value)}: {exc}",
                node.start_mark,
            ) from None


def load_yaml(text: str) -> Any:
    """``yaml.safe_load`` that also refuses duplicate keys and alias bombs.

    PyYAML silently keeps the last of two equal keys, so a second ``radius:`` would quietly win;
    the YAML spec requires keys to be unique. The checks run on the composed node graph, before
    construction, where merge keys (``<<``) are still distinguishable from written keys and shared
    (aliased) nodes are still shared.
    """
    loader = _SafeLoader(text)
    try:
        with cyclic_gc_paused():  # a large document's nodes all live until it is built
            node = loader.get_single_node()
            if node is None:
                return None
            if _refuse_duplicate_keys(node):  # only a document with aliases shares nodes
                _refuse_alias_bombs(node)
            return loader.construct_document(node)
    finally:
        loader.dispose()


def _refuse_duplicate_keys(root: yaml.Node) -> bool:
    """Refuse a mapping that writes a key twice, and nesting deeper than MAX_DEPTH; return
    whether any node is shared (aliased)."""
    # Iterative, and each collection once: aliases may share or even contain their own nodes.
    # Scalars are not stacked (most of a large document): a shared scalar cannot blow up.
    seen_nodes: set[int] = set()
    shared = False
    scalar = yaml.ScalarNode
    stack = [(root, 0)]
    while stack:
        node, depth = stack.pop()
        if id(node) in seen_nodes:
            shared = True
            continue
        seen_nodes.add(id(node))
        if depth > MAX_DEPTH:
            raise _too_deep(node)
        if isinstance(node, yaml.MappingNode):
            children = [n for pair in node.value for n in pair]
            first: dict[tuple[str, str], yaml.Node] = {}
            for key, _ in node.value:
                if isinstance(key, scalar) and key.tag != "tag:yaml.org,2002:merge":
                    other = first.setdefault((key.tag, key.value), key)
                    if other is not key:
                        raise yaml.constructor.ConstructorError(
                            None,
                            None,
                            f"duplicate key {short_repr(key.value)} "
                            f"(first written at line {other.start_mark.line + 1})",
                            key.start_mark,
                        )
        elif isinstance(node, yaml.SequenceNode):
            children = node.value
        else:
            continue
        if children and depth + 1 > MAX_DEPTH:
            raise _too_deep(children[-1])  # the child the stack would have met first
        stack.extend((c, depth + 1) for c in children if not isinstance(c, scalar))
    return shared


def _too_deep(node: yaml.Node) -> yaml.YAMLError:
    return yaml.constructor.ConstructorError(
        None, None, f"lists or mappings nested too deeply (more than {MAX_DEPTH} levels)",
        node.start_mark,
    )  # fmt: skip


def _yaml_message(exc: yaml.YAMLError) -> str:
    """`` at line L, column C: what`` (1-based, as editors count) from a PyYAML error."""
    mark = getattr(exc, "problem_mark", None)
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
    lines = str(exc).strip().splitlines()
    what = getattr(exc, "problem", None) or (lines[0] if lines else type(exc).__name__)
    return f"{where}: {what}"


def _refuse_alias_bombs(root: yaml.Node) -> None:
    """Refuse a document whose aliases expand to more than MAX_EXPANDED_NODES values, or refer
    to themselves (the expanded size is counted on the shared graph, each node once)."""
    size: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        children = _children(node)
        if done:
            on_path.discard(key)
            size[key] = 1 + sum(size[id(c)] for c in children)
            if size[key] > MAX_EXPANDED_NODES:
                raise yaml.constructor.ConstructorError(
                    None, None,
                    f"aliases expand the document to more than {MAX_EXPANDED_NODES:,} values",
                    node.start_mark,
                )  # fmt: skip
            continue
        if key in size:
            continue
        if key in on_path:
            raise yaml.constructor.ConstructorError(
                None, None, "a recursive alias (a value that contains itself)", node.start_mark
            )
        on_path.add(key)
        stack.append((node, True))
        stack.extend((c, False) for c in children if id(c) not in size)


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []
