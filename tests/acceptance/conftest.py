"""Fixtures of the acceptance campaign: the stand-in case made once per test process, a probe's
own folder (a copy of it), and each command run as users run it."""

import pytest
from hostile_machinery import Workspace


@pytest.fixture(autouse=True)
def _as_users_run_it(monkeypatch):
    """The CLI's own last-resort handler on (``LILIUM_DEBUG`` unset), also for the commands a
    probe's set-up runs in this process: the campaign checks what users see."""
    monkeypatch.delenv("LILIUM_DEBUG", raising=False)


@pytest.fixture(scope="session")
def standin_base(tmp_path_factory):
    """The probes' shared inputs: the stand-in case (``subjects/standin``,
    ``photos/standin_frontal``), made once."""
    from standin_case import make_standin_case

    base = tmp_path_factory.mktemp("standin-base") / "base"
    make_standin_case(base, seed=0)
    return base


@pytest.fixture
def workspace(tmp_path, standin_base):
    """A probe's folder (``tmp_path``): a fresh copy of the stand-in case under ``in/``, ``out/``
    for ``--out``. Data a group generates once (the generated dataset, the reference runs) is
    cached beside it, in the session's temporary folder."""
    return Workspace(tmp_path, standin_base)
