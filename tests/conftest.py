import pytest

from standin_case import make_standin_case


@pytest.fixture(autouse=True)
def _bugs_raise(monkeypatch):
    """``lilium`` commands re-raise unexpected exceptions in tests (``LILIUM_DEBUG=1``): the CLI's
    last-resort handler turns them into one line for users, but a bug must fail its test with
    the traceback. Tests of that handler unset the variable."""
    monkeypatch.setenv("LILIUM_DEBUG", "1")


@pytest.fixture
def case(tmp_path):
    """A stand-in subject folder and a frontal photo folder with known camera."""
    return make_standin_case(tmp_path / "case", seed=0)
