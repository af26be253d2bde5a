"""Crashes, interrupts, resumes and concurrency of the long runs (``hostile_resume.py``,
``hostile_scenarios.py``): a run resumed after a crash's leftovers ends as an uninterrupted run
or refuses in one line; killed, interrupted (Ctrl-C), run twice at once or under a file-size
limit, each command ends cleanly and its rerun completes."""

import pytest
from hostile_machinery import check_probe, probe_params
from hostile_resume import resume_probes
from hostile_scenarios import SCENARIOS, Scenarios

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(resume_probes()))
def test_resume_probe(probe, workspace):
    check_probe(probe, workspace)


@pytest.fixture(scope="module")
def scenarios(tmp_path_factory):
    """The scenarios' inputs (a generated dataset, the stand-in case and two scaled photos),
    made once."""
    s = Scenarios(tmp_path_factory.mktemp("scenarios"))
    s.prepare()
    return s


@pytest.mark.parametrize("scenario", [pytest.param(f, id=name) for name, f in SCENARIOS])
def test_resume_scenario(scenario, scenarios):
    problem = scenario(scenarios)
    assert problem is None, problem
