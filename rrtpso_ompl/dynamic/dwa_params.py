"""The DWA peer's parameters (:class:`DWAParams`), apart from the controller (:mod:`.dwa`) so that
listing them (the strategy registry, the command line) loads neither its grid nor SciPy."""

from __future__ import annotations

from ..params import Rule, declared, param

__all__ = ["DWAParams"]


def _positive(*names: str) -> Rule:
    return Rule(names, lambda *v: all(x > 0 for x in v), ", ".join(names) + " > 0")


@declared(
    rules=[
        _positive("sim_time", "accel_time", "resolution"),
        Rule(("v_samples", "w_samples"), lambda v, w: v * w <= 10_000,
             "v_samples * w_samples <= 10,000"),
    ]
)  # fmt: skip
class DWAParams:
    """The DWA's parameters (seconds, radians; lengths in robot radii SR)."""

    sim_time: float = param(
        2.0,
        "Roll-out time of each trajectory (at least one period plus half of accel_time is "
        "rolled out, so that every braking arc is checked).",
        unit="s",
        low=0.0,
    )
    obstacle_time: float = param(
        6.0,
        "How far ahead the moving obstacles are predicted: a trajectory goes on straight at full "
        "speed after sim_time (the robot turns, then drives), a stop stays.",
        unit="s",
        low=0.0,
    )
    v_samples: int = param(9, "Linear velocities sampled across the dynamic window.", low=2)
    w_samples: int = param(15, "Angular velocities sampled across the dynamic window.", low=2)
    accel_time: float = param(
        0.3,
        "Time to reach full speed (or full turn rate) from rest: the acceleration limits are "
        "v_max / accel_time and w_max / accel_time.",
        unit="s",
        low=0.0,
    )
    reverse: float = param(
        1.0, "Fastest backwards speed as a fraction of v_max (0: never backwards).",
        low=0.0, high=1.0,
    )  # fmt: skip
    prune_distance: float = param(
        12.0, "Length of the local plan ahead of the robot's progress.", unit="SR", low=0.0
    )
    forward_point: float = param(
        1.3, "Distance ahead of a trajectory's end at which the align critics look.", unit="SR",
        low=0.0,
    )  # fmt: skip
    path_dist: float = param(1.0, "Weight of the PathDist critic.", low=0.0)
    goal_dist: float = param(2.0, "Weight of the GoalDist critic.", low=0.0)
    path_align: float = param(0.5, "Weight of the PathAlign critic.", low=0.0)
    goal_align: float = param(0.5, "Weight of the GoalAlign critic.", low=0.0)
    obstacle: float = param(2.0, "Weight of the Obstacle critic.", low=0.0)
    prefer_forward: float = param(
        2.0, "Weight of the PreferForward critic (the backwards penalty, per v_max).", low=0.0
    )
    inflation: float = param(
        1.0, "Decay length of the obstacle cost exp(-clearance / inflation).", unit="SR", low=0.0
    )
    oscillation_distance: float = param(
        0.2, "Motion after which the oscillation critic forgets a sign flip.", unit="SR", low=0.0
    )
    oscillation_angle: float = param(
        0.2, "Turn after which the oscillation critic forgets a sign flip.", unit="rad", low=0.0
    )
    rotate_threshold_deg: float = param(
        60.0,
        "Heading error to the local plan beyond which a nearly stopped robot turns in place.",
        unit="deg",
        low=0.0,
    )
    progress_distance: float = param(
        0.5,
        "The progress checker: moving less than this in progress_time starts a recovery.",
        unit="SR",
        low=0.0,
    )
    progress_time: float = param(10.0, "The progress checker's time window.", unit="s", low=0.0)
    backup_time: float = param(
        1.0, "How long a recovery backs up (at half the reverse speed).", unit="s", low=0.0
    )
    max_recoveries: int = param(10, "Most recoveries in a run.", low=0, high=1000)
    resolution: float = param(
        0.25, "Cell size of the grid of the distance critics.", unit="SR", low=0.0
    )
