"""The same case transformed in ways that must not change the answer: resampled, padded,
another file format, the skull moved, inputs in another order (``hostile_metamorphic.py``)."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_metamorphic import metamorphic_probes

pytestmark = pytest.mark.slow

#: The Lilium runs of this group take longer than the campaign's 60 s.
LIMIT_S = 120


@pytest.mark.parametrize("probe", probe_params(metamorphic_probes()))
def test_metamorphic_probe(probe, workspace):
    check_probe(probe, workspace, LIMIT_S)
