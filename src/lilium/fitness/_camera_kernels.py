"""Compiled camera terms of Lilium's fitness: MSE_pix and P_cam (docs/method/lilium.md) of a
population, and the validity of its cameras; numba, see :mod:`lilium.jit`.

The numpy path they replace: :meth:`lilium.methods.lilium.LiliumProblem._terms` (MSE_pix, the
subject-to-camera distance, :func:`lilium.fitness.camera_penalty.camera_penalty_from_priors`)
and :meth:`~lilium.methods.lilium.LiliumProblem.cameras`' checks (the facing rule of
:func:`lilium.methods.checks.facing_check`, the focal range, the best capped fit). Per member,
element by element, in the numpy path's order of operations; sums and ``atan2`` may round
differently in the last bit (about 1e-15 relative).

A prior that is off is passed as NaN (both ends of an interval, the head tolerance).
"""

import numpy as np

from ..constants import C_INF, FOCAL_MIN_PX
from ..geometry._rotation_kernels import relative_angle_axis
from ..jit import njit
from ..pose._refine_kernels import refine_kernel
from ..softtissue._cone_kernels import decode_kernel


@njit
def _excess2(x, lo, hi):
    return max(0.0, lo - x) ** 2 + max(0.0, x - hi) ** 2


@njit
def _row_mean(sq, s):
    """Mean of row ``s`` of ``sq``, summed in order."""
    total = 0.0
    for n in range(sq.shape[1]):
        total += sq[s, n]
    return total / sq.shape[1]


@njit
def camera_terms_kernel(sq, ok, R, t, f, centre, focal, scd, head, tol, cap):
    """MSE_pix and P_cam of S cameras.

    Parameters
    ----------
    sq : ndarray of shape (S, N)
        Squared reprojection errors (pixels^2) under each camera.
    ok : ndarray of shape (S,) of bool
        Valid cameras (the others get ``C_INF`` for MSE_pix and count as failures in P_cam).
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
    f : ndarray of shape (S,)
    centre : ndarray of shape (S, 3)
        The point whose distance from the camera is the SCD (skull frame, mm).
    focal, scd : ndarray of shape (2,)
        The focal (px) and SCD (mm) intervals; NaN = off.
    head : ndarray of shape (3, 3)
        The a priori head rotation (ignored when ``tol`` is NaN).
    tol : float
        Head tolerance (degrees); NaN = off.
    cap : float
        The focal cap (:func:`lilium.constants.focal_cap_px`).

    Returns
    -------
    mse_pix, p_cam : ndarray of shape (S,)
    """
    S = sq.shape[0]
    mse = np.empty(S)
    p_cam = np.empty(S)
    focal_on, scd_on, head_on = not np.isnan(focal[0]), not np.isnan(scd[0]), not np.isnan(tol)
    for s in range(S):
        m = _row_mean(sq, s) if ok[s] else C_INF
        mse[s] = m if np.isfinite(m) else C_INF
        fs = f[s]
        fail = (not ok[s]) or (not np.isfinite(fs)) or fs < FOCAL_MIN_PX or fs > cap
        terms = 0.0
        if focal_on:
            value = _excess2(fs, focal[0], focal[1])  # a non-finite fs already fails
            terms += value if np.isfinite(value) else 0.0
        if scd_on:
            c = centre[s]
            X0 = R[s, 0, 0] * c[0] + R[s, 0, 1] * c[1] + R[s, 0, 2] * c[2] + t[s, 0]
            X1 = R[s, 1, 0] * c[0] + R[s, 1, 1] * c[1] + R[s, 1, 2] * c[2] + t[s, 1]
            X2 = R[s, 2, 0] * c[0] + R[s, 2, 1] * c[1] + R[s, 2, 2] * c[2] + t[s, 2]
            d = np.sqrt(X0 * X0 + X1 * X1 + X2 * X2)
            value = _excess2(d, scd[0], scd[1])
            fail = fail or not np.isfinite(d)
            terms += value if np.isfinite(value) else 0.0
        if head_on:
            dbeta = relative_angle_axis(R[s], head)[0]
            value = max(0.0, dbeta - tol) ** 2
            fail = fail or not np.isfinite(dbeta)
            terms += value if np.isfinite(value) else 0.0
        p_cam[s] = (C_INF if fail else 0.0) + terms
    return mse, p_cam


@njit
def camera_checks_kernel(R, t, f, cost, sq, origin, anterior, cos_max, cap, run_off_cap, lender):
    """The checks of a population's refined cameras, or a request for the numpy path.

    In :meth:`lilium.methods.lilium.LiliumProblem.cameras`' order: a camera is *broken* (a
    non-finite cost or error: it needs its own POSEST) or *valid* (focal length in
    ``[FOCAL_MIN_PX, cap]`` and, with a facing rule, the skull's front seen: the angle between
    ``anterior`` and the direction ``origin`` -> camera centre has a cosine not below
    ``cos_max``); among the cameras refused only for the cap (``cap < f <= run_off_cap``,
    facing) the one of least MSE. When a camera is broken, or none is valid and no member
    lends one (``lender`` False), nothing is changed and ``done`` is False: those cameras are
    replaced on the numpy path.

    Parameters
    ----------
    R, t, f : ndarray of shape (S, 3, 3), (S, 3), (S,)
        The refined cameras.
    cost : ndarray of shape (S,)
        The refinement's cost.
    sq : ndarray of shape (S, N)
        Their squared reprojection errors; set to ``inf`` for invalid cameras when ``done``.
    origin, anterior : ndarray of shape (3,)
        The skull's directions (:class:`lilium.methods.checks.SkullDirections`).
    cos_max : float
        NaN: no facing rule (every camera faces).
    cap, run_off_cap : float
    lender : bool

    Returns
    -------
    done : bool
    ok : ndarray of shape (S,) of bool
    capped : int
        Index of the capped camera of least MSE; -1 when none.
    capped_mse : float
    """
    S, N = sq.shape
    ok = np.zeros(S, np.bool_)
    capped, capped_mse = -1, np.inf
    any_ok = False
    for s in range(S):
        if not np.isfinite(cost[s]):
            return False, ok, capped, capped_mse
        for n in range(N):
            if not np.isfinite(sq[s, n]):
                return False, ok, capped, capped_mse
        facing = True
        if not np.isnan(cos_max):
            d0 = -(R[s, 0, 0] * t[s, 0] + R[s, 1, 0] * t[s, 1] + R[s, 2, 0] * t[s, 2]) - origin[0]
            d1 = -(R[s, 0, 1] * t[s, 0] + R[s, 1, 1] * t[s, 1] + R[s, 2, 1] * t[s, 2]) - origin[1]
            d2 = -(R[s, 0, 2] * t[s, 0] + R[s, 1, 2] * t[s, 1] + R[s, 2, 2] * t[s, 2]) - origin[2]
            big = max(abs(d0), abs(d1), abs(d2))
            if big > 0.0:  # a camera at the origin itself: NaN on the numpy path, so it passes
                d0, d1, d2 = d0 / big, d1 / big, d2 / big
                cos = (d0 * anterior[0] + d1 * anterior[1] + d2 * anterior[2]) / np.sqrt(
                    d0 * d0 + d1 * d1 + d2 * d2
                )
                facing = not (cos < cos_max)
        fs = f[s]
        ok[s] = fs >= FOCAL_MIN_PX and fs <= cap and facing
        any_ok = any_ok or ok[s]
        if fs > cap and fs <= run_off_cap and facing:
            mse = _row_mean(sq, s)
            if capped < 0 or mse < capped_mse:
                capped, capped_mse = s, mse
    if not lender and not any_ok:
        return False, ok, capped, capped_mse
    for s in range(S):
        if not ok[s]:
            for n in range(N):
                sq[s, n] = np.inf
    return True, ok, capped, capped_mse


@njit
def camera_stage_kernel(
    genes, cranial, cones, uv, w, R0, t0, f0, success, refine, origin, anterior, cos_max, cap,
    run_off_cap, scd_index, focal, scd, head, tol,
):  # fmt: skip
    """The cheap terms of a population of trials in one call: its facial landmarks (the
    genes decoded, :func:`~lilium.softtissue._cone_kernels.decode_kernel`), its cameras refined
    from the members' (:func:`~lilium.pose._refine_kernels.refine_kernel`), their checks
    (:func:`camera_checks_kernel`) and MSE_pix and P_cam (:func:`camera_terms_kernel`): the
    kernels :meth:`lilium.methods.lilium.LiliumProblem.camera_terms` calls one by one, in the
    same order on the same arrays.

    Parameters
    ----------
    genes : ndarray of shape (S, 3N)
    cranial : ndarray of shape (N, 3)
    cones : tuple
        :func:`lilium.softtissue.cones.decode_arguments`.
    uv, w : ndarray of shape (S, N, 2), (S, N)
        Centred landmarks and weights of the refinement.
    R0, t0, f0 : ndarray of shape (S, 3, 3), (S, 3), (S,)
        The members' cameras (not changed): each trial starts from its member's.
    success : ndarray of shape (S,) of bool
        The members with a valid camera; the others start from the first valid one's.
    refine : tuple
        ``(min_rms_px, max_iterations, initial_lambda, cost_tol, gradient_tol, max_lambda,
        log_focal_stop)`` of :class:`lilium.pose.refine.RefineOptions`.
    origin, anterior, cos_max, cap, run_off_cap
        As :func:`camera_checks_kernel` (``lender``: some member has a valid camera).
    scd_index : ndarray of shape (K,) of int64
        The landmarks whose mean is the SCD's centre.
    focal, scd, head, tol
        As :func:`camera_terms_kernel` (``cap`` the same).

    Returns
    -------
    facial, R, t, f, cost, sq
        Facial landmarks ``(S, N, 3)``, refined cameras, refinement cost ``(S,)``, squared
        errors ``(S, N)``.
    done : bool
        False when a camera must be replaced by its own POSEST (the numpy path does that from
        the refined cameras; the outputs below are then not computed).
    ok : ndarray of shape (S,) of bool
    capped, capped_mse : int, float
    mse_pix, p_cam : ndarray of shape (S,)
    """
    S, N = w.shape
    facial = decode_kernel(genes, *cones)
    for s in range(S):
        for n in range(N):
            for j in range(3):
                facial[s, n, j] = cranial[n, j] + facial[s, n, j]
    R, t, f = R0.copy(), t0.copy(), f0.copy()
    lent = -1
    for s in range(S):
        if success[s]:
            lent = s
            break
    if lent >= 0:
        for s in range(S):
            if not success[s]:
                R[s], t[s], f[s] = R0[lent], t0[lent], f0[lent]
    cost, _, sq = refine_kernel(uv, facial, w, R, t, f, *refine)
    done, ok, capped, capped_mse = camera_checks_kernel(
        R, t, f, cost, sq, origin, anterior, cos_max, cap, run_off_cap, lent >= 0
    )
    mse, p_cam = np.empty(S), np.empty(S)
    if done:
        K = scd_index.shape[0]
        centre = np.zeros((S, 3))
        for s in range(S):
            for j in range(3):
                total = facial[s, scd_index[0], j]
                for k in range(1, K):
                    total += facial[s, scd_index[k], j]
                centre[s, j] = total / K if K > 1 else total
        mse, p_cam = camera_terms_kernel(sq, ok, R, t, f, centre, focal, scd, head, tol, cap)
    return facial, R, t, f, cost, sq, done, ok, capped, capped_mse, mse, p_cam
