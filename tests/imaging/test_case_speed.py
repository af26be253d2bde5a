"""The pieces that make a case's steps after its SFO fast (issue 26): the binary PLY reader, the
content-keyed topology, the pictures' depth buffer."""

import numpy as np
import trimesh

from lilium.imaging._paint_kernels import nearest_face_index
from lilium.imaging.raster import cached_topology, mesh_edge_topology
from lilium.io.mesh import read_binary_ply, read_mesh


def _box_mesh():
    mesh = trimesh.creation.box(extents=(100.0, 120.0, 90.0))
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def test_binary_ply_reads_as_trimesh_does(tmp_path):
    vertices, faces = _box_mesh()
    path = tmp_path / "skull.ply"
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    fast = read_binary_ply(path)
    assert fast is not None
    np.testing.assert_array_equal(fast[0], vertices.astype(np.float32).astype(float))
    np.testing.assert_array_equal(fast[1], faces)
    v, f = read_mesh(path)
    np.testing.assert_array_equal(f, faces)


def test_other_ply_layouts_go_to_trimesh(tmp_path):
    vertices, faces = _box_mesh()
    path = tmp_path / "skull.ply"
    trimesh.Trimesh(vertices, faces, process=False).export(path, encoding="ascii")
    assert read_binary_ply(path) is None
    v, f = read_mesh(path)
    np.testing.assert_allclose(v, vertices, atol=1e-5)
    np.testing.assert_array_equal(f, faces)


def test_cached_topology_is_keyed_by_content():
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    first = cached_topology(faces)
    assert cached_topology(faces.copy()) is first
    other = cached_topology(np.array([[0, 1, 2], [0, 3, 2]]))
    assert other is not first
    np.testing.assert_array_equal(first.edges, mesh_edge_topology(faces).edges)


def test_depth_buffer_keeps_the_nearest_triangle():
    """Two triangles over the same pixels: the nearer one shows, whatever the order; pixel
    centres on an edge count; no triangle outside."""
    uv = np.array([[0.0, 0.0], [6.0, 0.0], [0.0, 6.0], [0.0, 0.0], [6.0, 0.0], [0.0, 6.0]])
    faces = np.array([[0, 1, 2], [3, 5, 4]])  # the same triangle, wound both ways
    near_first = nearest_face_index(uv, faces, np.array([1.0, 2.0]), (8, 8))
    near_second = nearest_face_index(uv, faces, np.array([2.0, 1.0]), (8, 8))
    inside = near_first >= 0
    assert np.all(near_first[inside] == 0) and np.all(near_second[inside] == 1)
    rows, cols = np.nonzero(inside)
    assert np.all(rows + cols <= 6) and inside[0, 6] and inside[6, 0] and not inside[7, 7]
    covered = np.zeros((8, 8), bool)
    covered[:2, :2] = True
    clipped = nearest_face_index(uv, faces, np.array([1.0, 2.0]), (8, 8), covered=covered)
    assert np.array_equal(clipped >= 0, covered)
