"""Levenberg-Marquardt refinement of pose and focal length, for many problems at once.

Seven unknowns per problem. Internally the camera is written about the weighted centroid ``m``
of the used points (skull frame): ``X_cam = R (X - m) + c`` with ``c = R m + t`` the centroid in
the camera frame, and the unknowns are

- a rotation, updated on the left by a rotation-vector increment (``R <- exp([w]x) R``, a turn
  about the centroid),
- ``a = focal_px * c[:2] / c[2]``, the centroid's image position (pixels from the principal
  point),
- ``sigma = log(focal_px / c[2])``, the image scale (pixels per mm at the centroid),
- ``tau = log(c[2])``, the centroid's depth (mm).

Image position, scale and depth are nearly decoupled, where the plain ``(t, log f)`` unknowns
share a long curved valley (a larger focal length with a farther head gives almost the same
image); in these unknowns Levenberg-Marquardt needs a few iterations where it needed tens, and
the focal length stays positive. The residuals are the reprojection errors (pixels) of the used
points. All problems of a batch share the number of points ``N``; a weight of 0 switches a point
off, so problems may use different subsets.
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..constants import FOCAL_MAX_PX, MIN_DEPTH_MM
from ..geometry.rotations import rotvec_to_matrix
from ._refine_kernels import refine_kernel
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
        Stop a problem when an accepted step lowers its cost by less than this fraction, or
        when a rejected step's linear model predicts a smaller relative decrease than this
        (the model has nothing left to gain; the rejection is rounding).
    gradient_tol : float
        Stop a problem when the largest scaled gradient entry (the cosine between the residual
        vector and a Jacobian column) falls below this.
    min_rms_px : float
        Stop a problem when the RMS of its weighted residuals falls below this (pixels): an
        exact fit, where relative decreases are rounding noise.
    max_lambda : float
        Stop a problem when its damping grows past this (no further progress possible).
    focal_stop_px : float
        Stop a problem when its focal length grows past this: it is running off towards the
        orthographic limit (a farther head seen through a longer lens), far beyond any real
        camera; its result is then out of range and the caller treats it as a failure.
    """

    max_iterations: int = 100
    initial_lambda: float = 1e-3
    cost_tol: float = 1e-12
    gradient_tol: float = 1e-10
    min_rms_px: float = 1e-10
    max_lambda: float = 1e10
    focal_stop_px: float = 100.0 * FOCAL_MAX_PX


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


def _residuals_and_jacobian(uv_c, P, w_sqrt, R, c, log_f):
    """Weighted residuals and their Jacobian over ``(w, a_x, a_y, sigma, tau)``.

    Parameters
    ----------
    uv_c : ndarray of shape (S, N, 2)
    P : ndarray of shape (S, N, 3)
        Points minus their centroid (skull frame, mm).
    w_sqrt : ndarray of shape (S, N)
    R : ndarray of shape (S, 3, 3)
    c : ndarray of shape (S, 3)
        The centroid in the camera frame (mm).
    log_f : ndarray of shape (S,)

    Returns
    -------
    r : ndarray of shape (S, 2N)
    cost : ndarray of shape (S,)
        ``inf`` when a used point is at or behind the camera.
    J : ndarray of shape (S, 2N, 7)
    """
    q = np.einsum("sij,snj->sni", R, P)  # rotated points, (S, N, 3)
    X = q + c[:, None, :]
    z = X[..., 2]
    ahead = z > MIN_DEPTH_MM
    z_safe = np.where(ahead, z, 1.0)
    f = np.exp(log_f)[:, None]
    x, y = X[..., 0] / z_safe, X[..., 1] / z_safe
    fx, fy = f * x, f * y
    r = np.empty(z.shape + (2,))
    r[..., 0] = (fx - uv_c[..., 0]) * w_sqrt
    r[..., 1] = (fy - uv_c[..., 1]) * w_sqrt
    cost = np.einsum("snk,snk->s", r, r)
    cost[np.any(~ahead & (w_sqrt > 0), axis=1)] = np.inf
    # u = f x, v = f y with (x, y) = X[:2] / X[2]. A left rotation increment moves X by
    # w x q; the image unknowns give X_xy = a exp(-sigma) + q_xy, X_z = exp(tau) + q_z and
    # f = exp(sigma + tau), so du/da_x = c_z / z, du/dsigma = f x - f c_x / z,
    # du/dtau = f x (1 - c_z / z), and likewise for v.
    fz = (f / z_safe) * w_sqrt
    wfx, wfy = fx * w_sqrt, fy * w_sqrt
    q0, q1, q2 = q[..., 0], q[..., 1], q[..., 2]
    J = np.empty(z.shape + (2, 7))
    J[..., 0, 0] = -fz * x * q1
    J[..., 0, 1] = fz * (q2 + x * q0)
    J[..., 0, 2] = -fz * q1
    J[..., 1, 0] = -fz * (q2 + y * q1)
    J[..., 1, 1] = fz * y * q0
    J[..., 1, 2] = fz * q0
    cz_over_z = c[:, 2, None] / z_safe
    J[..., 0, 3] = cz_over_z * w_sqrt
    J[..., 0, 4] = 0.0
    J[..., 1, 3] = 0.0
    J[..., 1, 4] = J[..., 0, 3]
    J[..., 0, 5] = wfx - fz * c[:, 0, None]
    J[..., 1, 5] = wfy - fz * c[:, 1, None]
    J[..., 0, 6] = wfx * (1.0 - cz_over_z)
    J[..., 1, 6] = wfy * (1.0 - cz_over_z)
    S, N = z.shape
    return r.reshape(S, 2 * N), cost, J.reshape(S, 2 * N, 7)


def _step_image_unknowns(c, log_f, step):
    """Apply an increment (S, 4) of ``(a_x, a_y, sigma, tau)``; return the new ``c`` and log f."""
    log_cz = np.log(c[:, 2])
    sigma = log_f - log_cz + step[:, 2]
    tau = log_cz + step[:, 3]
    a = c[:, :2] * np.exp(log_f - log_cz)[:, None] + step[:, :2]
    c_new = np.column_stack([a * np.exp(-sigma)[:, None], np.exp(tau)])
    return c_new, sigma + tau


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
    if jit.compiled():  # the same iterations, compiled (pose/_refine_kernels.py)
        return _refine_compiled(uv_centred_px, points_mm, weights, R, t, focal_px, options)
    P = np.broadcast_to(np.asarray(points_mm, dtype=float), (S,) + np.shape(points_mm)[-2:])
    N = P.shape[1]
    uv_c = np.broadcast_to(np.asarray(uv_centred_px, dtype=float), (S, N, 2))
    w = np.ones((S, N)) if weights is None else np.broadcast_to(np.asarray(weights, float), (S, N))
    t = np.array(np.broadcast_to(np.asarray(t, dtype=float), (S, 3)))  # the caller's copy
    w_sqrt = np.sqrt(w)
    log_f = np.log(np.asarray(focal_px, dtype=float))

    # Centre each problem on the weighted centroid of its used points.
    w_sum = w.sum(axis=1, keepdims=True)
    m = np.einsum("sn,snj->sj", w, P) / np.where(w_sum > 0, w_sum, 1.0)
    Pm = P - m[:, None, :]
    c = np.einsum("sij,sj->si", R, m) + t
    r, cost, J = _residuals_and_jacobian(uv_c, Pm, w_sqrt, R, c, log_f)
    # The centroid of points in front of the camera is in front of it too.
    cost = np.where(c[:, 2] > MIN_DEPTH_MM, cost, np.inf)
    # Cost below which a problem counts as fitted exactly (RMS of the used residuals).
    floor = options.min_rms_px**2 * 2.0 * np.count_nonzero(w_sqrt, axis=1)
    lam = np.full(S, options.initial_lambda)
    nu = np.full(S, 2.0)
    active = np.isfinite(cost) & (cost > floor)
    eye = np.eye(7)
    log_f_stop = np.log(options.focal_stop_px)
    iteration = 0
    while active.any() and iteration < options.max_iterations:
        iteration += 1
        idx = np.flatnonzero(active)
        ra, cost_a, c_a, logf_a = r[idx], cost[idx], c[idx], log_f[idx]
        Ja = J[idx]
        JtJ = np.einsum("smi,smj->sij", Ja, Ja)
        g = np.einsum("smi,sm->si", Ja, ra)
        diag = np.einsum("sii->si", JtJ)
        scale = np.sqrt(np.maximum(diag, 1e-300))
        small_gradient = np.max(np.abs(g) / scale, axis=1) <= options.gradient_tol * np.sqrt(cost_a)
        A = JtJ + lam[idx, None, None] * (diag[:, :, None] * eye + 1e-12 * eye)
        try:
            delta = -np.linalg.solve(A, g[..., None])[..., 0]
        except np.linalg.LinAlgError:
            delta = -np.einsum("sij,sj->si", np.linalg.pinv(A), g)
        # Decrease of the cost predicted by the linear model, -2 g.d - d^T J^T J d >= 0.
        predicted = -2.0 * np.einsum("si,si->s", g, delta) - np.einsum(
            "si,sij,sj->s", delta, JtJ, delta
        )
        R_new = rotvec_to_matrix(delta[:, :3]) @ R[idx]
        # A wild step (depth or focal length overflowing) gives a NaN cost and is rejected.
        with np.errstate(over="ignore", invalid="ignore"):
            c_new, logf_new = _step_image_unknowns(c_a, logf_a, delta[:, 3:])
            r_new, cost_new, J_new = _residuals_and_jacobian(
                uv_c[idx], Pm[idx], w_sqrt[idx], R_new, c_new, logf_new
            )
        better = cost_new < cost_a
        gain = np.where(better, cost_a - cost_new, 0.0)
        ok = idx[better]
        R[ok], c[ok], log_f[ok] = R_new[better], c_new[better], logf_new[better]
        r[ok], J[ok], cost[ok] = r_new[better], J_new[better], cost_new[better]
        # Nielsen's damping update: shrink by the gain ratio on success, grow 2, 4, 8... on failure.
        rho = gain / np.maximum(predicted, 1e-300)
        shrink = np.maximum(1.0 / 3.0, 1.0 - (2.0 * np.minimum(rho, 1.0) - 1.0) ** 3)
        lam[idx] = np.maximum(np.where(better, lam[idx] * shrink, lam[idx] * nu[idx]), 1e-12)
        nu[idx] = np.where(better, 2.0, nu[idx] * 2.0)
        done = (
            (better & (gain <= options.cost_tol * cost_a))
            | (~better & (predicted <= options.cost_tol * cost_a))
            | (cost[idx] <= floor[idx])
            | small_gradient
            | (lam[idx] > options.max_lambda)
            | (log_f[idx] > log_f_stop)
        )
        active[idx[done]] = False

    t = c - np.einsum("sij,sj->si", R, m)
    sq = reprojection_sq_errors(uv_c, P, R, t, np.exp(log_f))
    return BatchRefineResult(R, t, np.exp(log_f), sq, cost, iteration)


def _batched(a, shape):
    """``a`` as a writeable C array of floats of ``shape``: itself when it is one already, else
    a broadcast copy (one compiled signature for every call)."""
    a = np.asarray(a, dtype=float)
    if a.shape == shape and a.flags.c_contiguous and a.flags.writeable:
        return a
    return np.ascontiguousarray(np.broadcast_to(a, shape))


def _refine_compiled(uv_c, P, w, R, t, focal_px, options):
    """:func:`refine_batch` by :func:`~lilium.pose._refine_kernels.refine_kernel` (``R`` is the
    caller's copy, refined in place; ``uv_c``, ``P``, ``w`` and ``t`` as :func:`refine_batch`
    takes them)."""
    S = len(R)
    P = _batched(P, (S,) + np.shape(P)[-2:])
    N = P.shape[1]
    uv_c = _batched(uv_c, (S, N, 2))
    w = np.ones((S, N)) if w is None else _batched(w, (S, N))
    t = np.array(np.broadcast_to(np.asarray(t, dtype=float), (S, 3)))  # the caller's copy
    f = np.array(np.broadcast_to(np.asarray(focal_px, dtype=float), (S,)))
    cost, iterations, sq = refine_kernel(
        uv_c,
        P,
        w,
        R,
        t,
        f,
        float(options.min_rms_px),
        int(options.max_iterations),
        float(options.initial_lambda),
        float(options.cost_tol),
        float(options.gradient_tol),
        float(options.max_lambda),
        float(np.log(options.focal_stop_px)),
    )
    n_iterations = int(iterations.max()) if len(iterations) else 0
    return BatchRefineResult(R, t, f, sq, cost, n_iterations)
