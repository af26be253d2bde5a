"""Realistic hostile inputs of ``lilium photo``, ``import-ct`` and ``synth``: EXIF that lies,
image modes, faces, DICOM series, NIfTI affines, counts (``hostile_inputs.py``)."""

import pytest
from hostile_inputs import input_probes
from hostile_machinery import check_probe, probe_params

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(input_probes()))
def test_inputs_probe(probe, workspace):
    check_probe(probe, workspace)
