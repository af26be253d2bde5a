"""The compiled kernels against their numpy references (lilium.jit): same integers, same floats.

The references are the numpy code the kernels replaced (still the package's fallback path,
selected with ``lilium.jit.kernels("numpy")``) and the per-triangle oracle of
``tests/raster_oracle.py``.
"""

import numpy as np
import pytest

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

needs_numba = pytest.mark.skipif(not jit.NUMBA_AVAILABLE, reason="numba is not installed")

HEIGHT, WIDTH = 480, 640
CENTRE = np.array([320.0, 240.0])


def shell_skull(n_lat=40, n_lon=60, rng=0):
    """A bumpy two-walled shell (outer and inner table, mm) with a hole at the bottom.

    Open borders, back faces inside the front ones, about 2 n_lat n_lon faces per wall.
    """
    rng = np.random.default_rng(rng)
    theta = np.linspace(0.05, 0.8 * np.pi, n_lat)
    phi = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    T, P = np.meshgrid(theta, phi, indexing="ij")
    bumps = 0.08 * np.sin(3 * T) * np.cos(5 * P) + 0.01 * rng.standard_normal(T.shape)
    direction = np.stack([np.sin(T) * np.cos(P), np.cos(T), np.sin(T) * np.sin(P)], -1)
    radii = np.array([70.0, 85.0, 90.0])
    walls, faces = [], []
    idx = np.arange(n_lat * n_lon).reshape(n_lat, n_lon)
    nxt = np.roll(idx, -1, axis=1)
    quads = [
        np.stack([idx[:-1], nxt[:-1], nxt[1:]], -1).reshape(-1, 3),
        np.stack([idx[:-1], nxt[1:], idx[1:]], -1).reshape(-1, 3),
    ]
    for k, scale in enumerate((1.0, 0.9)):
        walls.append((direction * ((1 + bumps) * scale)[..., None] * radii).reshape(-1, 3))
        wall_faces = np.vstack(quads) + k * n_lat * n_lon
        faces.append(wall_faces if k == 0 else wall_faces[:, ::-1])
    return np.vstack(walls), np.vstack(faces)


def face_mask(holes=True):
    """An elliptical head mask, with a notch and a hole (non-convex, not simply connected)."""
    rows, cols = np.mgrid[:HEIGHT, :WIDTH]
    mask = ((cols - 320) / 190.0) ** 2 + ((rows - 250) / 215.0) ** 2 <= 1.0
    if not holes:
        return mask
    mask[300:330, 120:260] = False
    mask[150:170, 300:330] = False
    return mask


def cameras(n, rng=0):
    """Rotated, scaled and shifted cameras looking at the shell: some clip the image, some put
    vertices behind the camera."""
    rng = np.random.default_rng(rng)
    R = np.array([rotvec_to_matrix(rng.normal(scale=0.6, size=3)) for _ in range(n)])
    depth = rng.uniform(400.0, 2500.0, n)
    depth[: n // 8] = rng.uniform(60.0, 110.0, n // 8)  # the camera inside the shell's reach
    t = np.column_stack([rng.normal(scale=40.0, size=(n, 2)), depth])
    focal = depth * rng.uniform(1.2, 3.2, n)
    return R, t, focal


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


def _lm_problems(S=120, N=18, rng=7):
    from lilium.geometry.camera import project_points

    rng = np.random.default_rng(rng)
    X = rng.normal(scale=60.0, size=(S, N, 3))
    R = np.array([rotvec_to_matrix(rng.normal(size=3)) for _ in range(S)])
    t = np.column_stack([rng.normal(scale=20.0, size=(S, 2)), rng.uniform(500.0, 1500.0, S)])
    f = rng.uniform(1000.0, 4000.0, S)
    uv = project_points(X, R, t, f) + rng.normal(scale=2.0, size=(S, N, 2))
    turn = np.array([rotvec_to_matrix(rng.normal(scale=0.05, size=3)) for _ in range(S)])
    start = (turn @ R, t + rng.normal(scale=[5.0, 5.0, 50.0], size=(S, 3)), f * 1.05)
    weights = (rng.random((S, N)) > 0.2).astype(float)
    t[0, 2] = -5.0  # one problem starts behind the camera
    return uv, X, start, weights


@needs_numba
def test_lm_kernel_matches_the_numpy_iterations():
    """Lilium's warm-started refinement (6 iterations): the compiled loop takes the numpy
    path's steps (1e-9 relative)."""
    from lilium.methods.options import SfoOptions
    from lilium.pose.refine import refine_batch

    uv, X, (R0, t0, f0), w = _lm_problems()
    options = SfoOptions().refine
    compiled = refine_batch(uv, X, R0, t0, f0, w, options)
    with jit.kernels("numpy"):
        reference = refine_batch(uv, X, R0, t0, f0, w, options)
    assert compiled.n_iterations == reference.n_iterations
    for name in ("R", "t", "focal_px", "sq_err_px2", "cost"):
        a, b = getattr(compiled, name), getattr(reference, name)
        np.testing.assert_array_equal(np.isfinite(a), np.isfinite(b))
        ok = np.isfinite(b)
        np.testing.assert_allclose(a[ok], b[ok], rtol=1e-9, atol=1e-9 * np.abs(b[ok]).max())


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
def test_reprojection_errors_and_decoding_kernels_match_numpy():
    """The squared reprojection errors (shared and per-camera points, cameras behind the points)
    and the genes' decoding (bilateral hybrids included) agree with numpy to rounding."""
    from lilium.pose.residuals import reprojection_sq_errors
    from lilium.softtissue.cones import decode, make_cones
    from lilium.softtissue.landmarks import CRANIAL_NAMES

    rng = np.random.default_rng(4)
    S = 200
    R = np.array([rotvec_to_matrix(v) for v in rng.normal(size=(S, 3))])
    t = np.column_stack([rng.normal(scale=20.0, size=(S, 2)), rng.uniform(-100.0, 1500.0, S)])
    f = rng.uniform(1000.0, 4000.0, S)
    for X in (rng.normal(scale=60.0, size=(18, 3)), rng.normal(scale=60.0, size=(S, 18, 3))):
        uv = rng.normal(scale=300.0, size=(18, 2))
        compiled = reprojection_sq_errors(uv, X, R, t, f)
        with jit.kernels("numpy"), np.errstate(invalid="ignore"):
            reference = reprojection_sq_errors(uv, X, R, t, f)
        behind = np.isinf(reference)
        assert behind.any() and np.array_equal(np.isinf(compiled), behind)
        np.testing.assert_allclose(compiled[~behind], reference[~behind], rtol=1e-12)

    names = list(CRANIAL_NAMES)
    axes = rng.normal(size=(len(names), 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    low = rng.uniform(2.0, 8.0, len(names))
    cones = make_cones(names, axes, low, low + rng.uniform(3.0, 10.0, len(names)))
    assert len(cones.pairs)
    genes = rng.random((300, cones.n_genes))
    compiled = decode(genes, cones)
    with jit.kernels("numpy"):
        reference = decode(genes, cones)
    np.testing.assert_allclose(compiled, reference, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(decode(genes[0], cones), compiled[0])


@needs_numba
def test_projection_kernel_matches_numpy():
    """project_points, shared and per-camera points, some behind the camera: NaN in the same
    places, the same pixels to rounding."""
    from lilium.geometry.camera import project_points

    rng = np.random.default_rng(5)
    S = 50
    R = np.array([rotvec_to_matrix(v) for v in rng.normal(size=(S, 3))])
    t = np.column_stack([rng.normal(scale=20.0, size=(S, 2)), rng.uniform(-100.0, 1500.0, S)])
    f = rng.uniform(1000.0, 4000.0, S)
    for X in (rng.normal(scale=60.0, size=(40, 3)), rng.normal(scale=60.0, size=(S, 40, 3))):
        compiled = project_points(X, R, t, f, CENTRE)
        with jit.kernels("numpy"):
            reference = project_points(X, R, t, f, CENTRE)
        behind = np.isnan(reference)
        assert behind.any() and np.array_equal(np.isnan(compiled), behind)
        np.testing.assert_allclose(compiled[~behind], reference[~behind], rtol=1e-12)


@needs_numba
def test_compiled_projection_and_errors_broadcast_as_numpy_does():
    """A focal length and translation shared by the cameras ((1,) and (1, 3)), one point set
    for all of them given as (1, N, 3), and a mismatch of image and 3D points: the compiled
    wrappers answer as the numpy path does (same values, or an error) and never read past an
    array."""
    from lilium.geometry.camera import project_points
    from lilium.pose.refine import refine_batch
    from lilium.pose.residuals import reprojection_sq_errors

    rng = np.random.default_rng(6)
    R = np.repeat(np.eye(3)[None], 3, axis=0)
    X = rng.normal(scale=30.0, size=(4, 3))
    t, f = np.array([[0.0, 0.0, 500.0]]), np.array([800.0])
    uv = rng.normal(scale=10.0, size=(4, 2))
    for args in ((X, R, t, f), (X[None], R, t, f)):
        compiled = project_points(*args)
        with jit.kernels("numpy"):
            np.testing.assert_allclose(compiled, project_points(*args), rtol=1e-12)
    compiled = reprojection_sq_errors(uv, X, R, t, f)
    with jit.kernels("numpy"):
        np.testing.assert_allclose(compiled, reprojection_sq_errors(uv, X, R, t, f), rtol=1e-12)
    assert np.ptp(compiled, axis=0).max() == 0  # three identical cameras
    with pytest.raises(ValueError):
        reprojection_sq_errors(uv[:3], X, R, t, f)
    with pytest.raises(ValueError):
        project_points(np.repeat(X[None], 2, axis=0), R, t, f)
    one = refine_batch(uv, X, R[:1], t[0], [800.0])  # a (3,) translation for one camera
    with jit.kernels("numpy"):
        ref = refine_batch(uv, X, R[:1], t[0], [800.0])
    np.testing.assert_allclose(one.t, ref.t, rtol=1e-9)


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
@pytest.mark.parametrize("priors_on", [True, False])
def test_camera_terms_and_checks_kernels_match_numpy(case, priors_on):
    """A population's cameras and camera terms (the checks after the refinement: facing rule,
    focal range and cap, best capped fit; MSE_pix, P_cam with or without priors) agree with
    the numpy path: the same validity and capped fit, terms to rounding."""
    from dataclasses import replace

    from lilium.inputs import CameraPriors
    from lilium.io.case import read_photo, read_skull
    from lilium.methods import SfoOptions
    from lilium.methods.lilium import LiliumProblem

    skull, photo = read_skull(case[0]), read_photo(case[1])
    if priors_on:
        R_head = photo.priors.head_rotation_skull2cam
        if R_head is None:
            R_head = rotvec_to_matrix(np.array([np.pi, 0.0, 0.0]))
        photo = replace(
            photo,
            priors=CameraPriors(
                focal_px=(1100.0, 1150.0),
                scd_mm=(900.0, 950.0),
                head_rotation_skull2cam=R_head,
                head_tolerance_deg=1.0,
            ),
        )
    else:
        photo = replace(photo, priors=CameraPriors())
    rng = np.random.default_rng(6)
    outputs = []
    for path in ("numba", "numpy"):
        with jit.kernels(path):
            problem = LiliumProblem(skull, photo, SfoOptions("base"), rng=0)
            facial = problem.facial_landmarks(rng.random((120, problem.cones.n_genes)))
            first = problem.camera_terms(facial)  # POSEST, then the refinement
            members = {k: first[k] for k in ("R", "t", "focal_px", "success")}
            # Warm starts from other members' cameras: some fits fail the checks.
            shuffled = {k: np.asarray(v)[::-1].copy() for k, v in members.items()}
            second = problem.camera_terms(facial, shuffled)
            outputs.append((first, second, problem.capped_mse, problem.capped_focal_px))
        rng = np.random.default_rng(6)
    (a1, a2, a_mse, a_f), (b1, b2, b_mse, b_f) = outputs
    for a, b in ((a1, b1), (a2, b2)):
        np.testing.assert_array_equal(a["success"], b["success"])
        for key in ("mse_pix", "p_cam", "fitness", "focal_px"):
            np.testing.assert_allclose(a[key], b[key], rtol=1e-9)
    assert not a2["success"].all() and a2["success"].any()
    hinged = (a2["p_cam"] > 0) & (a2["p_cam"] < 1e12)
    assert hinged.any() if priors_on else not hinged.any()
    assert (a_f is None) == (b_f is None)
    if a_f is not None:
        np.testing.assert_allclose([a_mse, a_f], [b_mse, b_f], rtol=1e-9)


@needs_numba
def test_camera_checks_kernel_matches_the_numpy_rules():
    """Facing rule, focal range, best capped fit and the hand-back to the numpy path (a broken
    camera; no valid camera and no lender), against the numpy rules they replace."""
    from lilium.fitness._camera_kernels import camera_checks_kernel
    from lilium.methods.checks import FacingRule, SkullDirections

    rng = np.random.default_rng(8)
    S, N = 400, 12
    R = np.array([rotvec_to_matrix(v) for v in rng.normal(scale=1.5, size=(S, 3))])
    t = rng.normal(scale=400.0, size=(S, 3))
    f = rng.choice([0.5, 800.0, 1500.0, 2500.0, 4000.0, 9000.0], S)
    sq = rng.random((S, N)) * 50.0
    cost = sq.sum(axis=1)
    anterior = np.array([0.0, 0.0, 1.0])
    directions = SkullDirections(np.array([1.0, -2.0, 3.0]), anterior, None, None, "", "")
    rule = FacingRule(directions, 0.2)
    cap, run_off = 2000.0, 5000.0
    facing = rule(R, t)
    ok = (f >= 1.0) & (f <= cap) & facing
    capped = (f > cap) & (f <= run_off) & facing
    assert 0 < facing.sum() < S and ok.any() and capped.any()
    mse = np.where(capped, sq.mean(axis=1), np.inf)
    origin = rule.directions.origin_mm
    out = sq.copy()
    done, got_ok, k, k_mse = camera_checks_kernel(
        R, t, f, cost, out, origin, anterior, rule.cos_max, cap, run_off, True
    )
    assert done and np.array_equal(got_ok, ok)
    assert k == np.argmin(mse) and np.isclose(k_mse, mse.min(), rtol=1e-12)
    assert np.isinf(out[~ok]).all() and np.array_equal(out[ok], sq[ok])
    # Without the rule every camera faces.
    done, got_ok, _, _ = camera_checks_kernel(
        R, t, f, cost, sq.copy(), origin, anterior, np.nan, cap, run_off, True
    )
    assert done and np.array_equal(got_ok, (f >= 1.0) & (f <= cap))
    # A camera centred on the origin (no direction): it passes, as on the numpy path.
    eye, centred = np.eye(3)[None], -directions.origin_mm[None]
    with np.errstate(invalid="ignore"):
        assert rule(eye, centred)[0]
    one = sq[:1].copy()
    done, got_ok, _, _ = camera_checks_kernel(
        eye, centred, np.array([1000.0]), cost[:1], one, origin, anterior, rule.cos_max, cap,
        run_off, True,
    )  # fmt: skip
    assert done and got_ok[0]
    # Hand-backs: nothing is changed.
    broken = sq.copy()
    broken[7, 3] = np.inf
    assert not camera_checks_kernel(
        R, t, f, cost, broken, origin, anterior, rule.cos_max, cap, run_off, True
    )[0]
    assert np.isinf(broken).sum() == 1
    none_ok = np.full(S, 9000.0)
    assert not camera_checks_kernel(
        R, t, none_ok, cost, sq.copy(), origin, anterior, rule.cos_max, cap, run_off, False
    )[0]
    assert camera_checks_kernel(
        R, t, none_ok, cost, sq.copy(), origin, anterior, rule.cos_max, cap, run_off, True
    )[0]


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
@pytest.mark.parametrize("nasion", [True, False])
def test_camera_stage_in_one_call_is_the_steps_one_by_one(case, nasion):
    """A generation's camera terms in one compiled call (``LiliumProblem.evaluate`` with
    members) equal the kernels called one by one (``camera_terms``) bit for bit: members
    lending their camera to those without one, a warm start that breaks (a camera behind the
    skull: its own POSEST on the numpy path), the capped fit noted; the subject-to-camera
    distance from the nasion or, without it, from the mean of every facial landmark."""
    from dataclasses import replace

    from lilium.io.case import read_photo, read_skull
    from lilium.methods import SfoOptions
    from lilium.methods.lilium import LiliumProblem

    skull, photo = read_skull(case[0]), read_photo(case[1])
    if not nasion:
        landmarks = {k: v for k, v in photo.landmarks_uv.items() if k != "nasion"}
        photo = replace(photo, landmarks_uv=landmarks)
    results = []
    for one_call in (True, False):
        problem = LiliumProblem(skull, photo, SfoOptions("base"), rng=0)
        assert (len(problem.scd_index) == 1) == nasion
        genes = np.random.default_rng(15).random((60, problem.cones.n_genes))
        first = problem.evaluate(genes)
        members = {k: np.asarray(first[k])[::-1].copy() for k in ("R", "t", "focal_px", "success")}
        members["success"][:5] = False  # they take the first valid member's camera
        trials = np.random.default_rng(16).random(genes.shape)
        for broken in (False, True):
            if broken:
                members["t"][7] = [0.0, 0.0, -1000.0]  # behind the skull: the refinement breaks
                members["success"][7] = True
            if one_call:
                terms = problem.evaluate(trials, members)
            else:
                terms = problem.camera_terms(problem.facial_landmarks(trials), members)
            results.append((terms, problem.n_fallbacks, problem.capped_mse))
    for (a, fa, ma), (b, fb, mb) in zip(results[:2], results[2:], strict=True):
        assert fa == fb and ma == mb
        for key in ("fitness", "mse_pix", "p_cam", "R", "t", "focal_px", "success"):
            np.testing.assert_array_equal(a[key], b[key])
    assert results[0][1] == 0 and results[1][1] > 0  # the broken start went to POSEST
    assert results[0][0]["success"].any() and not results[0][0]["success"].all()


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


@needs_numba
def test_whitened_residuals_kernel_matches_numpy():
    """The identification refits' whitened residuals: compiled (the refit's kernel with the
    cameras not moved) and numpy agree to rounding, cameras with a landmark behind them (1e3
    everywhere) and one photo per camera included."""
    from lilium.identification._cohort_kernels import refit_whitened_kernel
    from lilium.identification.cohort import _whitened
    from lilium.identification.terms import soft_tissue_covariance

    rng = np.random.default_rng(19)
    K, N = 12, 15
    R = np.array([rotvec_to_matrix(rng.normal(scale=0.2, size=3)) for _ in range(K)])
    t = np.column_stack([rng.normal(scale=20.0, size=(K, 2)), rng.uniform(600, 1500, K)])
    t[3, 2] = -800.0  # every landmark behind the camera
    f = rng.uniform(1500, 4000, K)
    points = rng.normal(scale=60.0, size=(K, N, 3))
    axes = rng.normal(size=(K * N, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    cov = soft_tissue_covariance(axes, rng.uniform(3, 15, K * N), rng.uniform(1, 4, K * N))
    cov = cov.reshape(K, N, 3, 3)
    sigma = rng.uniform(1.5, 6.0, N)
    for uv in (rng.uniform(0, 2000, (N, 2)), rng.uniform(0, 2000, (K, N, 2))):
        uv_k = np.ascontiguousarray(np.broadcast_to(uv, (K, N, 2)))
        compiled = refit_whitened_kernel(
            np.zeros((K, 7)), R, t, f, 960.0, 540.0, points, cov, uv_k, sigma
        )
        reference = _whitened(R, t, f, np.array([960.0, 540.0]), points, cov, uv, sigma)
        assert np.all(compiled[3] == 1e3) and np.all(reference[3] == 1e3)
        np.testing.assert_allclose(compiled, reference, rtol=1e-12, atol=1e-12)


@needs_numba
def test_identification_refit_kernel_matches_numpy():
    """A whole camera refit of the identification (moves of the cameras and whitened residuals
    compiled together) agrees with the numpy path's (one photo per camera, each made by its
    skull: a well-posed refit; an ill-posed one may follow another Levenberg-Marquardt path
    from a difference of rounding, as any reordering of its sums would)."""
    from lilium.identification.cohort import refit_cameras

    rng = np.random.default_rng(20)
    K, N = 10, 14
    R0 = np.array([rotvec_to_matrix(rng.normal(scale=0.1, size=3)) for _ in range(K)])
    t0 = np.column_stack([rng.normal(scale=5.0, size=(K, 2)), rng.uniform(900, 1100, K)])
    f0 = rng.uniform(2500, 3500, K)
    cranial = rng.normal(scale=50.0, size=(K, N, 3))
    axes = rng.normal(size=(K, N, 3))
    axes /= np.linalg.norm(axes, axis=2, keepdims=True)
    mean_mm, sd_mm = rng.uniform(4, 12, N), rng.uniform(1, 3, N)
    truth = np.einsum("kij,knj->kni", R0, cranial + mean_mm[:, None] * axes) + t0[:, None]
    uv = truth[..., :2] * (f0[:, None, None] / truth[..., 2:3]) + [960.0, 540.0]
    uv += rng.normal(scale=2, size=uv.shape)
    f0 = f0 * rng.uniform(0.9, 1.1, K)  # start away from the cameras that made the photos
    sigma = np.full(N, 3.0)
    args = (R0, t0, f0, np.array([960.0, 540.0]), cranial, axes, mean_mm, sd_mm, uv, sigma)
    compiled = refit_cameras(*args)
    with jit.kernels("numpy"):
        reference = refit_cameras(*args)
    for a, b in zip(compiled, reference, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-7)
    assert not np.allclose(compiled[2], f0)  # the refit moved the cameras
