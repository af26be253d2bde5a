"""Experiments, reports and calibrations that must repeat whatever the workers, resumes and
orders (``hostile_determinism.py``): the same seed gives the same rows, files and datasets."""

import pytest
from hostile_detcampaign import _close_clusters
from hostile_determinism import determinism_probes
from hostile_machinery import check_probe, probe_params

pytestmark = pytest.mark.slow

#: Each probe runs a whole experiment (108 SFOs; about a minute on a loaded 2-core machine, more
#: than the campaign's 60 s in a process of its own): the limit here only catches a hang.
LIMIT_S = 600


@pytest.fixture(scope="module", autouse=True)
def _clusters_closed():
    """The Dask clusters a probe starts are closed by its check, or here at the end."""
    yield
    _close_clusters()


@pytest.mark.parametrize("probe", probe_params(determinism_probes()))
def test_determinism_probe(probe, workspace):
    check_probe(probe, workspace, LIMIT_S)
