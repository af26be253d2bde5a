"""The shared value checks: one rule and one message wherever an interval is given."""

import doctest

import numpy as np
import pytest

import lilium.validation
from lilium.validation import check_interval


def test_docstring_examples():
    result = doctest.testmod(lilium.validation, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


def test_interval_is_returned_as_floats():
    assert check_interval(np.array([2, 2]), "x") == (2.0, 2.0)


@pytest.mark.parametrize(
    "bad", [(0, 1), (-1, 1), (2, 1), (1, np.inf), (np.nan, 1), (1,), (1, 2, 3), "12", (True, 2)]
)
def test_bad_intervals_name_the_value(bad):
    with pytest.raises(ValueError, match=r"^where: x must be a finite interval \[lo, hi\]"):
        check_interval(bad, "where: x")
