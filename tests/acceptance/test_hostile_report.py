"""What the HTML reports and the console show against each ``result.json``
(``hostile_report.py``)."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_report import report_probes

pytestmark = pytest.mark.slow

#: The Lilium runs of this group take longer than the campaign's 60 s.
LIMIT_S = 120


@pytest.mark.parametrize("probe", probe_params(report_probes()))
def test_report_probe(probe, workspace):
    check_probe(probe, workspace, LIMIT_S)
