"""The paper's evaluation protocol at scale (SPEC section 7).

- :mod:`lilium.experiments.config`  TOML config and the presets ``quick`` and ``paper``
- :mod:`lilium.experiments.store`   SQLite results store (one row per finished SFO, WAL) and
  the lock that keeps a second run off a database
- :mod:`lilium.experiments.dataset` the dataset index, its files and its fingerprint, checked
  before the first SFO
- :mod:`lilium.experiments.runner`  task enumeration, local process pool or Dask, resume
- :mod:`lilium.experiments.processes` local workers that end when their parent dies
- :mod:`lilium.experiments.report`  the paper's tables, Wilcoxon tests and plots
"""

from .config import PRESETS, ExperimentConfig, load_config
from .runner import enumerate_tasks, run_experiment, run_task
from .store import ResultStore

__all__ = [
    "PRESETS",
    "ExperimentConfig",
    "ResultStore",
    "enumerate_tasks",
    "load_config",
    "run_experiment",
    "run_task",
]
