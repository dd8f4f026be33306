"""Moving obstacles (paper section 4.2, eqs. 14-15): prediction, replanning, simulation.

- :mod:`.motion`: timed stop-and-turn motions of the robot and the obstacles' tracks, with the
  exact closest approach and first entry (piecewise linear in time: quadratics, not sampling);
- :mod:`.prediction`: predicted collisions (:class:`Threat`) and swept capsules;
- :mod:`.options`: :class:`DynamicOptions`, the robot as driven, what it senses;
- :mod:`.result`: the records of a run (:class:`SimulationResult`, :class:`Replan`);
- :mod:`.world_view`: sensing, random turns and measurement, shared by every control loop;
- :mod:`.manager`: the :class:`ReplanningManager` (contour detours up and down, verification,
  wait and step-aside fallbacks), as a :class:`ReplanPolicy` asks;
- :mod:`.replanning`: the replanning strategies' control loop; :mod:`.local`:
  :func:`simulate_local`, the harness of a local controller (a :class:`LocalController`);
- :mod:`.dwa`: the DWA peer, a DWB-like local controller, and :mod:`.navgrid`, the grid of its
  distance critics;
- :mod:`.strategies`: ``contour``, ``global``, ``none`` and ``dwa``, one class each, and
  :mod:`.registry`, strategies by name (third-party ones through the entry-point group
  ``rrtpso_ompl.strategies``); :mod:`.simulation`: :func:`simulate`, which runs the named one;
- :mod:`.bounds`: the limits strategies are measured against (the static optimum at full speed,
  and a clairvoyant wait-then-drive baseline).

Imports run one way, in that order (``options`` first, ``simulation`` last).
"""

from .bounds import ClairvoyantWait, arrival_lower_bound, clairvoyant_wait
from .local import LocalController, simulate_local
from .manager import Detour, ReplanningManager, ReplanPolicy
from .motion import Motion, ObstacleTrack, closest_approach, first_entry
from .options import DynamicOptions, RobotModel, RobotState, SimulationError
from .prediction import Threat, capsule, predict_threats
from .registry import (
    STRATEGY_ENTRY_POINT_GROUP,
    StrategyRegistry,
    UnknownStrategyError,
    default_strategies,
)
from .result import Replan, SimulationResult
from .simulation import simulate
from .strategies import Strategy

__all__ = [
    "STRATEGY_ENTRY_POINT_GROUP",
    "ClairvoyantWait",
    "Detour",
    "DynamicOptions",
    "LocalController",
    "Motion",
    "ObstacleTrack",
    "Replan",
    "ReplanPolicy",
    "ReplanningManager",
    "RobotModel",
    "RobotState",
    "SimulationError",
    "SimulationResult",
    "Strategy",
    "StrategyRegistry",
    "Threat",
    "UnknownStrategyError",
    "arrival_lower_bound",
    "capsule",
    "clairvoyant_wait",
    "closest_approach",
    "default_strategies",
    "first_entry",
    "predict_threats",
    "simulate",
    "simulate_local",
]
