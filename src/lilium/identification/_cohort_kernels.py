"""Compiled whitened residuals of the identification's camera refits
(:func:`lilium.identification.cohort._whitened`, and :func:`refit_whitened_kernel`, which first
moves the cameras as ``cohort._cameras`` does: one call per evaluation of a refit); numba, see
:mod:`lilium.jit`.

Per camera and landmark, element by element, the numpy path's steps: the mean facial point in
the camera's frame and its pinhole projection (:func:`lilium.geometry._projection_kernels.pinhole`,
the projection the numpy path calls too), the projection's Jacobian, the marginal covariance
``S = J Sigma J^T + sigma^2 I`` and its Cholesky whitening. The numpy path takes the camera-frame
point of the Jacobian from a matrix product, this kernel from the pinhole's own sums, so the two
agree to rounding (about 1e-15 relative), not bit for bit (``tests/test_kernels_camera.py``);
a refit's accept / reject steps can carry such a difference further
(docs/decisions/0020-compiled-kernels.md, "The
identification's camera refits compiled").
"""

import numpy as np

from ..constants import MIN_DEPTH_MM
from ..geometry._projection_kernels import pinhole
from ..geometry._rotation_kernels import rotvec_to_matrix_kernel
from ..jit import njit


@njit
def whitened_kernel(R, t, f, c0, c1, points, cov, uv, sigma_px):
    """Whitened residuals ``(K, 2N)``; a camera with a non-finite residual or whitened value
    gets 1e3 everywhere (see ``cohort._whitened``).

    Parameters
    ----------
    R, t, f : ndarray of shape (K, 3, 3), (K, 3), (K,)
    c0, c1 : float
        Principal point.
    points : ndarray of shape (K, N, 3)
    cov : ndarray of shape (K, N, 3, 3)
    uv : ndarray of shape (K, N, 2)
    sigma_px : ndarray of shape (N,)
    """
    K, N = points.shape[0], points.shape[1]
    w = np.empty((K, 2 * N))
    J = np.empty((2, 3))
    JC = np.empty((2, 3))
    for k in range(K):
        Rk, tk, fk = R[k], t[k], f[k]
        bad = False
        for n in range(N):
            x, y, z = points[k, n, 0], points[k, n, 1], points[k, n, 2]
            u, v = pinhole(x, y, z, Rk, tk, fk, c0, c1)
            r0, r1 = uv[k, n, 0] - u, uv[k, n, 1] - v
            if not (np.isfinite(r0) and np.isfinite(r1)):
                bad = True
            X0 = Rk[0, 0] * x + Rk[0, 1] * y + Rk[0, 2] * z + tk[0]
            X1 = Rk[1, 0] * x + Rk[1, 1] * y + Rk[1, 2] * z + tk[1]
            X2 = Rk[2, 0] * x + Rk[2, 1] * y + Rk[2, 2] * z + tk[2]
            if not X2 > MIN_DEPTH_MM:
                bad = True
            fz = fk / X2
            a0, a2 = fz, -fz * X0 / X2  # row 0 of the camera-frame Jacobian: (fz, 0, a2)
            b1, b2 = fz, -fz * X1 / X2  # row 1: (0, fz, b2)
            for j in range(3):
                J[0, j] = a0 * Rk[0, j] + a2 * Rk[2, j]
                J[1, j] = b1 * Rk[1, j] + b2 * Rk[2, j]
            C = cov[k, n]
            for i in range(2):
                for j in range(3):
                    JC[i, j] = J[i, 0] * C[0, j] + J[i, 1] * C[1, j] + J[i, 2] * C[2, j]
            s00 = JC[0, 0] * J[0, 0] + JC[0, 1] * J[0, 1] + JC[0, 2] * J[0, 2]
            s10 = JC[1, 0] * J[0, 0] + JC[1, 1] * J[0, 1] + JC[1, 2] * J[0, 2]
            s11 = JC[1, 0] * J[1, 0] + JC[1, 1] * J[1, 1] + JC[1, 2] * J[1, 2]
            s00 += sigma_px[n] ** 2
            s11 += sigma_px[n] ** 2
            a = np.sqrt(s00)
            b = s10 / a
            c = np.sqrt(max(s11 - b * b, 1e-12))
            w0 = r0 / a
            w[k, 2 * n] = w0
            w[k, 2 * n + 1] = (r1 - b * w0) / c
            if not (np.isfinite(w[k, 2 * n]) and np.isfinite(w[k, 2 * n + 1])):
                bad = True
        if bad:
            for m in range(2 * N):
                w[k, m] = 1e3
    return w


@njit
def refit_whitened_kernel(p, R0, t0, f0, c0, c1, points, cov, uv, sigma_px):
    """:func:`whitened_kernel` of the cameras ``p`` (K, 7) moves from ``(R0, t0, f0)``
    (``cohort._cameras``: rotation vector, translation, log focal; Rodrigues' formula as
    :func:`lilium.geometry.rotations.rotvec_to_matrix` writes it)."""
    K = p.shape[0]
    R = np.empty((K, 3, 3))
    t = np.empty((K, 3))
    f = np.empty(K)
    dR = np.empty((3, 3))
    for k in range(K):
        rotvec_to_matrix_kernel(p[k, 0], p[k, 1], p[k, 2], dR)
        for i in range(3):
            for j in range(3):
                R[k, i, j] = (
                    dR[i, 0] * R0[k, 0, j] + dR[i, 1] * R0[k, 1, j] + dR[i, 2] * R0[k, 2, j]
                )
            t[k, i] = t0[k, i] + p[k, 3 + i]
        f[k] = f0[k] * np.exp(p[k, 6])
    return whitened_kernel(R, t, f, c0, c1, points, cov, uv, sigma_px)
