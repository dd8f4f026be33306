"""A map problem's occupancy grid as ``nav_msgs/msg/OccupancyGrid``, as map_server publishes it.

map_server (Nav2's ``nav2_map_server``) turns each pixel into a value: 100 occupied, 0 free,
-1 unknown in ``trinary`` mode; in ``scale`` mode the cells between the thresholds get
``rint(100 (p - free_thresh) / (occupied_thresh - free_thresh))`` and a transparent pixel is
unknown; in ``raw`` mode the grey value itself, unknown above 100. The states of
:class:`~rrtpso_ompl.model.OccupancyMap` decide occupied, free and unknown (so the thresholds
compare as ``docs/problem-format.md`` says); ``scale`` and ``raw`` maps read their image again
for the values in between, which the states do not keep.

The message's ``data`` is row-major from the *bottom* row of the image (row 0 of the message is
the image's last row: y grows upwards), ``info.origin`` is the pose of that row's first cell's
lower-left corner: the map YAML's ``origin`` ``[x, y, yaw]``, the yaw as a quaternion about z.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .messages import Messages

__all__ = ["OCCUPIED", "UNKNOWN", "occupancy_grid", "occupancy_values"]

#: map_server's values of an occupied and of an unknown cell (free is 0).
OCCUPIED, UNKNOWN = 100, -1


def occupancy_values(grid: Any) -> np.ndarray:
    """The map_server value of every cell, in image order (row 0 on top).

    Parameters
    ----------
    grid : OccupancyMap

    Returns
    -------
    (H, W) ndarray of int8
        100 occupied, 0 free, -1 unknown; ``scale`` and ``raw`` maps have values in between.
    """
    from ..model.occupancy import FREE
    from ..model.occupancy import OCCUPIED as BLOCKED

    state = grid.state
    values = np.full(state.shape, UNKNOWN, dtype=np.int8)
    values[state == FREE] = 0
    values[state == BLOCKED] = OCCUPIED
    if grid.mode == "trinary":
        return values
    from ..model.occupancy import read_image  # the same reader, so the same grey values

    grey, alpha, maxval = read_image(grid.source, Path(grid.image))
    opaque = np.ones(state.shape, dtype=bool) if alpha is None else alpha == 255
    if grid.mode == "raw":
        raw = grey.astype(np.int64)
        known = opaque & (raw <= OCCUPIED)
        values[known] = raw[known].astype(np.int8)
        return values
    # scale: the cells between the thresholds, linearly from 0 (free_thresh) to 100 (occupied)
    v = grey.astype(np.float64) * (255.0 / maxval)
    p = v / 255.0 if grid.negate else (255.0 - v) / 255.0
    between = opaque & (state != FREE) & (state != BLOCKED)
    span = grid.occupied_thresh - grid.free_thresh
    scaled = np.rint((p[between] - grid.free_thresh) / span * 100.0)
    values[between] = np.clip(scaled, 0, OCCUPIED).astype(np.int8)
    return values


def occupancy_grid(msgs: Messages, grid: Any, scale: float, t: float) -> Any:
    """The ``nav_msgs/OccupancyGrid`` of ``grid`` (lengths times ``scale``: metres).

    Parameters
    ----------
    msgs : Messages
    grid : OccupancyMap
    scale : float
        Metres per map unit.
    t : float
        Stamp and ``info.map_load_time``, seconds.
    """
    h, w = grid.shape
    ox, oy = grid.origin[0], grid.origin[1]
    info = msgs.MapMetaData(
        map_load_time=msgs.time(t),
        resolution=float(grid.resolution * scale),
        width=int(w),
        height=int(h),
        origin=msgs.pose(ox * scale, oy * scale, origin_yaw(grid)),
    )
    data = np.ascontiguousarray(occupancy_values(grid)[::-1]).reshape(-1)
    return msgs.OccupancyGrid(header=msgs.header(t), info=info, data=data)


def origin_yaw(grid: Any) -> float:
    """The yaw of the map YAML's origin, radians (0 for a map read without one)."""
    return float(getattr(grid, "yaw", 0.0) or 0.0)
