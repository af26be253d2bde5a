"""The pinhole camera of SPEC section 8.

Convention, written once: ``skull2cam`` is a 4x4 rigid transform (mm) from the skull-mesh frame to
the camera frame (x right, y down, z forward). A point ``X`` of the skull frame goes to
``X_cam = R X + t`` and projects to ``uv = principal_point_px + focal_px * X_cam[:2] / X_cam[2]``.
Pixel coordinates ``uv`` are (u = column, v = row), the centre of the top-left pixel is (0, 0).
Square pixels, no distortion. Points at or behind the camera project to NaN, so row i stays
point i.
"""

import numpy as np

from ..constants import MIN_DEPTH_MM
from .rotations import check_rotation


def principal_point_of(image_size_wh):
    """Image centre (pixels) of an image of ``(width, height)`` pixels.

    With pixel centres at integer coordinates the centre is ``((w - 1) / 2, (h - 1) / 2)``.
    """
    width, height = image_size_wh
    return np.array([(width - 1) / 2.0, (height - 1) / 2.0])


def check_skull2cam(skull2cam, name="skull2cam"):
    """Validate a 4x4 rigid transform and return it as a float array."""
    T = np.asarray(skull2cam, dtype=float)
    if T.shape != (4, 4):
        raise ValueError(f"{name} must be a 4x4 matrix, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise ValueError(f"{name} contains NaN or infinite values")
    check_rotation(T[:3, :3], name=f"{name}[:3, :3]")
    if not np.allclose(T[3], [0, 0, 0, 1]):
        raise ValueError(f"{name} last row must be [0, 0, 0, 1], got {T[3].tolist()}")
    return T


def project(points_mm, skull2cam, focal_px, principal_point_px):
    """Project skull-frame points into the image.

    Parameters
    ----------
    points_mm : array_like of shape (N, 3)
        Points in the skull frame (mm).
    skull2cam : array_like of shape (4, 4)
    focal_px : float
    principal_point_px : array_like of shape (2,)

    Returns
    -------
    uv : ndarray of shape (N, 2)
        Pixel coordinates; NaN for points with camera depth <= ``MIN_DEPTH_MM``.
    """
    T = np.asarray(skull2cam, dtype=float)
    return project_population(
        points_mm,
        T[None, :3, :3],
        T[None, :3, 3],
        np.array([float(focal_px)]),
        np.asarray(principal_point_px, dtype=float),
    )[0]


def project_batch(points_mm, R, t, focal_px, principal_point_px):
    """Project many point sets under many cameras at once.

    Parameters
    ----------
    points_mm : array_like of shape (S, N, 3)
    R : array_like of shape (S, 3, 3)
    t : array_like of shape (S, 3)
    focal_px : array_like of shape (S,)
    principal_point_px : array_like of shape (2,)

    Returns
    -------
    uv : ndarray of shape (S, N, 2)
        NaN where a point is at or behind its camera.
    """
    X = np.einsum("sij,snj->sni", R, points_mm) + np.asarray(t)[:, None, :]
    z = X[..., 2:3]
    behind = z <= MIN_DEPTH_MM
    uv = np.asarray(principal_point_px, dtype=float) + np.asarray(focal_px)[:, None, None] * X[
        ..., :2
    ] / np.where(behind, 1.0, z)
    return np.where(behind, np.nan, uv)


def project_population(points_mm, R, t, focal_px, principal_point_px):
    """Project one point set under S cameras.

    Parameters
    ----------
    points_mm : ndarray of shape (K, 3)
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
    focal_px : ndarray of shape (S,)
    principal_point_px : ndarray of shape (2,)

    Returns
    -------
    uv : ndarray of shape (S, K, 2)
        NaN at or behind the camera.
    """
    S = len(R)
    # One (3S, 3) x (3, K) product instead of S small ones: X[s, i, k] = (R_s p_k)_i + t_s,i.
    X = (np.reshape(R, (3 * S, 3)) @ np.asarray(points_mm, dtype=float).T).reshape(S, 3, -1)
    X += t[:, :, None]
    z = X[:, 2]
    behind = z <= MIN_DEPTH_MM
    scale = focal_px[:, None] / np.where(behind, 1.0, z)
    scale[behind] = np.nan
    uv = np.empty((S, X.shape[2], 2))
    uv[..., 0] = X[:, 0] * scale + principal_point_px[0]
    uv[..., 1] = X[:, 1] * scale + principal_point_px[1]
    return uv


def backproject_rays(uv, skull2cam, focal_px, principal_point_px):
    """Rays through pixels, in the skull frame.

    Parameters
    ----------
    uv : array_like of shape (N, 2)
    skull2cam : array_like of shape (4, 4)
    focal_px : float
    principal_point_px : array_like of shape (2,)

    Returns
    -------
    origin_mm : ndarray of shape (3,)
        The camera centre in the skull frame.
    directions : ndarray of shape (N, 3)
        Unit ray directions in the skull frame.
    """
    T = np.asarray(skull2cam, dtype=float)
    R, t = T[:3, :3], T[:3, 3]
    uv = np.asarray(uv, dtype=float)
    xy = (uv - np.asarray(principal_point_px, dtype=float)) / focal_px
    d_cam = np.column_stack([xy, np.ones(len(xy))])
    d = d_cam @ R  # R.T @ d_cam for each row
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return -R.T @ t, d


def point_ray_distance(points_mm, origin_mm, directions):
    """Distance (mm) from each point to its ray ``origin + s * direction`` (s unrestricted).

    Parameters
    ----------
    points_mm : array_like of shape (N, 3)
    origin_mm : array_like of shape (3,)
    directions : array_like of shape (N, 3)
        Unit vectors.

    Returns
    -------
    distance_mm : ndarray of shape (N,)
    """
    v = np.asarray(points_mm, dtype=float) - np.asarray(origin_mm, dtype=float)
    return np.linalg.norm(np.cross(v, directions), axis=1)


def subject_camera_distance(point_mm, skull2cam):
    """Distance (mm) from the camera centre to a skull-frame point (SCD of SPEC section 5).

    Parameters
    ----------
    point_mm : array_like of shape (..., 3)
    skull2cam : array_like of shape (4, 4)

    Returns
    -------
    scd_mm : ndarray of shape (...)
    """
    T = np.asarray(skull2cam, dtype=float)
    return np.linalg.norm(np.asarray(point_mm, dtype=float) @ T[:3, :3].T + T[:3, 3], axis=-1)
