"""Deprecated: the old name of :mod:`rrtpso_ompl.harness` and :mod:`rrtpso_ompl.groundtruth`.

``rrtpso_ompl.evaluation`` held both the harness (batches, benchmarks, worker processes, results
files, OMPL logs) and the ground truth (the exact optimum, certificates, generated problems);
they are subpackages of their own now. Importing this module, or ``rrtpso_ompl.evaluation.X``
for one of its old modules, still works and warns.
"""

from __future__ import annotations

import importlib
import sys
import warnings

from .. import groundtruth, harness
from ..groundtruth import *  # noqa: F403 - the old public names
from ..harness import *  # noqa: F403

warnings.warn(
    "rrtpso_ompl.evaluation is deprecated: use rrtpso_ompl.harness (batch, bench, workers, "
    "results files, OMPL logs) and rrtpso_ompl.groundtruth (optimum, certify, generate)",
    DeprecationWarning,
    stacklevel=2,
)

# The old module paths (rrtpso_ompl.evaluation.optimum, ...) name the moved modules.
_MOVED = {
    "certify": "groundtruth",
    "generate": "groundtruth",
    "optimum": "groundtruth",
    "batch": "harness",
    "bench": "harness",
    "ompl_log": "harness",
    "results_file": "harness",
    "workers": "harness",
}
for _name, _package in _MOVED.items():
    sys.modules[f"{__name__}.{_name}"] = importlib.import_module(f"rrtpso_ompl.{_package}.{_name}")

__all__ = [*groundtruth.__all__, *harness.__all__]
