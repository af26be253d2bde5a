"""The pure geometry of benchmarks/studies/chin_profile_geometry.py on shapes with known
answers."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from lilium.ct.mesh import volume_to_mesh

_PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "studies" / "chin_profile_geometry.py"
_SPEC = importlib.util.spec_from_file_location("chin_profile_geometry", _PATH)
chin = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(chin)

VOXEL_MM = 0.5


def _sphere(radius_mm, centre_mm):
    """A sphere meshed by the CT pipeline (outward winding), mm."""
    n = 80
    origin = -20.0
    k, j, i = np.indices((n, n, n), dtype=float) * VOXEL_MM + origin
    r = np.sqrt((i - centre_mm[0]) ** 2 + (j - centre_mm[1]) ** 2 + (k - centre_mm[2]) ** 2)
    v, f = volume_to_mesh(radius_mm - r, 0.0, spacing=(VOXEL_MM,) * 3)
    return v + origin, f


@pytest.fixture(scope="module")
def spheres():
    """Bone: radius 10 at the origin; skin: radius 15, concentric."""
    return _sphere(10.0, (0, 0, 0)), _sphere(15.0, (0, 0, 0))


def test_first_hit_meets_one_triangle():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    f = np.array([[0, 1, 2]])
    hit = chin.first_hit(v, f, np.array([0.25, 0.25, 2.0]), np.array([0.0, 0, -1]))
    np.testing.assert_allclose(hit, [0.25, 0.25, 0.0])
    assert np.isnan(chin.first_hit(v, f, np.array([0.25, 0.25, 2.0]), np.array([0.0, 0, 1]))).all()
    assert np.isnan(chin.first_hit(v, f, np.array([2.0, 2, 2]), np.array([0.0, 0, -1]))).all()


def test_plane_section_lies_on_the_plane_and_the_sphere(spheres):
    (v, f), _ = spheres
    p = chin.plane_section(v, f, 6.0)
    np.testing.assert_allclose(p[:, 0], 6.0)
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 10.0, atol=0.1)


def test_concentric_spheres_give_a_constant_normal_depth(spheres):
    """Parallel surfaces: depth along the normal is 5 mm everywhere; the rises follow the
    radii (skin rise = 1.5 x bone rise); straight down, the depth grows sideways."""
    bone, skin = spheres
    region = chin.ChinRegion(x_mid_mm=0.0, z_back_mm=-20.0, y_top_mm=-5.0, marks={})
    x = np.array([-6.0, 0.0, 6.0])
    normal = chin.chin_profile(bone, skin, region, x, ray="normal")
    assert normal.along_normal.all()
    np.testing.assert_allclose(normal.depth_mm, 5.0, atol=0.2)
    np.testing.assert_allclose(normal.bone_rise_mm, [2.0, 0.0, 2.0], atol=0.15)
    np.testing.assert_allclose(normal.skin_rise_mm, 1.5 * normal.bone_rise_mm, atol=0.25)
    np.testing.assert_allclose(np.abs(normal.tilt_deg), [36.9, 0.0, 36.9], atol=2.0)
    assert (normal.tilt_deg[[0, 2]] > 0).all()  # leaning away from the midline
    down = chin.chin_profile(bone, skin, region, x, ray="down")
    expected = np.sqrt(15.0**2 - 36) - 8.0  # skin minus bone below x = 6
    np.testing.assert_allclose(down.depth_mm, [expected, 5.0, expected], atol=0.2)
    assert not down.at_edge.any()


def test_cut_and_empty_columns(spheres):
    bone, skin = spheres
    region = chin.ChinRegion(x_mid_mm=0.0, z_back_mm=-20.0, y_top_mm=-5.0, marks={})
    p = chin.chin_profile(bone, skin, region, [0.0, 12.0], cut_y_mm=-14.8, ray="down")
    assert p.cut[0]  # the skin at y = -15 lies below the last slice
    assert np.isnan(p.border_mm[1]).all() and np.isnan(p.depth_mm[1])  # no bone at x = 12
    with pytest.raises(ValueError, match="ray must be"):
        chin.chin_profile(bone, skin, region, [0.0], ray="sideways")


def test_summary_of_one_profile(spheres):
    bone, skin = spheres
    region = chin.ChinRegion(x_mid_mm=0.0, z_back_mm=-20.0, y_top_mm=-5.0, marks={})
    p = chin.chin_profile(bone, skin, region, [-20.0, 0.0, 20.0])
    summary = chin.profile_summary([p])
    assert summary["depth_median_mm"] == pytest.approx(5.0, abs=0.2)
    assert np.isnan(summary["bone_rise_mm"][20.0])  # no bone 20 mm out: a NaN, not an error


def test_lps_to_head_is_a_rotation():
    m = chin.lps_to_head(np.eye(3))
    assert np.linalg.det(m) == pytest.approx(1.0)
    np.testing.assert_allclose(chin.lps_to_head([[0.0, -1, 0]]), [[0, 0, 1]])  # anterior
