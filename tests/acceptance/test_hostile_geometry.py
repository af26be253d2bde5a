"""Degenerate or damaged geometry: mesh fragments, unreferenced vertices, twins at one place,
planar landmarks, masks of every pixel (``hostile_geometry.py``)."""

import pytest
from hostile_geometry import geometry_probes
from hostile_machinery import check_probe, probe_params

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("probe", probe_params(geometry_probes()))
def test_geometry_probe(probe, workspace):
    check_probe(probe, workspace)
