"""A car-like robot's curves as a trajectory: arcs and straight lines, forwards and backwards.

A differential-drive robot may turn in place; a car may not. Its path (Dubins or Reeds-Shepp
curves, :mod:`rrtpso_ompl.ompl_setup.car`) already has its headings, so nothing is fitted: the
reference is the curve itself, given as dense poses ``(x, y, yaw)`` (its chords' ends), with the
curvature of each piece ``kappa = d(yaw) / ds`` over its arc length (exactly ``0`` or ``+-1 /
rho`` inside a straight line or an arc; a piece across a junction gets the mean, so that the
heading is exact at every pose). The path is cut at its cusps (where a Reeds-Shepp car stops and
changes gear); each stretch of one gear is time-parametrised as the plane's curves are
(:func:`~.profile.time_parametrize`: the constant or the limits profile, the wheel-speed cap in
turns), with no turn in place; a stretch driven backwards has ``v < 0`` (the heading is the
car's, so ``omega = v kappa`` turns it the right way). The stretches follow each other, at rest
at each cusp under the limits profile.
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np

from ..model.problem_types import Robot
from .diffdrive import integrate_wheels, wheel_speeds
from .drive import DriveResult
from .profile import Trajectory, time_parametrize
from .reference import ReferenceCurve
from .tracking import track

__all__ = ["curve_of_poses", "drive_car", "gears"]


def gears(poses: np.ndarray) -> np.ndarray:
    """The gear of each piece between consecutive poses: ``+1`` forwards, ``-1`` backwards (the
    chord against the mean heading of its ends)."""
    d = np.diff(poses[:, :2], axis=0)
    yaw = poses[:, 2]
    mean = yaw[:-1] + 0.5 * np.angle(np.exp(1j * (yaw[1:] - yaw[:-1])))
    along = d[:, 0] * np.cos(mean) + d[:, 1] * np.sin(mean)
    return np.where(along < 0.0, -1, 1)


def curve_of_poses(poses: np.ndarray, kind: str) -> ReferenceCurve:
    """The reference curve of one gear's poses: the arc length of each piece (its chord over
    the arc's), the heading unwrapped, each piece's curvature on its first pose (the last pose
    repeats the last)."""
    chord = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    theta = np.unwrap(poses[:, 2])
    # A piece of an arc turning by dtheta is longer than its chord by (dtheta / 2) / sin(dtheta
    # / 2): with that length its curvature is exactly the arc's.
    ds = chord / np.sinc(0.5 * np.diff(theta) / np.pi)
    s = np.concatenate([[0.0], np.cumsum(ds)])
    with np.errstate(divide="ignore", invalid="ignore"):
        piece = np.where(ds > 0, np.diff(theta) / np.where(ds > 0, ds, 1.0), 0.0)
    kappa = np.append(piece, piece[-1] if len(piece) else 0.0)
    return ReferenceCurve(s=s, x=poses[:, 0].copy(), y=poses[:, 1].copy(), theta=theta,
                          kappa=kappa, turns=np.zeros(len(s)), kind=kind,
                          knots=poses[:, :2].copy())  # fmt: skip


def drive_car(poses: np.ndarray, robot: Robot, profile: str = "auto",
              kind: str = "Dubins") -> DriveResult:  # fmt: skip
    """The trajectory of a car's curves, its open-loop replay and its closed-loop tracking.

    Parameters
    ----------
    poses : ndarray, shape (n, 3)
        The curves' dense poses ``x, y, yaw`` (units, rad), from the start to the goal.
    robot : Robot
        ``speed``, ``sample_time``, ``track_width``, ``wheel_radius`` and the optional limits.
    profile : {"auto", "constant", "limits"}
        As :func:`~.profile.time_parametrize`.
    kind : str
        ``"Dubins"`` or ``"Reeds-Shepp"`` (the curve's ``kind``).

    Returns
    -------
    DriveResult
        No reference polynomial (the curves are the reference); ``curve`` is the whole path's.
    """
    poses = np.asarray(poses, dtype=float).reshape(-1, 3)
    gear = gears(poses)
    cuts = np.flatnonzero(np.diff(gear)) + 1  # pieces where the gear changes
    bounds = np.concatenate([[0], cuts, [len(gear)]])
    parts: list[Trajectory] = []
    for lo, hi in itertools.pairwise(bounds):
        part = time_parametrize(curve_of_poses(poses[lo : hi + 1], kind), robot, profile)
        parts.append(_backwards(part, robot) if gear[lo] < 0 else part)
    traj = _joined(parts)
    start = (traj.x[0], traj.y[0], traj.theta[0])
    replay = integrate_wheels(start, traj.v_right, traj.v_left, traj.track_width,
                              traj.sample_time)  # fmt: skip
    open_loop = float(np.hypot(replay[:, 0] - traj.x, replay[:, 1] - traj.y).max())
    return DriveResult(polynomial=None, curve=curve_of_poses(poses, kind), trajectory=traj,
                       open_loop_error=open_loop,
                       tracking=track(traj, max_wheel_speed=robot.max_wheel_speed))  # fmt: skip


def _backwards(part: Trajectory, robot: Robot) -> Trajectory:
    """A stretch driven backwards: the same poses, the linear speed negated (the heading's
    rate is the poses' own), the wheels from both."""
    v = -part.v
    v_r, v_l, w_r, w_l = wheel_speeds(v, part.omega, robot.track_width, robot.wheel_radius)
    return dataclasses.replace(part, v=v, v_right=v_r, v_left=v_l, omega_right=w_r,
                               omega_left=w_l)  # fmt: skip


def _joined(parts: list[Trajectory]) -> Trajectory:
    """The stretches one after the other: each one's last row (at rest at the cusp) is the next
    one's first pose, so it is dropped, and the times run on."""
    if len(parts) == 1:
        return parts[0]
    names = ("x", "y", "theta", "v", "omega", "v_right", "v_left", "omega_right", "omega_left")
    cols: dict[str, list[np.ndarray]] = {n: [] for n in (*names, "t")}
    offset = 0.0
    for k, part in enumerate(parts):
        keep = slice(None) if k == len(parts) - 1 else slice(0, -1)
        for n in names:
            cols[n].append(getattr(part, n)[keep])
        cols["t"].append(part.t[keep] + offset)
        offset += float(part.t[-1])
    joined = {n: np.concatenate(c) for n, c in cols.items()}
    joined["theta"] = np.unwrap(joined["theta"])  # each stretch unwrapped its own headings
    return dataclasses.replace(parts[0], **joined, goal_turn_times=None)
