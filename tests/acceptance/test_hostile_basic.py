"""Hostile inputs of ``lilium sfo``, ``case``, ``experiment``, ``report``, ``synth``, ``demo``,
``photo`` and ``import-ct``: broken ``photo.json``, subject folders, meshes, images, masks, face
curves, options, experiment configs and result databases (``hostile_basic.py``)."""

import pytest
from hostile_basic import (
    experiment_probes,
    image_probes,
    option_probes,
    photo_and_ct_probes,
    photo_json_probes,
    skull_probes,
)
from hostile_machinery import check_probe, probe_params

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(
    "probe",
    probe_params(
        photo_json_probes(),
        skull_probes(),
        image_probes(),
        option_probes(),
        experiment_probes(),
        photo_and_ct_probes(),
    ),
)
def test_basic_probe(probe, workspace):
    check_probe(probe, workspace)
