"""Camera geometry and rotations: round trips against known answers."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lilium.geometry import (
    Camera,
    Cameras,
    check_rotation,
    check_skull2cam,
    geodesic_angle_deg,
    matrix_to_rotvec,
    point_ray_distance,
    principal_point_of,
    rotvec_to_matrix,
)

PRINCIPAL_POINT_PX = np.array([1999.5, 1499.5])


def a_camera(rng):
    skull2cam = np.eye(4)
    skull2cam[:3, :3] = Rotation.random(random_state=rng.integers(2**31)).as_matrix()
    skull2cam[:3, 3] = [20.0, -35.0, 1200.0]
    return skull2cam


def test_principal_point_is_the_pixel_centre_of_the_image():
    assert np.array_equal(principal_point_of((4000, 3000)), [1999.5, 1499.5])


def test_project_then_backproject_gives_rays_through_the_points():
    rng = np.random.default_rng(0)
    skull2cam = a_camera(rng)
    points = rng.normal(scale=80.0, size=(30, 3))
    camera = Camera(skull2cam, 3000.0, PRINCIPAL_POINT_PX)
    uv = camera.project(points)
    origin, directions = camera.rays(uv)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(point_ray_distance(points, origin, directions), 0.0, atol=1e-9)
    # The origin is the camera centre: it projects nowhere (depth 0) and maps to 0 in the camera.
    np.testing.assert_allclose(skull2cam[:3, :3] @ origin + skull2cam[:3, 3], 0.0, atol=1e-9)
    # Points along a ray project to the same pixel.
    further = origin + 1.5 * (points - origin)
    np.testing.assert_allclose(camera.project(further), uv, atol=1e-8)


def test_point_ray_distance_of_an_offset_point():
    d = point_ray_distance([[0.0, 3.0, 10.0]], [0.0, 0.0, 0.0], [[0.0, 0.0, 1.0]])
    np.testing.assert_allclose(d, [3.0])


def test_points_behind_the_camera_are_nan_and_rows_keep_their_order():
    points = np.array([[0.0, 0.0, 100.0], [10.0, 0.0, -50.0], [0.0, 20.0, 200.0], [0, 0, 0.0]])
    uv = Camera(np.eye(4), 1000.0, [0.0, 0.0]).project(points)
    assert uv.shape == (4, 2)
    assert np.isnan(uv[1]).all() and np.isnan(uv[3]).all()
    np.testing.assert_allclose(uv[0], [0.0, 0.0])
    np.testing.assert_allclose(uv[2], [0.0, 100.0])


def test_cameras_project_like_each_camera_shared_and_per_member_points():
    rng = np.random.default_rng(1)
    cams = [a_camera(rng) for _ in range(3)]
    points = rng.normal(scale=60.0, size=(3, 10, 3))
    points[1, 4] = [0.0, 0.0, -5000.0]  # far behind camera 1 whatever its rotation
    cams[1][:3, :3] = np.eye(3)
    focal = np.array([1000.0, 2000.0, 3000.0])
    cameras = Cameras(
        np.stack([c[:3, :3] for c in cams]),
        np.stack([c[:3, 3] for c in cams]),
        focal,
        PRINCIPAL_POINT_PX,
    )
    uv = cameras.project(points)
    shared = cameras.project(points[0])
    for s in range(3):
        single = Camera(cams[s], focal[s], PRINCIPAL_POINT_PX)
        np.testing.assert_allclose(uv[s], single.project(points[s]), equal_nan=True)
        np.testing.assert_allclose(shared[s], single.project(points[0]), rtol=1e-12)
        np.testing.assert_array_equal(cameras[s].skull2cam, cams[s])
    assert np.isnan(uv[1, 4]).all()
    assert len(cameras.take(np.array([True, False, True]))) == 2


def test_camera_dict_round_trip_and_crop():
    camera = Camera(a_camera(np.random.default_rng(3)), 2500.0, [639.5, 479.5])
    back = Camera.from_dict(camera.to_dict())
    np.testing.assert_array_equal(back.skull2cam, camera.skull2cam)
    assert back.focal_px == camera.focal_px
    with pytest.raises(ValueError, match="focal_px must be > 0"):
        Camera.from_dict({**camera.to_dict(), "focal_px": -1.0})
    # A crop scaled by 2 sees the same points at twice the distance from the crop's origin.
    points = np.random.default_rng(4).normal(scale=50.0, size=(6, 3))
    crop = camera.cropped((100.0, 50.0), 2.0)
    np.testing.assert_allclose(
        crop.project(points) + 0.5, 2.0 * (camera.project(points) - [100.0, 50.0] + 0.5)
    )


def test_subject_camera_distance():
    skull2cam = np.eye(4)
    skull2cam[:3, 3] = [30.0, 40.0, 1200.0]
    np.testing.assert_allclose(
        Camera(skull2cam, 1.0, [0.0, 0.0]).distance_mm([0.0, 0.0, 0.0]), 1201.0412, rtol=1e-7
    )
    rng = np.random.default_rng(2)
    skull2cam = a_camera(rng)
    points = rng.normal(size=(5, 3))
    centre = -skull2cam[:3, :3].T @ skull2cam[:3, 3]
    np.testing.assert_allclose(
        Camera(skull2cam, 1.0, [0.0, 0.0]).distance_mm(points),
        np.linalg.norm(points - centre, axis=1),
    )


@pytest.mark.parametrize("angle_deg", [0.0, 1e-4, 30.0, 90.0, 179.0, 180.0])
def test_geodesic_angle_of_a_known_rotation(angle_deg):
    axis = np.array([1.0, 2.0, -2.0]) / 3.0
    R_a = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    R_b = rotvec_to_matrix(np.radians(angle_deg) * axis) @ R_a
    assert geodesic_angle_deg(R_b, R_a) == pytest.approx(angle_deg, abs=1e-5)
    assert geodesic_angle_deg(R_a, R_b) == pytest.approx(geodesic_angle_deg(R_b, R_a), abs=1e-9)


def test_geodesic_angle_is_zero_for_identical_and_batched():
    R = Rotation.random(5, random_state=3).as_matrix()
    np.testing.assert_allclose(geodesic_angle_deg(R, R), 0.0, atol=1e-5)
    assert geodesic_angle_deg(R, R).shape == (5,)


def test_rotvec_to_matrix_matches_scipy_including_tiny_angles():
    rng = np.random.default_rng(4)
    rotvecs = rng.normal(size=(60, 3)) * np.repeat([1e-12, 1e-9, 1e-4, 1.0, 3.0, 0.0], 10)[:, None]
    np.testing.assert_allclose(
        rotvec_to_matrix(rotvecs), Rotation.from_rotvec(rotvecs).as_matrix(), atol=1e-14
    )
    assert rotvec_to_matrix(rotvecs.reshape(6, 10, 3)).shape == (6, 10, 3, 3)
    big = rng.normal(size=(10, 3))
    big *= rng.uniform(0.1, 3.0, (10, 1)) / np.linalg.norm(big, axis=1, keepdims=True)
    np.testing.assert_allclose(matrix_to_rotvec(rotvec_to_matrix(big)), big, atol=1e-12)


def test_check_skull2cam_accepts_a_rigid_transform():
    T = a_camera(np.random.default_rng(5))
    out = check_skull2cam(T.tolist())
    assert out.dtype == float and np.array_equal(out, T)


@pytest.mark.parametrize(
    ("matrix", "match"),
    [
        (np.eye(3), r"4x4 matrix, got shape \(3, 3\)"),
        (np.full((4, 4), np.nan), "NaN or infinite"),
        (np.diag([1.0, 1.0, 2.0, 1.0]), "not a rotation"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), "not a rotation"),
        (np.vstack([np.eye(4)[:3], [0.0, 0.0, 1.0, 1.0]]), "last row must be"),
    ],
)
def test_check_skull2cam_errors(matrix, match):
    with pytest.raises(ValueError, match=match):
        check_skull2cam(matrix)


def test_check_rotation_names_the_argument():
    with pytest.raises(ValueError, match="head_rotation must be a 3x3"):
        check_rotation(np.eye(4), name="head_rotation")


def test_rotation_vectors_and_euler_angles_are_scipys():
    """matrix_to_rotvec and matrix_to_euler_xyz_deg give scipy's Rotation (not imported by them:
    scipy.spatial costs a command 0.17 s), near 0 and pi and at gimbal lock too."""
    import warnings

    from scipy.spatial.transform import Rotation

    from lilium.geometry.rotations import matrix_to_euler_xyz_deg

    rng = np.random.default_rng(3)
    axes = rng.normal(size=(50, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    edges = [0.0, 1e-12, 1e-5, 1e-3, np.pi - 1e-3, np.pi - 1e-9]
    angles = np.concatenate([edges, rng.random(44) * np.pi])
    rotvecs = axes * angles[:, None]
    R = Rotation.from_rotvec(rotvecs).as_matrix()
    np.testing.assert_allclose(matrix_to_rotvec(R), Rotation.from_matrix(R).as_rotvec(), atol=1e-12)
    locked = Rotation.from_euler("xyz", [[30, 90, 0], [-40, -90, 0]], degrees=True).as_matrix()
    for m in [*R, *locked]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # scipy warns at gimbal lock
            want = Rotation.from_matrix(m).as_euler("xyz", degrees=True)
        np.testing.assert_allclose(matrix_to_euler_xyz_deg(m), want, atol=1e-9)


def test_open_edge_points_are_a_cut_not_a_pinhole():
    import trimesh

    from lilium.geometry.mesh import open_edge_points

    sphere = trimesh.creation.icosphere(4, radius=50.0)
    v, f = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    assert open_edge_points(v, f, 20.0).shape == (0, 3)  # closed
    pinhole = np.delete(f, 0, axis=0)  # one triangle's rim, a few mm
    assert open_edge_points(v, pinhole, 20.0).shape == (0, 3)
    assert len(open_edge_points(v, pinhole, 1.0)) == 3
    cut = f[~(v[f][:, :, 1] > 40.0).any(axis=1)]  # the cap above y = 40 cut off
    rim = open_edge_points(v, cut, 20.0)
    assert len(rim) > 10
    assert np.all(np.abs(rim[:, 1] - 40.0) < 5.0)  # on the cut's rim, nowhere else
