"""Hostile inputs of ``lilium lineup``, ``calibrate``, ``--calibration`` and the joint SFO
(``hostile_casework.py``)."""

import pytest
from hostile_casework import casework_probes
from hostile_machinery import check_probe, probe_params

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(casework_probes()))
def test_casework_probe(probe, workspace):
    check_probe(probe, workspace)
