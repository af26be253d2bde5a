"""Valid files that do not belong together: another photo's landmarks or mask, implausible
soft tissue, a wrong view (``hostile_semantic.py``)."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_semantic import semantic_probes

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(semantic_probes()))
def test_semantic_probe(probe, workspace):
    check_probe(probe, workspace)
