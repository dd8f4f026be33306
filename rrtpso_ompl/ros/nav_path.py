"""Paths as ROS ``nav_msgs/msg/Path`` documents (YAML or JSON) that rclpy turns into a message.

A ``nav_msgs/Path`` is a header (``frame_id``, ``stamp``) and a list of
``geometry_msgs/PoseStamped``; the poses here are :class:`~rrtpso_ompl.ros.Poses` (metres, dense
along the path, each with its heading), the heading as a quaternion about z:
``(0, 0, sin(theta / 2), cos(theta / 2))``. The document has exactly
the message's field names, so ``rosidl_runtime_py.set_message_fields`` fills a message from it
(``docs/ros.md`` shows the few lines of rclpy that publish it).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .poses import Poses

__all__ = ["nav_path", "nav_path_yaml", "write_nav_path"]


def nav_path(poses: Poses, frame_id: str = "map", stamp: float = 0.0) -> dict[str, Any]:
    """A ``nav_msgs/Path``-shaped dictionary of poses.

    Parameters
    ----------
    poses : Poses
        Positions (map frame, metres) and headings (radians), e.g.
        :meth:`rrtpso_ompl.ros.RosFrame.poses`.
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
    sec = math.floor(stamp)
    header = {"stamp": {"sec": sec, "nanosec": round((stamp - sec) * 1e9)},
              "frame_id": frame_id}  # fmt: skip
    poses = [
        {
            "header": {"stamp": dict(header["stamp"]), "frame_id": frame_id},  # no YAML aliases
            "pose": {
                "position": {"x": float(x), "y": float(y), "z": 0.0},
                "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(0.5 * t), "w": math.cos(0.5 * t)},
            },
        }
        for (x, y), t in zip(poses.xy.tolist(), poses.yaw.tolist(), strict=True)
    ]
    return {"header": header, "poses": poses}


def write_nav_path(doc: dict[str, Any], out: str | Path) -> None:
    """Write a :func:`nav_path` document: JSON for a ``.json`` name, YAML otherwise (by the
    package's atomic, never-clobbering output rules)."""
    from ..outputs import write_json_atomic, write_text_atomic

    if str(out).lower().endswith(".json"):
        write_json_atomic(doc, out)
        return
    write_text_atomic(nav_path_yaml(doc), out)


def nav_path_yaml(doc: dict[str, Any]) -> str:
    """A :func:`nav_path` document as YAML, the text ``yaml.safe_dump(doc, sort_keys=False,
    default_flow_style=None)`` writes, character for character, in a twentieth of its time.

    PyYAML represents every value in Python (8 s for the 17,940 poses of a long spiral, 4 s with
    its C emitter). A pose differs from the next only in its five numbers, so the header lines
    come from PyYAML once and each pose is one format string, its floats written as PyYAML's
    ``SafeRepresenter.represent_float`` writes them (:func:`_yaml_float`).
    """
    import yaml

    poses = doc["poses"]
    head = yaml.safe_dump({"header": doc["header"]}, sort_keys=False, default_flow_style=None)
    if not poses:
        return head + "poses: []\n"
    # A pose's header, as PyYAML writes it inside the list (indented under "- header:").
    pose_header = "".join("  " + line + "\n" for line in head.splitlines()[1:])
    rows = []
    for p in poses:
        position, orientation = p["pose"]["position"], p["pose"]["orientation"]
        rows.append(
            f"- header:\n{pose_header}  pose:\n"
            f"    position: {{x: {_yaml_float(position['x'])}, y: {_yaml_float(position['y'])}, "
            f"z: {_yaml_float(position['z'])}}}\n"
            f"    orientation: {{x: {_yaml_float(orientation['x'])}, "
            f"y: {_yaml_float(orientation['y'])}, z: {_yaml_float(orientation['z'])}, "
            f"w: {_yaml_float(orientation['w'])}}}\n"
        )
    return head + "poses:\n" + "".join(rows)


def _yaml_float(value: float) -> str:
    """A float as PyYAML's safe representer writes it (finite values: the poses are)."""
    text = repr(float(value)).lower()
    if "." not in text and "e" in text:
        text = text.replace("e", ".0e", 1)
    return text
