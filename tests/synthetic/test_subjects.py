"""Procedural subjects: landmarks, proportions, soft tissue within the cones, reproducibility."""

import json

import numpy as np
import pytest

from lilium.constants import CONE_MAX_POLAR_DEG
from lilium.geometry.camera import Camera, principal_point_of
from lilium.softtissue.depths import BUILTIN_DEPTHS
from lilium.softtissue.landmarks import (
    CORRESPONDENCES,
    CRANIAL_NAMES,
    FACIAL_NAMES,
    MIDLINE_CRANIAL,
    base_name,
)
from lilium.synthetic.anatomy.soft_tissue import direction_centre
from lilium.synthetic.subjects import make_subject, make_subjects, write_subject


@pytest.fixture(scope="module")
def subjects():
    return make_subjects(2, seed=0)


def _closest_distance(vertices, faces, points, radius_mm=8.0):
    """Distance from each point to the mesh (exact point-triangle, triangles nearby)."""
    from scipy.spatial import cKDTree

    tri = vertices[faces]
    tree = cKDTree(tri.mean(axis=1))
    out = []
    for p in points:
        t = tri[tree.query_ball_point(p, radius_mm)]
        # Dense barycentric sampling of each nearby triangle (resolution ~1 % of an edge).
        w = np.array([(a, b) for a in np.linspace(0, 1, 41) for b in np.linspace(0, 1, 41)])
        w = w[w.sum(axis=1) <= 1]
        q = t[:, None, 0] + w[None, :, :1] * (t[:, None, 1] - t[:, None, 0])
        q = q + w[None, :, 1:] * (t[:, None, 2] - t[:, None, 0])
        out.append(np.linalg.norm(q - p, axis=2).min() if len(t) else np.inf)
    return np.array(out)


def test_every_landmark_is_there(subjects):
    for s in subjects:
        assert set(s.cranial_landmarks) == set(CRANIAL_NAMES)
        assert set(s.facial_landmarks) == set(FACIAL_NAMES)
        assert set(s.soft_tissue_axes) == {c for c, _ in CORRESPONDENCES}
        for p in [*s.cranial_landmarks.values(), *s.facial_landmarks.values()]:
            assert p.shape == (3,) and np.all(np.isfinite(p))
        for name in MIDLINE_CRANIAL:
            assert abs(s.cranial_landmarks[name][0]) < 1.0


def test_proportions_are_human(subjects):
    for s in subjects:
        v = s.skull_vertices_mm
        assert 175 <= np.ptp(v[:, 2]) <= 205  # glabella-opisthocranion (incl. nasal bones)
        assert 125 <= np.ptp(v[v[:, 1] > 20, 0]) <= 152  # cranial breadth
        lm = s.cranial_landmarks
        assert 118 <= np.linalg.norm(lm["zygion_l"] - lm["zygion_r"]) <= 142
        assert 105 <= lm["nasion"][1] - lm["gnathion"][1] <= 140  # face height
        assert lm["bregma"][1] > lm["metopion"][1] > lm["glabella"][1] > lm["nasion"][1]
        assert lm["nasion"][1] > lm["subspinale"][1] > lm["prosthion"][1] > lm["pogonion"][1]
        assert lm["ectoconchion_l"][0] > lm["dacryon_l"][0] > 0 > lm["dacryon_r"][0]
        assert lm["porion_l"][1] == pytest.approx(lm["orbitale_l"][1], abs=15)  # Frankfurt


def test_face_proportions_are_human(subjects):
    # The eye corners' and alae's soft tissue lies beside their bone landmark (adult norms:
    # outer eye corners about 85-95 mm apart, inner 31-33, alae 31-35), not along the normal.
    for s in subjects:
        lm = s.facial_landmarks
        assert 80 <= np.linalg.norm(lm["exocanthion_l"] - lm["exocanthion_r"]) <= 105
        assert 25 <= np.linalg.norm(lm["endocanthion_l"] - lm["endocanthion_r"]) <= 40
        assert 26 <= np.linalg.norm(lm["alare_l"] - lm["alare_r"]) <= 42


def test_soft_tissue_inside_the_cones(subjects):
    for s in subjects:
        for cranial, facial in CORRESPONDENCES:
            st = s.facial_landmarks[facial] - s.cranial_landmarks[cranial]
            depth = np.linalg.norm(st)
            stats = BUILTIN_DEPTHS[base_name(cranial)]
            assert stats.min_mm <= depth <= stats.max_mm, cranial
            assert depth == pytest.approx(s.soft_tissue_depths_mm[cranial], abs=1e-9)
            axis = s.soft_tissue_axes[cranial]
            np.testing.assert_allclose(st / depth, axis, atol=1e-9)
            centre = direction_centre(cranial, s.bone_normals[cranial])
            angle = np.degrees(np.arccos(np.clip(axis @ centre, -1, 1)))
            assert angle <= min(25.0, CONE_MAX_POLAR_DEG), cranial


def test_landmarks_lie_on_their_surfaces(subjects):
    for s in subjects:
        facial = np.array([s.facial_landmarks[n] for n in FACIAL_NAMES])
        assert _closest_distance(s.skin_vertices_mm, s.skin_faces, facial).max() < 1.0
        cranial = np.array([s.cranial_landmarks[n] for n in CRANIAL_NAMES])
        assert _closest_distance(s.skull_vertices_mm, s.skull_faces, cranial).max() < 1.0


def test_meshes_are_moderate(subjects):
    for s in subjects:
        assert 10_000 <= len(s.skull_faces) <= 60_000
        assert 10_000 <= len(s.skin_faces) <= 60_000


def test_same_seed_same_subject_and_seeds_differ(subjects):
    again = make_subjects(1, seed=0)[0]
    np.testing.assert_array_equal(again.skull_vertices_mm, subjects[0].skull_vertices_mm)
    for n in FACIAL_NAMES:
        np.testing.assert_array_equal(again.facial_landmarks[n], subjects[0].facial_landmarks[n])
    a, b = subjects
    assert a.shape != b.shape
    diff = [np.linalg.norm(a.cranial_landmarks[n] - b.cranial_landmarks[n]) for n in CRANIAL_NAMES]
    assert np.mean(diff) > 2.0


def test_write_subject_folder(tmp_path, subjects):
    s = subjects[0]
    folder = write_subject(tmp_path / s.subject_id, s)
    for name in ("skull.ply", "face.ply"):
        assert (folder / name).is_file()
    cranial = json.loads((folder / "cranial_landmarks.json").read_text())["landmarks"]
    facial = json.loads((folder / "facial_landmarks.json").read_text())["landmarks"]
    axes = json.loads((folder / "soft_tissue_axes.json").read_text())["axes"]
    assert set(cranial) == set(CRANIAL_NAMES) and set(facial) == set(FACIAL_NAMES)
    np.testing.assert_allclose(cranial["nasion"], s.cranial_landmarks["nasion"])
    np.testing.assert_allclose(np.linalg.norm(list(axes.values()), axis=1), 1.0)
    from lilium.io.mesh import read_mesh

    v, f = read_mesh(folder / "skull.ply")
    assert len(f) == len(s.skull_faces)


def test_make_subject_accepts_a_seed():
    with pytest.raises(TypeError):
        make_subject("x", rng="not a seed")


@pytest.mark.parametrize(
    "seeds", [range(3), pytest.param(range(3, 10), marks=pytest.mark.slow)], ids=["0-2", "3-9"]
)
def test_facial_landmarks_on_the_skin_for_many_seeds(seeds):
    """Every facial landmark lies on the skin mesh (meshing keeps the piece of skin it is on).
    Seeds 0-2 in the default tier, 3-9 with ``-m slow``."""
    from lilium.synthetic.subjects import distance_to_mesh

    for seed in seeds:
        s = make_subject(f"s{seed:02d}", rng=seed)
        pts = np.array([s.facial_landmarks[n] for n in FACIAL_NAMES])
        d = distance_to_mesh(s.skin_vertices_mm, s.skin_faces, pts)
        assert d.max() < 1.5, (seed, FACIAL_NAMES[int(np.argmax(d))], float(d.max()))


def test_silhouette_landmarks_are_seen_in_frontal_and_profile_views(subjects):
    """Subnasale, zygia, gonia are seen straight from the front; labiale superius, pogonion
    and gnathion in a true profile (z-buffer test of lilium.synthetic.photos)."""
    from lilium.synthetic import photos as P
    from lilium.synthetic.head import prepare_head

    frontal = ("subnasale", "zygion_l", "zygion_r", "gonion_l", "gonion_r")
    profile = ("labiale_superius", "pogonion", "gnathion")
    for s in subjects:
        head = prepare_head(s)
        for yaw, names in ((0.0, frontal), (90.0, profile), (-90.0, profile)):
            R = P.head_rotation(yaw, 0.0, 0.0)
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = R, np.array([0.0, 0.0, 1500.0]) - R @ head.nasion_mm
            view = "frontal" if yaw == 0 else ("lateral_right" if yaw > 0 else "lateral_left")
            camera = Camera(T, 3000.0, principal_point_of((1280, 960)))
            cam = P.PhotoCamera(view, camera, (1280, 960), 1500.0, yaw, 0.0, 0.0)
            photo = P.render_photo(head, cam)
            for n in names:
                assert n in photo.visible, (s.subject_id, yaw, n)


def test_shape_priors_cover_every_parameter_and_bound_the_draws():
    from dataclasses import asdict, fields

    from lilium.synthetic.anatomy.shape import SHAPE_PRIORS, SubjectShape, draw_shape

    assert list(SHAPE_PRIORS) == [f.name for f in fields(SubjectShape)]
    for seed in range(20):
        for name, value in asdict(draw_shape(seed)).items():
            prior = SHAPE_PRIORS[name]
            assert prior.lo <= value <= prior.hi, name


def test_a_skull_without_eye_corner_axes_is_warned(tmp_path, subjects):
    """A subject folder without axes is read with the bone normals (the file contract's default)
    and warning ``normal_axes`` naming the eye corners' and the alae's landmarks; with its axes
    file, no warning."""
    from lilium.casework.build import read_skull

    s = subjects[0]
    folder = write_subject(tmp_path / s.subject_id, s)
    assert not [w for w in read_skull(folder).warnings if w.code == "normal_axes"]
    (folder / "soft_tissue_axes.json").unlink()
    skull = read_skull(folder)
    (warning,) = [w for w in skull.warnings if w.code == "normal_axes"]
    for name in ("ectoconchion_l", "dacryon_r", "alare_l"):
        assert name in warning.message
        np.testing.assert_allclose(skull.axes[name], s.bone_normals[name], atol=0.05)
    assert "nasion" not in warning.message and "--landmarks" in warning.message
