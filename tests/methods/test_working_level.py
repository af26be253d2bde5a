"""The DE's working level (issue 26): the rule, the camera mapping, and a result recomputed at
full level."""

from dataclasses import replace

import numpy as np
import pytest

from lilium.casework.build import read_photo, read_skull
from lilium.geometry.camera import Camera
from lilium.methods import SfoOptions
from lilium.methods.lilium import lilium_sfo
from lilium.methods.lilium_terms import SkofTerm, full_image_terms
from lilium.methods.pairs import correspondences
from lilium.methods.working_level import (
    WorkingLevel,
    cluster_vertices,
    face_extent_px,
    resample_photo,
    working_level,
)
from lilium.optimisation import DEOptions


def _grid_mesh(n=20, size_mm=100.0):
    """A flat square of ``2 n^2`` triangles in the z = 0 plane."""
    x = np.linspace(0.0, size_mm, n + 1)
    u, v = np.meshgrid(x, x)
    vertices = np.column_stack([u.ravel(), v.ravel(), np.zeros(u.size)])
    i = np.arange(n)[:, None] * (n + 1) + np.arange(n)[None]
    i = i.ravel()
    faces = np.concatenate(
        [np.column_stack([i, i + 1, i + n + 2]), np.column_stack([i, i + n + 2, i + n + 1])]
    )
    return vertices, faces


def test_cluster_vertices_keeps_a_fine_mesh_and_coarsens_with_the_cell():
    vertices, faces = _grid_mesh(20, 100.0)  # 5 mm edges
    v, f = cluster_vertices(vertices, faces, 1.0)
    assert len(f) == len(faces) and len(v) == len(vertices)
    v, f = cluster_vertices(vertices, faces, 10.5)
    assert 0 < len(f) < len(faces) / 3
    assert f.min() >= 0 and f.max() < len(v)
    assert np.all((f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2]))


def test_working_camera_projects_to_the_scaled_pixel():
    """A working camera sees a point where the full one does, scaled with pixel centres at
    integers: ``u' = (u + 1/2) s - 1/2``."""
    camera = Camera.from_rt(np.eye(3), [5.0, -3.0, 900.0], 3000.0, [799.5, 599.5])
    level = WorkingLevel(0.25, None, None, 0.0)
    points = np.array([[10.0, 20.0, 30.0], [-40.0, 5.0, 0.0]])
    full = camera.project(points)
    work = level.cameras(camera.as_batch()).project(points)[0]
    np.testing.assert_allclose(work, (full + 0.5) * 0.25 - 0.5, atol=1e-9)


def test_resample_photo_scales_landmarks_mask_and_curve(case):
    photo = read_photo(case[1])
    half = resample_photo(photo, 0.5)
    width, height = photo.image_size_wh
    assert half.image_size_wh == (round(width / 2), round(height / 2))
    assert half.face_mask.shape == (half.image_size_wh[1], half.image_size_wh[0])
    for name, uv in photo.landmarks_uv.items():
        np.testing.assert_allclose(half.landmarks_uv[name], (uv + 0.5) * 0.5 - 0.5)
    # About a quarter of the face pixels.
    assert half.face_mask.sum() == pytest.approx(photo.face_mask.sum() / 4, rel=0.05)


def test_the_rule_scales_only_large_faces(case):
    skull, photo = read_skull(case[0]), read_photo(case[1])
    corr = correspondences(skull, photo)
    extent = face_extent_px(corr.uv_px)
    assert working_level(skull, photo, corr, face_px=None).is_full
    assert working_level(skull, photo, corr, face_px=2 * extent).scale == 1.0
    level = working_level(skull, photo, corr, face_px=extent / 3)
    assert level.scale == pytest.approx(1 / 3)
    assert level.cell_mm > 0 and len(level.skull.faces) < len(skull.faces)


def test_working_skof_counts_like_the_full_term_on_the_full_level(case):
    """At scale 1 on the full mesh, the working wrapper gives the full term's values."""
    from lilium.methods.working_level import WorkingSkof

    skull, photo = read_skull(case[0]), read_photo(case[1])
    centre = np.array([(photo.image_size_wh[0] - 1) / 2, (photo.image_size_wh[1] - 1) / 2])
    full = SkofTerm(skull, photo, centre)
    wrapped = WorkingSkof(SkofTerm(skull, photo, centre), WorkingLevel(1.0, skull, photo, 1.0))
    camera = _true_camera(case)
    assert wrapped(camera.as_batch())[0] == full(camera.as_batch())[0]


def _true_camera(case):
    from lilium.io.truth import read_ground_truth

    return read_ground_truth(case[1]).camera


def test_result_terms_are_recomputed_at_full_level(case):
    """With a working level (here: the face 1/3 of its size, so a coarser photo and mesh), the
    result's image terms, outside count and fitness are the full level's for its camera."""
    skull, photo = read_skull(case[0]), read_photo(case[1])
    extent = face_extent_px(correspondences(skull, photo).uv_px)
    options = SfoOptions("skof+pll", DEOptions(10, max_generations=15), working_face_px=extent / 3)
    result = lilium_sfo(skull, photo, options, seed=2)
    assert result and result.extra["working_scale"] == pytest.approx(1 / 3)
    terms, outside = full_image_terms(skull, photo, result.camera, True, False)
    assert result.terms["p_skof"] == terms["p_skof"]
    assert result.terms["p_pll"] is None  # the stand-in skull has no mandible landmarks
    assert result.extra["outside_px"] == outside.outside_px
    total = sum(v for v in result.terms.values() if v is not None)
    assert result.fitness == pytest.approx(total, rel=1e-12)
    again = lilium_sfo(skull, photo, options, seed=2)
    assert again.fitness == result.fitness  # deterministic with the seed


def test_full_level_option_is_the_old_path(case):
    skull, photo = read_skull(case[0]), read_photo(case[1])
    options = SfoOptions("skof", DEOptions(10, max_generations=8), working_face_px=None)
    result = lilium_sfo(skull, photo, options, seed=1)
    assert result.fitness == result.extra["history"][-1]
    assert result.extra["working_scale"] == 1.0 and "outside_px" not in result.extra
    assert replace(options, working_face_px=None) == options
