"""The paper's evaluation protocol at scale (docs/method/evaluation.md).

- :mod:`lilium.experiments.config`  TOML config and the presets ``quick`` and ``paper``
- :mod:`lilium.experiments.store`   SQLite results store (one row per finished SFO, WAL) and
  the lock that keeps a second run off a database
- :mod:`lilium.experiments.dataset` the dataset index, its files and its fingerprint, checked
  before the first SFO
- :mod:`lilium.experiments.runner`  task enumeration, local process pool or Dask, resume
- :mod:`lilium.experiments.report`  the paper's tables, Wilcoxon tests and plots
"""

import importlib

#: The package's names and the modules that define them, imported on first use: every
#: ``lilium`` command registers ``lilium experiment`` (its presets, from ``config``), and the
#: runner and the store (about 25 ms of imports) are for ``lilium experiment`` alone.
_EXPORTS = {
    "PRESETS": "config",
    "ExperimentConfig": "config",
    "load_config": "config",
    "enumerate_tasks": "runner",
    "run_experiment": "runner",
    "run_task": "runner",
    "ResultStore": "store",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
