"""The compiled camera kernels against their numpy references (lilium.jit): the same validity,
floats the same or equal to rounding.

The projection and reprojection errors, the genes' decoding, the Levenberg-Marquardt
refinement, the camera checks and terms and the whole camera stage in one call, and the
identification's whitened residuals and camera refits. The references are the numpy code the
kernels replaced (still the package's fallback path, selected with
``lilium.jit.kernels("numpy")``). The mesh, raster and curve kernels are
``test_kernels_mesh.py``'s.
"""

import numpy as np
import pytest

from kernel_cases import CENTRE, needs_numba
from lilium import jit
from lilium.geometry.rotations import rotvec_to_matrix


def _cameras_some_behind(rng, S):
    """``S`` random cameras (rotations, translations, focal lengths), some with the scene
    behind them (depth from -100 to 1500 mm)."""
    R = np.array([rotvec_to_matrix(v) for v in rng.normal(size=(S, 3))])
    t = np.column_stack([rng.normal(scale=20.0, size=(S, 2)), rng.uniform(-100.0, 1500.0, S)])
    f = rng.uniform(1000.0, 4000.0, S)
    return R, t, f


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
def test_reprojection_errors_and_decoding_kernels_match_numpy():
    """The squared reprojection errors (shared and per-camera points, cameras behind the points)
    and the genes' decoding (bilateral hybrids included) agree with numpy to rounding."""
    from lilium.pose.residuals import reprojection_sq_errors
    from lilium.softtissue.cones import decode, make_cones
    from lilium.softtissue.landmarks import CRANIAL_NAMES

    rng = np.random.default_rng(4)
    S = 200
    R, t, f = _cameras_some_behind(rng, S)
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
    R, t, f = _cameras_some_behind(rng, S)
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
@pytest.mark.parametrize("priors_on", [True, False])
def test_camera_terms_and_checks_kernels_match_numpy(case, priors_on):
    """A population's cameras and camera terms (the checks after the refinement: facing rule,
    focal range and cap, best capped fit; MSE_pix, P_cam with or without priors) agree with
    the numpy path: the same validity and capped fit, terms to rounding."""
    from dataclasses import replace

    from lilium.casework.build import read_photo, read_skull
    from lilium.inputs import CameraPriors
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
@pytest.mark.parametrize("nasion", [True, False])
def test_camera_stage_in_one_call_is_the_steps_one_by_one(case, nasion):
    """A generation's camera terms in one compiled call (``LiliumProblem.evaluate`` with
    members) equal the kernels called one by one (``camera_terms``) bit for bit: members
    lending their camera to those without one, a warm start that breaks (a camera behind the
    skull: its own POSEST on the numpy path), the capped fit noted; the subject-to-camera
    distance from the nasion or, without it, from the mean of every facial landmark."""
    from dataclasses import replace

    from lilium.casework.build import read_photo, read_skull
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
