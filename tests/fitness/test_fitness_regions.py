"""Mesh regions of P_pll: Frankfurt frame, forehead and chin-jaw cuts."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lilium.fitness.regions import (
    anatomical_frame,
    chin_jaw_region,
    face_chin_jaw_region,
    forehead_region,
    submesh,
)

# Mesh frame of this synthetic head: x = subject's left, y = up, z = anterior; Frankfurt at y = 0.
LANDMARKS = {
    "porion_l": [60.0, 0, 0],
    "porion_r": [-60.0, 0, 0],
    "orbitale_l": [35.0, 0, 80],
    "glabella": [0.0, 30, 95],
    "metopion": [0.0, 70, 80],
    "nasion": [0.0, 20, 92],
    "infradentale": [0.0, -60, 85],
    "gnathion": [0.0, -95, 80],
    "mental_foramen_l": [22.0, -70, 75],
    "mental_foramen_r": [-22.0, -70, 75],
    "cheilion_l": [25.0, -45, 95],
    "cheilion_r": [-25.0, -45, 95],
}


def grid_mesh():
    """A 3D lattice of vertices (x, y, z in -100..100 by 10) with a strip of faces per row."""
    g = np.arange(-100, 101, 10.0)
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    verts = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    n = len(g)
    idx = np.arange(len(verts)).reshape(n, n, n)
    a, b, c = idx[:-1, :, :], idx[1:, :, :], np.roll(idx, -1, axis=2)[:-1, :, :]
    faces = np.stack([a, b, c], -1).reshape(-1, 3)
    return verts, faces


def test_frankfurt_frame_axes():
    frame = anatomical_frame(LANDMARKS)
    assert frame.source == "frankfurt"
    assert np.allclose(frame.up, [0, 1, 0])
    assert np.allclose(frame.left, [1, 0, 0])
    assert np.allclose(frame.anterior, [0, 0, 1])


def test_forehead_region_is_the_slab_between_glabella_and_metopion():
    verts, faces = grid_mesh()
    region = forehead_region(verts, faces, LANDMARKS)
    expected = (verts[:, 1] >= 30) & (verts[:, 1] <= 70) & (verts[:, 2] >= 95 - 80)
    assert np.array_equal(region.vertex_mask, expected)
    whole = forehead_region(verts, faces, LANDMARKS, depth_mm=None)
    assert np.array_equal(whole.vertex_mask, (verts[:, 1] >= 30) & (verts[:, 1] <= 70))
    # Faces are kept when all three vertices are in; indices are compact.
    assert np.all(expected[region.vertex_index])
    assert np.array_equal(region.vertex_index[region.faces], faces[region.face_index])
    assert np.all(expected[faces[region.face_index]])


def test_chin_jaw_region_is_below_infradentale_between_the_foramina():
    verts, faces = grid_mesh()
    region = chin_jaw_region(verts, faces, LANDMARKS)
    expected = (verts[:, 1] <= -60) & (np.abs(verts[:, 0]) <= 22)
    assert np.array_equal(region.vertex_mask, expected)
    face = face_chin_jaw_region(verts, faces, LANDMARKS, anatomical_frame(LANDMARKS))
    assert np.array_equal(face.vertex_mask, (verts[:, 1] <= -60) & (np.abs(verts[:, 0]) <= 25))


def test_regions_follow_the_head_when_the_mesh_frame_is_rotated():
    verts, faces = grid_mesh()
    R = Rotation.from_euler("xyz", [20, -35, 50], degrees=True).as_matrix()
    t = np.array([5.0, -7, 12])
    moved = {k: np.asarray(v) @ R.T + t for k, v in LANDMARKS.items()}
    for region_of in (forehead_region, chin_jaw_region):
        a = region_of(verts, faces, LANDMARKS)
        b = region_of(verts @ R.T + t, faces, moved)
        assert np.array_equal(a.vertex_mask, b.vertex_mask)


def test_fallback_frame_without_frankfurt_landmarks():
    lm = {k: v for k, v in LANDMARKS.items() if not k.startswith(("porion", "orbitale"))}
    lm["zygion_l"], lm["zygion_r"] = [65.0, 10, 40], [-65.0, 10, 40]
    frame = anatomical_frame(lm)
    assert frame.source == "fallback"
    assert np.allclose(frame.left, [1, 0, 0])
    assert frame.up @ [0, 1, 0] > np.cos(np.radians(15))  # facial height axis, near vertical
    assert frame.anterior @ [0, 0, 1] > 0.9


def test_missing_landmarks_say_which():
    verts, faces = grid_mesh()
    with pytest.raises(ValueError, match="needs the landmarks \\['metopion'\\]"):
        forehead_region(verts, faces, {k: v for k, v in LANDMARKS.items() if k != "metopion"})
    with pytest.raises(ValueError, match="cannot orient the head"):
        anatomical_frame({"glabella": [0, 0, 0]})


def test_submesh_keeps_faces_with_all_vertices_in():
    faces = np.array([[0, 1, 2], [1, 2, 3], [2, 3, 4]])
    region = submesh(np.array([False, True, True, True, False]), faces)
    assert region.face_index.tolist() == [1]
    assert region.vertex_index.tolist() == [1, 2, 3]
    assert region.faces.tolist() == [[0, 1, 2]]
