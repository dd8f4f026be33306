"""The files of a generated map: the problem, the map YAML and its PGM image, written together.

:class:`GeneratedMap` holds a map kind's result (:mod:`.map_problem`): the problem dictionary, the
blocked cells and the ROS map_server YAML keys (:mod:`rrtpso_ompl.model.occupancy`: an 8-bit PGM,
free 254, occupied 0). :meth:`GeneratedMap.write` writes the problem file with
``<stem>_map.yaml`` and ``<stem>_map.pgm`` beside it, all or nothing, through
:func:`rrtpso_ompl.outputs.atomic_files`: the three files are written in a temporary folder beside
them, the problem read back from there (map included), then published into place; when anything
fails nothing is left behind.
"""

from __future__ import annotations

import dataclasses
import os
import stat
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import GenerationError, OutputError
from ..model.problem_file import write_problem
from ..outputs import atomic_files

__all__ = ["FREE_GREY", "OCCUPIED_GREY", "GeneratedMap", "check_map_place", "map_output_paths"]

#: Grey values of the image (ROS map_saver's).
FREE_GREY, OCCUPIED_GREY = 254, 0


# ----------------------------------------------------------------------------------------------
# What a map kind generates
# ----------------------------------------------------------------------------------------------
@dataclasses.dataclass(frozen=True, eq=False)
class GeneratedMap:
    """A generated map and the problem on it.

    Attributes
    ----------
    problem : dict
        The problem dictionary (file format); its ``map`` is ``map_file`` (relative).
    blocked : ndarray of bool, shape (cells, cells)
        Blocked cells in image order (row 0 on top).
    map_yaml : dict
        The map_server YAML keys (``image`` is ``image_file``).
    map_file, image_file : str
        The names the problem and the map YAML give them.
    header : str
        Comment lines for the top of the problem and map files (the command that regenerates
        them).
    decimals : int
        Decimal places of the problem's coordinates.
    """

    problem: dict[str, Any]
    blocked: np.ndarray
    map_yaml: dict[str, Any]
    map_file: str
    image_file: str
    header: str = ""
    decimals: int = 3

    @property
    def image(self) -> np.ndarray:
        """(cells, cells) uint8 grey image: free 254, occupied 0."""
        return np.where(self.blocked, OCCUPIED_GREY, FREE_GREY).astype(np.uint8)

    def pgm_bytes(self) -> bytes:
        """The image as an 8-bit binary PGM (P5)."""
        h, w = self.blocked.shape
        return f"P5\n{w} {h}\n255\n".encode("ascii") + self.image.tobytes()

    def yaml_text(self) -> str:
        """The map YAML file's text."""
        m = self.map_yaml
        lines = [f"# {line}".rstrip() for line in self.header.splitlines()]
        lines += [
            f"image: {m['image']}",
            f"resolution: {m['resolution']!r}",
            f"origin: [{m['origin'][0]!r}, {m['origin'][1]!r}, {m['origin'][2]!r}]",
            f"negate: {m['negate']}",
            f"occupied_thresh: {m['occupied_thresh']}",
            f"free_thresh: {m['free_thresh']}",
            f"mode: {m['mode']}",
        ]
        return "\n".join(lines) + "\n"

    def renamed(self, stem: str) -> GeneratedMap:
        """The same, the map files named ``<stem>_map.yaml`` and ``<stem>_map.pgm``."""
        map_file, image_file = f"{stem}_map.yaml", f"{stem}_map.pgm"
        return dataclasses.replace(
            self,
            problem={**self.problem, "map": map_file},
            map_yaml={**self.map_yaml, "image": image_file},
            map_file=map_file,
            image_file=image_file,
        )

    def write(self, out: str | Path) -> Path:
        """Write the problem to ``out`` and the map beside it (``<out stem>_map.yaml`` and
        ``.pgm``), all or nothing.

        Existing regular files are replaced; a path that is ``-``, a symbolic link, a fifo or
        anything but a regular file is refused before anything is written
        (:class:`GenerationError`). The three files are written in a temporary folder beside
        ``out``, the problem validated by reading it back (the map with it), then renamed into
        place (:func:`~rrtpso_ompl.outputs.atomic_files`); when a step fails the files already
        moved are removed, and so is the folder.

        Returns
        -------
        Path
            ``out``.
        """
        out = Path(out)
        named = self.renamed(out.stem if out.suffix else out.name)
        paths = map_output_paths(out)
        for p in paths:
            check_map_place(p)
        try:
            # The image, the map YAML, then the problem naming them: published in that order.
            with atomic_files(paths[::-1]) as (image, map_yaml, problem):
                image.write_bytes(named.pgm_bytes())
                map_yaml.write_text(named.yaml_text(), encoding="utf-8")
                # write_problem reads the problem back, the map from beside it: the files are
                # valid.
                write_problem(named.problem, problem, header=named.header,
                              decimals=named.decimals)  # fmt: skip
        except OutputError as exc:
            raise GenerationError(f"cannot write '{out}' and its map: {exc.reason}") from None
        return out


def map_output_paths(out: str | Path) -> list[Path]:
    """``[out, <stem>_map.yaml, <stem>_map.pgm]`` beside ``out``."""
    out = Path(out)
    stem = out.stem if out.suffix else out.name
    return [out, out.with_name(f"{stem}_map.yaml"), out.with_name(f"{stem}_map.pgm")]


def check_map_place(path: Path) -> None:
    """Refuse ``-`` and an existing path that is not a regular file (a link is not followed: the
    map must lie beside the problem).

    Raises
    ------
    GenerationError
        Naming ``path`` and what it is.
    """
    if str(path) == "-":
        raise GenerationError("a map kind writes three files; give --out a file name, not '-'")
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise GenerationError(f"cannot write '{path}': {exc.strerror}") from None
    if stat.S_ISLNK(mode):
        raise GenerationError(f"'{path}' is a symbolic link; a map kind writes regular files only")
    if not stat.S_ISREG(mode):
        what = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
        raise GenerationError(f"'{path}' is {what}; it is left as it is")
