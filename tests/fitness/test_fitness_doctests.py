"""The examples in the fitness docstrings run."""

import doctest
import importlib

import numpy as np
import pytest


@pytest.mark.parametrize("name", ["skof", "pll", "camera_penalty"])
def test_docstring_examples(name):
    module = importlib.import_module(f"lilium.fitness.{name}")
    result = doctest.testmod(module, extraglobs={"np": np}, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
