"""Paths as ROS ``nav_msgs/msg/Path`` documents (YAML or JSON) that rclpy turns into a message.

A ``nav_msgs/Path`` is a header (``frame_id``, ``stamp``) and a list of
``geometry_msgs/PoseStamped``; each pose here is a waypoint of the path, its orientation the
heading of the segment leaving it (the last waypoint keeps the heading of the segment that reaches
it), as a quaternion about z: ``(0, 0, sin(theta / 2), cos(theta / 2))``. The document has exactly
the message's field names, so ``rosidl_runtime_py.set_message_fields`` fills a message from it
(``docs/ros.md`` shows the few lines of rclpy that publish it).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["nav_path", "write_nav_path"]


def nav_path(path: np.ndarray, frame_id: str = "map", stamp: float = 0.0) -> dict[str, Any]:
    """A ``nav_msgs/Path``-shaped dictionary of a polyline.

    Parameters
    ----------
    path : (m, 2) array_like
        Waypoints, map frame, metres.
    frame_id : str
        The frame the coordinates are in (``map`` for map problems: the map YAML's origin).
    stamp : float
        Header time, seconds (0: "latest", the usual value for a stored plan).

    Returns
    -------
    dict
        ``{"header": {...}, "poses": [{"header": ..., "pose": {"position": ...,
        "orientation": ...}}, ...]}``.
    """
    p = np.asarray(path, dtype=float).reshape(-1, 2)
    sec = math.floor(stamp)
    header = {"stamp": {"sec": sec, "nanosec": round((stamp - sec) * 1e9)},
              "frame_id": frame_id}  # fmt: skip
    if len(p) >= 2:
        d = np.diff(p, axis=0)
        theta = np.arctan2(d[:, 1], d[:, 0])
        theta = np.append(theta, theta[-1])
    else:
        theta = np.zeros(len(p))
    poses = [
        {
            "header": {"stamp": dict(header["stamp"]), "frame_id": frame_id},  # no YAML aliases
            "pose": {
                "position": {"x": float(x), "y": float(y), "z": 0.0},
                "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(0.5 * t), "w": math.cos(0.5 * t)},
            },
        }
        for (x, y), t in zip(p.tolist(), theta.tolist(), strict=True)
    ]
    return {"header": header, "poses": poses}


def write_nav_path(doc: dict[str, Any], out: str | Path) -> None:
    """Write a :func:`nav_path` document: JSON for a ``.json`` name, YAML otherwise (by the
    package's atomic, never-clobbering output rules)."""
    from ..outputs import write_json_atomic, write_text_atomic

    if str(out).lower().endswith(".json"):
        write_json_atomic(doc, out)
        return
    import yaml

    write_text_atomic(yaml.safe_dump(doc, sort_keys=False, default_flow_style=None), out)
