"""What the commands write and where: links in the output folder, names, their own inputs
(``hostile_outputs.py``)."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_outputs import output_probes

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(output_probes()))
def test_outputs_probe(probe, workspace):
    check_probe(probe, workspace)
