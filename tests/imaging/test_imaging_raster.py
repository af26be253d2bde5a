"""The one mesh raster: overlays, the outside-face metric and P_skof all see the same ``S``."""

import doctest

import numpy as np
import pytest

import lilium.imaging.raster
from lilium.evaluation.metrics import implausible_sfo, outside_face
from lilium.fitness.skof import skull_outside_pixels
from lilium.geometry.camera import Camera
from lilium.imaging.overlay import draw_overlay, render_mesh_shaded
from lilium.imaging.raster import mesh_edge_topology, mesh_mask, skull_raster
from lilium.synthetic.head import prepare_head
from lilium.synthetic.photos import CameraRanges, make_photo
from lilium.synthetic.toyhead import make_toy_subject
from raster_oracle import skull_raster_per_triangle

SMALL = CameraRanges(image_sizes=((640, 480),))


@pytest.fixture(scope="module")
def toy():
    subject = make_toy_subject("toy", rng=3)
    photo = make_photo(prepare_head(subject), "frontal", 2, SMALL)
    return subject, photo


def _off_camera(camera, shift_mm=(12.0, -8.0, 0.0)):
    """The true camera moved so part of the skull leaves the face mask."""
    skull2cam = camera.skull2cam.copy()
    skull2cam[:3, 3] += shift_mm
    return Camera(skull2cam, camera.focal_px, camera.principal_point_px)


def test_docstring_examples():
    result = doctest.testmod(lilium.imaging.raster, extraglobs={"np": np})
    assert result.attempted > 0 and result.failed == 0


@pytest.mark.parametrize("moved", [False, True])
def test_overlay_covered_mask_is_the_exact_raster(toy, moved):
    subject, photo = toy
    camera, size_wh = photo.camera.camera, photo.camera.image_size_wh
    if moved:
        camera = _off_camera(camera)
    v, f = subject.skull_vertices_mm, subject.skull_faces
    shade, covered = render_mesh_shaded(v, f, camera, size_wh)
    uv = camera.project(v)
    shape = size_wh[::-1]
    assert covered.shape == shape and covered.sum() > 1000
    assert np.array_equal(covered, skull_raster(uv, f, shape))
    assert np.array_equal(covered, mesh_mask(v, f, camera, size_wh))
    # The production raster against the independent per-triangle oracle.
    assert np.array_equal(covered, skull_raster_per_triangle(uv, f, shape))
    # Shading fills exactly the silhouette: no unshaded covered pixel, nothing outside it.
    assert np.all(shade[covered] > 0) and not np.any(shade[~covered])
    topology = mesh_edge_topology(f)
    _, again = render_mesh_shaded(v, f, camera, size_wh, topology=topology)
    assert np.array_equal(again, covered)


def test_overlay_outline_follows_the_exact_raster(toy):
    subject, photo = toy
    camera, (w, h) = photo.camera.camera, photo.camera.image_size_wh
    image = np.zeros((h, w, 3), np.uint8)
    out = draw_overlay(image, subject.skull_vertices_mm, subject.skull_faces, camera, opacity=0)
    covered = mesh_mask(subject.skull_vertices_mm, subject.skull_faces, camera, (w, h))
    drawn = out.any(axis=2)
    # The outline (drawn 1 px wide, anti-aliased) hugs the silhouette's border.
    assert drawn.sum() > 100 and not np.any(drawn & ~_grown(covered, 2))


def _grown(mask, px):
    from scipy import ndimage

    return ndimage.binary_dilation(mask, iterations=px)


@pytest.mark.parametrize("moved", [False, True])
def test_outside_face_is_the_p_skof_count(toy, moved):
    subject, photo = toy
    camera = photo.camera.camera
    if moved:
        camera = _off_camera(camera)
    v, f = subject.skull_vertices_mm, subject.skull_faces
    result = outside_face(camera, v, f, photo.face_mask)
    assert result.outside_px == skull_outside_pixels(camera.project(v), f, photo.face_mask)
    skull = mesh_mask(v, f, camera, photo.camera.image_size_wh)
    assert result == implausible_sfo(skull, photo.face_mask)
    assert result.implausible == moved
    if moved:
        assert 0 < result.percent_outside < 100
    cached = outside_face(camera, v, f, photo.face_mask, topology=mesh_edge_topology(f))
    assert cached == result


def test_outside_face_says_what_is_wrong(toy):
    subject, photo = toy
    colour = np.repeat(photo.face_mask[..., None], 3, axis=2)
    with pytest.raises(ValueError, match="face_mask must be a 2D"):
        outside_face(photo.camera.camera, subject.skull_vertices_mm, subject.skull_faces, colour)


def test_mesh_mask_drops_faces_behind_the_camera():
    square = np.array([[-1.0, -1.0, 10.0], [1.0, -1.0, 10.0], [1.0, 1.0, 10.0], [-1.0, 1.0, 10.0]])
    behind = np.vstack([square, [0.0, 0.0, -5.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 4]])
    camera = Camera(np.eye(4), 50.0, (20.5, 20.5))  # the square spans u, v = 15.5 .. 25.5
    with_behind = mesh_mask(behind, faces, camera, (40, 40))
    assert np.array_equal(with_behind, mesh_mask(square, faces[:2], camera, (40, 40)))
    assert with_behind.sum() == 100 and with_behind[16:26, 16:26].all()
