"""What the HTML reports and the console show against each ``result.json``
(``hostile_report.py``)."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_report import report_probes

pytestmark = pytest.mark.slow

#: The Lilium runs of this group take longer than the campaign's 60 s.
LIMIT_S = 120


_NO_TIE = (
    "fails on main (05067e4) under the former runner too: the probe's premise no longer holds, "
    "no tie to break (log10 LRs +1.23 and +0.49 with the shipped calibration); the tie needs "
    "another pair of candidates"
)

#: Probes whose premise the shipped calibration no longer gives (not a bug of the commands).
KNOWN_LIMITS = {
    "report lineup candidates tied at the calibration bound": _NO_TIE,
    "report lineup tie, candidates given in the other order": _NO_TIE,
}


@pytest.mark.parametrize("probe", probe_params(report_probes(), known_limits=KNOWN_LIMITS))
def test_report_probe(probe, workspace):
    check_probe(probe, workspace, LIMIT_S)
