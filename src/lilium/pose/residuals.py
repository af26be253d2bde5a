"""Reprojection errors of point sets under many cameras (centred pixel coordinates)."""

import numpy as np

from .. import jit
from ..geometry.camera import project_points
from ._refine_kernels import sq_errors_kernel


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
    if jit.compiled():  # the same formula, compiled (pose/_refine_kernels.py)
        R = np.ascontiguousarray(np.reshape(np.asarray(R, dtype=float), (-1, 3, 3)))
        S = len(R)
        P = np.asarray(points_mm, dtype=float)
        uv = np.asarray(uv_centred_px, dtype=float)
        if P.shape[-2] != uv.shape[-2]:
            raise ValueError(f"{uv.shape[-2]} image points for {P.shape[-2]} points")
        return sq_errors_kernel(
            np.ascontiguousarray(np.broadcast_to(uv, (S,) + uv.shape[-2:])),
            np.ascontiguousarray(np.broadcast_to(P, (S,) + P.shape[-2:])),
            R,
            np.ascontiguousarray(np.broadcast_to(np.asarray(t, dtype=float), (S, 3))),
            np.ascontiguousarray(np.broadcast_to(np.asarray(focal_px, dtype=float), (S,))),
        )
    uv = project_points(points_mm, R, t, focal_px)  # centred: principal point (0, 0)
    sq = np.sum((uv - uv_centred_px) ** 2, axis=-1)
    return np.where(np.isnan(sq), np.inf, sq)
