"""Moving obstacles (paper section 4.2, eqs. 14-15): prediction, replanning, simulation.

- :mod:`.motion`: timed stop-and-turn motions of the robot and the obstacles' tracks, with the
  exact closest approach and first entry (piecewise linear in time: quadratics, not sampling);
- :mod:`.prediction`: predicted collisions (:class:`Threat`) and swept capsules;
- :mod:`.manager`: the :class:`ReplanningManager` (contour detours up and down, verification,
  wait and step-aside fallbacks);
- :mod:`.simulation`: :func:`simulate`, the control loop, and its :class:`SimulationResult`;
  :func:`simulate_local`, the same harness for a local controller (a :class:`LocalController`);
- :mod:`.dwa`: the DWA peer, a DWB-like local controller, and :mod:`.navgrid`, the grid of its
  distance critics;
- :mod:`.bounds`: the limits strategies are measured against (the static optimum at full speed,
  and a clairvoyant wait-then-drive baseline).
"""

from .bounds import ClairvoyantWait, arrival_lower_bound, clairvoyant_wait
from .manager import Detour, Replan, ReplanningManager
from .motion import Motion, ObstacleTrack, closest_approach, first_entry
from .prediction import Threat, capsule, predict_threats
from .simulation import (
    STRATEGIES,
    DynamicOptions,
    LocalController,
    RobotModel,
    RobotState,
    SimulationResult,
    simulate,
    simulate_local,
)

__all__ = [
    "STRATEGIES",
    "ClairvoyantWait",
    "Detour",
    "DynamicOptions",
    "LocalController",
    "Motion",
    "ObstacleTrack",
    "Replan",
    "ReplanningManager",
    "RobotModel",
    "RobotState",
    "SimulationResult",
    "Threat",
    "arrival_lower_bound",
    "capsule",
    "clairvoyant_wait",
    "closest_approach",
    "first_entry",
    "predict_threats",
    "simulate",
    "simulate_local",
]
