"""ROS 2 bags of a plan or a simulation (``--bag OUT``), written by ``rosbags``.

A bag is MCAP when ``OUT`` ends in ``.mcap`` (one file, ``ros2 bag play run.mcap``), else a
rosbag2 directory with a sqlite3 database and ``metadata.yaml``. It is rosbag2 format version 8,
whose QoS profiles (integers) both Humble and Jazzy read, with the message definitions of
:data:`~rrtpso_ompl.ros.messages.DISTRO` (:mod:`.messages` says why that suits Jazzy too). The
bag is made in a temporary folder beside ``OUT`` and moved there only when complete
(:func:`~rrtpso_ompl.outputs.atomic_folder`): an interrupted run leaves no bag at ``OUT``.

Every length is in metres, every time in seconds. A plan's bag (``solve``, ``optimum``:
:func:`plan_records`) holds ``/map`` (map problems), ``/obstacles``, ``/initialpose``,
``/goal_pose`` and ``/plan``, all at t = 0; a simulation's (:func:`simulation_records`) adds
``/tf_static``, and at every sample ``/odom``, ``/tf``, ``/cmd_vel``, ``/wheel_speeds`` and
``/moving_obstacles``, and ``/plan`` at every change of plan. :data:`TOPICS` gives each topic's
type; ``docs/ros.md`` describes them for users.

``/map``, ``/obstacles`` and ``/tf_static`` are recorded with map_server's and
static_transform_publisher's QoS (reliable, transient local, depth 1), so that a player offers
them latched; the others reliable and volatile. A bag's log time is its messages' stamp: 0 for a
plan, the simulation clock for a simulation (``ros2 bag play --clock`` replays it).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .messages import DISTRO, Messages, nanoseconds
from .plan import RosFrame

__all__ = [
    "DATABASE_SUFFIX",
    "MAX_MOVING",
    "MAX_PLAN_POSES",
    "MAX_SAMPLES",
    "MCAP_MAGIC",
    "TOPICS",
    "WHEEL_JOINTS",
    "BagRecord",
    "check_pose_count",
    "is_mcap",
    "is_mcap_file",
    "plan_poses",
    "plan_records",
    "simulation_records",
    "write_bag",
    "write_plan_bag",
    "write_simulation_bag",
]

#: Most samples of a simulation a bag holds (an input-driven loop): longer runs are thinned to
#: every k-th sample (the last kept), about 25 minutes at a 0.15 s sample time.
MAX_SAMPLES = 10_000
#: Most poses of one ``/plan`` in a bag (an input-driven allocation: the path's length over
#: ``--path-resolution``): 500,000 poses take about 30 s and 300 MB to build, 36 MB in the bag
#: (a 25 km plan at 5 cm).
MAX_PLAN_POSES = 500_000
#: Most moving-obstacle positions a bag holds (samples times moving obstacles): a run with many
#: moving obstacles gets ``/moving_obstacles`` at every k-th sample only (the last kept).
MAX_MOVING = 200_000
#: The first bytes of every MCAP file (its magic and format version "0").
MCAP_MAGIC = b"\x89MCAP0\r\n"
#: The suffix of a bag directory's database, named after the directory (``run/run.db3``).
DATABASE_SUFFIX = ".db3"
#: The joints of ``/wheel_speeds`` (a differential drive's two wheels, REP 105's base frame).
WHEEL_JOINTS = ("right_wheel_joint", "left_wheel_joint")
#: Topic name -> (message type, latched): the type each topic carries and whether it is recorded
#: transient local (latched).
TOPICS: dict[str, tuple[str, bool]] = {
    "/map": ("nav_msgs/msg/OccupancyGrid", True),
    "/obstacles": ("visualization_msgs/msg/MarkerArray", True),
    "/initialpose": ("geometry_msgs/msg/PoseWithCovarianceStamped", False),
    "/goal_pose": ("geometry_msgs/msg/PoseStamped", False),
    "/plan": ("nav_msgs/msg/Path", False),
    "/tf_static": ("tf2_msgs/msg/TFMessage", True),
    "/tf": ("tf2_msgs/msg/TFMessage", False),
    "/odom": ("nav_msgs/msg/Odometry", False),
    "/cmd_vel": ("geometry_msgs/msg/Twist", False),
    "/wheel_speeds": ("sensor_msgs/msg/JointState", False),
    "/moving_obstacles": ("visualization_msgs/msg/MarkerArray", False),
}


@dataclass(frozen=True)
class BagRecord:
    """One message of a bag: its time (s), topic and CDR bytes (serialised at once, so that a
    bag's many messages are held as bytes, not as Python objects)."""

    t: float
    topic: str
    data: bytes

    @classmethod
    def of(cls, msgs: Messages, t: float, topic: str, msg: Any) -> BagRecord:
        return cls(t, topic, msgs.serialize(msg))


def is_mcap(out: str | Path) -> bool:
    """Whether ``out`` names an MCAP bag (one file) rather than a sqlite3 bag directory."""
    return str(out).lower().endswith(".mcap")


def is_mcap_file(path: str | Path) -> bool:
    """Whether the file at ``path`` starts with the MCAP magic (False when unreadable)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(len(MCAP_MAGIC)) == MCAP_MAGIC
    except OSError:
        return False


# ----------------------------------------------------------------------------------------------
# What a bag holds
# ----------------------------------------------------------------------------------------------
def plan_records(
    problem: Any, frame: RosFrame, path: Any, msgs: Messages, t: float = 0.0
) -> list[BagRecord]:
    """The scene and the plan at time ``t``: ``/map`` (map problems), ``/obstacles``,
    ``/initialpose``, ``/goal_pose`` and ``/plan`` (when ``path`` has a point; None: unsolved).

    Parameters
    ----------
    problem : Problem
    frame : RosFrame
        Units, pose spacing, frame id and goal heading.
    path : (m, 2) array_like or None
        The plan, problem units.
    """
    from .grid import occupancy_grid
    from .markers import obstacle_markers

    records: list[BagRecord] = []

    def add(topic: str, msg: Any) -> None:
        records.append(BagRecord.of(msgs, t, topic, msg))

    if problem.map is not None:
        add("/map", occupancy_grid(msgs, problem.map, frame.scale, t))
    add("/obstacles", obstacle_markers(msgs, problem, frame.scale, frame.resolution, t))
    poses = plan_poses(frame, path) if path is not None and len(path) else None
    start, goal = frame.metres(problem.start), frame.metres(problem.goal)
    toward = math.atan2(goal[1] - start[1], goal[0] - start[0])
    start_yaw = float(poses.yaw[0]) if poses is not None and len(poses) > 1 else toward
    goal_yaw = frame.goal_yaw
    if goal_yaw is None:
        goal_yaw = float(poses.yaw[-1]) if poses is not None and len(poses) > 1 else toward
    add("/initialpose", msgs.initial_pose(start, start_yaw, t))
    add("/goal_pose", msgs.pose_stamped(goal, goal_yaw, t))
    if poses is not None:
        add("/plan", msgs.path(poses, t))
    return records


def simulation_records(problem: Any, frame: RosFrame, sim: Any, msgs: Messages) -> list[BagRecord]:
    """A simulation on its own clock: the scene and the first plan at t = 0, then at every
    sample ``/odom``, ``/tf``, ``/cmd_vel``, ``/wheel_speeds`` (when the robot has
    ``wheel_radius`` and ``track_width``) and ``/moving_obstacles`` (every k-th sample when more
    than :data:`MAX_MOVING` positions), and ``/plan`` at every change of plan (a replan's
    detour, a re-shortening). At most :data:`MAX_SAMPLES` samples.

    Parameters
    ----------
    sim : SimulationResult
        Its ``trajectory`` (the samples, as in ``simulate --json``), ``motion`` (the commands),
        ``plans`` and ``tracks``.
    """
    from .markers import moving_markers

    static = sim.static_path if len(sim.static_path) else None
    records = [r for r in plan_records(problem, frame, static, msgs) if r.topic != "/plan"]

    def add(t: float, topic: str, msg: Any) -> None:
        records.append(BagRecord.of(msgs, t, topic, msg))

    add(0.0, "/tf_static", msgs.tf(msgs.transform(frame.frame_id, msgs.ODOM, (0, 0), 0.0, 0.0)))
    for t, plan in sim.plans:
        add(float(t), "/plan", msgs.path(plan_poses(frame, plan.waypoints_after(t)), float(t)))
    if not sim.plans and static is not None:  # the robot never set off: the static path
        add(0.0, "/plan", msgs.path(plan_poses(frame, static), 0.0))
    samples = _thin(sim.trajectory)
    n = len(samples)
    if not n:
        return records
    v, omega = commands(sim.motion, samples[:, 0])
    v = v * frame.scale  # m/s; omega is rad/s in every unit
    robot = problem.robot
    wheels = _wheel_speeds(robot, frame, v, omega)
    xy = frame.metres(samples[:, 1:3])
    shown, centres = _moving_samples(sim.tracks, samples[:, 0])
    radii = [tr.radius for tr in sim.tracks]
    for k, (t, yaw) in enumerate(zip(samples[:, 0].tolist(), samples[:, 3].tolist(), strict=True)):
        add(t, "/odom", msgs.odometry(xy[k], yaw, v[k], omega[k], t))
        add(t, "/tf", msgs.tf(msgs.transform(msgs.ODOM, msgs.BASE, xy[k], yaw, t)))
        add(t, "/cmd_vel", msgs.twist(v[k], omega[k]))
        if wheels is not None:
            add(t, "/wheel_speeds", msgs.joint_state(list(WHEEL_JOINTS), wheels[k], t))
        if shown[k]:
            add(
                t,
                "/moving_obstacles",
                moving_markers(msgs, centres[k], radii, robot.radius, frame.scale, t),
            )
    return records


def _wheel_speeds(robot: Any, frame: RosFrame, v: np.ndarray, omega: np.ndarray):
    """Eqs. 9-12: the right and left wheels' angular speeds, rad/s, as ``(n, 2)`` (units
    cancel); None when the robot has no ``wheel_radius`` and ``track_width``."""
    if not (robot.wheel_radius and robot.track_width):
        return None
    from ..kinematics.diffdrive import wheel_speeds

    _, _, w_right, w_left = wheel_speeds(
        v, omega, robot.track_width * frame.scale, robot.wheel_radius * frame.scale
    )
    return np.column_stack([w_right, w_left])


def _moving_samples(tracks: list, times: np.ndarray):
    """Which samples carry ``/moving_obstacles`` (every k-th, and the last, so that at most
    :data:`MAX_MOVING` positions are written) and the obstacles' centres at every sample."""
    n = len(times)
    shown = np.zeros(n, dtype=bool)
    if not tracks:
        return shown, None
    shown[:: max(1, math.ceil(n * len(tracks) / MAX_MOVING))] = True
    shown[-1] = True
    return shown, np.stack([tr.position(times) for tr in tracks], axis=1)


def plan_poses(frame: RosFrame, path: Any) -> Any:
    """``frame.poses(path)``, at most about :data:`MAX_PLAN_POSES` of them
    (:func:`check_pose_count`)."""
    given = np.asarray(path, dtype=float)
    p = frame.metres(given[:, :2] if given.ndim == 2 and given.shape[1] == 3 else
                     given.reshape(-1, 2))  # fmt: skip
    check_pose_count(frame, float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0)
    return frame.poses(path)


def check_pose_count(frame: RosFrame, length: float, what: str = "the plan") -> None:
    """Refuse (ValueError, naming ``--path-resolution``) a plan of ``length`` metres that needs
    more than :data:`MAX_PLAN_POSES` poses at the frame's resolution."""
    needed = length / frame.resolution
    if needed > MAX_PLAN_POSES:
        raise ValueError(
            f"{what} ({length:.6g} m) needs about {needed:,.0f} poses at --path-resolution "
            f"{frame.resolution:g} m, more than the {MAX_PLAN_POSES:,} a bag's /plan holds; "
            "give a coarser --path-resolution"
        )


def commands(motion: Any, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The body velocities commanded at times ``t``: the linear speed ``v`` (units/s, negative
    backwards) and turn rate ``omega`` (rad/s) of the piece of ``motion`` under way
    (:meth:`~rrtpso_ompl.dynamic.motion.Motion.body_velocities`; eqs. 7-8 give them back from
    the piece's wheel speeds); 0 before the first knot and after the last (arrived).
    """
    t = np.asarray(t, dtype=float)
    if motion is None or len(motion.t) < 2:
        return np.zeros(len(t)), np.zeros(len(t))
    v_piece, w_piece = motion.body_velocities()
    # The piece that starts at or before t (a piece of no duration at t is passed over).
    i = np.searchsorted(motion.t, t, side="right") - 1
    moving = (i >= 0) & (i < len(v_piece))
    i = np.clip(i, 0, len(v_piece) - 1)
    return np.where(moving, v_piece[i], 0.0), np.where(moving, w_piece[i], 0.0)


def _thin(samples: np.ndarray) -> np.ndarray:
    """At most :data:`MAX_SAMPLES` of ``samples``, evenly, the first and last kept."""
    n = len(samples)
    if n <= MAX_SAMPLES:
        return samples
    keep = np.unique(np.linspace(0, n - 1, MAX_SAMPLES).round().astype(np.int64))
    return samples[keep]


# ----------------------------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------------------------
def write_bag(
    records: Iterable[BagRecord],
    out: str | Path,
    msgs: Messages,
    custom: dict[str, str] | None = None,
) -> None:
    """Write ``records`` as a bag at ``out``, in time order, whole or not at all.

    Parameters
    ----------
    records : iterable of BagRecord
    out : str or Path
        MCAP file when it ends in ``.mcap`` (an existing file is replaced atomically), else a
        sqlite3 bag directory (a new name, or an empty folder: :func:`~.outputs.atomic_folder`).
    msgs : Messages
    custom : dict, optional
        The bag's ``custom_data`` (strings).

    Raises
    ------
    OutputError
        When the bag cannot be written (the disk is full); nothing is left at ``out``.
    """
    import sqlite3

    from rosbags.rosbag2 import StoragePlugin, Writer, WriterError

    from ..errors import OutputError
    from ..outputs import atomic_folder

    ordered = sorted(records, key=lambda r: r.t)  # stable: same-time messages keep their order
    mcap = is_mcap(out)
    plugin = StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3
    pick = (lambda folder: folder / f"{folder.name}.mcap") if mcap else None
    try:
        with atomic_folder(out, publish_file=pick, name="bag") as folder:
            writer = Writer(folder, version=8, storage_plugin=plugin)
            with writer:
                for key, value in {
                    "rrtpso.msg_definitions": f"ros2_{DISTRO}",
                    **(custom or {}),
                }.items():
                    writer.set_custom_data(key, value)
                connections = {}
                for rec in ordered:
                    conn = connections.get(rec.topic)
                    if conn is None:
                        msgtype, latched = TOPICS[rec.topic]
                        conn = writer.add_connection(
                            rec.topic,
                            msgtype,
                            typestore=msgs.ts,
                            offered_qos_profiles=[_qos(latched)],
                        )
                        connections[rec.topic] = conn
                    writer.write(conn, nanoseconds(rec.t), rec.data)
    except (WriterError, sqlite3.Error) as exc:
        raise OutputError(str(out), str(exc)) from None


def _qos(latched: bool) -> Any:
    """The offered QoS a topic is recorded with: reliable, keep last; transient local and depth 1
    when ``latched`` (map_server's ``/map``), else volatile, depth 10."""
    from rosbags.interfaces import (
        Qos,
        QosDurability,
        QosHistory,
        QosLiveliness,
        QosReliability,
        QosTime,
    )

    default = QosTime(0, 0)  # RMW_DURATION_UNSPECIFIED: the middleware's default (infinite)
    durability = QosDurability.TRANSIENT_LOCAL if latched else QosDurability.VOLATILE
    return Qos(
        QosHistory.KEEP_LAST,
        1 if latched else 10,
        QosReliability.RELIABLE,
        durability,
        default,
        default,
        QosLiveliness.AUTOMATIC,
        default,
        False,
    )


def _custom(problem: Any, frame: RosFrame, command: str) -> dict[str, str]:
    """The bag's ``custom_data``: where it came from and how its lengths were converted."""
    units = problem.units or "m"
    return {
        "rrtpso.command": command,
        "rrtpso.problem": str(problem.name),
        "rrtpso.source": str(problem.source),
        "rrtpso.units": f"metres: the problem's lengths ({units}) times {frame.scale:g}",
        "rrtpso.frame_id": frame.frame_id,
    }


def write_plan_bag(
    problem: Any, frame: RosFrame, path: Any, out: str | Path, command: str = "solve"
) -> None:
    """``--bag`` of ``solve`` and ``optimum``: the scene and the plan (:func:`plan_records`)."""
    msgs = Messages(frame.frame_id)
    records = _records(out, plan_records, problem, frame, path, msgs)
    write_bag(records, out, msgs, _custom(problem, frame, command))


def write_simulation_bag(problem: Any, frame: RosFrame, sim: Any, out: str | Path) -> None:
    """``--bag`` of ``simulate`` (:func:`simulation_records`)."""
    msgs = Messages(frame.frame_id)
    records = _records(out, simulation_records, problem, frame, sim, msgs)
    write_bag(records, out, msgs, _custom(problem, frame, "simulate"))


def _records(out: str | Path, build: Any, *args: Any) -> list[BagRecord]:
    """``build(*args)``; a plan too long for its poses (ValueError) is an OutputError of ``out``
    (exit status 2, nothing written)."""
    from ..errors import OutputError

    try:
        return build(*args)
    except ValueError as exc:
        raise OutputError(str(out), str(exc)) from None
