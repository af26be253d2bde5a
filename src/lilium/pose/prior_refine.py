"""Levenberg-Marquardt on the reprojection error *and* the camera priors, for many problems.

:func:`~lilium.pose.refine.refine_batch` fits the camera to the landmarks alone; the priors
(focal length, subject-to-camera distance, head orientation intervals) then only judge the
result (P_cam, docs/method/lilium.md). :func:`refine_with_priors` moves a camera to the minimum of

``mean_i |P(X_i) - uv_i|^2 + max(0, fmin - f)^2 + max(0, f - fmax)^2
+ max(0, SCDmin - SCD)^2 + max(0, SCD - SCDmax)^2 + max(0, dbeta - tol)^2``

i.e. ``MSE_pix + P_cam`` of docs/method/lilium.md for a fixed set of 3D points: the camera-dependent
part of Lilium's fitness without the image terms. A prior that is None switches its residuals
off. Used by the joint SFO (:mod:`lilium.methods.joint`, docs/method/joint.md: one shared soft
tissue
cannot bend itself to bring every photo's least-squares camera inside that photo's priors).

Unknowns as in :mod:`lilium.pose.refine` (a left rotation increment; the image position, log
scale and log depth of the centroid of the points); the reprojection Jacobian is that module's,
the five prior residuals are differentiated analytically (focal length, distance; the head
angle's derivative over the rotation increment is the unit axis of the rotation from the prior);
their kinks are where they switch on. Compiled by
:func:`~lilium.pose._prior_refine_kernels.prior_refine_kernel` (the same steps; this numpy code
is its reference).
"""

import numpy as np

from .. import jit
from ..constants import MIN_DEPTH_MM
from ..geometry.rotations import geodesic_angle_deg, rotvec_to_matrix
from ._prior_refine_kernels import prior_refine_kernel
from .refine import BatchRefineResult, _residuals_and_jacobian, _step_image_unknowns
from .residuals import reprojection_sq_errors


def _prior_residuals(R, c, log_f, scd_rel, focal_interval, scd_interval, head_rotation, tol):
    """The five hinge residuals ``(S, 5)`` (zero where a prior is off) and their Jacobian
    ``(S, 5, 7)`` over the unknowns of :mod:`lilium.pose.refine`."""
    S = len(R)
    h = np.zeros((S, 5))
    J = np.zeros((S, 5, 7))
    f = np.exp(log_f)
    if focal_interval is not None:
        # log f = sigma + tau: df/dsigma = df/dtau = f.
        lo, hi = focal_interval[0] - f > 0.0, f - focal_interval[1] > 0.0
        h[:, 0] = np.where(lo, focal_interval[0] - f, 0.0)
        h[:, 1] = np.where(hi, f - focal_interval[1], 0.0)
        J[:, 0, 5] = J[:, 0, 6] = np.where(lo, -f, 0.0)
        J[:, 1, 5] = J[:, 1, 6] = np.where(hi, f, 0.0)
    if scd_interval is not None:
        q = np.einsum("sij,sj->si", R, scd_rel)
        X = q + c
        scd = np.linalg.norm(X, axis=1)
        # dX/dw = -[q]x (a left rotation increment), dX/da = exp(-sigma) on x, y,
        # dX/dsigma = (-c_x, -c_y, 0), dX/dtau = (0, 0, c_z).
        dX = np.zeros((S, 3, 7))
        dX[:, 0, 1], dX[:, 0, 2] = q[:, 2], -q[:, 1]
        dX[:, 1, 0], dX[:, 1, 2] = -q[:, 2], q[:, 0]
        dX[:, 2, 0], dX[:, 2, 1] = q[:, 1], -q[:, 0]
        inv_scale = c[:, 2] / np.exp(log_f)  # exp(-sigma) = c_z / f
        dX[:, 0, 3] = dX[:, 1, 4] = inv_scale
        dX[:, 0, 5], dX[:, 1, 5] = -c[:, 0], -c[:, 1]
        dX[:, 2, 6] = c[:, 2]
        dscd = np.einsum("si,sik->sk", X, dX) / scd[:, None]
        lo, hi = scd_interval[0] - scd > 0.0, scd - scd_interval[1] > 0.0
        h[:, 2] = np.where(lo, scd_interval[0] - scd, 0.0)
        h[:, 3] = np.where(hi, scd - scd_interval[1], 0.0)
        J[:, 2] = np.where(lo[:, None], -dscd, 0.0)
        J[:, 3] = np.where(hi[:, None], dscd, 0.0)
    if head_rotation is not None and tol is not None:
        dbeta = geodesic_angle_deg(R, head_rotation)
        on = dbeta - tol > 0.0
        h[:, 4] = np.where(on, dbeta - tol, 0.0)
        if on.any():
            # d angle / d w of a left increment exp([w]x) R is the unit axis of R P^T (the
            # rotation from the prior): turning about that axis changes the angle one for one,
            # about a perpendicular axis only at second order. In degrees.
            Q = R @ np.asarray(head_rotation, float).T
            axis = np.stack([Q[:, 2, 1] - Q[:, 1, 2], Q[:, 0, 2] - Q[:, 2, 0],
                             Q[:, 1, 0] - Q[:, 0, 1]], axis=1)  # fmt: skip
            norm = np.linalg.norm(axis, axis=1, keepdims=True)
            with np.errstate(invalid="ignore", divide="ignore"):
                unit = np.where(norm > 0.0, axis / norm, 0.0)
            J[:, 4, :3] = np.where(on[:, None], np.degrees(unit), 0.0)
    return h, J


def _step(R, c, log_f, delta):
    """Apply an increment ``(S, 7)`` of the unknowns: ``(R, c, log_f)``."""
    R_new = rotvec_to_matrix(delta[:, :3]) @ R
    c_new, logf_new = _step_image_unknowns(c, log_f, delta[:, 3:])
    return R_new, c_new, logf_new


def refine_with_priors(
    uv_centred_px,
    points_mm,
    R,
    t,
    focal_px,
    scd_points_mm,
    *,
    focal_interval_px=None,
    scd_interval_mm=None,
    head_rotation=None,
    head_tolerance_deg=None,
    max_iterations=10,
):
    """Refine S cameras on ``MSE_pix + P_cam`` (module notes), vectorised over the batch.

    Parameters
    ----------
    uv_centred_px : array_like of shape (N, 2) or (S, N, 2)
        Image points minus the principal point (pixels).
    points_mm : array_like of shape (S, N, 3)
        3D points of each problem (mm).
    R : array_like of shape (S, 3, 3)
    t : array_like of shape (S, 3)
    focal_px : array_like of shape (S,)
        Start cameras (e.g. the least-squares ones), in front of every point.
    scd_points_mm : array_like of shape (S, 3)
        The point whose distance from the camera centre is the SCD (the facial nasion).
    focal_interval_px, scd_interval_mm : (float, float), optional
    head_rotation : ndarray of shape (3, 3), optional
    head_tolerance_deg : float, optional
    max_iterations : int

    Returns
    -------
    BatchRefineResult
        Its ``cost`` is ``MSE_pix + P_cam`` (the prior terms that are on; ``inf`` behind the
        camera). A problem keeps its start unless a step lowers its cost.
    """
    R = np.array(R, dtype=float)
    S = len(R)
    P = np.broadcast_to(np.asarray(points_mm, dtype=float), (S,) + np.shape(points_mm)[-2:])
    N = P.shape[1]
    uv_c = np.broadcast_to(np.asarray(uv_centred_px, dtype=float), (S, N, 2))
    if jit.compiled():
        return _refine_compiled(
            uv_c,
            P,
            R,
            t,
            focal_px,
            scd_points_mm,
            (focal_interval_px, scd_interval_mm, head_rotation, head_tolerance_deg),
            max_iterations,
        )
    w_sqrt = np.full((S, N), 1.0 / np.sqrt(N))
    log_f = np.log(np.asarray(focal_px, dtype=float)).copy()
    m = P.mean(axis=1)
    Pm = P - m[:, None, :]
    c = np.einsum("sij,sj->si", R, m) + np.asarray(t, dtype=float)
    scd_rel = np.asarray(scd_points_mm, dtype=float) - m
    priors = (focal_interval_px, scd_interval_mm, head_rotation, head_tolerance_deg)

    def evaluate(R_, c_, logf_, rel):
        with np.errstate(over="ignore", invalid="ignore"):
            r, cost, J = _residuals_and_jacobian(uv_c[rel], Pm[rel], w_sqrt[rel], R_, c_, logf_)
            h, Jh = _prior_residuals(R_, c_, logf_, scd_rel[rel], *priors)
        cost = cost + np.sum(h**2, axis=1)
        cost = np.where((c_[:, 2] > MIN_DEPTH_MM) & np.isfinite(cost), cost, np.inf)
        return np.concatenate([r, h], axis=1), cost, np.concatenate([J, Jh], axis=1)

    everyone = np.arange(S)
    r, cost, J = evaluate(R, c, log_f, everyone)
    lam = np.full(S, 1e-3)
    active = np.isfinite(cost)
    eye = np.eye(7)
    iteration = 0
    while active.any() and iteration < max_iterations:
        iteration += 1
        idx = np.flatnonzero(active)
        Ja, ra = J[idx], r[idx]
        JtJ = np.einsum("smi,smj->sij", Ja, Ja)
        g = np.einsum("smi,sm->si", Ja, ra)
        diag = np.einsum("sii->si", JtJ)
        A = JtJ + lam[idx, None, None] * (diag[:, :, None] * eye + 1e-12 * eye)
        try:
            delta = -np.linalg.solve(A, g[..., None])[..., 0]
        except np.linalg.LinAlgError:
            delta = -np.einsum("sij,sj->si", np.linalg.pinv(A), g)
        with np.errstate(over="ignore", invalid="ignore"):
            R_new, c_new, logf_new = _step(R[idx], c[idx], log_f[idx], delta)
        r_new, cost_new, J_new = evaluate(R_new, c_new, logf_new, idx)
        better = cost_new < cost[idx]
        gain = np.where(better, cost[idx] - cost_new, 0.0)
        ok = idx[better]
        R[ok], c[ok], log_f[ok] = R_new[better], c_new[better], logf_new[better]
        r[ok], J[ok] = r_new[better], J_new[better]
        before = cost[idx]
        cost[ok] = cost_new[better]
        lam[idx] = np.where(better, np.maximum(lam[idx] / 3.0, 1e-12), lam[idx] * 4.0)
        done = (better & (gain <= 1e-9 * before)) | (lam[idx] > 1e10)
        active[idx[done]] = False

    t_out = c - np.einsum("sij,sj->si", R, m)
    f_out = np.exp(log_f)
    sq = reprojection_sq_errors(uv_c, P, R, t_out, f_out)
    return BatchRefineResult(R, t_out, f_out, sq, cost, iteration)


def _refine_compiled(uv_c, P, R, t, focal_px, scd_points_mm, priors, max_iterations):
    """:func:`refine_with_priors` by the compiled kernel (``R`` is the caller's copy); the
    priors as the compiled camera terms take them (intervals of 2, a prior that is off NaN)."""
    focal_interval, scd_interval, head_rotation, tol = priors
    off = np.full(2, np.nan)
    focal = off if focal_interval is None else np.array(focal_interval, float)
    scd = off if scd_interval is None else np.array(scd_interval, float)
    head_on = head_rotation is not None and tol is not None
    S = len(R)
    t = np.array(np.broadcast_to(np.asarray(t, dtype=float), (S, 3)))
    f = np.array(np.broadcast_to(np.asarray(focal_px, dtype=float), (S,)))
    cost, iterations, sq = prior_refine_kernel(
        np.require(uv_c, float, ["C", "W"]),
        np.require(P, float, ["C", "W"]),
        R,
        t,
        f,
        np.require(np.broadcast_to(np.asarray(scd_points_mm, float), (S, 3)), float, ["C", "W"]),
        focal,
        scd,
        np.require(head_rotation if head_on else np.eye(3), float, ["C", "W"]),
        float(tol) if head_on else np.nan,
        int(max_iterations),
    )
    n_iterations = int(iterations.max()) if len(iterations) else 0
    return BatchRefineResult(R, t, f, sq, cost, n_iterations)
