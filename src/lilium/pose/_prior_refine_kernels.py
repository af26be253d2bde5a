"""Compiled Levenberg-Marquardt of :func:`lilium.pose.prior_refine.refine_with_priors` (numba,
see :mod:`lilium.jit`).

The numpy code runs the problems of a batch in lockstep; here each problem runs its own loop
with the same unknowns, residuals (the reprojection errors of
:func:`lilium.pose._refine_kernels._residuals`, weighted ``1 / sqrt(N)``, then the five prior
hinges), Jacobian, damping updates and stopping tests, so every problem takes the same steps.
As in :mod:`lilium.pose._refine_kernels`, the 7 x 7 system is solved by Gaussian elimination
(a singular system is a rejected step, where numpy turns to a pseudo-inverse) and sums run in a
fixed order: results agree with the numpy path to rounding (``tests/pose/test_prior_refine.py``).
A prior is switched off by NaN bounds (NaN ``tol`` for the head orientation).
"""

import numpy as np

from ..constants import MIN_DEPTH_MM
from ..geometry._rotation_kernels import DEG_PER_RAD, relative_angle_axis
from ..jit import njit
from ._refine_kernels import (
    _apply_step,
    _normal_equations,
    _residuals,
    _solve7,
    sq_errors_kernel,
)


@njit
def _hinges(R, c, log_f, rel, focal, scd, head, tol, r, J, row):
    """The five prior hinges into ``r[row:row + 5]`` and ``J[row:row + 5]``; their sum of
    squares (the formulas of :func:`lilium.pose.prior_refine._prior_residuals`)."""
    for k in range(5):
        r[row + k] = 0.0
        for j in range(7):
            J[row + k, j] = 0.0
    f = np.exp(log_f)
    if not np.isnan(focal[0]):
        if focal[0] - f > 0.0:
            r[row] = focal[0] - f
            J[row, 5] = -f
            J[row, 6] = -f
        if f - focal[1] > 0.0:
            r[row + 1] = f - focal[1]
            J[row + 1, 5] = f
            J[row + 1, 6] = f
    if not np.isnan(scd[0]):
        q0 = R[0, 0] * rel[0] + R[0, 1] * rel[1] + R[0, 2] * rel[2]
        q1 = R[1, 0] * rel[0] + R[1, 1] * rel[1] + R[1, 2] * rel[2]
        q2 = R[2, 0] * rel[0] + R[2, 1] * rel[1] + R[2, 2] * rel[2]
        X0, X1, X2 = q0 + c[0], q1 + c[1], q2 + c[2]
        dist = np.sqrt(X0 * X0 + X1 * X1 + X2 * X2)
        inv_scale = c[2] / f
        # d scd / d unknown = X . dX / scd (dX of a left rotation increment, the image
        # position, the log scale and the log depth, as in the numpy code).
        d = (
            (-X1 * q2 + X2 * q1) / dist,
            (X0 * q2 - X2 * q0) / dist,
            (-X0 * q1 + X1 * q0) / dist,
            X0 * inv_scale / dist,
            X1 * inv_scale / dist,
            (-X0 * c[0] - X1 * c[1]) / dist,
            X2 * c[2] / dist,
        )
        if scd[0] - dist > 0.0:
            r[row + 2] = scd[0] - dist
            for j in range(7):
                J[row + 2, j] = -d[j]
        if dist - scd[1] > 0.0:
            r[row + 3] = dist - scd[1]
            for j in range(7):
                J[row + 3, j] = d[j]
    if not np.isnan(tol):
        dbeta, x, y, z, norm = relative_angle_axis(R, head)
        if dbeta - tol > 0.0:
            r[row + 4] = dbeta - tol
            if norm > 0.0:  # the unit axis of R P^T, in degrees (see the numpy code)
                J[row + 4, 0] = x / norm * DEG_PER_RAD
                J[row + 4, 1] = y / norm * DEG_PER_RAD
                J[row + 4, 2] = z / norm * DEG_PER_RAD
    total = 0.0
    for k in range(5):
        total += r[row + k] * r[row + k]
    return total


@njit
def prior_refine_kernel(
    uv,
    P,
    R,
    t,
    focal_px,
    scd_points,
    focal,
    scd,
    head,
    tol,
    max_iterations,
):
    """The whole of :func:`~lilium.pose.prior_refine.refine_with_priors`: ``R``, ``t``,
    ``focal_px`` in place.

    Parameters
    ----------
    uv : ndarray of shape (S, N, 2)
        Image points minus the principal point (pixels).
    P : ndarray of shape (S, N, 3)
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
    focal_px : ndarray of shape (S,)
    scd_points : ndarray of shape (S, 3)
    focal, scd : ndarray of shape (2,)
        Prior intervals (px, mm); NaN switches a prior off (the layout of
        :func:`lilium.fitness._camera_kernels.camera_terms_kernel`'s priors).
    head : ndarray of shape (3, 3)
    tol : float
        Head tolerance (degrees); NaN switches the head prior off.
    max_iterations : int

    Returns
    -------
    cost : ndarray of shape (S,)
        ``MSE_pix + P_cam`` (``inf`` behind the camera).
    iterations : ndarray of shape (S,) of int64
    sq_err_px2 : ndarray of shape (S, N)
    """
    S, N = P.shape[0], P.shape[1]
    M = 2 * N + 5
    ws = np.full(N, 1.0 / np.sqrt(N))
    Pm = np.empty((N, 3))
    m = np.empty((S, 3))
    rel = np.empty(3)
    c = np.empty(3)
    r = np.empty(M)
    J = np.empty((M, 7))
    r_new = np.empty(M)
    J_new = np.empty((M, 7))
    JtJ = np.empty((7, 7))
    A = np.empty((7, 7))
    g = np.empty(7)
    delta = np.empty(7)
    dR = np.empty((3, 3))
    R_new = np.empty((3, 3))
    c_new = np.empty(3)
    cost = np.empty(S)
    iterations = np.zeros(S, np.int64)
    for s in range(S):
        for j in range(3):
            acc = 0.0
            for n in range(N):
                acc += P[s, n, j]
            m[s, j] = acc / N
        for n in range(N):
            for j in range(3):
                Pm[n, j] = P[s, n, j] - m[s, j]
        for j in range(3):
            rel[j] = scd_points[s, j] - m[s, j]
        for i in range(3):
            c[i] = R[s, i, 0] * m[s, 0] + R[s, i, 1] * m[s, 1] + R[s, i, 2] * m[s, 2] + t[s, i]
        log_f = np.log(focal_px[s])
        cost_s = _residuals(uv[s], Pm, ws, R[s], c, log_f, r, J)
        cost_s += _hinges(R[s], c, log_f, rel, focal, scd, head, tol, r, J, 2 * N)
        if not (c[2] > MIN_DEPTH_MM and np.isfinite(cost_s)):
            cost_s = np.inf
        lam = 1e-3
        active = np.isfinite(cost_s)
        it = 0
        while active and it < max_iterations:
            it += 1
            _normal_equations(J, r, M, JtJ, g)
            for i in range(7):
                for j in range(7):
                    A[i, j] = JtJ[i, j]
                A[i, i] += lam * (JtJ[i, i] + 1e-12)
            if not _solve7(A, g, delta):
                for i in range(7):
                    delta[i] = np.nan
            logf_new = _apply_step(R[s], c, log_f, delta, dR, R_new, c_new)
            cost_new = _residuals(uv[s], Pm, ws, R_new, c_new, logf_new, r_new, J_new)
            cost_new += _hinges(
                R_new, c_new, logf_new, rel, focal, scd, head, tol, r_new, J_new, 2 * N
            )
            if not (c_new[2] > MIN_DEPTH_MM and np.isfinite(cost_new)):
                cost_new = np.inf
            better = cost_new < cost_s
            before = cost_s
            if better:
                gain = cost_s - cost_new
                R[s] = R_new
                c[:] = c_new
                log_f = logf_new
                r[:] = r_new
                J[:, :] = J_new
                cost_s = cost_new
                lam = max(lam / 3.0, 1e-12)
            else:
                gain = 0.0
                lam = lam * 4.0
            if (better and gain <= 1e-9 * before) or lam > 1e10:
                active = False
        cost[s] = cost_s
        iterations[s] = it
        for i in range(3):
            t[s, i] = c[i] - (R[s, i, 0] * m[s, 0] + R[s, i, 1] * m[s, 1] + R[s, i, 2] * m[s, 2])
        focal_px[s] = np.exp(log_f)
    return cost, iterations, sq_errors_kernel(uv, P, R, t, focal_px)
