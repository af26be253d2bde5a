"""Compiled camera terms of Lilium's fitness: MSE_pix and P_cam (SPEC section 5) of a
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
