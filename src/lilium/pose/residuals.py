"""Reprojection errors of point sets under many cameras (centred pixel coordinates)."""

import numpy as np

from ..constants import MIN_DEPTH_MM


def reprojection_sq_errors(uv_centred_px, points_mm, R, t, focal_px):
    """Squared reprojection errors of N points under K cameras.

    Parameters
    ----------
    uv_centred_px : ndarray of shape (N, 2) or (K, N, 2)
        Observed image points minus the principal point (pixels).
    points_mm : ndarray of shape (N, 3) or (K, N, 3)
    R : ndarray of shape (K, 3, 3)
    t : ndarray of shape (K, 3)
    focal_px : ndarray of shape (K,)

    Returns
    -------
    sq_err_px2 : ndarray of shape (K, N)
        ``inf`` where a point is at or behind the camera.
    """
    X = np.asarray(points_mm) @ np.swapaxes(R, -1, -2) + t[:, None, :]
    z = X[..., 2]
    behind = z <= MIN_DEPTH_MM
    uv = focal_px[:, None, None] * X[..., :2] / np.where(behind, 1.0, z)[..., None]
    sq = np.sum((uv - uv_centred_px) ** 2, axis=-1)
    return np.where(behind, np.inf, sq)
