import numpy as np
import pytest

from lilium.softtissue import (
    BUILTIN_DEPTHS,
    CORRESPONDENCES,
    CRANIAL_NAMES,
    DepthStats,
    check_depth_table,
    decode,
    landmark_normals,
    make_cones,
    midsagittal_plane,
    surface_normals_at,
)
from lilium.softtissue.cones import hybrid_genes

NAMES = ("nasion", "zygion_l", "zygion_r", "gonion_l", "gonion_r", "pogonion")


def _cones(rng=0):
    rng = np.random.default_rng(rng)
    axes = rng.normal(size=(len(NAMES), 3))
    # Twins: right axis = mirror of left across x = 0, slightly perturbed.
    mirror = np.diag([-1.0, 1, 1])
    axes[2] = mirror @ axes[1] + 0.05 * rng.normal(size=3)
    axes[4] = mirror @ axes[3]
    lo = np.array([BUILTIN_DEPTHS[n.removesuffix("_l").removesuffix("_r")].min_mm for n in NAMES])
    hi = np.array([BUILTIN_DEPTHS[n.removesuffix("_l").removesuffix("_r")].max_mm for n in NAMES])
    return make_cones(NAMES, axes, lo, hi, mirror_normal=[1.0, 0, 0])


def test_catalogue_has_every_spec_landmark():
    assert len(CORRESPONDENCES) == 20
    for name in ("infradentale", "mental_foramen_l", "porion_r", "orbitale_l"):
        assert name in CRANIAL_NAMES
    assert dict(CORRESPONDENCES)["prosthion"] == "labiale_superius"


def test_decoded_depth_and_polar_angle_stay_in_cone():
    cones = _cones()
    genes = np.random.default_rng(1).uniform(size=(500, cones.n_genes))
    st = decode(genes, cones)
    depth = np.linalg.norm(st, axis=-1)
    assert np.all(depth >= cones.depth_min_mm - 1e-9)
    assert np.all(depth <= cones.depth_max_mm + 1e-9)
    cos = np.einsum("scj,cj->sc", st, cones.axes) / depth
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() <= 40.0 + 1e-9


def test_gene_extremes_give_interval_ends_and_axis():
    cones = _cones()
    zeros = decode(np.zeros(cones.n_genes), cones)
    np.testing.assert_allclose(zeros, cones.depth_min_mm[:, None] * cones.axes, atol=1e-12)
    ones = decode(np.ones(cones.n_genes), cones)
    np.testing.assert_allclose(np.linalg.norm(ones, axis=1), cones.depth_max_mm, rtol=1e-12)


def test_azimuth_is_periodic():
    cones = _cones()
    genes = np.random.default_rng(2).uniform(size=(20, cones.n_genes))
    a, b = genes.copy(), genes.copy()
    a[:, 2::3], b[:, 2::3] = 0.0, 1.0
    np.testing.assert_allclose(decode(a, cones), decode(b, cones), atol=1e-12)


def test_twins_are_mirror_symmetric_at_equal_genes():
    axes = np.random.default_rng(3).normal(size=(len(NAMES), 3))
    mirror = np.diag([-1.0, 1, 1])
    axes[2], axes[4] = mirror @ axes[1], mirror @ axes[3]
    cones = make_cones(NAMES, axes, np.full(6, 5.0), np.full(6, 15.0), mirror_normal=[1, 0, 0])
    genes = np.random.default_rng(4).uniform(size=(30, 6, 3))
    genes[:, 2] = genes[:, 1]
    genes[:, 4] = genes[:, 3]
    st = decode(genes.reshape(30, -1), cones)
    np.testing.assert_allclose(st[:, 2], st[:, 1] @ mirror.T, atol=1e-12)
    np.testing.assert_allclose(st[:, 4], st[:, 3] @ mirror.T, atol=1e-12)


def test_bilateral_hybrid_mixes_right_genes():
    cones = _cones()
    genes = np.zeros((1, cones.n_genes))
    genes[0, 3:6] = [1.0, 1.0, 0.95]  # zygion_l
    genes[0, 6:9] = [0.0, 0.0, 0.05]  # zygion_r
    g = hybrid_genes(genes, cones.pairs)[0]
    np.testing.assert_allclose(g[2, :2], [0.9, 0.9])
    # Azimuths 0.95 and 0.05 average on the circle near 0.96, not 0.86.
    assert abs(g[2, 2] - 0.96) < 0.005


def test_midsagittal_plane_from_pairs():
    landmarks = {"zygion_l": [60, 0, 10], "zygion_r": [-60, 0, 10], "nasion": [0, 20, 80]}
    point, normal = midsagittal_plane(landmarks)
    np.testing.assert_allclose(normal, [1, 0, 0])
    assert abs(point[0]) < 1e-12


def test_surface_normals_of_a_sphere_point_outward():
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=4, radius=80.0)
    points = sphere.vertices[[0, 10, 100]]
    normals = surface_normals_at(sphere.vertices, sphere.faces[:, ::-1], points)  # inverted winding
    expected = points / np.linalg.norm(points, axis=1, keepdims=True)
    assert np.all(np.einsum("ij,ij->i", normals, expected) > 0.999)
    faces = sphere.faces[:, ::-1]
    named = landmark_normals(sphere.vertices, faces, {"c": points[2], "a": points[0]})
    assert list(named) == ["c", "a"]  # the landmarks' own order, each its own normal
    np.testing.assert_allclose(named["a"], normals[0], atol=1e-12)
    np.testing.assert_allclose(named["c"], normals[2], atol=1e-12)


def test_depth_table_checks():
    table = check_depth_table({"exocanthion": DepthStats(10, 2, 6, 15)})
    assert "ectoconchion" in table
    with pytest.raises(ValueError, match="unknown landmark 'nose'"):
        check_depth_table({"nose": DepthStats(1, 1, 0, 2)})
    with pytest.raises(ValueError, match="min <= mean <= max"):
        check_depth_table({"nasion": DepthStats(12, 1, 3, 10)})


def test_fitted_axes_of_eye_corners_and_alae_lie_beside_the_normal():
    """The eye corners' and the alae's axes in an oriented head: the offset along the head's lateral
    direction, the rest of the mean depth to the front; every other landmark's is its normal,
    and without the head's directions every axis is."""
    import trimesh

    from lilium.softtissue.normals import LATERAL_OFFSET_MM, fitted_axes

    sphere = trimesh.creation.icosphere(subdivisions=4, radius=80.0)
    v, f = sphere.vertices, sphere.faces
    points = {"ectoconchion_l": v[5], "dacryon_r": v[40], "alare_l": v[60], "nasion": v[80]}
    normals = landmark_normals(v, f, points)
    left, anterior = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    axes = fitted_axes(v, f, points, left, anterior)
    assert list(axes) == list(points)
    np.testing.assert_allclose(axes["nasion"], normals["nasion"])
    for name, lateral in (("ectoconchion_l", left), ("dacryon_r", -left), ("alare_l", left)):
        base = name[:-2]
        expected = LATERAL_OFFSET_MM[base] / BUILTIN_DEPTHS[base].mean_mm
        assert np.isclose(axes[name] @ lateral, expected), name  # medial eye corner: < 0
        assert axes[name] @ anterior > 0.8 and abs(axes[name][1]) < 1e-12, name
    assert axes["ectoconchion_l"] @ left < 0 < axes["alare_l"] @ left
    bare = fitted_axes(v, f, points)
    for name in points:
        np.testing.assert_allclose(bare[name], normals[name])
