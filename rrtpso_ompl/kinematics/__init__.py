"""From a planned path to wheel commands of a differential-drive robot (paper section 5.1).

Stages, each a pure function:

1. :func:`reference_polynomial`: the paper's cubic fit ``y_ref(x_ref)`` (eq. 6), and
   :func:`reference_curve`: a smooth curve certified collision-free (:mod:`.reference`), with
   :func:`with_goal_heading` the in-place turn to a goal heading at its end;
2. :func:`time_parametrize`: the paper's constant speed, or a profile within ``max_speed``,
   ``max_wheel_speed`` and ``max_accel``, optionally slower where clearance is small, with v and
   omega (eqs. 7-8) (:mod:`.profile`);
3. :func:`wheel_speeds`: eqs. 9-12, and :func:`integrate_wheels`: the corrected eqs. 1-3
   (:mod:`.diffdrive`);
4. :func:`track`: Kanayama's kinematic controller on that model (:mod:`.tracking`);
5. :func:`drive`: all of it for one path (:mod:`.drive`); :func:`drive_car`: a car-like
   robot's curves, forwards and backwards, with no turn in place (:mod:`.car_drive`).

Printed typos and their corrections are listed in ``docs/kinematics.md``.
"""

from .car_drive import drive_car
from .diffdrive import integrate_wheels, wheel_speeds
from .drive import REQUIRED_ROBOT_KEYS, DriveResult, drive
from .profile import (
    CSV_HEADER,
    SLOW_FLOOR,
    Trajectory,
    TrajectoryError,
    check_samples,
    clearance_speed_share,
    time_parametrize,
    turn_limits,
)
from .reference import ReferenceCurve, reference_curve, reference_polynomial, with_goal_heading
from .tracking import TrackingResult, track

__all__ = [
    "CSV_HEADER",
    "REQUIRED_ROBOT_KEYS",
    "SLOW_FLOOR",
    "DriveResult",
    "ReferenceCurve",
    "TrackingResult",
    "Trajectory",
    "TrajectoryError",
    "check_samples",
    "clearance_speed_share",
    "drive",
    "drive_car",
    "integrate_wheels",
    "reference_curve",
    "reference_polynomial",
    "time_parametrize",
    "track",
    "turn_limits",
    "wheel_speeds",
    "with_goal_heading",
]
