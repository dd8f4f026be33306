"""Occupancy-grid maps as ROS's ``map_server`` (Nav2's ``nav2_map_server``) writes them: a YAML
file and an image (PGM, PNG, BMP).

The map YAML holds ``image`` (relative to the YAML file), ``resolution`` (metres per cell),
``origin: [x, y, yaw]`` (the pose of the image's lower-left corner in the map frame), ``negate``,
``occupied_thresh``, ``free_thresh`` and ``mode`` (``trinary``, ``scale`` or ``raw``); other keys
are ignored. Each pixel becomes a cell state, as ``docs/problem-format.md`` specifies:

- colour is averaged to grey ``v`` (0..255; 16-bit PGMs are scaled to 0..255);
- missing keys default to ``negate: 0``, ``occupied_thresh: 0.65``, ``free_thresh: 0.196``
  (ROS map_saver's, under which its unknown grey 205 stays unknown) and ``mode: trinary``;
- ``negate: 0``: occupancy ``p = (255 - v) / 255``; ``negate: 1``: ``p = v / 255``;
- ``p >= occupied_thresh``: occupied; ``p <= free_thresh``: free; otherwise unknown (trinary)
  or in between (scale; blocked like unknown unless ``unknown: free``);
- ``raw``: ``v`` itself is the occupancy in percent; values above 100 are unknown (``negate``
  does not apply), and ``v / 100`` is compared with the thresholds;
- a pixel whose alpha is below 255 is unknown, in every mode.

(Nav2 compares with ``>`` and ``<`` where the contract says ``>=`` and ``<=``; the two differ only
for a pixel exactly on a threshold, which the usual 0.65, 0.25 and 0.196 never meet: ``255 * 0.35``,
``255 * 0.75`` and ``255 * 0.804`` are not integers. Note that under Nav2's ``free_thresh: 0.25``
the grey 205 reads as free, exactly as Nav2 reads it.)

Image row 0 is the top of the map: the cell in row ``i``, column ``j`` of an ``H``-row image is
the square ``[ox + j res, ox + (j + 1) res] x [oy + (H - 1 - i) res, oy + (H - i) res]``. The
blocked cells are merged into axis-aligned rectangles (runs along rows, then equal runs of
consecutive rows), which the exact checks of :class:`~rrtpso_ompl.model.world.World` treat as
boxes: a 1.7-million-cell warehouse map becomes a few thousand boxes, not 260,000 squares.

A yaw other than 0 turns the whole image about ``(ox, oy)``, the lower-left corner of its
lower-left cell, as map_server and RViz place it (nav_msgs/MapMetaData: the origin is the pose of
that corner). The squares above are then the cells in *grid coordinates*
(:class:`~rrtpso_ompl.model.geometry.GridFrame`); in the map frame each is that square turned by
``yaw`` about ``(ox, oy)``. The merged boxes stay in grid coordinates, and the world's checks
turn each query into them, exactly (a rotation keeps distances).

Every way a map can be wrong is one :class:`~rrtpso_ompl.errors.ProblemError` naming the file and
the key. Images larger than :data:`MAX_CELLS` cells are refused before they are decoded.
"""

from __future__ import annotations

import math
import numbers
import os
import re
import warnings
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ProblemError
from ..validation import MAX_COORDINATE, describe, number_hint
from .geometry import GridFrame
from .yamlfile import open_input, read_yaml_file

__all__ = [
    "MAX_CELLS",
    "MODES",
    "OccupancyMap",
    "is_map_yaml",
    "load_map",
    "map_image_path",
    "merge_cells",
    "read_image",
    "read_pgm",
]

#: Most cells a map may have (25 million: 5,000 x 5,000, 250 m square at 5 cm).
MAX_CELLS = 25_000_000
#: The map_server modes.
MODES = ("trinary", "scale", "raw")
#: Cell states.
FREE, OCCUPIED, UNKNOWN = 0, 1, -1
#: Defaults of the optional keys: ROS map_saver's thresholds, which keep its unknown grey (205,
#: occupancy 0.19608) unknown.
_DEFAULTS = {"negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.196, "mode": "trinary"}
_MAP_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")


@dataclass(frozen=True, eq=False)
class OccupancyMap:
    """An occupancy grid read from a map_server YAML file and its image.

    Attributes
    ----------
    source : str
        The map YAML file.
    image : str
        The image file it names.
    resolution : float
        Side of a cell, map units (metres) per cell.
    origin : (float, float)
        Map-frame position of the lower-left corner of the image (of its lower-left cell).
    state : ndarray of int8, shape (H, W)
        Cell states in image order (row 0 on top): 0 free, 1 occupied, -1 unknown or, in
        ``scale`` mode, in between.
    unknown_blocks : bool
        Whether unknown cells are obstacles (the problem's ``unknown: obstacle``, the default).
    mode : str
        ``trinary``, ``scale`` or ``raw``.
    negate : bool
    occupied_thresh, free_thresh : float
    yaw : float
        The image's turn about ``origin``, radians, counter-clockwise (``origin[2]`` of the YAML).
    """

    source: str
    image: str
    resolution: float
    origin: tuple[float, float]
    state: np.ndarray = field(repr=False)
    unknown_blocks: bool = True
    mode: str = "trinary"
    negate: bool = False
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    yaw: float = 0.0

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns) of the image."""
        return self.state.shape

    @property
    def extent(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((xmin, ymin), (xmax, ymax))`` of the map in grid coordinates, map units (the map
        frame's when the yaw is 0; see :attr:`bounding_box`)."""
        h, w = self.state.shape
        ox, oy = self.origin
        return (ox, oy), (ox + w * self.resolution, oy + h * self.resolution)

    @cached_property
    def frame(self) -> GridFrame | None:
        """The grid's frame when the map is turned (a yaw other than 0), else None (grid
        coordinates are the map frame's)."""
        return GridFrame(self.origin, self.yaw) if self.yaw != 0.0 else None

    @property
    def corners(self) -> np.ndarray:
        """(4, 2) corners of the map's rectangle in the map frame, counter-clockwise from the
        origin (the image's lower-left corner)."""
        (x0, y0), (x1, y1) = self.extent
        corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
        return corners if self.frame is None else self.frame.to_world(corners)

    @property
    def bounding_box(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """``((xmin, ymin), (xmax, ymax))`` of the map's rectangle in the map frame: its extent,
        or for a turned map the smallest axis-aligned box around it (a problem's default
        bounds)."""
        if self.frame is None:
            return self.extent
        c = self.corners
        lo, hi = c.min(axis=0), c.max(axis=0)
        return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))

    @cached_property
    def blocked(self) -> np.ndarray:
        """(H, W) booleans in image order: occupied, and unknown unless ``unknown: free``."""
        if self.unknown_blocks:
            return self.state != FREE
        return self.state == OCCUPIED

    @cached_property
    def boxes(self) -> np.ndarray:
        """(k, 4) rectangles ``(xmin, ymin, xmax, ymax)`` covering exactly the blocked cells."""
        return merge_cells(self.blocked, self.resolution, self.origin)

    def cell_box(self, row: int, col: int) -> tuple[float, float, float, float]:
        """The square of the cell in image row ``row``, column ``col``: (xmin, ymin, xmax, ymax),
        grid coordinates (the map frame's when the yaw is 0)."""
        h = self.state.shape[0]
        res = self.resolution
        x0 = self.origin[0] + col * res
        y0 = self.origin[1] + (h - 1 - row) * res
        return x0, y0, x0 + res, y0 + res

    def cell_centre(self, row: int, col: int) -> tuple[float, float]:
        """The map-frame centre of the cell in image row ``row``, column ``col``."""
        x0, y0, x1, y1 = self.cell_box(row, col)
        x, y = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        if self.frame is not None:
            x, y = self.frame.to_world([x, y]).tolist()
        return x, y

    def nearest_blocked(self, x: float, y: float, reach: float) -> tuple[int, int, float] | None:
        """The blocked cell nearest to the map-frame point ``(x, y)`` within ``reach``:
        ``(row, col, distance)``.

        Exact distance from the point to the cell's square (0 inside it; for a turned map, from
        the point in grid coordinates, which keeps distances); only the cells of the window
        ``reach`` around the point are looked at.
        """
        if self.frame is not None:
            x, y = self.frame.to_grid_xy(x, y)
        h, w = self.state.shape
        res = self.resolution
        ox, oy = self.origin
        c0 = max(0, math.floor((x - reach - ox) / res))
        c1 = min(w - 1, math.floor((x + reach - ox) / res))
        # Rows from the bottom (y up), then flipped to image rows.
        b0 = max(0, math.floor((y - reach - oy) / res))
        b1 = min(h - 1, math.floor((y + reach - oy) / res))
        if c0 > c1 or b0 > b1:
            return None
        window = self.blocked[h - 1 - b1 : h - b0, c0 : c1 + 1]
        rows, cols = np.nonzero(window)
        if not len(rows):
            return None
        rows = rows + (h - 1 - b1)
        cols = cols + c0
        x0 = ox + cols * res
        y0 = oy + (h - 1 - rows) * res
        dx = np.maximum.reduce([x0 - x, np.zeros(len(x0)), x - (x0 + res)])
        dy = np.maximum.reduce([y0 - y, np.zeros(len(y0)), y - (y0 + res)])
        d = np.hypot(dx, dy)
        k = int(np.argmin(d))
        if d[k] > reach:
            return None
        return int(rows[k]), int(cols[k]), float(d[k])

    def counts(self) -> dict[str, int]:
        """Cells by state: ``{"free", "occupied", "unknown", "blocked", "boxes"}``."""
        return {
            "free": int(np.count_nonzero(self.state == FREE)),
            "occupied": int(np.count_nonzero(self.state == OCCUPIED)),
            "unknown": int(np.count_nonzero(self.state == UNKNOWN)),
            "blocked": int(np.count_nonzero(self.blocked)),
            "boxes": len(self.boxes),
        }


# ----------------------------------------------------------------------------------------------
def is_map_yaml(path: str | Path) -> bool:
    """Whether a file looks like a map_server map YAML (small, with top-level ``image`` and
    ``resolution`` keys) rather than a problem: folders of problems keep their maps beside them,
    and a batch over the folder skips them."""
    try:
        if Path(path).stat().st_size > 65536:
            return False
        with open(path, encoding="utf-8", errors="replace") as fh:
            text = fh.read()
    except OSError:
        return False
    keys = {m.group(1) for m in re.finditer(r"^([A-Za-z_]+)\s*:", text, re.MULTILINE)}
    return {"image", "resolution"} <= keys and "start" not in keys


def load_map(path: str | Path, unknown_blocks: bool = True) -> OccupancyMap:
    """Read a map_server map: its YAML file and the image it names.

    Parameters
    ----------
    path : str or Path
        The map YAML file.
    unknown_blocks : bool
        Whether unknown cells are obstacles (default) or free.

    Returns
    -------
    OccupancyMap

    Raises
    ------
    ProblemError
        Naming the map YAML and the key (``image`` for an image that is missing, unreadable or
        too large) for anything wrong.
    """
    path = Path(path)
    source = str(path)
    keys = _map_keys(source, _read_map_yaml(path))
    image_path = map_image_path(path, keys.image)
    grey, alpha, maxval = read_image(source, image_path)
    _check_extent(source, keys, grey.shape)
    state = _states(grey, alpha, maxval, keys.mode, keys.negate, keys.occupied_thresh,
                    keys.free_thresh)  # fmt: skip
    # The boxes are merged from the states on first use (OccupancyMap.boxes).
    return OccupancyMap(
        source=source,
        image=str(image_path),
        resolution=keys.resolution,
        origin=keys.origin,
        yaw=keys.yaw,
        state=state,
        unknown_blocks=unknown_blocks,
        mode=keys.mode,
        negate=keys.negate,
        occupied_thresh=keys.occupied_thresh,
        free_thresh=keys.free_thresh,
    )


@dataclass(frozen=True)
class _MapKeys:
    """The keys of a map YAML, checked and with their defaults."""

    image: str
    resolution: float
    origin: tuple[float, float]
    yaw: float
    negate: bool
    occupied_thresh: float
    free_thresh: float
    mode: str


def _read_map_yaml(path: Path) -> dict:
    """The map YAML's top-level mapping."""
    doc = read_yaml_file(path)
    if not isinstance(doc, dict):
        raise ProblemError(str(path), "", f"a map YAML must be a mapping, got {describe(doc)}")
    return doc


def _map_keys(source: str, doc: dict) -> _MapKeys:
    """Every key of the map YAML checked, in the order of the format (the first wrong one is
    reported)."""
    for key in ("image", "resolution", "origin"):
        if doc.get(key) is None:
            raise ProblemError(source, key, "required key is missing")
    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise ProblemError(source, "image", f"must be a file name, got {describe(image)}")
    resolution = _resolution(source, doc["resolution"])
    ox, oy, yaw = _origin(source, doc["origin"])
    negate = _negate(source, doc.get("negate", _DEFAULTS["negate"]))
    occ, free = _thresholds(source, doc)
    mode = _get(doc, "mode")
    if mode not in MODES:
        raise ProblemError(
            source, "mode", f"must be one of {', '.join(MODES)}, got {describe(mode)}"
        )
    if "\0" in image:
        raise ProblemError(source, "image", "the file name holds a NUL byte")
    return _MapKeys(image, resolution, (ox, oy), yaw, negate, occ, free, mode)


def _resolution(source: str, value: Any) -> float:
    """Metres per cell: positive, at most the largest length."""
    resolution = _number(source, "resolution", value)
    if not resolution > 0.0:
        raise ProblemError(
            source, "resolution", f"must be > 0 (metres per cell), got {resolution:g}"
        )
    if resolution > MAX_COORDINATE:
        raise ProblemError(
            source,
            "resolution",
            f"must be at most {MAX_COORDINATE:g} (the largest length: exact checks allow for "
            f"round-off of 1e-9 of the workspace's scale), got {resolution:g}",
        )
    return resolution


def _origin(source: str, origin: Any) -> tuple[float, float, float]:
    """``[x, y]`` or ``[x, y, yaw]``: the pose of the image's lower-left corner (yaw in radians,
    any finite number)."""
    if not isinstance(origin, list | tuple) or len(origin) not in (2, 3):
        raise ProblemError(source, "origin", f"must be [x, y, yaw], got {describe(origin)}")
    ox, oy, *rest = (_number(source, f"origin[{i}]", v) for i, v in enumerate(origin))
    for i, v in enumerate((ox, oy)):
        if abs(v) > MAX_COORDINATE:
            raise ProblemError(source, f"origin[{i}]", f"must be within +-{MAX_COORDINATE:g}")
    return ox, oy, (rest[0] if rest else 0.0)


def _negate(source: str, negate: Any) -> bool:
    """``negate``: 0 or 1 (a boolean or null accepted)."""
    if negate is None:
        negate = 0
    if isinstance(negate, bool):
        negate = int(negate)
    if not isinstance(negate, numbers.Integral) or negate not in (0, 1):
        raise ProblemError(source, "negate", f"must be 0 or 1, got {describe(negate)}")
    return bool(negate)


def _thresholds(source: str, doc: dict) -> tuple[float, float]:
    """``occupied_thresh`` and ``free_thresh``: in [0, 1], free below occupied."""
    occ = _number(source, "occupied_thresh", _get(doc, "occupied_thresh"))
    free = _number(source, "free_thresh", _get(doc, "free_thresh"))
    for key, v in (("occupied_thresh", occ), ("free_thresh", free)):
        if not 0.0 <= v <= 1.0:
            raise ProblemError(source, key, f"must be between 0 and 1, got {v:g}")
    if not free < occ:
        raise ProblemError(
            source, "free_thresh", f"must be below occupied_thresh ({occ:g}), got {free:g}"
        )
    return occ, free


def _check_extent(source: str, keys: _MapKeys, shape: tuple[int, int]) -> None:
    """The map's far corners stay within the coordinate limit (turned with the map)."""
    h, w = shape
    for i, (corner, cells) in enumerate(((keys.origin[0], w), (keys.origin[1], h))):
        end = corner + cells * keys.resolution
        if abs(end) > MAX_COORDINATE:
            axis = "xy"[i]
            raise ProblemError(
                source,
                "resolution",
                f"{cells} cells of {keys.resolution:g} from origin {corner:g} reach {axis} = "
                f"{end:g}, beyond +-{MAX_COORDINATE:g} (the coordinate limit: exact checks allow "
                "for round-off of 1e-9 of the workspace's scale)",
            )
    if keys.yaw != 0.0:
        (x0, y0), res = keys.origin, keys.resolution
        corners = [[x0 + w * res, y0], [x0 + w * res, y0 + h * res], [x0, y0 + h * res]]
        far = np.abs(GridFrame(keys.origin, keys.yaw).to_world(corners)).max()
        if far > MAX_COORDINATE:
            raise ProblemError(
                source,
                "origin[2]",
                f"turned by {keys.yaw:g} rad, the map's corners reach {far:g}, beyond "
                f"+-{MAX_COORDINATE:g} (the coordinate limit)",
            )


def map_image_path(map_yaml: str | Path, image: str) -> Path:
    """The image a map YAML's ``image`` names: relative to the YAML's folder, resolved (absolute,
    links followed; a symbolic link loop stays as written, for the reader to report)."""
    if Path(image).is_absolute():
        return Path(image)
    return Path(os.path.realpath(Path(map_yaml).parent / image))


def _get(doc: dict, key: str) -> Any:
    """A key's value, or its default when absent or null."""
    value = doc.get(key)
    return _DEFAULTS[key] if value is None else value


def _number(source: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ProblemError(source, key, f"must be a number, got {describe(value)}"
                           f"{number_hint(value)}")  # fmt: skip
    x = float(value)
    if not math.isfinite(x):
        raise ProblemError(source, key, f"must be finite, got {x}")
    return x


def _states(grey, alpha, maxval: int, mode: str, negate: bool, occ: float, free: float):
    """Cell states from grey values (see the module docstring)."""
    if mode == "raw":
        v = grey.astype(np.int32)
        p = v / 100.0
        known = v <= 100
    else:
        v = grey.astype(np.float64) * (255.0 / maxval) if maxval != 255 else grey
        p = (v / 255.0) if negate else (255.0 - v) / 255.0
        known = np.ones(grey.shape, dtype=bool)
    state = np.full(grey.shape, UNKNOWN, dtype=np.int8)
    state[known & (p <= free)] = FREE
    state[known & (p >= occ)] = OCCUPIED
    if alpha is not None:
        state[alpha < 255] = UNKNOWN
    return state


# ----------------------------------------------------------------------------------------------
def read_image(source: str, path: Path) -> tuple[np.ndarray, np.ndarray | None, int]:
    """Grey values (H, W), alpha (H, W) or None, and the grey maxval, of a map image."""
    try:
        with open_input(path) as fh:  # a regular file, or why not
            head = fh.read(2)
    except ValueError as exc:
        what = f"no such image file: {path}" if str(exc) == "no such file" else f"{path} {exc}"
        raise ProblemError(source, "image", what) from None
    except OSError as exc:
        raise ProblemError(source, "image", f"cannot read {path}: {exc.strerror or exc}") from None
    if head in (b"P2", b"P5"):
        try:
            grey, maxval = read_pgm(path)
        except ValueError as exc:
            raise ProblemError(source, "image", f"{path}: {exc}") from None
        return grey, None, maxval
    return _read_with_pillow(source, path)


def read_pgm(path: str | Path) -> tuple[np.ndarray, int]:
    """A PGM image (P2 ASCII or P5 binary, 8 or 16 bits): its (H, W) values and maxval.

    Raises
    ------
    ValueError
        For a malformed or truncated file, or one of more than :data:`MAX_CELLS` pixels.
    """
    with open(path, "rb") as fh:
        data = fh.read(12 * MAX_CELLS + 4096)  # P2 text: up to 11 characters a value
    magic = data[:2]
    if magic not in (b"P2", b"P5"):
        raise ValueError("not a PGM image (P2 or P5)")
    (width, height, maxval), pos = _pgm_header(data)
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise ValueError(f"bad PGM header: width {width}, height {height}, maxval {maxval}")
    if width * height > MAX_CELLS:
        raise ValueError(f"{width} x {height} pixels, more than the {MAX_CELLS:,} allowed")
    values = _pgm_pixels(data, pos, width * height, maxval).astype(np.int64)
    if values.max(initial=0) > maxval:
        raise ValueError(f"a pixel value exceeds maxval {maxval}")
    if values.min(initial=0) < 0:
        # P2 text can hold "-1"; read as an unsigned byte it would be 255, free space.
        k = int(np.argmax(values < 0))
        raise ValueError(
            f"pixel {k} (row {k // width}, column {k % width}) is {values[k]}: pixel values "
            f"run from 0 to maxval {maxval}"
        )
    return values.reshape(height, width).astype(np.uint16 if maxval > 255 else np.uint8), maxval


def _pgm_header(data: bytes) -> tuple[list[int], int]:
    """Width, height and maxval of a PGM file's bytes (``# comments`` between the tokens
    skipped), and the position just after the last of them."""
    pos, values = 2, []
    while len(values) < 3:
        while pos < len(data) and data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            end = data.find(b"\n", pos)
            pos = len(data) if end < 0 else end + 1
            continue
        start = pos
        while pos < len(data) and data[pos : pos + 1].isdigit():
            pos += 1
        if start == pos:
            raise ValueError("malformed PGM header (width, height and maxval expected)")
        values.append(int(data[start:pos]))
    return values, pos


def _pgm_pixels(data: bytes, pos: int, n: int, maxval: int) -> np.ndarray:
    """The ``n`` pixel values after the header (which ends at ``pos``): binary for P5 (two bytes
    a value, big-endian, when ``maxval`` > 255), whitespace-separated text for P2; not checked
    against ``maxval``."""
    if data[:2] == b"P5":
        pos += 1  # exactly one whitespace character ends the header
        dtype = np.dtype(">u2") if maxval > 255 else np.dtype("u1")
        need = n * dtype.itemsize
        if len(data) - pos < need:
            raise ValueError(f"truncated: {n} pixels need {need} bytes, {len(data) - pos} left")
        return np.frombuffer(data[pos : pos + need], dtype=dtype)
    text = data[pos:].decode("ascii", errors="replace")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns, then stops, at a non-number
        try:
            raw = np.fromstring(text, dtype=np.int64, sep=" ")
        except (ValueError, DeprecationWarning):
            raise ValueError("P2 pixel values must be whitespace-separated integers") from None
    if len(raw) < n:
        raise ValueError(f"truncated or not numbers: {n} pixel values expected, {len(raw)} read")
    return raw[:n]


def _read_with_pillow(source: str, path: Path) -> tuple[np.ndarray, np.ndarray | None, int]:
    """PNG, BMP and the other formats Pillow reads: grey (channels averaged) and alpha."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as img:
            w, h = img.size
            if w * h > MAX_CELLS:
                too_many = f"{w} x {h} pixels, more than the {MAX_CELLS:,} allowed"
                raise ProblemError(source, "image", f"{path}: {too_many}")
            if img.mode == "P":  # palette: its colours (and transparency) decide
                img = img.convert("RGBA")
            elif img.mode in ("1", "CMYK", "YCbCr", "LAB", "HSV"):
                img = img.convert("RGB")
            arr = np.asarray(img)
            mode = img.mode
    except ProblemError:
        raise
    except (UnidentifiedImageError, OSError, ValueError, Image.DecompressionBombError) as exc:
        raise ProblemError(source, "image", f"cannot read {path}: {exc}") from None
    alpha = None
    maxval = 255
    if mode in ("I;16", "I;16B", "I;16L", "I"):
        grey = arr.astype(np.int64)
        maxval = 65535
        grey = np.clip(grey, 0, maxval).astype(np.uint16)
        return grey, None, maxval
    if mode == "F":
        raise ProblemError(source, "image", f"{path}: floating-point images are not supported")
    if arr.ndim == 2:
        return arr.astype(np.uint8), None, maxval
    channels = arr.shape[2]
    if mode in ("LA", "RGBA", "La", "RGBa"):
        alpha = arr[..., -1]
        colour = arr[..., :-1]
    else:
        colour = arr[..., : min(channels, 3)]
    # Colour averaged to grey, as map_server does; rounded so that equal channels stay exact.
    grey = np.rint(colour.astype(np.float64).mean(axis=2)).astype(np.uint8)
    return grey, alpha, maxval


# ----------------------------------------------------------------------------------------------
def merge_cells(blocked: np.ndarray, resolution: float, origin) -> np.ndarray:
    """Rectangles ``(xmin, ymin, xmax, ymax)`` that exactly cover the blocked cells.

    Blocked cells are joined into runs along each row, and runs with the same columns in
    consecutive rows into one rectangle (walls and shelves, drawn along the axes, become one box
    each). Fully vectorised: O(cells) time, memory for the runs only.

    Parameters
    ----------
    blocked : (H, W) bool ndarray
        In image order (row 0 on top).
    resolution : float
        Side of a cell.
    origin : (float, float)
        Lower-left corner of the image.
    """
    h, w = blocked.shape
    if not blocked.any():
        return np.empty((0, 4))
    # Runs along rows: where a row switches from free to blocked and back.
    pad = np.zeros((h, w + 2), dtype=np.int8)
    pad[:, 1:-1] = blocked
    step = np.diff(pad, axis=1)
    r_start, c_start = np.nonzero(step == 1)
    _, c_end = np.nonzero(step == -1)  # both in row-major order, so they pair up
    rows, c0, c1 = r_start, c_start, c_end  # columns c0 .. c1 - 1
    # Equal runs in consecutive rows merge: sort by (c0, c1, row), break where they differ.
    order = np.lexsort((rows, c1, c0))
    rows, c0, c1 = rows[order], c0[order], c1[order]
    new = np.ones(len(rows), dtype=bool)
    new[1:] = (c0[1:] != c0[:-1]) | (c1[1:] != c1[:-1]) | (rows[1:] != rows[:-1] + 1)
    group = np.cumsum(new) - 1
    top = rows[new]  # first (top-most) image row of each rectangle
    bottom = np.zeros(group[-1] + 1, dtype=rows.dtype)
    np.maximum.at(bottom, group, rows)
    left, right = c0[new], c1[new]
    ox, oy = origin
    xmin = ox + left * resolution
    xmax = ox + right * resolution
    ymin = oy + (h - 1 - bottom) * resolution
    ymax = oy + (h - top) * resolution
    return np.column_stack([xmin, ymin, xmax, ymax]).astype(float)
