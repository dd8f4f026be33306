"""``rrtpso generate``: a seeded random problem file, certified solvable.

The kinds and their option flags are derived from the generator's declarations
(:data:`~rrtpso_ompl.groundtruth.generate.GENERATORS`): one flag per option, its help from the
option's doc, its type and range from its declaration, a range option as two numbers.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import Any

from ..errors import GenerationError, UsageError
from ..outputs import is_stream
from .common import EXIT_OK, Output, check_outputs, check_seed_flag, note

__all__ = ["HELP", "add_parser", "run"]

#: The line of ``rrtpso --help``. It does not list the kinds: they are known once the generators
#: are imported, which ``rrtpso --help`` does not do (``rrtpso generate --help`` lists them).
HELP = "write a seeded random problem, certified solvable (kinds: rrtpso generate --help)"


def add_parser(sub: Any, parents: list[argparse.ArgumentParser]) -> None:
    from ..groundtruth.generate import GENERATORS

    kinds = list(GENERATORS)
    g = sub.add_parser(
        "generate",
        parents=parents,
        help=HELP,
        description="Write a seeded random problem file whose start and goal are free and "
        "connected (certified by a collision-checked grid path). The same seed and options give "
        "the same file, byte for byte. Each option applies to the kinds named in its help.",
    )
    g.add_argument("kind", choices=kinds)
    g.add_argument("--seed", type=int, required=True, help="seed (>= 0)")
    g.add_argument("--out", required=True, metavar="FILE.yaml", help="where to write the problem")
    for name, declarations in _options().items():
        g.add_argument(f"--{name.replace('_', '-')}", dest=name, **_flag(declarations))
    g.add_argument("--overwrite", action="store_true",
                   help="replace --out when it exists (it is refused otherwise)")  # fmt: skip
    g.set_defaults(func=run)


def _options() -> dict[str, list[tuple[str, Any]]]:
    """Every option of every kind: name -> ``[(kind, ParamSpec), ...]``, in declaration order."""
    from ..groundtruth.generate import GENERATORS

    out: dict[str, list[tuple[str, Any]]] = {}
    for kind, options in GENERATORS.items():
        for spec in options.PARAMS:
            out.setdefault(spec.name, []).append((kind, spec))
    return out


def _flag(declarations: list[tuple[str, Any]]) -> dict[str, Any]:
    """``add_argument`` keywords of one option, from its declarations (one per kind)."""
    from ..groundtruth.generate import GENERATORS

    spec = declarations[0][1]
    kw: dict[str, Any] = {"default": None}
    if spec.type is bool:
        kw["action"] = argparse.BooleanOptionalAction
    else:
        kw["type"] = spec.type
    if spec.choices is not None:
        kw["choices"] = spec.choices
    if spec.length is not None:
        kw["nargs"] = spec.length
        kw["metavar"] = ("MIN", "MAX") if spec.length == 2 else spec.name.upper()
    texts = {}
    for kind, s in declarations:
        default = "" if s.default is None else f" Default: {_value(s.default)}."
        texts.setdefault(f"{s.doc}{default}", []).append(kind)
    if len(texts) == 1:
        (text, kinds), = texts.items()  # fmt: skip
        help_ = text if len(kinds) == len(GENERATORS) else f"{', '.join(kinds)}: {text}"
    else:
        help_ = " ".join(f"{', '.join(kinds)}: {text}" for text, kinds in texts.items())
    kw["help"] = help_.replace("%", "%%")
    return kw


def _value(value: Any) -> str:
    return " ".join(map(str, value)) if isinstance(value, tuple) else str(value)


#: Bytes of an existing output read to tell what it is.
_HEAD_BYTES = 4096
#: How files that no problem or map is begin, and what they are.
_MAGIC = ((b"SQLite format 3\0", "an SQLite database"), (b"\x89PNG", "a PNG image"),
          (b"%PDF", "a PDF document"), (b"PK\x03\x04", "a ZIP archive"))  # fmt: skip


def _check_replaceable(path: Path) -> None:
    """``--overwrite`` replaces what ``generate`` could have written, a problem or map YAML file
    (text) or a map image, and any other text: a file that is recognisably something else (an
    SQLite database such as a bench's, a PNG image, a PDF, a ZIP archive; binary data where a
    YAML file goes) is refused, unread beyond its first :data:`_HEAD_BYTES` (a fifo is never
    opened)."""
    from ..model.yamlfile import open_input

    try:
        with open_input(path) as fh:
            head = fh.read(_HEAD_BYTES)
    except (OSError, ValueError):
        return  # not a regular file, or unreadable: the output checks said what they could
    what = next((w for magic, w in _MAGIC if head.startswith(magic)), None)
    if what is None and path.suffix.lower() != ".pgm" and not _is_text(head):
        what = "binary data"  # a map image is binary; a problem or map YAML file is text
    if what is None:
        return
    raise UsageError(f"--out: '{path}' is {what}, not a problem or map file generate writes; "
                     "--overwrite does not replace it: choose another file")  # fmt: skip


def _is_text(head: bytes) -> bool:
    """Whether the beginning of a file is UTF-8 text (a character cut at the end allowed)."""
    if b"\0" in head:
        return False
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        return exc.start >= len(head) - 3 and len(head) == _HEAD_BYTES
    return True


def run(args: argparse.Namespace) -> int:
    from ..groundtruth import generate_to_file
    from ..groundtruth.generate import GENERATORS

    check_seed_flag(args.seed)
    options = {k: getattr(args, k) for k in _options() if getattr(args, k) is not None}
    # A map kind writes the map beside the problem (<stem>_map.yaml and .pgm): each is checked.
    kind = GENERATORS[args.kind]
    try:
        kind.check_places(args.out)
    except GenerationError as exc:
        raise UsageError(f"--out: {exc}") from None
    paths = kind.output_paths(args.out) if args.out != "-" else [args.out]
    check_outputs([Output("--out", str(p)) for p in paths])
    for p in paths:
        if not os.path.lexists(p) or is_stream(p):
            continue
        if not args.overwrite:
            raise UsageError(f"--out: '{p}' exists; pass --overwrite to replace it")
        _check_replaceable(p)
    try:
        path = generate_to_file(args.kind, args.seed, args.out, **options)
    except (GenerationError, ValueError) as exc:
        where = f"generate {args.kind}:"
        text = str(exc)
        raise UsageError(text if text.startswith(where) else f"{where} {text}") from None
    # A map kind's map files are written too, beside the problem: say so (and where).
    maps = [str(p) for p in paths[1:]]
    note(f"wrote {path}" + (f" and its map, {' and '.join(maps)}" if maps else ""))
    return EXIT_OK
