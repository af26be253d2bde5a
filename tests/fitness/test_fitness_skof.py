"""P_skof: the exact union raster and the outside-pixel count."""

import cv2
import numpy as np
import pytest

from lilium.fitness.skof import (
    face_mask_index,
    prepare_skof,
    skof_penalty,
    skull_outside_pixels,
    skull_outside_pixels_batch,
)
from lilium.imaging.raster import mesh_edge_topology, skull_raster
from raster_oracle import skull_raster_cv2, skull_raster_per_triangle

# A square of pixel centres 11..20 x 11..20 (corners between pixel centres).
SQUARE_UV = np.array([[10.5, 10.5], [20.5, 10.5], [20.5, 20.5], [10.5, 20.5]])
SQUARE = np.array([[0, 1, 2], [0, 2, 3]])


def bumpy_sphere(n_lat=20, n_lon=30, rng=0):
    """Closed, consistently oriented, non-convex sphere (unit scale)."""
    rng = np.random.default_rng(rng)
    theta = np.linspace(0, np.pi, n_lat + 2)[1:-1]
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    r = 1 + 0.15 * np.sin(3 * T) * np.cos(4 * P) + 0.01 * rng.standard_normal(T.shape)
    xyz = np.stack([np.sin(T) * np.cos(P), np.cos(T), np.sin(T) * np.sin(P)], -1) * r[..., None]
    verts = np.vstack([[0, 1, 0], xyz.reshape(-1, 3), [0, -1, 0]])
    idx = 1 + np.arange(n_lat * n_lon).reshape(n_lat, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    faces = np.vstack(
        [
            np.stack([idx[:-1], nxt[:-1], nxt[1:]], -1).reshape(-1, 3),
            np.stack([idx[:-1], nxt[1:], idx[1:]], -1).reshape(-1, 3),
            np.stack([np.zeros(n_lon, int), nxt[0], idx[0]], -1),
            np.stack([np.full(n_lon, len(verts) - 1), idx[-1], nxt[-1]], -1),
        ]
    )
    return verts, faces


def projected_sphere(rng=0, shape=(200, 300)):
    verts, faces = bumpy_sphere(rng=rng)
    a, b = np.random.default_rng(rng).uniform(-1, 1, 2)
    c, s = np.cos(a), np.sin(a)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ np.array(
        [[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]]
    )
    X = verts @ R.T + [0, 0, 6]
    uv = 400 * X[:, :2] / X[:, 2:] + [shape[1] / 2 - 20, shape[0] / 2 + 10]
    return uv, faces


def test_square_inside_mask_costs_nothing():
    mask = np.zeros((40, 40), bool)
    mask[5:30, 5:30] = True
    assert skull_outside_pixels(SQUARE_UV, SQUARE, mask) == 0
    assert skull_raster(SQUARE_UV, SQUARE, (40, 40)).sum() == 100


def test_square_partly_outside_counts_exactly_the_outside_pixels():
    mask = np.zeros((40, 40), bool)
    mask[:, :16] = True  # columns 0..15 are face
    mask[:14, :] = False  # rows 0..13 are not
    # Square columns 11..20, rows 11..20: outside = columns 16..20 (5 x 10) + rows 11..13 of
    # columns 11..15 (3 x 5).
    assert skull_outside_pixels(SQUARE_UV, SQUARE, mask) == 50 + 15
    assert skof_penalty(65) == 6500.0


def test_overlapping_triangles_are_counted_once_whatever_their_orientation():
    faces = np.array([[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 1, 2], [1, 3, 0]])
    mask = np.zeros((40, 40), bool)
    assert skull_raster(SQUARE_UV, faces, (40, 40)).sum() == 100
    assert skull_outside_pixels(SQUARE_UV, faces, mask) == 100
    # The even-odd fill of cv2.fillPoly, for contrast, loses the doubly covered pixels.
    even_odd = np.zeros((40, 40), np.uint8)
    cv2.fillPoly(even_odd, list(np.round(SQUARE_UV[faces]).astype(np.int32)), 1)
    assert even_odd.sum() < 100


@pytest.mark.parametrize("rng", [0, 1, 2])
def test_union_raster_equals_per_triangle_union_on_a_closed_mesh(rng):
    uv, faces = projected_sphere(rng)
    shape = (200, 300)
    exact = skull_raster_per_triangle(uv, faces, shape)
    fast = skull_raster(uv, faces, shape)
    assert exact.sum() > 5000
    assert np.array_equal(fast, exact)
    # OpenCV's own rule paints a little more (edges), never less.
    cv = skull_raster_cv2(uv, faces, shape)
    assert np.all(cv[exact]) and 0 < cv.sum() - exact.sum() < 0.1 * exact.sum()


@pytest.mark.parametrize("rng", [0, 3])
def test_outside_count_matches_raster_with_and_without_culling(rng):
    uv, faces = projected_sphere(rng)
    shape = (200, 300)
    v, u = np.mgrid[0 : shape[0], 0 : shape[1]]
    mask = ((u - 170) / 70.0) ** 2 + ((v - 100) / 80.0) ** 2 <= 1
    expected = int(np.count_nonzero(skull_raster_per_triangle(uv, faces, shape) & ~mask))
    assert expected > 100
    ctx = prepare_skof(faces, mask)
    assert skull_outside_pixels(uv, topology=ctx.topology, mask_index=ctx.mask_index) == expected
    assert skull_outside_pixels(uv, faces, mask, cull=False) == expected


def test_batch_equals_single_calls():
    shape = (200, 300)
    mask = np.zeros(shape, bool)
    mask[40:160, 60:220] = True
    uvs, faces = [], None
    for rng in range(4):
        uv, faces = projected_sphere(rng)
        uvs.append(uv)
    topo = mesh_edge_topology(faces)
    index = face_mask_index(mask)
    batch = skull_outside_pixels_batch(np.array(uvs), topology=topo, mask_index=index)
    single = [skull_outside_pixels(uv, topology=topo, mask_index=index) for uv in uvs]
    assert batch.tolist() == single


def test_pixels_beyond_the_image_do_not_count():
    uv = SQUARE_UV - [15, 0]  # columns -4..5
    mask = np.zeros((40, 40), bool)
    assert skull_outside_pixels(uv, SQUARE, mask) == 6 * 10


def test_faces_with_a_vertex_behind_the_camera_are_dropped():
    uv = np.vstack([SQUARE_UV, [np.nan, np.nan]])
    faces = np.vstack([SQUARE, [[0, 1, 4]]])
    assert skull_outside_pixels(uv, faces, np.zeros((40, 40), bool)) == 100


def test_open_mesh_with_shared_edges_leaves_no_gap():
    # A 3x3 grid of unit squares with corners at half-integers: 9 x 9 pixels... of 3 x 3 cells.
    g = np.arange(4) * 3 + 0.5
    U, V = np.meshgrid(g, g)
    uv = np.column_stack([U.ravel(), V.ravel()])
    i = np.arange(16).reshape(4, 4)
    a, b, c, d = i[:-1, :-1], i[:-1, 1:], i[1:, 1:], i[1:, :-1]
    faces = np.vstack(
        [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    )
    assert skull_raster(uv, faces, (20, 20)).sum() == 81


def test_invalid_inputs_say_what_is_wrong():
    with pytest.raises(ValueError, match="faces must have shape"):
        skull_outside_pixels(SQUARE_UV, np.array([0, 1, 2]), np.ones((4, 4)))
    with pytest.raises(ValueError, match="uv must have shape"):
        skull_outside_pixels(SQUARE_UV[None], SQUARE, np.ones((4, 4)))
    with pytest.raises(ValueError, match="face_mask must be a 2D"):
        skull_outside_pixels(SQUARE_UV, SQUARE, np.ones((4, 4, 3)))
    with pytest.raises(ValueError, match="topology was built for 2 faces"):
        skull_outside_pixels(
            SQUARE_UV, np.zeros((3, 3), int), np.ones((4, 4)), topology=mesh_edge_topology(SQUARE)
        )
