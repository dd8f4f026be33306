"""ROS 2 messages built from the project's objects, with one distribution's message definitions.

Everything here is already in metres, radians and seconds: the callers convert the problem's
lengths through :class:`~rrtpso_ompl.ros.RosFrame`. The message classes come from the
``rosbags`` type store of :data:`DISTRO` (ROS 2 Humble). Jazzy's definitions of every message
written here are the same fields in the same order (the CDR bytes and the RIHS01 type hashes
agree); its ``visualization_msgs/msg/Marker`` only adds the constant ``ARROW_STRIP = 12``, which
is not serialised. So Humble's definitions, the older of the two, are what a bag declares, and
both distributions' tools read it (``docs/ros.md``).
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np

from .poses import Poses

__all__ = ["DISTRO", "NS_PER_S", "Messages", "nanoseconds", "typestore"]

#: The ROS 2 distribution whose message definitions a bag declares (module docstring).
DISTRO = "humble"
#: Nanoseconds per second (ROS time stamps are integer nanoseconds).
NS_PER_S = 1_000_000_000


@lru_cache(maxsize=1)
def typestore() -> Any:
    """The ``rosbags`` type store of :data:`DISTRO` (built once: it compiles the serialisers)."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(Stores.ROS2_HUMBLE)


def nanoseconds(t: float) -> int:
    """A time in seconds as integer nanoseconds (a bag's log time; ``t >= 0``)."""
    return round(t * NS_PER_S)


class Messages:
    """Builds the messages of one bag.

    Parameters
    ----------
    frame_id : str
        The fixed frame (``map``) of plans, poses, the map and the markers.
    """

    #: The odometry frame and the robot's body frame (REP 105).
    ODOM, BASE = "odom", "base_link"

    #: The packages whose message classes are attributes of this object by their short names.
    PACKAGES = (
        "builtin_interfaces",
        "geometry_msgs",
        "nav_msgs",
        "sensor_msgs",
        "std_msgs",
        "tf2_msgs",
        "visualization_msgs",
    )

    def __init__(self, frame_id: str = "map") -> None:
        self.frame_id = frame_id
        self.ts = typestore()
        self._classes = {
            name.rsplit("/", 1)[1]: cls
            for name, cls in self.ts.types.items()
            if name.split("/")[0] in self.PACKAGES and "/msg/" in name
        }

    def __getattr__(self, name: str) -> Any:
        """``msgs.Marker``, ``msgs.Path``, ...: the message classes by their short names."""
        cls = self.__dict__.get("_classes", {}).get(name)
        if cls is None:
            raise AttributeError(name)
        return cls

    def serialize(self, msg: Any) -> bytes:
        """The message's CDR bytes, as a bag stores them."""
        return bytes(self.ts.serialize_cdr(msg, msg.__msgtype__))

    # -- building blocks ---------------------------------------------------------------------
    def time(self, t: float) -> Any:
        """``builtin_interfaces/Time`` of ``t`` seconds."""
        sec, nanosec = divmod(nanoseconds(t), NS_PER_S)
        return self.Time(sec=int(sec), nanosec=int(nanosec))

    def header(self, t: float, frame_id: str | None = None) -> Any:
        return self.Header(
            stamp=self.time(t), frame_id=self.frame_id if frame_id is None else frame_id
        )

    def point(self, x: float, y: float, z: float = 0.0) -> Any:
        return self.Point(x=float(x), y=float(y), z=float(z))

    def quaternion(self, yaw: float) -> Any:
        """The rotation by ``yaw`` (radians) about z."""
        return self.Quaternion(x=0.0, y=0.0, z=math.sin(0.5 * yaw), w=math.cos(0.5 * yaw))

    def pose(self, x: float, y: float, yaw: float = 0.0, z: float = 0.0) -> Any:
        return self.Pose(position=self.point(x, y, z), orientation=self.quaternion(yaw))

    def vector3(self, x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Any:
        return self.Vector3(x=float(x), y=float(y), z=float(z))

    # -- messages ----------------------------------------------------------------------------
    def path(self, poses: Poses, t: float) -> Any:
        """``nav_msgs/Path`` of ``poses`` (metres, radians), stamped ``t``."""
        header = self.header(t)
        return self.Path(
            header=header,
            poses=[
                self.PoseStamped(header=header, pose=self.pose(x, y, yaw))
                for (x, y), yaw in zip(poses.xy.tolist(), poses.yaw.tolist(), strict=True)
            ],
        )

    def pose_stamped(self, xy: Any, yaw: float, t: float) -> Any:
        """``geometry_msgs/PoseStamped`` (``/goal_pose``, as RViz's "2D Goal Pose" sends it)."""
        return self.PoseStamped(header=self.header(t), pose=self.pose(xy[0], xy[1], yaw))

    def initial_pose(self, xy: Any, yaw: float, t: float) -> Any:
        """``geometry_msgs/PoseWithCovarianceStamped`` (``/initialpose``): the start, known
        exactly (zero covariance)."""
        return self.PoseWithCovarianceStamped(
            header=self.header(t),
            pose=self.PoseWithCovariance(
                pose=self.pose(xy[0], xy[1], yaw), covariance=np.zeros(36)
            ),
        )

    def odometry(self, xy: Any, yaw: float, v: float, omega: float, t: float) -> Any:
        """``nav_msgs/Odometry``: the pose in ``odom``, the twist in ``base_link`` (``v`` m/s
        forwards, ``omega`` rad/s counter-clockwise)."""
        return self.Odometry(
            header=self.header(t, self.ODOM),
            child_frame_id=self.BASE,
            pose=self.PoseWithCovariance(
                pose=self.pose(xy[0], xy[1], yaw), covariance=np.zeros(36)
            ),
            twist=self.TwistWithCovariance(twist=self.twist(v, omega), covariance=np.zeros(36)),
        )

    def twist(self, v: float, omega: float) -> Any:
        """``geometry_msgs/Twist`` (``/cmd_vel``): ``linear.x = v``, ``angular.z = omega``."""
        return self.Twist(linear=self.vector3(v), angular=self.vector3(z=omega))

    def transform(self, parent: str, child: str, xy: Any, yaw: float, t: float) -> Any:
        """``geometry_msgs/TransformStamped`` from ``parent`` to ``child``."""
        return self.TransformStamped(
            header=self.header(t, parent),
            child_frame_id=child,
            transform=self.Transform(
                translation=self.vector3(xy[0], xy[1]), rotation=self.quaternion(yaw)
            ),
        )

    def tf(self, *transforms: Any) -> Any:
        """``tf2_msgs/TFMessage`` of the transforms."""
        return self.TFMessage(transforms=list(transforms))

    def joint_state(self, names: list[str], velocity: Any, t: float) -> Any:
        """``sensor_msgs/JointState`` with the joints' velocities (rad/s) only."""
        return self.JointState(
            header=self.header(t, self.BASE),
            name=list(names),
            position=np.zeros(0),
            velocity=np.asarray(velocity, dtype=np.float64),
            effort=np.zeros(0),
        )
