import pytest

from standin_case import make_standin_case


@pytest.fixture
def case(tmp_path):
    """A stand-in subject folder and a frontal photo folder with known camera."""
    return make_standin_case(tmp_path / "case", seed=0)
