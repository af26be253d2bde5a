"""Levenberg-Marquardt on reprojection error + camera priors (lilium.pose.prior_refine)."""

import numpy as np
import pytest

from lilium import jit
from lilium.geometry import Camera
from lilium.geometry.rotations import geodesic_angle_deg, rotvec_to_matrix
from lilium.pose import refine_batch
from lilium.pose.prior_refine import _prior_residuals, _step, refine_with_priors

CENTRE = np.array([512.0, 384.0])


def scene(seed, n=12, noise_px=3.0):
    rng = np.random.default_rng(seed)
    X = rng.normal(scale=(60.0, 70.0, 25.0), size=(n, 3))  # a flat-ish face
    R = rotvec_to_matrix(rng.normal(scale=0.15, size=3))
    t = np.array([5.0, -10.0, 900.0])
    truth = Camera.from_rt(R, t, 2400.0, CENTRE)
    uv = truth.project(X) + rng.normal(scale=noise_px, size=(n, 2))
    return X, uv, truth


def test_prior_jacobian_matches_finite_differences():
    rng = np.random.default_rng(3)
    S = 5
    R = rotvec_to_matrix(rng.normal(scale=0.3, size=(S, 3)))
    c = np.column_stack([rng.normal(scale=20.0, size=(S, 2)), rng.uniform(500, 900, S)])
    log_f = np.log(rng.uniform(1500, 3500, S))
    rel = rng.normal(scale=30.0, size=(S, 3))
    priors = ((2000.0, 2100.0), (950.0, 1000.0), np.eye(3), 2.0)
    h, J = _prior_residuals(R, c, log_f, rel, *priors)
    assert np.all(h[:, :4].sum(axis=1) > 0)
    for k in range(7):
        d = np.zeros((S, 7))
        d[:, k] = 1e-6 if k < 3 else (1e-4 if k < 5 else 1e-7)
        hk, _ = _prior_residuals(*_step(R, c, log_f, d), rel, *priors)
        np.testing.assert_allclose(J[:, :, k], (hk - h) / d[0, k], rtol=1e-3, atol=1e-3)


def test_inside_every_prior_is_plain_least_squares():
    X, uv, truth = scene(1)
    ls = refine_batch(uv - CENTRE, X, truth.R[None], truth.t[None], [truth.focal_px])
    wide = refine_with_priors(
        uv - CENTRE,
        X[None],
        ls.R,
        ls.t,
        ls.focal_px,
        X[:1],
        focal_interval_px=(10.0, 1e5),
        scd_interval_mm=(1.0, 1e5),
    )
    np.testing.assert_allclose(wide.focal_px, ls.focal_px, rtol=1e-6)
    np.testing.assert_allclose(wide.cost, ls.cost / len(X), rtol=1e-6)


@pytest.mark.parametrize("seed", [2, 5, 9])
def test_camera_is_pulled_into_the_priors(seed):
    X, uv, truth = scene(seed, noise_px=6.0)
    ls = refine_batch(uv - CENTRE, X, truth.R[None], truth.t[None], [truth.focal_px])
    f = truth.focal_px
    prior = (0.97 * f, 1.03 * f)
    out = refine_with_priors(
        uv - CENTRE,
        X[None],
        ls.R,
        ls.t,
        ls.focal_px,
        X[:1],
        focal_interval_px=prior,
        head_rotation=truth.R,
        head_tolerance_deg=1.0,
    )
    excess = max(0.0, prior[0] - out.focal_px[0], out.focal_px[0] - prior[1])
    start_excess = max(0.0, prior[0] - ls.focal_px[0], ls.focal_px[0] - prior[1])
    assert start_excess > 10.0 and excess <= 0.05 * start_excess
    # The cost is MSE_pix + P_cam of the refined camera, below the least-squares camera's.
    head = max(0.0, geodesic_angle_deg(out.R[0], truth.R) - 1.0)
    start_head = max(0.0, geodesic_angle_deg(ls.R[0], truth.R) - 1.0)
    mse = np.mean(out.sq_err_px2[0])
    assert out.cost[0] == pytest.approx(mse + excess**2 + head**2)
    assert out.cost[0] < np.mean(ls.sq_err_px2[0]) + start_excess**2 + start_head**2


@pytest.mark.skipif(not jit.NUMBA_AVAILABLE, reason="numba not installed")
@pytest.mark.parametrize("head", [True, False])
def test_compiled_path_takes_the_numpy_steps(head):
    """The compiled kernel against the numpy reference: a batch of cameras started off their
    priors (focal, distance, head), every prior on, or the head's off."""
    rng = np.random.default_rng(11)
    S = 12
    X, uv, truth = scene(4, noise_px=5.0)
    P = X[None] + rng.normal(scale=2.0, size=(S,) + X.shape)  # members' soft tissue
    R0 = rotvec_to_matrix(rng.normal(scale=0.05, size=(S, 3))) @ truth.R
    t0 = truth.t + rng.normal(scale=(5.0, 5.0, 80.0), size=(S, 3))
    f0 = truth.focal_px * rng.uniform(0.6, 1.5, S)
    kwargs = dict(
        focal_interval_px=(0.95 * truth.focal_px, 1.05 * truth.focal_px),
        scd_interval_mm=(880.0, 920.0),
        head_rotation=truth.R if head else None,
        head_tolerance_deg=1.0 if head else None,
        max_iterations=8,
    )
    args = (uv - CENTRE, P, R0, t0, f0, P[:, 0])
    start = R0.copy()
    with jit.kernels("numpy"):
        ref = refine_with_priors(*args, **kwargs)
    with jit.kernels("numba"):
        out = refine_with_priors(*args, **kwargs)
    assert np.all(np.isfinite(ref.cost)) and ref.n_iterations >= 4  # real work, not one step
    np.testing.assert_allclose(out.cost, ref.cost, rtol=1e-9)
    np.testing.assert_allclose(out.focal_px, ref.focal_px, rtol=1e-9)
    np.testing.assert_allclose(out.R, ref.R, atol=1e-9)
    np.testing.assert_allclose(out.t, ref.t, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(out.sq_err_px2, ref.sq_err_px2, rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(R0, start)  # the caller's start is not refined in place
