"""Hostile inputs of the protocol's runs: ``lilium experiment``, ``report`` and ``demo``
(``hostile_runs.py``)."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_runs import run_probes

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(run_probes()))
def test_runs_probe(probe, workspace):
    check_probe(probe, workspace)
