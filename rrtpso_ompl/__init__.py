"""rrtpso-ompl: the hybrid RRT*PSO path planner as a first-class OMPL planner.

Stages, one module each: :mod:`~rrtpso_ompl.problem` (files) -> :mod:`~rrtpso_ompl.world`
(exact geometry) -> :mod:`~rrtpso_ompl.ompl_setup` (OMPL objects) -> planners
(:mod:`~rrtpso_ompl.rrtstar_pso`, :mod:`~rrtpso_ompl.pso_planner`, OMPL's own) ->
:mod:`~rrtpso_ompl.path_optimizer` and :mod:`~rrtpso_ompl.pso` (post-optimiser) ->
:mod:`~rrtpso_ompl.results` / :mod:`~rrtpso_ompl.plotting`. Around them:
:mod:`~rrtpso_ompl.kinematics` (wheel speeds), :mod:`~rrtpso_ompl.dynamic` (moving obstacles),
:mod:`~rrtpso_ompl.optimum` (the exact shortest path), :mod:`~rrtpso_ompl.batch` and
:mod:`~rrtpso_ompl.bench` (many runs, OMPL benchmark logs via :mod:`~rrtpso_ompl.ompl_log`),
:mod:`~rrtpso_ompl.generate` (random worlds).

The planner classes import OMPL; import them from their modules (``from rrtpso_ompl.rrtstar_pso
import RRTstarPSO``) or through :func:`rrtpso_ompl.registry.default_registry`.
"""

from importlib.metadata import PackageNotFoundError, version

from .model.problem import Problem, ProblemError, load_problem, problem_from_dict
from .model.world import World

try:
    __version__ = version("rrtpso-ompl")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

__all__ = ["Problem", "ProblemError", "World", "__version__", "load_problem", "problem_from_dict"]
