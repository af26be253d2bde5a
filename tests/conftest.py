import signal

import pytest

from standin_case import make_standin_case

# A pytest started in the background of a non-interactive shell (``cmd &``) inherits SIGINT
# ignored, and so would every command the tests start: the Ctrl-C tests would then see no
# interrupt at all. A handler (not the ignored disposition) is what a started command resets.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


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


@pytest.fixture
def calibration_without_ranges(tmp_path):
    """The shipped calibration without its features' ranges: the stand-in case (a noise-free
    ellipsoid "skull") fits its photo far better than any generated person, so the shipped
    models read it as outside the calibration; tests of the other rules use this file."""
    import json

    from lilium.io.calibration import shipped_path

    data = json.loads(shipped_path().read_text())
    for model in data["models"].values():
        model.pop("ranges", None)
    path = tmp_path / "calibration-without-ranges.json"
    path.write_text(json.dumps(data))
    return path
