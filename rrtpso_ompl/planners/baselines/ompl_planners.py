"""OMPL's geometric planners as registry entries: their parameters, capabilities and figures.

Parameter names, defaults and ranges are OMPL's own (``declareParam`` in each planner's ``.cpp``);
the test suite checks every default against the planner's getter so these declarations cannot
drift. They are applied through the setters, because ``Planner.params()`` is not usable from
Python. RRTstarPSO reuses the declarations of the RRT* parameters it passes to its inner RRT*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from ompl import geometric as og

from ...params import ParamSpec, ParamTable
from ..base import PlannerStats
from ..registry import Capabilities, PlannerEntry
from ..result import BenchmarkRun

__all__ = ["PLANNERS", "RRTSTAR_PARAMS", "UNAVAILABLE", "AnytimeStats"]

# --- parameters shared by several planners (OMPL's names) --------------------------------------
RANGE = ParamSpec(
    "range",
    float,
    0.0,
    "Longest motion added to the tree; 0 lets OMPL choose (20% of the space's extent).",
    unit="length",
    low=0.0,
    setter="setRange",
    getter="getRange",
)
GOAL_BIAS = ParamSpec(
    "goal_bias",
    float,
    0.05,
    "Probability of sampling the goal.",
    low=0.0,
    high=1.0,
    setter="setGoalBias",
    getter="getGoalBias",
)
INTERMEDIATE = ParamSpec(
    "intermediate_states",
    bool,
    False,
    "Add the intermediate states of each motion to the tree.",
    setter="setIntermediateStates",
    getter="getIntermediateStates",
)
REWIRE = ParamSpec(
    "rewire_factor",
    float,
    1.1,
    "Scale of the rewiring radius/number of neighbours (> 1 keeps asymptotic optimality).",
    low=1.0,
    high=10.0,
    setter="setRewireFactor",
    getter="getRewireFactor",
)
K_NEAREST = ParamSpec(
    "use_k_nearest",
    bool,
    True,
    "Rewire with the k nearest neighbours instead of a radius.",
    setter="setKNearest",
    getter="getKNearest",
)
DELAY_CC = ParamSpec(
    "delay_collision_checking",
    bool,
    True,
    "Check motions for collision only when they could improve the cost.",
    setter="setDelayCC",
    getter="getDelayCC",
)
BORDER = ParamSpec(
    "border_fraction",
    float,
    0.9,
    "Fraction of time spent on the border of the explored region.",
    low=0.0,
    high=1.0,
    setter="setBorderFraction",
    getter="getBorderFraction",
)
MIN_VALID = ParamSpec(
    "min_valid_path_fraction",
    float,
    0.5,
    "Fraction of a motion that must be valid to be kept.",
    low=0.0,
    high=1.0,
    setter="setMinValidPathFraction",
    getter="getMinValidPathFraction",
)
FAILED_SCORE = ParamSpec(
    "failed_expansion_score_factor",
    float,
    0.5,
    "Score factor of a cell whose expansion failed.",
    low=0.0,
    high=1.0,
    setter="setFailedExpansionCellScoreFactor",
    getter="getFailedExpansionCellScoreFactor",
)
MAX_NN = ParamSpec(
    "max_nearest_neighbors",
    int,
    10,
    "Neighbours each roadmap vertex tries to connect to.",
    low=1,
    high=1000,
    setter="setMaxNearestNeighbors",
    getter=None,
)

TREE_PRUNING = ParamSpec(
    "tree_pruning",
    bool,
    False,
    "Prune tree vertices that cannot improve the solution.",
    setter="setTreePruning",
    getter="getTreePruning",
)
INFORMED_SAMPLING = ParamSpec(
    "informed_sampling",
    bool,
    False,
    "Sample only the informed set (ellipse) once a solution exists.",
    setter="setInformedSampling",
    getter="getInformedSampling",
)

#: The RRT* parameters (also those RRTstarPSO passes to its inner RRT*).
RRTSTAR_PARAMS = ParamTable(
    RANGE,
    GOAL_BIAS,
    REWIRE,
    K_NEAREST,
    DELAY_CC,
    TREE_PRUNING,
    ParamSpec(
        "prune_threshold",
        float,
        0.05,
        "Relative cost improvement that triggers pruning.",
        low=0.0,
        high=1.0,
        setter="setPruneThreshold",
        getter="getPruneThreshold",
    ),
    INFORMED_SAMPLING,
    ParamSpec(
        "sample_rejection",
        bool,
        False,
        "Reject samples that cannot improve the solution.",
        setter="setSampleRejection",
        getter="getSampleRejection",
    ),
    ParamSpec(
        "new_state_rejection",
        bool,
        False,
        "Reject new states that cannot improve the solution.",
        setter="setNewStateRejection",
        getter="getNewStateRejection",
    ),
    ParamSpec(
        "use_admissible_heuristic",
        bool,
        True,
        "Use an admissible cost-to-come heuristic when pruning.",
        setter="setAdmissibleCostToCome",
        getter="getAdmissibleCostToCome",
    ),
    ParamSpec(
        "focus_search",
        bool,
        False,
        "Focus the search on the current solution's neighbourhood.",
        setter="setFocusSearch",
        getter="getFocusSearch",
    ),
    ParamSpec(
        "number_sampling_attempts",
        int,
        100,
        "Attempts to draw an informed sample.",
        low=1,
        high=100000,
        setter="setNumSamplingAttempts",
        getter="getNumSamplingAttempts",
    ),
)


BITSTAR = ParamTable(
    REWIRE,
    ParamSpec(
        "samples_per_batch",
        int,
        100,
        "Samples added per batch.",
        low=1,
        high=1_000_000,
        setter="setSamplesPerBatch",
        getter="getSamplesPerBatch",
    ),
    ParamSpec(
        "use_k_nearest",
        bool,
        True,
        "Use k nearest neighbours instead of a radius.",
        setter="setUseKNearest",
        getter="getUseKNearest",
    ),
    ParamSpec(
        "use_graph_pruning",
        bool,
        True,
        "Prune the graph when the solution improves.",
        setter="setPruning",
        getter="getPruning",
    ),
    ParamSpec(
        "prune_threshold_as_fractional_cost_change",
        float,
        0.05,
        "Relative improvement that triggers pruning.",
        low=0.0,
        high=1.0,
        setter="setPruneThresholdFraction",
        getter="getPruneThresholdFraction",
    ),
    ParamSpec(
        "use_just_in_time_sampling",
        bool,
        False,
        "Generate samples only when needed.",
        setter="setJustInTimeSampling",
        getter="getJustInTimeSampling",
    ),
    ParamSpec(
        "drop_unconnected_samples_on_prune",
        bool,
        False,
        "Drop unconnected samples when pruning.",
        setter="setDropSamplesOnPrune",
        getter="getDropSamplesOnPrune",
    ),
    ParamSpec(
        "stop_on_each_solution_improvement",
        bool,
        False,
        "Return after every improvement.",
        setter="setStopOnSolnImprovement",
        getter="getStopOnSolnImprovement",
    ),
    ParamSpec(
        "find_approximate_solutions",
        bool,
        False,
        "Report approximate solutions.",
        setter="setConsiderApproximateSolutions",
        getter="getConsiderApproximateSolutions",
    ),
)

FMT_FAMILY = ParamTable(
    ParamSpec(
        "num_samples",
        int,
        1000,
        "Samples drawn up front.",
        low=10,
        high=1_000_000,
        setter="setNumSamples",
        getter="getNumSamples",
    ),
    ParamSpec(
        "radius_multiplier",
        float,
        1.1,
        "Scale of the connection radius.",
        low=0.1,
        high=10.0,
        setter="setRadiusMultiplier",
        getter="getRadiusMultiplier",
    ),
    ParamSpec(
        "nearest_k",
        bool,
        True,
        "Use k nearest neighbours instead of a radius.",
        setter="setNearestK",
        getter="getNearestK",
    ),
    ParamSpec(
        "cache_cc",
        bool,
        True,
        "Cache collision-check results.",
        setter="setCacheCC",
        getter="getCacheCC",
    ),
    ParamSpec(
        "heuristics",
        bool,
        False,
        "Order the search with a cost-to-go heuristic.",
        setter="setHeuristics",
        getter="getHeuristics",
    ),
    ParamSpec(
        "extended_fmt",
        bool,
        True,
        "Add samples when the search fails.",
        setter="setExtendedFMT",
        getter="getExtendedFMT",
    ),
)


# Planners that set other defaults in their constructors than their family does.
INFORMED_RRTSTAR = RRTSTAR_PARAMS.with_defaults(tree_pruning=True, informed_sampling=True)
BFMT_PARAMS = FMT_FAMILY.with_defaults(radius_multiplier=1.0, heuristics=True)


@dataclass
class AnytimeStats(PlannerStats):
    """What OMPL's anytime planners (the RRT* family, BIT*) tell about a solve.

    Attributes
    ----------
    iterations : int
        Iterations of the planner's main loop.
    best_cost : float or None
        Cost (here: length) of its best solution, None before the first.
    """

    iterations: int = 0
    best_cost: float | None = None

    @classmethod
    def of(cls, planner: Any) -> AnytimeStats:
        best = planner.bestCost().value()
        return cls(
            iterations=planner.numIterations(), best_cost=best if math.isfinite(best) else None
        )

    def benchmark_run(self, elapsed: float, length: float | None) -> BenchmarkRun:
        # The properties OMPL's own RRT* logs from its PlannerData.
        properties = {
            "iterations": ("INTEGER", self.iterations),
            "best cost": ("REAL", self.best_cost),
        }
        return BenchmarkRun(time=elapsed, solution_length=length, properties=properties)


_ANYTIME = Capabilities(optimizing=True, progress_polling=True, simplify_in_benchmark=True)
_OPTIMIZING = Capabilities(optimizing=True, simplify_in_benchmark=True)
_FEASIBLE = Capabilities(simplify_in_benchmark=True)

# (class name, parameters, capabilities, figures, description, MoveIt name if it differs).
# Anytime planners that poll their condition in the planning thread only have their progress
# sampled; PRM* is optimising but runs a second thread. Keep these in alphabetical order.
_TABLE = [
    ("BFMT", BFMT_PARAMS, _OPTIMIZING, None, "Bidirectional Fast Marching Tree", None),
    ("BITstar", BITSTAR, _ANYTIME, AnytimeStats.of, "Batch Informed Trees", None),
    ("BKPIECE1", ParamTable(RANGE, BORDER, FAILED_SCORE, MIN_VALID), _FEASIBLE, None,
     "Bidirectional KPIECE", "geometric::BKPIECE"),
    ("FMT", FMT_FAMILY, _OPTIMIZING, None, "Fast Marching Tree", None),
    ("InformedRRTstar", INFORMED_RRTSTAR, _ANYTIME, AnytimeStats.of,
     "RRT* with informed sampling", None),
    ("KPIECE1", ParamTable(RANGE, GOAL_BIAS, BORDER, FAILED_SCORE, replace(MIN_VALID, default=0.2)),
     _FEASIBLE, None, "Kinodynamic Planning by Interior-Exterior Cell Exploration",
     "geometric::KPIECE"),
    ("LBKPIECE1", ParamTable(RANGE, BORDER, MIN_VALID), _FEASIBLE, None,
     "Lazy bidirectional KPIECE", "geometric::LBKPIECE"),
    ("PRM", ParamTable(MAX_NN), _FEASIBLE, None, "Probabilistic Roadmap", None),
    ("PRMstar", ParamTable(), _OPTIMIZING, None, "Asymptotically optimal PRM", None),
    ("RRT", ParamTable(RANGE, GOAL_BIAS, INTERMEDIATE), _FEASIBLE, None,
     "Rapidly-exploring Random Tree", None),
    ("RRTConnect", ParamTable(RANGE, INTERMEDIATE), _FEASIBLE, None, "Bidirectional RRT", None),
    ("RRTstar", RRTSTAR_PARAMS, _ANYTIME, AnytimeStats.of,
     "Optimal RRT (the first stage of RRTstarPSO)", None),
    ("SORRTstar", INFORMED_RRTSTAR, _ANYTIME, AnytimeStats.of, "Sorted informed RRT*", None),
]  # fmt: skip


def _entry(cls_name, params, capabilities, stats, description, moveit_name) -> PlannerEntry:
    aliases = [f"geometric::{cls_name}"]
    if moveit_name and moveit_name not in aliases:
        aliases.append(moveit_name)
    return PlannerEntry(
        name=cls_name,
        factory=getattr(og, cls_name),
        params=params,
        description=f"OMPL: {description}",
        aliases=tuple(aliases),
        capabilities=capabilities,
        stats=stats,
    )


PLANNERS = [_entry(*row) for row in _TABLE if hasattr(og, row[0])]
#: Planners the wheel binds but that cannot be used, with the measured reason.
UNAVAILABLE = {
    "AORRTC": (
        "excluded: in the OMPL 2.0.1 wheel AORRTC reports 'Initial search simplified to cost "
        "0' and returns 'Invalid goal' even in a plain SimpleSetup, and with a Python motion "
        "validator it crashes the process (segmentation fault); see docs/planners.md"
    ),
}
