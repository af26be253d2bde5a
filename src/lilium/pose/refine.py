"""Levenberg-Marquardt refinement of pose and focal length, for many problems at once.

Parameters per problem: a rotation (updated on the left by a rotation-vector increment,
``R <- exp([w]x) R``), the translation ``t`` (mm) and ``log(focal_px)`` (so the focal length stays
positive): seven unknowns. The residuals are the reprojection errors (pixels) of the used points.
All problems of a batch share the number of points ``N``; a weight of 0 switches a point off,
so problems may use different subsets.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import MIN_DEPTH_MM
from ..geometry.rotations import rotvec_to_matrix
from .residuals import reprojection_sq_errors


@dataclass(frozen=True)
class RefineOptions:
    """Options of :func:`refine_batch`.

    Attributes
    ----------
    max_iterations : int
        Levenberg-Marquardt iterations at most.
    initial_lambda : float
        Initial Marquardt damping (relative to the diagonal of J^T J).
    cost_tol : float
        Stop a problem when an accepted step lowers its cost by less than this fraction.
    gradient_tol : float
        Stop a problem when the largest scaled gradient entry falls below this.
    max_lambda : float
        Stop a problem when its damping grows past this (no further progress possible).
    """

    max_iterations: int = 100
    initial_lambda: float = 1e-3
    cost_tol: float = 1e-14
    gradient_tol: float = 1e-14
    max_lambda: float = 1e10


@dataclass(frozen=True)
class BatchRefineResult:
    """Refined cameras of S problems.

    Attributes
    ----------
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
        World-to-camera translation (mm).
    focal_px : ndarray of shape (S,)
    sq_err_px2 : ndarray of shape (S, N)
        Squared reprojection error of every point (used or not; ``inf`` behind the camera).
    cost : ndarray of shape (S,)
        Weighted sum of squared errors of the used points.
    n_iterations : int
        Iterations run (the slowest problem's).
    """

    R: np.ndarray
    t: np.ndarray
    focal_px: np.ndarray
    sq_err_px2: np.ndarray
    cost: np.ndarray
    n_iterations: int


def _residuals_and_jacobian(uv_c, P, w_sqrt, R, t, log_f, with_jacobian=True):
    """Weighted residuals (S, 2N) and Jacobian (S, 2N, 7); cost inf if a used point is behind."""
    q = np.einsum("sij,snj->sni", R, P)  # rotated points, (S, N, 3)
    X = q + t[:, None, :]
    z = X[..., 2]
    behind = (z <= MIN_DEPTH_MM) & (w_sqrt > 0)
    z_safe = np.where(z > MIN_DEPTH_MM, z, 1.0)
    f = np.exp(log_f)[:, None]
    x, y = X[..., 0] / z_safe, X[..., 1] / z_safe
    r = np.stack([f * x - uv_c[..., 0], f * y - uv_c[..., 1]], axis=-1)  # (S, N, 2)
    r = r * w_sqrt[..., None]
    cost = np.sum(r**2, axis=(1, 2))
    cost = np.where(behind.any(axis=1), np.inf, cost)
    if not with_jacobian:
        return r, cost, None
    S, N = z.shape
    fz = (f / z_safe) * w_sqrt  # (S, N)
    # d(u, v)/dX for X = (X, Y, Z): [[f/Z, 0, -f X/Z^2], [0, f/Z, -f Y/Z^2]]
    dproj = np.zeros((S, N, 2, 3))
    dproj[..., 0, 0] = fz
    dproj[..., 1, 1] = fz
    dproj[..., 0, 2] = -fz * x
    dproj[..., 1, 2] = -fz * y
    # dX/dw = -[q]x (left increment), dX/dt = I.
    skew = np.zeros((S, N, 3, 3))
    skew[..., 0, 1], skew[..., 0, 2] = q[..., 2], -q[..., 1]
    skew[..., 1, 0], skew[..., 1, 2] = -q[..., 2], q[..., 0]
    skew[..., 2, 0], skew[..., 2, 1] = q[..., 1], -q[..., 0]
    J = np.empty((S, N, 2, 7))
    J[..., :3] = dproj @ skew
    J[..., 3:6] = dproj
    J[..., 0, 6] = f * x * w_sqrt
    J[..., 1, 6] = f * y * w_sqrt
    return r.reshape(S, 2 * N), cost, J.reshape(S, 2 * N, 7)


def refine_batch(uv_centred_px, points_mm, R, t, focal_px, weights=None, options=RefineOptions()):
    """Refine S cameras at once by Levenberg-Marquardt (vectorised over the batch).

    Parameters
    ----------
    uv_centred_px : array_like of shape (S, N, 2) or (N, 2)
        Observed image points minus the principal point (pixels); shared when 2-D.
    points_mm : array_like of shape (S, N, 3) or (N, 3)
        3D points (mm); shared when 2-D.
    R : array_like of shape (S, 3, 3)
        Initial rotations (warm start, e.g. the previous generation's cameras).
    t : array_like of shape (S, 3)
    focal_px : array_like of shape (S,)
        Initial focal lengths, > 0.
    weights : array_like of shape (S, N) or (N,), optional
        Per-point weights (0 = unused). Default all ones.
    options : RefineOptions

    Returns
    -------
    BatchRefineResult
        A problem whose start had a used point behind the camera keeps its start and an
        infinite cost.
    """
    R = np.array(R, dtype=float)
    S = R.shape[0]
    P = np.broadcast_to(np.asarray(points_mm, dtype=float), (S,) + np.shape(points_mm)[-2:])
    N = P.shape[1]
    uv_c = np.broadcast_to(np.asarray(uv_centred_px, dtype=float), (S, N, 2))
    w = np.ones((S, N)) if weights is None else np.broadcast_to(np.asarray(weights, float), (S, N))
    w_sqrt = np.sqrt(w)
    t = np.array(t, dtype=float)
    log_f = np.log(np.asarray(focal_px, dtype=float))

    r, cost, J = _residuals_and_jacobian(uv_c, P, w_sqrt, R, t, log_f)
    lam = np.full(S, options.initial_lambda)
    active = np.isfinite(cost)
    eye = np.eye(7)
    iteration = 0
    while active.any() and iteration < options.max_iterations:
        iteration += 1
        idx = np.flatnonzero(active)
        Ja, ra = J[idx], r[idx]
        JtJ = np.einsum("smi,smj->sij", Ja, Ja)
        g = np.einsum("smi,sm->si", Ja, ra)
        diag = np.einsum("sii->si", JtJ)
        scale = np.sqrt(np.maximum(diag, 1e-300))
        small_gradient = np.max(np.abs(g) / scale, axis=1) <= options.gradient_tol * np.sqrt(
            np.maximum(cost[idx], 1e-300)
        )
        A = JtJ + lam[idx, None, None] * (diag[:, :, None] * eye + 1e-12 * eye)
        try:
            delta = -np.linalg.solve(A, g[..., None])[..., 0]
        except np.linalg.LinAlgError:
            delta = -np.einsum("sij,sj->si", np.linalg.pinv(A), g)
        R_new = rotvec_to_matrix(delta[:, :3]) @ R[idx]
        t_new = t[idx] + delta[:, 3:6]
        logf_new = log_f[idx] + delta[:, 6]
        r_new, cost_new, J_new = _residuals_and_jacobian(
            uv_c[idx], P[idx], w_sqrt[idx], R_new, t_new, logf_new
        )
        better = cost_new < cost[idx]
        gain = np.where(better, cost[idx] - cost_new, 0.0)
        ok = idx[better]
        R[ok], t[ok], log_f[ok] = R_new[better], t_new[better], logf_new[better]
        r[ok], J[ok], cost[ok] = r_new[better], J_new[better], cost_new[better]
        lam[idx] = np.where(better, lam[idx] * 0.1, lam[idx] * 10.0)
        lam[idx] = np.maximum(lam[idx], 1e-12)
        done = (
            (better & (gain <= options.cost_tol * cost[idx] + 1e-30))
            | small_gradient
            | (lam[idx] > options.max_lambda)
        )
        active[idx[done]] = False

    sq = reprojection_sq_errors(uv_c, P, R, t, np.exp(log_f))
    return BatchRefineResult(R, t, np.exp(log_f), sq, cost, iteration)
