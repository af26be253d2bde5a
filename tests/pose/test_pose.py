"""POSEST round trips: make a camera, project, recover it; failures are falsy values."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lilium.geometry import Camera, geodesic_angle_deg
from lilium.pose import (
    PosestOptions,
    RansacOptions,
    msac,
    p4pf,
    posest,
    refine_batch,
    reprojection_sq_errors,
)

PRINCIPAL_POINT_PX = np.array([1999.5, 1499.5])
#: Noise-free recovery (docs/method/pose.md target).
EXACT_FOCAL_REL = 1e-6
EXACT_RMS_PX = 1e-6


def head_scene(rng, n=20, focal_px=None, depth_mm=None, yaw_deg=None):
    """Points on a head-sized ellipsoid's visible side, a camera and the noise-free image.

    Returns points (n, 3) mm, skull2cam (4, 4), focal_px and uv (n, 2) px.
    """
    focal = rng.uniform(1500.0, 5000.0) if focal_px is None else focal_px
    depth = rng.uniform(600.0, 1500.0) if depth_mm is None else depth_mm
    yaw = rng.uniform(-80.0, 80.0) if yaw_deg is None else yaw_deg
    az = np.radians(rng.uniform(-80.0, 80.0, n) + yaw)
    el = np.radians(rng.uniform(-50.0, 40.0, n))
    points = np.column_stack([np.sin(az) * np.cos(el), -np.sin(el), -np.cos(az) * np.cos(el)])
    points *= [75.0, 100.0, 90.0]
    skull2cam = np.eye(4)
    skull2cam[:3, :3] = Rotation.from_euler(
        "YXZ", [-yaw, rng.uniform(-15, 15), rng.uniform(-10, 10)], degrees=True
    ).as_matrix()
    skull2cam[:3, 3] = [rng.uniform(-50, 50), rng.uniform(-50, 50), depth]
    return points, skull2cam, focal, Camera(skull2cam, focal, PRINCIPAL_POINT_PX).project(points)


@pytest.mark.parametrize("seed", range(8))
def test_noise_free_round_trip_is_exact(seed):
    points, skull2cam, focal, uv = head_scene(np.random.default_rng(seed))
    result = posest(uv, points, PRINCIPAL_POINT_PX)
    assert result, result.message
    assert result.message == ""
    assert abs(result.camera.focal_px - focal) / focal < EXACT_FOCAL_REL
    assert result.rms_px < EXACT_RMS_PX
    assert geodesic_angle_deg(result.camera.R, skull2cam[:3, :3]) < 1e-6
    np.testing.assert_allclose(result.camera.t, skull2cam[:3, 3], rtol=1e-6)
    np.testing.assert_array_equal(result.camera.skull2cam[3], [0, 0, 0, 1])
    assert result.inliers.all()


@pytest.mark.parametrize("seed", range(4))
def test_noisy_round_trip(seed):
    rng = np.random.default_rng(100 + seed)
    points, skull2cam, focal, uv = head_scene(rng, n=25, depth_mm=700.0)
    noisy = uv + rng.normal(scale=1.0, size=uv.shape)
    result = posest(noisy, points, PRINCIPAL_POINT_PX)
    assert result, result.message
    assert abs(result.camera.focal_px - focal) / focal < 0.05
    assert geodesic_angle_deg(result.camera.R, skull2cam[:3, :3]) < 2.0
    # Least squares: better than the true camera on the noisy points, about the noise level.
    true_rms = np.sqrt(np.mean(np.sum((uv - noisy) ** 2, axis=1)))
    assert result.rms_px <= true_rms + 1e-9
    assert 0.5 < result.rms_px < 1.5
    assert result.mean_error_px <= result.rms_px


def test_posest_is_least_squares_on_all_points_when_all_are_inliers():
    rng = np.random.default_rng(7)
    points, _, _, uv = head_scene(rng, n=20)
    noisy = uv + rng.normal(scale=2.0, size=uv.shape)
    default = posest(noisy, points, PRINCIPAL_POINT_PX)
    on_all = posest(noisy, points, PRINCIPAL_POINT_PX, PosestOptions(refine_on="all"))
    assert default.inliers.all()
    assert default.rms_px == pytest.approx(on_all.rms_px, rel=1e-9)


def test_msac_recovers_with_30_percent_gross_outliers():
    rng = np.random.default_rng(11)
    points, skull2cam, focal, uv = head_scene(rng, n=30)
    bad = rng.choice(30, size=9, replace=False)
    corrupted = uv.copy()
    corrupted[bad] += rng.uniform(60.0, 400.0, (9, 2)) * rng.choice([-1.0, 1.0], (9, 2))
    result = posest(corrupted, points, PRINCIPAL_POINT_PX, rng=3)
    assert result, result.message
    assert abs(result.camera.focal_px - focal) / focal < EXACT_FOCAL_REL
    expected = np.ones(30, bool)
    expected[bad] = False
    np.testing.assert_array_equal(result.inliers, expected)
    np.testing.assert_allclose(result.errors_px[expected], 0.0, atol=EXACT_RMS_PX)
    # Plain least squares on every point is dragged off by the outliers (or fails).
    on_all = posest(corrupted, points, PRINCIPAL_POINT_PX, PosestOptions(refine_on="all"))
    assert not on_all or abs(on_all.camera.focal_px - focal) / focal > 1e-3


def test_same_seed_same_result():
    rng = np.random.default_rng(12)
    points, _, _, uv = head_scene(rng)
    noisy = uv + rng.normal(scale=2.0, size=uv.shape)
    a = posest(noisy, points, PRINCIPAL_POINT_PX, rng=5)
    b = posest(noisy, points, PRINCIPAL_POINT_PX, rng=np.random.default_rng(5))
    assert a.camera.focal_px == b.camera.focal_px
    np.testing.assert_array_equal(a.camera.skull2cam, b.camera.skull2cam)


def test_msac_keeps_ranked_candidates():
    points, _, focal, uv = head_scene(np.random.default_rng(13))
    hyp = msac(uv - PRINCIPAL_POINT_PX, points, RansacOptions(n_candidates=3), rng=0)
    R, t, f, cost = hyp.candidates
    assert R.shape == (3, 3, 3) and t.shape == (3, 3) and f.shape == cost.shape == (3,)
    assert np.all(np.diff(cost) >= 0) and hyp.cost == cost[0] and hyp.focal_px == f[0]
    assert abs(hyp.focal_px - focal) / focal < 1e-6
    assert hyp.n_samples >= RansacOptions().min_iterations


def test_p4pf_on_an_exact_sample():
    points, skull2cam, focal, uv = head_scene(np.random.default_rng(14), n=4)
    R, t, f = p4pf(uv - PRINCIPAL_POINT_PX, points)
    k = np.argmin(np.abs(f - focal))
    assert abs(f[k] - focal) / focal < 1e-6
    assert geodesic_angle_deg(R[k], skull2cam[:3, :3]) < 1e-5


def test_refine_batch_solves_50_different_problems_with_masks_from_perturbed_starts():
    rng = np.random.default_rng(20)
    S, N = 50, 20
    P, uv, R_true, t_true, f_true = [], [], [], [], []
    for _ in range(S):
        points, skull2cam, focal, image = head_scene(rng, n=N)
        P.append(points)
        uv.append(image - PRINCIPAL_POINT_PX)
        R_true.append(skull2cam[:3, :3])
        t_true.append(skull2cam[:3, 3])
        f_true.append(focal)
    P, uv, R_true = np.stack(P), np.stack(uv), np.stack(R_true)
    t_true, f_true = np.stack(t_true), np.array(f_true)
    weights = (rng.random((S, N)) > 0.25).astype(float)
    weights[:, :6] = 1.0  # at least six used points per problem
    uv[weights == 0] += 500.0  # masked points are garbage; they must not matter
    tilt = rng.normal(size=(S, 3))
    tilt *= np.radians(3.0) / np.linalg.norm(tilt, axis=1, keepdims=True)
    R0 = Rotation.from_rotvec(tilt).as_matrix() @ R_true
    t0 = t_true * rng.uniform(0.95, 1.05, (S, 1)) + rng.normal(scale=5.0, size=(S, 3))
    f0 = f_true * rng.uniform(0.9, 1.1, S)

    result = refine_batch(uv, P, R0, t0, f0, weights)

    np.testing.assert_allclose(result.focal_px, f_true, rtol=EXACT_FOCAL_REL)
    assert np.all(geodesic_angle_deg(result.R, R_true) < 1e-6)
    np.testing.assert_allclose(result.t, t_true, rtol=1e-6)
    used_sq = np.where(weights > 0, result.sq_err_px2, 0.0)
    assert np.sqrt(used_sq.sum() / weights.sum()) < EXACT_RMS_PX
    assert np.all(result.sq_err_px2[weights == 0] > 400.0**2)
    assert result.cost.shape == (S,) and np.all(result.cost < 1e-10)
    assert result.n_iterations < 30


def test_refine_batch_matches_single_problem_calls_and_shares_points():
    rng = np.random.default_rng(21)
    points, skull2cam, focal, uv = head_scene(rng, n=15)
    uv_c = uv - PRINCIPAL_POINT_PX + rng.normal(scale=1.0, size=uv.shape)
    R0 = np.stack([skull2cam[:3, :3]] * 3)
    t0 = skull2cam[:3, 3] + np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 20.0], [0.0, -5.0, -30.0]])
    batch = refine_batch(uv_c, points, R0, t0, [focal, 1.1 * focal, 0.9 * focal])
    single = refine_batch(uv_c, points, R0[1:2], t0[1:2], [1.1 * focal])
    np.testing.assert_allclose(batch.focal_px, batch.focal_px[0], rtol=1e-7)
    np.testing.assert_allclose(batch.focal_px[1], single.focal_px[0], rtol=1e-9)
    np.testing.assert_allclose(batch.cost, batch.cost[0], rtol=1e-9)


def test_refine_batch_start_behind_the_camera_keeps_its_start_with_infinite_cost():
    points, skull2cam, focal, uv = head_scene(np.random.default_rng(22))
    t_behind = skull2cam[:3, 3] * [1.0, 1.0, -1.0]
    result = refine_batch(
        uv - PRINCIPAL_POINT_PX, points, skull2cam[None, :3, :3], t_behind[None], [focal]
    )
    assert np.isinf(result.cost[0])
    np.testing.assert_array_equal(result.t[0], t_behind)
    sq = reprojection_sq_errors(
        uv - PRINCIPAL_POINT_PX, points, skull2cam[None, :3, :3], t_behind[None], np.array([focal])
    )
    assert np.isinf(sq).all()


def test_too_few_points_is_a_falsy_result():
    points, _, _, uv = head_scene(np.random.default_rng(30), n=3)
    result = posest(uv, points, PRINCIPAL_POINT_PX)
    assert not result
    assert result.camera is None
    assert "3 correspondences, POSEST needs at least 4" in result.message


def test_collinear_points_are_a_falsy_result():
    points = np.outer(np.linspace(-80.0, 80.0, 12), [1.0, 0.5, 0.3])
    skull2cam = np.eye(4)
    skull2cam[2, 3] = 1000.0
    uv = Camera(skull2cam, 3000.0, PRINCIPAL_POINT_PX).project(points)
    result = posest(uv, points, PRINCIPAL_POINT_PX)
    assert not result
    assert result.message == "no 4-point sample gave a real camera"


def test_focal_length_beyond_the_limit_is_a_falsy_result():
    rng = np.random.default_rng(31)
    points, _, _, uv = head_scene(rng, focal_px=20_000.0, depth_mm=6000.0, yaw_deg=0.0)
    result = posest(uv, points, PRINCIPAL_POINT_PX)
    assert not result
    assert "exceeds the 10000 px limit" in result.message
    # The same scene is fine once the limit allows it.
    relaxed = posest(uv, points, PRINCIPAL_POINT_PX, PosestOptions(focal_max_px=30_000.0))
    assert relaxed and abs(relaxed.camera.focal_px - 20_000.0) / 20_000.0 < EXACT_FOCAL_REL


def test_unknown_refine_on_is_a_value_error():
    points, _, _, uv = head_scene(np.random.default_rng(32))
    with pytest.raises(ValueError, match="refine_on must be 'inliers' or 'all'"):
        posest(uv, points, PRINCIPAL_POINT_PX, PosestOptions(refine_on="best"))


def test_unknown_select_is_a_value_error():
    points, _, _, uv = head_scene(np.random.default_rng(32))
    with pytest.raises(ValueError, match="select must be 'inliers' or 'msac'"):
        posest(uv, points, PRINCIPAL_POINT_PX, PosestOptions(select="best"))


@pytest.mark.parametrize("select", ["inliers", "msac"])
def test_either_selection_recovers_with_gross_outliers(select):
    rng = np.random.default_rng(11)
    points, _, focal, uv = head_scene(rng, n=30)
    bad = rng.choice(30, size=9, replace=False)
    corrupted = uv.copy()
    corrupted[bad] += rng.uniform(60.0, 400.0, (9, 2)) * rng.choice([-1.0, 1.0], (9, 2))
    result = posest(corrupted, points, PRINCIPAL_POINT_PX, PosestOptions(select=select), rng=3)
    assert result and abs(result.camera.focal_px - focal) / focal < EXACT_FOCAL_REL
    assert result.inliers.sum() == 21
