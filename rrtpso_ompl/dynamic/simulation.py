"""The simulation: the robot drives its plan among moving obstacles, senses, predicts, replans.

The robot drives its planned path (the differential-drive stop-and-turn motion of
:class:`~rrtpso_ompl.dynamic.motion.Motion`), the moving obstacles move at constant velocity
(eqs. 14-15, optionally with random heading changes), and every ``sample_time`` the robot

1. **senses** the moving obstacles whose disc comes within ``sensor_range`` of its centre and
   measures their position and velocity;
2. **predicts**, for each sensed obstacle, the *cross point*: the first time at which its remaining
   motion and the obstacle's constant-velocity extrapolation come closer than
   ``SR + SO + margin/2`` (exact, :func:`~rrtpso_ompl.dynamic.prediction.predict_threats`), and
   the collision zone (the stretch of its path during which they stay that close);
3. on a predicted collision, **replans** (:class:`~rrtpso_ompl.dynamic.manager.
   ReplanningManager`: contour detours up and down, verified, or a verified wait or step aside).

:func:`simulate_local` is the same harness for a local controller (a :class:`LocalController`,
such as the DWA peer of :mod:`.dwa`), which instead chooses the velocities every period.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from ..errors import RrtpsoError
from ..model.geometry import path_length
from ..model.problem import Problem
from ..model.world import World
from ..validation import MAX_STEPS as _MAX_STEPS
from .manager import Observations, Replan, ReplanningManager
from .motion import Motion, ObstacleTrack, arc_position, closest_approach
from .prediction import predict_threats

__all__ = [
    "MAX_REPLANS",
    "MAX_STEPS",
    "STRATEGIES",
    "SUBSTEPS",
    "DynamicOptions",
    "LocalController",
    "RobotModel",
    "RobotState",
    "SimulationError",
    "SimulationResult",
    "goal_tolerance",
    "simulate",
    "simulate_local",
]


class SimulationError(RrtpsoError):
    """A simulation that cannot be run as asked (the message says why)."""


#: Most control steps one simulation may take (simulated time / sample time): the limit every
#: sampled motion shares.
MAX_STEPS = _MAX_STEPS
#: Most reactions (detours and fallbacks) one simulation may make before it gives up: each one
#: plans or verifies, so this bounds the wall time of a run that can never get through.
MAX_REPLANS = 500

#: Least simulated time between two attempts to shortcut the rest of the plan, s.
RESHORTEN_PERIOD = 1.0

#: Knots per control period of a local controller's executed motion (the arc between knots is
#: replaced by its chord: at most ``v w dt^2 / (8 SUBSTEPS^2)`` off, 0.001 cm for the paper's
#: robot).
SUBSTEPS = 5

#: The strategies: the paper's contour detours, replanning the whole remaining path (baseline),
#: or driving the static path blindly (baseline).
STRATEGIES = ("contour", "global", "none")


@dataclass(frozen=True)
class DynamicOptions:
    """Parameters of the simulation and of the replanning manager.

    Attributes
    ----------
    planner : str
        Planner of the initial path and of the detours (any registered name).
    strategy : {"contour", "global", "none"}
        ``contour``: detours around the collision zone, up and down (the paper's method);
        ``global``: replan the whole remaining path to the goal (one plan); ``none``: never replan.
    replan_time : float
        Simulated seconds one replan takes: the planners' total budget (the two contour detours
        get half each). The robot keeps driving its old plan meanwhile.
    initial_time : float or None
        Budget for the initial static path, s (default: the problem's ``planner.time_limit``,
        else 1.0). The robot waits for it at the start; it is not counted as driving time.
    margin : float or None
        Extra separation kept beyond ``SR + SO``, units (default 10 % of ``SR + SO`` of the
        smallest obstacle). Detours are planned with the full margin; a collision is *predicted*
        when the separation would drop below ``SR + SO + margin / 2``.
    stretch : float
        How much longer than the straight line a detour may be (>= 1) when the relevant time
        windows are computed.
    max_time : float or None
        Simulated time limit, s (default: four times the static path's duration plus 60 s).
    heading_changes : float
        Mean number of random heading changes per obstacle per second (Poisson); 0 keeps the
        paper's constant velocity.
    heading_change_deg : float
        Standard deviation of a heading change, degrees.
    reshorten : bool
        ``contour`` only: while no collision is predicted, shortcut the rest of the plan in the
        static world (at most every :data:`RESHORTEN_PERIOD` s, verified against the sensed
        obstacles), so that a detour's bends go once the obstacle has passed.
    params : mapping
        Parameters for the planner.
    """

    planner: str = "RRTstarPSO"
    strategy: str = "contour"
    replan_time: float = 0.1
    initial_time: float | None = None
    margin: float | None = None
    stretch: float = 2.0
    max_time: float | None = None
    heading_changes: float = 0.0
    heading_change_deg: float = 45.0
    reshorten: bool = True
    params: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.strategy not in STRATEGIES:
            raise ValueError(
                f"strategy must be one of {', '.join(STRATEGIES)}, got {self.strategy!r}"
            )
        if not self.replan_time > 0:
            raise ValueError("replan_time must be > 0")
        if not self.stretch >= 1.0:
            raise ValueError("stretch must be >= 1")
        if self.heading_changes < 0 or self.heading_change_deg < 0:
            raise ValueError("heading_changes and heading_change_deg must be >= 0")
        if self.margin is not None and self.margin < 0:
            raise ValueError("margin must be >= 0")


@dataclass
class SimulationResult:
    """The outcome of one simulation; :meth:`to_dict` is the ``rrtpso simulate --json`` output.

    Distances are centre to centre (units): the robot and obstacle ``k`` touch at
    ``SR + SO_k``. ``collisions`` counts the sample instants at which any separation was below
    that; ``min_separation_continuous`` is exact between samples too.
    """

    problem: str
    strategy: str
    planner: str
    seed: int | None
    reached_goal: bool
    collisions: int
    min_separation: list[float | None]
    min_separation_continuous: list[float | None]
    contact_distance: list[float]
    total_time: float
    path_length: float
    static_length: float | None
    sample_time: float
    motion: Motion | None
    static_path: np.ndarray
    tracks: list[ObstacleTrack]
    replans: list[Replan]
    plans: list[tuple[float, Motion]]
    status: str = "ok"

    @property
    def trajectory(self) -> np.ndarray:
        """``[t, x, y, theta]`` every sample time from the start to the goal (or the end)."""
        if self.motion is None:
            return np.empty((0, 4))
        return self.motion.sample(self.sample_time)

    @property
    def success(self) -> bool:
        """Goal reached without any collision."""
        return self.reached_goal and self.collisions == 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "problem": self.problem,
            "status": self.status,
            "strategy": self.strategy,
            "planner": self.planner,
            "seed": self.seed,
            "reached_goal": self.reached_goal,
            "collisions": self.collisions,
            "min_separation": self.min_separation,
            "min_separation_continuous": self.min_separation_continuous,
            "contact_distance": self.contact_distance,
            "total_time": self.total_time,
            "path_length": self.path_length,
            "static_length": self.static_length,
            "replans": [r.to_dict() for r in self.replans],
            "trajectory": self.trajectory.tolist(),
            "static_path": self.static_path.tolist(),
        }


@dataclass(frozen=True)
class RobotModel:
    """The robot as the simulation drives it (units, units/s, rad/s, s).

    Attributes
    ----------
    speed : float
        Top linear speed: the least of ``robot.speed``, ``max_speed`` and ``max_wheel_speed``.
    turn_rate : float or None
        Top turn rate in place, ``2 v_w / L`` (None without a track width: instantaneous turns).
    sample_time, radius, sensor_range : float
        The control period Ts, the safety radius SR and the sensor range.
    wheel_speed : float
        Top wheel speed ``v_w`` (``max_wheel_speed``, else ``speed``): a differential drive
        needs ``|v| + |w| L / 2 <= v_w``.
    track_width : float or None
        ``L``.
    """

    speed: float
    turn_rate: float | None
    sample_time: float
    radius: float
    sensor_range: float
    wheel_speed: float = math.inf
    track_width: float | None = None

    @classmethod
    def of(cls, problem: Problem) -> RobotModel:
        robot = problem.robot
        for key in ("speed", "sample_time", "sensor_range"):
            if getattr(robot, key) is None:
                raise ValueError(f"robot.{key} is required for a simulation")
        speed = min(
            v for v in (robot.speed, robot.max_speed, robot.max_wheel_speed) if v is not None
        )
        wheel = robot.max_wheel_speed or robot.speed
        turn_rate = None
        if robot.track_width:
            turn_rate = 2.0 * wheel / robot.track_width
        return cls(speed, turn_rate, float(robot.sample_time), robot.radius, robot.sensor_range,
                   float(wheel), robot.track_width or None)  # fmt: skip


def simulate(
    problem: Problem,
    options: DynamicOptions | None = None,
    seed: int | None = None,
    initial_path: np.ndarray | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> SimulationResult:
    """Drive the robot from start to goal among the problem's moving obstacles.

    Parameters
    ----------
    problem : Problem
        Needs ``robot.speed``, ``robot.sample_time`` and ``robot.sensor_range``; the turn rate
        comes from ``robot.track_width`` and ``max_wheel_speed`` (else ``speed``), with
        instantaneous turns when there is no track width.
    options : DynamicOptions, optional
    seed : int, optional
        Seeds the planners and the obstacles' random heading changes (numpy ``Generator``).
    initial_path : (n, 2) array, optional
        The static path to start from (planned with ``options.planner`` when omitted); passing it
        lets several strategies start from the same path.
    progress : callable, optional
        Called as ``progress(t, t_estimate)`` after every step.

    Returns
    -------
    SimulationResult
    """
    options = options or DynamicOptions()
    robot = RobotModel.of(problem)
    radii = [m.radius for m in problem.moving_obstacles]
    margin = options.margin
    if margin is None:
        margin = 0.1 * (robot.radius + min(radii, default=0.0))
    plan_rng, world_rng = np.random.default_rng(seed).spawn(2)
    if initial_path is None:
        initial_path = _static_path(problem, options, seed)
    static_path = np.asarray(initial_path, dtype=float).reshape(-1, 2)
    tracks = [ObstacleTrack.from_obstacle(m) for m in problem.moving_obstacles]
    if len(static_path) < 2:
        return _no_static_path(problem, options, seed, robot, static_path, tracks)

    plan = Motion.from_path(static_path, 0.0, None, robot.speed, robot.turn_rate)
    t_max = options.max_time if options.max_time is not None else 4 * plan.t_end + 60.0
    _check_steps(t_max, robot.sample_time)
    blocked = _blocked(problem, tracks, robot)
    if blocked:
        return _no_static_path(problem, options, seed, robot, static_path, tracks, blocked)
    manager = ReplanningManager(problem, options, robot.speed, robot.turn_rate, margin, plan_rng)
    plan, t, plans, replans = _drive(
        plan, tracks, robot, manager, options, margin, t_max, world_rng, progress
    )
    reached = plan.t_end <= t_max + 1e-9
    executed = plan if reached else plan.until(min(t, plan.t_end))
    result = _measure(
        problem, options, seed, robot, executed, reached, static_path, tracks, replans, plans
    )
    if len(replans) >= MAX_REPLANS and not result.reached_goal:
        result.status = f"gave up after {MAX_REPLANS} replans"
    return result


@dataclass(frozen=True)
class RobotState:
    """What a local controller knows of the robot at a control instant.

    Attributes
    ----------
    xy : (2,) ndarray
        Position, units.
    theta : float
        Heading, rad (unwrapped).
    v, w : float
        Linear (units/s, negative backwards) and angular (rad/s) velocity of the last period.
    """

    xy: np.ndarray
    theta: float
    v: float
    w: float


class LocalController(Protocol):
    """A local planner that :func:`simulate_local` drives: every control period it gets the
    robot's state and the sensed obstacles and returns the velocities for the next period.

    ``name`` is what the result reports as its planner (its strategy in lower case).
    """

    name: str

    def reset(self, xy: np.ndarray, theta: float) -> None:
        """Start a new run at ``xy`` facing ``theta``."""

    def step(self, state: RobotState, obstacles: Observations, t: float) -> tuple[float, float]:
        """``(v, w)`` for the period from ``t``; ``obstacles`` as :func:`simulate` senses them
        (index -> (position, velocity, radius), measured at ``t``)."""


def simulate_local(
    problem: Problem,
    controller: LocalController,
    reference_path: np.ndarray,
    options: DynamicOptions | None = None,
    seed: int | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> SimulationResult:
    """Drive the robot with a local controller among the problem's moving obstacles.

    Every ``sample_time`` the robot senses as in :func:`simulate`, asks ``controller.step`` for
    ``(v, w)`` and drives them for one period on an exact arc (knots every
    ``sample_time / SUBSTEPS``). The plant saturates commands at the robot's limits (speed,
    turn rate, ``|v| + |w| L / 2 <= v_w``). Within one period's travel (or SR/10) of the goal,
    with the straight line free, it drives the last chord in. The executed motion's static
    validity is checked exactly afterwards: unlike a planned path, a controller's arcs are not,
    and the result's ``status`` says when the robot clipped a static obstacle.

    Parameters
    ----------
    problem : Problem
        As for :func:`simulate`.
    controller : LocalController
    reference_path : (n, 2) array
        The path the controller follows (units): its first point is the start, its first
        segment the initial heading, its length sets the time limit (``4 L / v + 60`` s unless
        ``options.max_time``); fewer than two points report "no static path".
    options : DynamicOptions, optional
        Only ``max_time``, ``heading_changes`` and ``heading_change_deg`` are used (the same
        obstacles and the same random turns as :func:`simulate` with the same seed).
    seed : int, optional
        Seeds the obstacles' random heading changes exactly as :func:`simulate` does.
    progress : callable, optional
        Called as ``progress(t, t_max)`` after every step.

    Returns
    -------
    SimulationResult
        ``planner`` is ``controller.name``, ``strategy`` its lower case; no replans.
    """
    options = options or DynamicOptions()
    robot = RobotModel.of(problem)
    name = str(controller.name)
    opts = dataclasses.replace(options, strategy="none", planner=name)
    path = np.asarray(reference_path, dtype=float).reshape(-1, 2)
    tracks = [ObstacleTrack.from_obstacle(m) for m in problem.moving_obstacles]
    blocked = _blocked(problem, tracks, robot) if len(path) >= 2 else "no static path"
    if blocked:
        result = _no_static_path(problem, opts, seed, robot, path, tracks, blocked)
    else:
        _, world_rng = np.random.default_rng(seed).spawn(2)
        t_max = options.max_time
        if t_max is None:
            t_max = 4.0 * path_length(path) / robot.speed + 60.0
        _check_steps(t_max, robot.sample_time)
        world = World.from_problem(problem)
        motion, reached = _drive_local(problem, controller, robot, world, path, tracks, options,
                                       t_max, world_rng, progress)  # fmt: skip
        # The driven motion is the only "plan" a local controller has (the animation draws it).
        result = _measure(problem, opts, seed, robot, motion, reached, path, tracks, [],
                          [(0.0, motion)])  # fmt: skip
        free = world.segments_free(motion.xy[:-1], motion.xy[1:])
        if not (free.all() and world.points_in_bounds(motion.xy).all()):
            result.status = "clipped a static obstacle or left the bounds"
    result.strategy = name.lower()
    return result


def _drive_local(problem, controller, robot, world, path, tracks, options, t_max, world_rng,
                 progress) -> tuple[Motion, bool]:  # fmt: skip
    """The control loop of :func:`simulate_local`: the executed motion and whether it arrived."""
    dt = robot.sample_time
    goal = np.asarray(problem.goal, dtype=float)
    x = path[0].copy()
    th = math.atan2(path[1, 1] - path[0, 1], path[1, 0] - path[0, 0])
    controller.reset(x.copy(), th)
    v = w = 0.0
    ts, xs, ths = [0.0], [x.copy()], [th]
    change_p = options.heading_changes * dt
    tol = goal_tolerance(robot)
    taus = dt * np.arange(1, SUBSTEPS + 1) / SUBSTEPS
    k = 0
    while k * dt <= t_max and k < MAX_STEPS:
        t = k * dt
        d = math.dist(x, goal)
        if d <= tol and world.motion_free(*x, *goal):
            ts.append(t + d / robot.speed)
            xs.append(goal.copy())
            ths.append(th)
            return Motion(np.array(ts), np.array(xs), np.array(ths)), True
        obs = _sense(x, tracks, t, robot.sensor_range)
        v, w = _saturate(robot, *controller.step(RobotState(x.copy(), th, v, w), obs, t))
        xs.extend(arc_position(x, th, v, w, taus))
        ths.extend(th + w * taus)
        ts.extend(t + taus)
        x, th = xs[-1].copy(), float(ths[-1])
        k += 1
        if change_p > 0:
            _turn_at_random(tracks, k * dt, change_p, options.heading_change_deg, world_rng)
        if progress is not None:
            progress(k * dt, t_max)
    return Motion(np.array(ts), np.array(xs), np.array(ths)), False


def goal_tolerance(robot: RobotModel) -> float:
    """How near the goal a local controller's robot must be at a control instant for
    :func:`simulate_local` to drive the last chord in: one period's travel, at least SR/10."""
    return max(robot.speed * robot.sample_time, 0.1 * robot.radius)


def _saturate(robot: RobotModel, v: float, w: float) -> tuple[float, float]:
    """The command the wheels can drive: speed and turn rate clipped, then both scaled down
    until ``|v| + |w| L / 2 <= v_w``."""
    if not (math.isfinite(v) and math.isfinite(w)):
        raise SimulationError(f"the local controller commanded v = {v}, w = {w}")
    v = min(max(v, -robot.speed), robot.speed)
    if robot.turn_rate is not None:
        w = min(max(w, -robot.turn_rate), robot.turn_rate)
        need = abs(v) + abs(w) * 0.5 * (robot.track_width or 0.0)
        if need > robot.wheel_speed:
            v, w = v * robot.wheel_speed / need, w * robot.wheel_speed / need
    return v, w


def _check_steps(t_max: float, sample_time: float) -> None:
    """Refuse a run that would take more than MAX_STEPS control steps."""
    steps = t_max / sample_time
    if steps > MAX_STEPS:
        raise SimulationError(
            f"robot.sample_time {sample_time:g} s would take {steps:.3g} control steps to drive "
            f"the path (simulated time up to {t_max:.3g} s); at most {MAX_STEPS:,}: use a longer "
            "sample time or a higher speed"
        )


def _blocked(problem: Problem, tracks: list[ObstacleTrack], robot: RobotModel) -> str:
    """Why the robot cannot set off: an obstacle on its start at t = 0, or one that never moves
    on its goal (empty when neither)."""
    for j, tr in enumerate(tracks):
        contact = robot.radius + tr.radius
        if math.dist(tr.position(0.0), problem.start) < contact:
            return f"start blocked: moving_obstacles[{j}] overlaps the robot at t = 0"
        if tr.speed == 0 and math.dist(tr.position(0.0), problem.goal) < contact:
            return f"goal blocked: moving_obstacles[{j}] stands still on the goal"
    return ""


def _static_path(problem: Problem, options: DynamicOptions, seed: int | None) -> np.ndarray:
    """The initial static path, planned with the options' planner (empty when unsolved)."""
    from ..planners import solve

    res = solve(
        problem,
        options.planner,
        time_limit=options.initial_time,
        seed=seed,
        params=dict(options.params),
    )
    return res.path if res.solved else np.empty((0, 2))


def _drive(plan, tracks, robot, manager, options, margin, t_max, world_rng, progress):
    """The control loop: every sample time sense, predict and react, until the plan ends or
    ``t_max``. Returns ``(plan, t, plans, replans)``."""
    plans = [(0.0, plan)]
    replans: list[Replan] = []
    busy_until = -math.inf
    last_short = -math.inf
    change_p = options.heading_changes * robot.sample_time
    t = 0.0
    k = 0
    while t < plan.t_end - 1e-9 and t <= t_max and len(replans) < MAX_REPLANS:
        obs = _sense(plan.position(t), tracks, t, robot.sensor_range)
        threats = []
        if obs and options.strategy != "none":
            threats = predict_threats(plan, t, obs, robot.radius, 0.5 * margin)
            rec = None
            if threats and t >= busy_until:
                plan, rec = manager.react(t, plan, obs, threats)
                busy_until = t + rec.budget
            elif threats and threats[0].t_enter <= busy_until + robot.sample_time:
                # A new threat while the planner is busy and before it can help: react at once.
                plan, rec = manager.fallback(t, plan, obs, threats, t)
            if rec is not None:
                replans.append(rec)
                plans.append((t, plan))
        if (
            not threats
            and options.reshorten
            and options.strategy == "contour"
            and len(plans) > 1
            and t - last_short >= RESHORTEN_PERIOD
        ):
            # No collision predicted: the bends of an earlier detour may no longer be needed.
            last_short = t
            shorter = manager.reshorten(t, plan, obs)
            if shorter is not None:
                plan = shorter
                plans.append((t, plan))
        k += 1
        t = k * robot.sample_time
        if change_p > 0:
            _turn_at_random(tracks, t, change_p, options.heading_change_deg, world_rng)
        if progress is not None:
            progress(min(t, plan.t_end), plan.t_end)
    return plan, t, plans, replans


def _sense(p: np.ndarray, tracks: list[ObstacleTrack], t: float, sensor_range: float):
    """The obstacles whose disc comes within the sensor range: index -> (position, velocity,
    radius), measured at time ``t``."""
    obs = {}
    for j, tr in enumerate(tracks):
        q = tr.position(t)
        if math.hypot(*(q - p)) - tr.radius <= sensor_range:
            obs[j] = (q, tr.velocity, tr.radius)
    return obs


def _turn_at_random(tracks, t, probability, sigma_deg, rng) -> None:
    """Each obstacle turns with ``probability`` by a normal angle of ``sigma_deg`` degrees."""
    for tr in tracks:
        if rng.random() < probability:
            tr.turn(t, tr.heading + math.radians(rng.normal(0.0, sigma_deg)))


def _measure(problem, options, seed, robot, executed, reached, static_path, tracks, replans,
             plans) -> SimulationResult:  # fmt: skip
    """Separations at every sample and exactly in between, collisions, arrival."""
    samples = executed.sample(robot.sample_time)
    contact = [robot.radius + tr.radius for tr in tracks]
    min_sep: list[float | None] = []
    min_cont: list[float | None] = []
    collisions = np.zeros(len(samples), dtype=bool)
    for tr, c in zip(tracks, contact, strict=True):
        d = np.hypot(*(samples[:, 1:3] - tr.position(samples[:, 0])).T)
        collisions |= d < c * (1 - 1e-9)
        min_sep.append(float(d.min()))
        dc, _ = closest_approach(
            executed, tr.position, executed.t[0], executed.t_end, tr.breakpoints()
        )
        min_cont.append(dc)
    at_goal = np.allclose(executed.end, problem.goal, atol=1e-6 + problem.goal_tolerance)
    return SimulationResult(
        problem=problem.name,
        strategy=options.strategy,
        planner=options.planner,
        seed=seed,
        reached_goal=bool(reached and at_goal),
        collisions=int(collisions.sum()),
        min_separation=min_sep,
        min_separation_continuous=min_cont,
        contact_distance=contact,
        total_time=executed.t_end,
        path_length=executed.path_length(),
        static_length=path_length(static_path),
        sample_time=robot.sample_time,
        motion=executed,
        static_path=static_path,
        tracks=tracks,
        replans=replans,
        plans=plans,
    )


def _no_static_path(problem, options, seed, robot, static_path, tracks,
                    status: str = "no static path") -> SimulationResult:  # fmt: skip
    """The result when the robot cannot set off (no static path, a blocked start or goal)."""
    n = len(tracks)
    return SimulationResult(
        problem=problem.name,
        strategy=options.strategy,
        planner=options.planner,
        seed=seed,
        reached_goal=False,
        collisions=0,
        min_separation=[None] * n,
        min_separation_continuous=[None] * n,
        contact_distance=[robot.radius + tr.radius for tr in tracks],
        total_time=0.0,
        path_length=0.0,
        static_length=None,
        sample_time=robot.sample_time,
        motion=None,
        static_path=static_path,
        tracks=tracks,
        replans=[],
        plans=[],
        status=status,
    )
