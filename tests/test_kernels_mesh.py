"""The compiled mesh, raster and curve kernels against their numpy references (lilium.jit):
same integers, same floats.

The edge table, the scan crossings, SKOF's culled outside-pixel counts and the face mask's
distance transform; curve detection, PLL's trims, pairs and terms (one by one and in one call)
and the facial curve's nearest-point table; vertex clustering and vertex normals. The references
are the numpy code the kernels replaced (still the package's fallback path, selected with
``lilium.jit.kernels("numpy")``), the per-triangle oracle of ``tests/raster_oracle.py`` and
scipy. The cases are ``tests/kernel_cases.py``'s; the camera kernels are
``test_kernels_camera.py``'s.
"""

import numpy as np
import pytest

from kernel_cases import CENTRE, HEIGHT, WIDTH, cameras, face_mask, needs_numba, shell_skull
from lilium import jit
from lilium.fitness._skof_kernels import face_clusters, project_vertices
from lilium.fitness.skof import (
    prepare_skof,
    skull_outside_pixels_batch,
    skull_outside_pixels_cameras,
)
from lilium.geometry.rotations import rotvec_to_matrix
from lilium.imaging.raster import mesh_edge_topology, scan_crossings
from raster_oracle import skull_raster_per_triangle


@needs_numba
@pytest.mark.parametrize("window", [((0, HEIGHT), (0, WIDTH)), ((-37, 700), (-50, 900))])
def test_scan_kernel_gives_the_numpy_crossings(window):
    vertices, faces = shell_skull()
    topology = mesh_edge_topology(faces)
    uv = project_vertices(vertices, *cameras(12, rng=1), CENTRE)
    compiled = scan_crossings(uv, topology, *window)
    with jit.kernels("numpy"):
        reference = scan_crossings(uv, topology, *window)
    assert len(reference.row) > 1000
    for field in ("member", "row", "column", "winding"):
        np.testing.assert_array_equal(getattr(compiled, field), getattr(reference, field))


def test_full_skull_count_equals_the_raster_of_every_face():
    """The culled count (either path) equals the full mesh's, never fewer, on rotated and
    scaled skulls."""
    vertices, faces = shell_skull(rng=2)
    mask = face_mask()
    context = prepare_skof(faces, mask, vertices)
    R, t, focal = cameras(64, rng=3)
    uv = project_vertices(vertices, R, t, focal, CENTRE)
    with jit.kernels("numpy"):
        full = skull_outside_pixels_batch(uv, faces, mask, cull=False)
        numpy_path = skull_outside_pixels_cameras(context, R, t, focal, CENTRE)
    np.testing.assert_array_equal(numpy_path, full)
    assert (full < 2000).sum() >= 3 and (full > 50_000).sum() >= 10  # near and far cases
    if jit.NUMBA_AVAILABLE:
        np.testing.assert_array_equal(
            skull_outside_pixels_cameras(context, R, t, focal, CENTRE), full
        )
    # The independent per-triangle union agrees where it is defined (no vertex behind).
    for m in np.flatnonzero(np.all(np.isfinite(uv), axis=(1, 2)))[:6]:
        oracle = skull_raster_per_triangle(uv[m], faces, (HEIGHT, WIDTH))
        assert int((oracle & ~mask).sum()) == full[m]


@needs_numba
def test_skull_slightly_inside_the_mask_counts_its_few_outside_pixels():
    """Cameras near one that fits: the shortcut skips most clusters and still counts exactly."""
    vertices, faces = shell_skull(rng=4)
    mask = face_mask(holes=False)
    context = prepare_skof(faces, mask, vertices)
    rng = np.random.default_rng(5)
    n = 40
    R = np.array([rotvec_to_matrix(rng.normal(scale=0.03, size=3)) for _ in range(n)])
    t = np.column_stack([rng.normal(scale=4.0, size=(n, 2)), rng.uniform(1500, 1700, n)])
    focal = t[:, 2] * rng.uniform(1.5, 2.3, n)
    uv = project_vertices(vertices, R, t, focal, CENTRE)
    full = skull_outside_pixels_batch(uv, faces, mask, cull=False)
    np.testing.assert_array_equal(skull_outside_pixels_cameras(context, R, t, focal, CENTRE), full)
    assert (full == 0).any() and (full > 0).any()
    # The scratch arrays kept between calls: the same counts in any batching and order.
    order = rng.permutation(n)
    again = np.concatenate(
        [
            skull_outside_pixels_cameras(context, R[i], t[i], focal[i], CENTRE)
            for i in np.array_split(order, 7)
        ]
    )
    np.testing.assert_array_equal(again, full[order])
    assert context.scratch.next_stamp == 2 * n


def test_clusters_cover_every_face_once():
    vertices, faces = shell_skull(n_lat=11, n_lon=13)
    clusters = face_clusters(vertices, faces, leaf_faces=8, fan_out=4)
    np.testing.assert_array_equal(np.sort(clusters.order), np.arange(len(faces)))
    leaves = clusters.node_children[:, 1] == clusters.node_children[:, 0]
    ranges = clusters.node_faces[leaves]
    np.testing.assert_array_equal(ranges[1:, 0], ranges[:-1, 1])
    assert ranges[0, 0] == 0 and ranges[-1, 1] == len(faces)
    # Every node's sphere holds the corners of its faces.
    clustered = vertices[faces[clusters.order]]
    for (lo, hi), sphere in zip(clusters.node_faces, clusters.node_sphere, strict=True):
        d = np.linalg.norm(clustered[lo:hi].reshape(-1, 3) - sphere[:3], axis=1)
        assert d.max() <= sphere[3]


def test_context_without_vertices_is_refused():
    context = prepare_skof(np.array([[0, 1, 2]]), np.ones((4, 4), bool))
    with pytest.raises(ValueError, match="with the skull's vertices"):
        skull_outside_pixels_cameras(context, np.eye(3)[None], [[0, 0, 10.0]], [10.0], [2, 2])


@needs_numba
@pytest.mark.parametrize("view", ["frontal", "lateral_left", "lateral_right"])
def test_curve_detection_kernel_gives_the_numpy_curves(view):
    from lilium.fitness.curves import detect_curves_batch

    vertices, faces = shell_skull(n_lat=30, n_lon=40, rng=8)
    low = vertices[faces].mean(axis=1)[:, 1] < -20.0  # an open cap: a chin-like region
    used, region = np.unique(faces[low], return_inverse=True)
    region = region.reshape(-1, 3)
    topology = mesh_edge_topology(region)
    R, t, focal = cameras(40, rng=9)
    uv = project_vertices(vertices[used], R, t, focal, CENTRE)
    uv[3] += 5000.0  # a window clipped at the image's surroundings
    uv[4] = np.nan  # behind the camera
    uv[5, ::3] = np.nan  # partly behind
    span = uv[:, :2, 1].copy() if view != "frontal" else None
    if span is not None:
        span[6, 0] = np.nan  # a span end behind the camera
        span[7] = span[7, ::-1]
    compiled = detect_curves_batch(
        uv, view, topology=topology, span_v=span, image_shape=(HEIGHT, WIDTH)
    )
    with jit.kernels("numpy"):
        reference = detect_curves_batch(
            uv, view, topology=topology, span_v=span, image_shape=(HEIGHT, WIDTH)
        )
    assert len(reference.points) > 400
    np.testing.assert_array_equal(compiled.offset, reference.offset)
    np.testing.assert_array_equal(compiled.points, reference.points)


def _pll_cases(view, rng=10):
    """Skull curves of 40 cameras of an open cap (30 near one camera, 10 anywhere), the facial
    curve: the middle of that camera's curve, shifted; and the awkward members: empty, one to
    three points, sub-pixel points, far off the face curve's table."""
    from lilium.fitness.curves import CurveBatch, detect_curves_batch
    from lilium.fitness.pll import face_curve_index

    vertices, faces = shell_skull(n_lat=30, n_lon=40, rng=rng)
    low = vertices[faces].mean(axis=1)[:, 1] < -20.0
    used, region = np.unique(faces[low], return_inverse=True)
    topology = mesh_edge_topology(region.reshape(-1, 3))
    rng = np.random.default_rng(rng)
    turn = {"frontal": [0.3, 0, 0], "lateral_left": [0, -1.4, 0], "lateral_right": [0, 1.4, 0]}
    R = np.array([rotvec_to_matrix(turn[view] + rng.normal(scale=0.05, size=3)) for _ in range(30)])
    t = np.column_stack([rng.normal(scale=8.0, size=(30, 2)), rng.uniform(800, 900, 30)])
    focal = t[:, 2] * rng.uniform(1.8, 2.2, 30)
    R2, t2, focal2 = cameras(10, rng=11)
    R, t, focal = np.vstack([R, R2]), np.vstack([t, t2]), np.concatenate([focal, focal2])
    uv = project_vertices(vertices[used], R, t, focal, CENTRE)
    batch = detect_curves_batch(uv, view, topology=topology, image_shape=(HEIGHT, WIDTH))
    curves = [batch.curve(m) for m in range(len(batch))]
    c = curves[0]
    face = c[len(c) // 5 : len(c) - len(c) // 6] + [3.0, 5.0]
    curves += [np.zeros((0, 2)), curves[5][:1], curves[6][:2], curves[7][:3]]
    curves += [curves[8] + rng.uniform(-0.5, 0.5, curves[8].shape), curves[9] + 900.0]
    return CurveBatch.from_curves(curves), face_curve_index(face)


@needs_numba
@pytest.mark.parametrize("view", ["frontal", "lateral_left", "lateral_right"])
def test_pll_kernels_give_the_numpy_trims_pairs_and_terms(view):
    from lilium.fitness.pll import (
        face_curve_index,
        pair_curves_batch,
        pll_terms_batch,
        terms_from_pairs,
        trim_curves_batch,
    )

    curves, index = _pll_cases(view)
    assert len(curves.points) > 2000
    short = face_curve_index(index.curve[:2])  # no end normals: nothing trimmed
    for face_index in (index, short):
        steps = {}
        for name in ("numba", "numpy"):
            with jit.kernels(name):
                skull, lo, hi = trim_curves_batch(curves, face_index)
                pairs = pair_curves_batch(skull, face_index, lo, hi)
                untrimmed = pair_curves_batch(curves, face_index)
                terms = terms_from_pairs(pairs, view)
                batch = pll_terms_batch(curves, face_index, view)
            steps[name] = (skull.points, skull.offset, lo, hi, *vars(pairs).values())
            steps[name] += (*vars(untrimmed).values(), *vars(terms).values())
            steps[name] += tuple(vars(batch).values())
        for a, b in zip(steps["numba"], steps["numpy"], strict=True):
            assert a.dtype == b.dtype
            np.testing.assert_array_equal(a, b)
    # The cases exercise every rule: trimmed on both curves, NaN terms, wrong-side pairs.
    with jit.kernels("numba"):
        skull, lo, hi = trim_curves_batch(curves, index)
        terms = pll_terms_batch(curves, index, view)
    assert (skull.lengths < curves.lengths).sum() >= 10
    assert ((lo > 0) | (hi < len(index.curve))).any()
    assert np.isnan(terms.delta_d).sum() == 1 and (terms.p_int > 0).any()
    assert (terms.p_conv > 0).any()


@needs_numba
@pytest.mark.parametrize("view", ["frontal", "lateral_left", "lateral_right"])
def test_pll_in_one_call_is_the_kernels_one_by_one(view):
    """``PllContext.terms_cameras`` (one compiled call from the cameras to the terms) gives
    the projection and the kernels called one by one, bit for bit, awkward cameras included."""
    from lilium.fitness.pll_context import PllContext
    from lilium.geometry.camera import Cameras

    vertices, faces = shell_skull(n_lat=30, n_lon=40, rng=12)
    low = vertices[faces].mean(axis=1)[:, 1] < -20.0
    used, region = np.unique(faces[low], return_inverse=True)
    vertices = vertices[used]
    rng = np.random.default_rng(12)
    turn = {"frontal": [0.3, 0, 0], "lateral_left": [0, -1.4, 0], "lateral_right": [0, 1.4, 0]}
    R = np.array([rotvec_to_matrix(turn[view] + rng.normal(scale=0.05, size=3)) for _ in range(30)])
    t = np.column_stack([rng.normal(scale=8.0, size=(30, 2)), rng.uniform(800, 900, 30)])
    focal = t[:, 2] * rng.uniform(1.8, 2.2, 30)
    R2, t2, focal2 = cameras(10, rng=13)  # far off, clipped, behind the camera
    t2[0, 2] = -2000.0  # the whole region behind the camera: no curve
    population = Cameras(
        np.vstack([R, R2]), np.vstack([t, t2]), np.concatenate([focal, focal2]), CENTRE
    )
    span_mm = None if view == "frontal" else vertices[:2]
    probe = PllContext.build(region.reshape(-1, 3), np.zeros((0, 2)), view, (HEIGHT, WIDTH))
    c = probe.skull_curve(population[0].project(vertices))
    face = c[len(c) // 5 : len(c) - len(c) // 6] + [3.0, 5.0]
    context = PllContext.build(region.reshape(-1, 3), face, view, (HEIGHT, WIDTH))
    one_call = context.terms_cameras(vertices, population, span_mm)
    span_v = None if span_mm is None else population.project(span_mm)[..., 1]
    by_steps = context.terms_batch(population.project(vertices), span_v)
    for a, b in zip(vars(one_call).values(), vars(by_steps).values(), strict=True):
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)
    assert (by_steps.n_pairs > 0).sum() >= 20 and (by_steps.n_pairs == 0).any()
    with jit.kernels("numpy"):  # the numpy path: projection and steps in numpy, same terms
        reference = context.terms_cameras(vertices, population, span_mm)
    np.testing.assert_array_equal(reference.n_pairs, by_steps.n_pairs)
    np.testing.assert_allclose(reference.total, by_steps.total, rtol=1e-9)


@needs_numba
def test_distance_to_background_is_scipys_exactly():
    """The compiled distance transform of the face mask index is scipy's EDT, exactly."""
    from scipy import ndimage

    from lilium.fitness._skof_kernels import squared_distance_to_background
    from lilium.fitness.skof import face_mask_index

    rng = np.random.default_rng(12)
    masks = [rng.random((31, 47)) > p for p in (0.002, 0.05, 0.6)] + [face_mask()]
    masks.append(np.ones((5, 6), bool))
    for mask in masks:
        got = np.sqrt(squared_distance_to_background(mask))
        want = ndimage.distance_transform_edt(mask) if not mask.all() else np.inf
        np.testing.assert_array_equal(got, np.broadcast_to(want, mask.shape))
    compiled = face_mask_index(face_mask())
    with jit.kernels("numpy"):
        reference = face_mask_index(face_mask())
    np.testing.assert_array_equal(compiled.clearance2, reference.clearance2)


@needs_numba
def test_edge_table_kernel_gives_numpys_topology():
    """The compiled edge table (a counting sort) gives np.unique's edges, in its order, and the
    same face-edge links, also for a fan of 500 faces round one vertex, repeated and
    degenerate faces."""
    rng = np.random.default_rng(8)
    vertices, faces = shell_skull(rng=1)
    fan = np.column_stack([np.zeros(500, np.int64), np.arange(1, 501), np.arange(2, 502)])
    odd = np.concatenate([fan, rng.integers(0, 600, (3000, 3)), [[5, 5, 7], [1, 2, 3], [1, 2, 3]]])
    for f in (faces, odd):
        compiled = mesh_edge_topology(f)
        with jit.kernels("numpy"):
            reference = mesh_edge_topology(f)
        for name in ("edges", "face_edges", "face_dirs", "edges_a", "edges_b"):
            np.testing.assert_array_equal(getattr(compiled, name), getattr(reference, name))
        for name in ("indptr", "indices", "data"):
            np.testing.assert_array_equal(
                getattr(compiled.incidence, name), getattr(reference.incidence, name)
            )
        # scipy's CSR of the same entries (sum_duplicates), the product as scipy computes it
        from scipy import sparse

        n = len(f)
        scipy_incidence = sparse.csr_matrix(
            (reference.incidence.data, reference.incidence.indices, reference.incidence.indptr),
            shape=reference.incidence.shape,
        )
        a, b = f.reshape(-1), f[:, [1, 2, 0]].reshape(-1)
        direct = sparse.csr_matrix(
            (np.where(a < b, 1.0, -1.0), (compiled.face_edges.reshape(-1), np.arange(3 * n) // 3)),
            shape=compiled.incidence.shape,
        )
        direct.sum_duplicates()
        assert (direct != scipy_incidence).nnz == 0
        sign = rng.choice([-1.0, 0.0, 1.0], (4, n))
        np.testing.assert_array_equal(compiled.incidence @ sign.T, direct @ sign.T)


@needs_numba
@pytest.mark.parametrize("cell_mm", [0.5, 4.0, 2000.0])
def test_vertex_clustering_kernel_is_numpys_bit_for_bit(cell_mm):
    """Dense cell numbering (a compact shell) and sorted numbering (a few vertices spread over a
    bounding box of far more cells than the table may hold)."""
    from lilium.geometry.mesh import cluster_vertices

    vertices, faces = shell_skull(n_lat=30, n_lon=40, rng=14)
    spread = np.vstack([vertices, vertices[:50] * 400.0])
    for v, f in ((vertices, faces), (spread, faces)):
        compiled = cluster_vertices(v, f, cell_mm)
        with jit.kernels("numpy"):
            reference = cluster_vertices(v, f, cell_mm)
        for a, b in zip(compiled, reference, strict=True):
            assert a.dtype == b.dtype
            np.testing.assert_array_equal(a, b)


@needs_numba
def test_vertex_normals_kernel_is_numpys_bit_for_bit():
    """Area-weighted vertex normals, an unused vertex (0) and a degenerate face included."""
    from lilium.imaging.shading import vertex_normals

    vertices, faces = shell_skull(n_lat=20, n_lon=30, rng=17)
    vertices = np.vstack([vertices, [[1e3, 0.0, 0.0]]])  # unused: a zero normal
    faces = np.vstack([faces, [[0, 0, 1]]])  # degenerate: adds nothing
    compiled = vertex_normals(vertices, faces)
    with jit.kernels("numpy"):
        reference = vertex_normals(vertices, faces)
    np.testing.assert_array_equal(compiled, reference)
    assert not compiled[-1].any()
    np.testing.assert_allclose(np.linalg.norm(compiled[:-1], axis=1), 1.0, rtol=1e-12)


@needs_numba
def test_nearest_point_table_kernel_is_the_k_d_trees():
    """The facial curve's nearest-point table by the compiled bucket search equals the numpy
    path's (k-d tree candidates, ties settled by brute force): integer and sub-pixel curves,
    many coincident points (ties to the lowest index), margins from 0 to 70 px."""
    from lilium.fitness.pll import face_curve_index

    rng = np.random.default_rng(18)
    for trial in range(24):
        n = int(rng.integers(1, 300))
        points = np.round(rng.uniform(0, rng.uniform(5, 400), (n, 2)))
        if trial % 3 == 0:
            points += rng.uniform(-0.5, 0.5, points.shape)
        if trial % 4 == 0:
            points[: n // 2] = points[0]
        margin = int(rng.integers(0, 70))
        compiled = face_curve_index(points, margin_px=margin)
        with jit.kernels("numpy"):
            reference = face_curve_index(points, margin_px=margin)
        assert compiled.origin == reference.origin
        np.testing.assert_array_equal(compiled.table, reference.table)
