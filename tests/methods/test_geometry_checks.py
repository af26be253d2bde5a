"""Degenerate or damaged geometry (the probes of tests/acceptance/hostile_geometry.py): parts of
a skull mesh apart from the skull, unreferenced vertices, coarse meshes, bilateral twins at one
place, too few or planar landmarks for POSEST, masks of (nearly) every pixel or of one pixel."""

import json
from dataclasses import replace

import numpy as np
import pytest

from lilium import jit
from lilium.casework.build import read_photo, read_skull
from lilium.geometry.mesh import (
    compact,
    face_components,
    parts_apart,
    point_surface_distance,
)
from lilium.io.mesh import read_mesh, write_mesh
from standin_case import make_standin_case

# -- mesh pieces ------------------------------------------------------------------------------


def _two_tetrahedra(offset):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return np.vstack([v, v + offset]), np.vstack([f, f + 4])


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_face_components_split_the_pieces(backend):
    rng = np.random.default_rng(0)
    v, f = _two_tetrahedra([10.0, 0, 0])
    # a third piece of two faces sharing an edge, listed between the others
    v = np.vstack([v, [[20, 0, 0], [21, 0, 0], [20, 1, 0], [21, 1, 0]]])
    f = np.vstack([f[:4], [[8, 9, 10], [9, 11, 10]], f[4:]])
    perm = rng.permutation(len(v))  # vertex numbering must not matter
    inv = np.argsort(perm)
    with jit.kernels(backend):
        labels = face_components(inv[f], len(v))
    assert len(set(labels[:4])) == 1 and len(set(labels[4:6])) == 1
    assert len(set(labels[6:])) == 1 and len(set(labels)) == 3
    assert sorted(np.bincount(labels)) == [2, 4, 4]


def test_compact_keeps_the_vertex_order():
    v = np.arange(18.0).reshape(6, 3)
    f = np.array([[5, 1, 3], [3, 1, 4]])
    cv, cf = compact(v, f)
    np.testing.assert_array_equal(cv, v[[1, 3, 4, 5]])
    np.testing.assert_array_equal(cv[cf], v[f])


def test_parts_apart_keep_the_landmarks_part_and_what_touches_it():
    v, f = _two_tetrahedra([100.0, 0, 0])
    v2, f2 = _two_tetrahedra([1.5, 0, 0])  # two pieces 0.5 apart: both kept
    apart, parts = parts_apart(v, f, np.array([[0.2, 0.2, 0.2]]), 20.0)
    assert apart.tolist() == [False] * 4 + [True] * 4
    assert parts == [(4, pytest.approx(99.0))]
    apart, parts = parts_apart(v2, f2, np.array([[0.2, 0.2, 0.2]]), 20.0)
    assert not apart.any() and parts == []
    # anchors on both pieces: both are the skull
    apart, _ = parts_apart(v, f, np.array([[0.2, 0.2, 0.2], [100.2, 0.2, 0.2]]), 20.0)
    assert not apart.any()


def test_point_surface_distance_is_to_the_triangles_not_the_vertices():
    v = np.array([[0, 0, 0], [100, 0, 0], [0, 100, 0]], float)
    f = np.array([[0, 1, 2]])
    points = np.array([[20, 20, 5], [60, 60, 0], [-3, -4, 0], [50, -10, 0]], float)
    np.testing.assert_allclose(
        point_surface_distance(points, v, f), [5.0, np.hypot(10, 10), 5.0, 10.0]
    )


# -- the skull as read ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def standin(tmp_path_factory):
    return make_standin_case(tmp_path_factory.mktemp("geometry"))


def _subject_copy(standin, tmp_path, edit):
    subject = tmp_path / "subject"
    subject.mkdir()
    for p in standin[0].iterdir():
        (subject / p.name).write_bytes(p.read_bytes())
    v, f = read_mesh(subject / "skull.ply")
    write_mesh(subject / "skull.ply", *edit(v, f))
    return subject


def test_a_fragment_apart_is_left_out_and_named(standin, tmp_path):
    def fragment(v, f):
        piece = v * 0.1 + [-150.0, 0, 0]  # a blob of 15 mm, 150 mm aside
        return np.vstack([v, piece]), np.vstack([f, f + len(v)])

    clean = read_skull(standin[0])
    skull = read_skull(_subject_copy(standin, tmp_path, fragment))
    assert len(skull.faces) == len(clean.faces) and len(skull.vertices_mm) == len(clean.vertices_mm)
    np.testing.assert_array_equal(skull.vertices_mm, clean.vertices_mm)
    (warning,) = skull.warnings
    assert warning.code == "mesh_part_left_out"
    assert "skull.ply" in warning.message and "1 fragment(s)" in warning.message
    assert clean.warnings == ()


def test_a_far_stray_triangle_is_not_taken_for_metres(standin, tmp_path):
    def stray(v, f):
        tri = np.array([[-1000, 0, 0], [-1000, 1, 0], [-1000, 0, 1]], float)
        return np.vstack([v, tri]), np.vstack([f, [[len(v), len(v) + 1, len(v) + 2]]])

    skull = read_skull(_subject_copy(standin, tmp_path, stray))
    assert [w.code for w in skull.warnings] == ["mesh_part_left_out"]
    assert np.ptp(skull.vertices_mm, axis=0).max() < 200


def test_unreferenced_vertices_neither_widen_nor_hide_the_landmark_check(standin, tmp_path):
    """A mesh cut with its vertices kept: the jaw's landmarks are off the remaining bone."""

    def cut(v, f):
        keep = np.all(v[f][:, :, 1] > -5, axis=1)  # faces below the orbits deleted
        far = np.array([[3000.0, 0, 0]])  # and an unreferenced vertex 3 m away
        return np.vstack([v, far]), f[keep]

    with pytest.raises(ValueError, match="cranial_landmarks.json: landmarks.* from the skull"):
        read_skull(_subject_copy(standin, tmp_path, cut))


def test_a_coarse_mesh_measures_landmarks_to_its_facets(standin, tmp_path):
    """An 80-face skull: glabella is 19 mm from the nearest vertex but on a facet."""
    from standin_case import SKULL_RADII_MM, _ellipsoid

    subject = _subject_copy(standin, tmp_path, lambda v, f: _ellipsoid(SKULL_RADII_MM, 1))
    skull = read_skull(subject)
    assert len(skull.faces) == 80


# -- twins at one place -----------------------------------------------------------------------


def test_twins_at_one_place_are_an_error_on_the_photo_and_on_the_skull(standin):
    from lilium.methods.checks import check_inputs

    skull, photo = read_skull(standin[0]), read_photo(standin[1], load_image=False)
    check_inputs(skull, photo)
    lm = dict(photo.landmarks_uv, zygion_r=photo.landmarks_uv["zygion_l"] + [0.001, 0])
    copied = replace(photo, landmarks_uv=lm, landmarks_file="photo.json")
    with pytest.raises(ValueError, match="photo.json: zygion_l and zygion_r lie at one place"):
        check_inputs(skull, copied)
    lm3 = dict(skull.landmarks_mm, gonion_l=skull.landmarks_mm["gonion_r"])
    copied = replace(skull, landmarks_mm=lm3, landmarks_file="cranial.json")
    with pytest.raises(ValueError, match="cranial.json: gonion_l and gonion_r lie at one place"):
        check_inputs(copied, photo)


# -- POSEST without a usable minimal sample ---------------------------------------------------


def test_posest_without_a_real_sample_names_the_files_and_the_fix(standin):
    from lilium.methods import SfoOptions, run_sfo

    skull, photo = read_skull(standin[0]), read_photo(standin[1], load_image=False)
    midline = ("nasion", "glabella", "metopion", "bregma", "subnasale", "pogonion", "gnathion")
    photo = replace(
        photo,
        landmarks_uv={k: v for k, v in photo.landmarks_uv.items() if k in midline},
        landmarks_file="photo.json",
        priors=replace(photo.priors, head_rotation_skull2cam=None, head_tolerance_deg=None),
    )
    result = run_sfo(
        "posest-sfo", replace(skull, landmarks_file="cranial.json"), photo, SfoOptions(), 0
    )
    if result:
        pytest.skip("POSEST found a camera on this draw")
    assert "photo.json and cranial.json" in result.error
    assert "off the midline" in result.error and "--method lilium" in result.error


# -- masks ------------------------------------------------------------------------------------


def test_a_mask_of_nearly_every_pixel_is_refused(tmp_path):
    from PIL import Image

    from lilium.io.images import read_mask

    mask = np.full((100, 120), 255, np.uint8)
    mask[0, 0] = 0
    Image.fromarray(mask).save(tmp_path / "m.png")
    with pytest.raises(ValueError, match="m.png: the face mask covers all but 1 px"):
        read_mask(tmp_path / "m.png", (120, 100))
    mask[:20, :20] = 0  # 3 % background: a tight portrait
    Image.fromarray(mask).save(tmp_path / "m.png")
    assert read_mask(tmp_path / "m.png", (120, 100)).mean() == pytest.approx(0.9667, abs=1e-3)


def test_a_mask_of_one_pixel_says_so(standin, tmp_path):
    from lilium.methods.photo_checks import check_landmarks_in_mask

    photo = read_photo(standin[1], load_image=False)
    mask = np.zeros_like(photo.face_mask)
    mask[0, 0] = True
    photo = replace(photo, face_mask=mask, mask_file="face_mask.png", landmarks_file="photo.json")
    with pytest.raises(ValueError) as err:
        check_landmarks_in_mask(photo)
    assert "the face mask face_mask.png" in str(err.value)
    assert "the mask covers 1 px against" in str(err.value)
    json.dumps(str(err.value))  # one line
    assert "\n" not in str(err.value)


def test_a_triangle_soup_stays_whole(standin, tmp_path):
    """An STL holds loose triangles (no shared vertices): every triangle is a part of its own,
    and the parts touch, so the skull stays whole; a fragment apart is still found."""
    clean = read_skull(standin[0])
    v, f = clean.vertices_mm, clean.faces
    soup_v, soup_f = v[f].reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3)
    apart, parts = parts_apart(soup_v, soup_f, np.array(list(clean.landmarks_mm.values())), 20.0)
    assert not apart.any() and parts == []
    blob_v = np.vstack([soup_v, soup_v[:300] * 0.05 + [0.0, -300.0, 0.0]])
    blob_f = np.vstack([soup_f, soup_f[:100] + len(soup_v)])
    apart, parts = parts_apart(blob_v, blob_f, np.array(list(clean.landmarks_mm.values())), 20.0)
    assert apart.sum() == 100 and len(parts) == 100


def test_a_skull_in_centimetres_is_refused(standin, tmp_path):
    from lilium.io.mesh import check_mesh

    v, f = read_mesh(standin[0] / "skull.ply")
    with pytest.raises(ValueError, match="rescale it to millimetres"):
        check_mesh(v / 10, f, "skull.ply")


def test_an_stl_skull_reads_as_its_ply(standin, tmp_path):
    """STL stores loose triangles: read, they are welded back into the PLY's surface."""
    from lilium.geometry.mesh import weld

    v, f = read_mesh(standin[0] / "skull.ply")
    write_mesh(tmp_path / "skull.stl", v, f)
    sv, sf = read_mesh(tmp_path / "skull.stl")
    assert len(sv) == len(np.unique(v, axis=0)) and len(sf) == len(f)
    np.testing.assert_allclose(sv[sf], v[f], atol=1e-4)  # float32 in the file
    assert weld(v, f)[0] is v  # no duplicates: unchanged
