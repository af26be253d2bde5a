"""Compiled Levenberg-Marquardt of :func:`lilium.pose.refine.refine_batch` (numba, see
:mod:`lilium.jit`).

The numpy code of :mod:`lilium.pose.refine` runs the problems of a batch in lockstep, one
vectorised iteration for all active problems at a time; here each problem runs its own loop,
with the same unknowns, residuals, Jacobian, damping updates and stopping tests, so every
problem takes the same steps. Sums are accumulated in a fixed order, ``exp`` is libm's (numpy's
SIMD ``exp`` differs in the last bit for a few per cent of arguments) and the 7 x 7 system is
solved by Gaussian elimination with partial pivoting rather than LAPACK, so results agree with
the numpy path to rounding, not bit for bit: to about 1e-12 relative for Lilium's warm-started
refinements (``tests/test_kernels_camera.py`` checks 1e-9); where a problem ends in a flat valley (a
distant head, focal length and depth nearly interchangeable) the two paths stop at points that
differ by up to about 1e-7 relative, within the refinement's own stopping tolerance. A
singular system (LAPACK's error, where the numpy path turns to a pseudo-inverse) gives a
rejected step and a larger damping.
"""

import numpy as np

from ..constants import MIN_DEPTH_MM
from ..geometry._projection_kernels import pinhole
from ..geometry._rotation_kernels import rotvec_to_matrix_kernel
from ..jit import njit


@njit
def _residuals(uv, P, ws, R, c, log_f, r, J):
    """Weighted residuals ``r`` (2N,) and Jacobian ``J`` (2N, 7) of one problem; its cost.

    The formulas of :func:`lilium.pose.refine._residuals_and_jacobian`.
    """
    N = P.shape[0]
    f = np.exp(log_f)
    cost = 0.0
    behind = False
    for n in range(N):
        p0, p1, p2 = P[n, 0], P[n, 1], P[n, 2]
        q0 = R[0, 0] * p0 + R[0, 1] * p1 + R[0, 2] * p2
        q1 = R[1, 0] * p0 + R[1, 1] * p1 + R[1, 2] * p2
        q2 = R[2, 0] * p0 + R[2, 1] * p1 + R[2, 2] * p2
        X0, X1, z = q0 + c[0], q1 + c[1], q2 + c[2]
        w = ws[n]
        ahead = z > MIN_DEPTH_MM
        if not ahead and w > 0:
            behind = True
        zs = z if ahead else 1.0
        x, y = X0 / zs, X1 / zs
        fx, fy = f * x, f * y
        ru = (fx - uv[n, 0]) * w
        rv = (fy - uv[n, 1]) * w
        r[2 * n] = ru
        r[2 * n + 1] = rv
        cost += ru * ru
        cost += rv * rv
        fz = (f / zs) * w
        wfx, wfy = fx * w, fy * w
        cz = c[2] / zs
        i, k = 2 * n, 2 * n + 1
        J[i, 0] = -fz * x * q1
        J[i, 1] = fz * (q2 + x * q0)
        J[i, 2] = -fz * q1
        J[k, 0] = -fz * (q2 + y * q1)
        J[k, 1] = fz * y * q0
        J[k, 2] = fz * q0
        J[i, 3] = cz * w
        J[i, 4] = 0.0
        J[k, 3] = 0.0
        J[k, 4] = cz * w
        J[i, 5] = wfx - fz * c[0]
        J[k, 5] = wfy - fz * c[1]
        J[i, 6] = wfx * (1.0 - cz)
        J[k, 6] = wfy * (1.0 - cz)
    return np.inf if behind else cost


@njit
def _solve7(A, g, out):
    """``out = -A^{-1} g`` by Gaussian elimination with partial pivoting; False if singular."""
    M = A.copy()
    b = g.copy()
    n = 7
    for col in range(n):
        p = col
        best = abs(M[col, col])
        for i in range(col + 1, n):
            if abs(M[i, col]) > best:
                best = abs(M[i, col])
                p = i
        if best == 0.0 or not np.isfinite(best):
            return False
        if p != col:
            for j in range(n):
                M[col, j], M[p, j] = M[p, j], M[col, j]
            b[col], b[p] = b[p], b[col]
        for i in range(col + 1, n):
            factor = M[i, col] / M[col, col]
            for j in range(col, n):
                M[i, j] -= factor * M[col, j]
            b[i] -= factor * b[col]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= M[i, j] * out[j]
        out[i] = s / M[i, i]
    for i in range(n):
        out[i] = -out[i]
    return True


@njit
def _normal_equations(J, r, rows, JtJ, g):
    """``JtJ = J^T J`` and ``g = J^T r`` over the first ``rows`` rows (fixed summation order)."""
    for i in range(7):
        for j in range(i + 1):  # symmetric: J[k, i] J[k, j] == J[k, j] J[k, i] exactly
            acc = 0.0
            for k in range(rows):
                acc += J[k, i] * J[k, j]
            JtJ[i, j] = acc
            JtJ[j, i] = acc
        acc = 0.0
        for k in range(rows):
            acc += J[k, i] * r[k]
        g[i] = acc


@njit
def _apply_step(R, c, log_f, delta, dR, R_new, c_new):
    """The camera after an increment ``delta`` (7,) of the unknowns (module
    :mod:`lilium.pose.refine`): ``R_new``, ``c_new`` filled; returns the new log focal length."""
    rotvec_to_matrix_kernel(delta[0], delta[1], delta[2], dR)
    for i in range(3):
        for j in range(3):
            R_new[i, j] = dR[i, 0] * R[0, j] + dR[i, 1] * R[1, j] + dR[i, 2] * R[2, j]
    log_cz = np.log(c[2])
    sigma = log_f - log_cz + delta[5]
    tau = log_cz + delta[6]
    scale = np.exp(log_f - log_cz)
    back = np.exp(-sigma)
    c_new[0] = (c[0] * scale + delta[3]) * back
    c_new[1] = (c[1] * scale + delta[4]) * back
    c_new[2] = np.exp(tau)
    return sigma + tau


@njit
def lm_kernel(
    uv,
    P,
    ws,
    R,
    c,
    log_f,
    floor,
    max_iterations,
    initial_lambda,
    cost_tol,
    gradient_tol,
    max_lambda,
    log_f_stop,
):
    """Levenberg-Marquardt of S problems, each to its own stop; ``R``, ``c``, ``log_f`` in place.

    Parameters
    ----------
    uv : ndarray of shape (S, N, 2)
    P : ndarray of shape (S, N, 3)
        Points minus their weighted centroid.
    ws : ndarray of shape (S, N)
        Square roots of the weights.
    R : ndarray of shape (S, 3, 3)
    c : ndarray of shape (S, 3)
    log_f : ndarray of shape (S,)
    floor : ndarray of shape (S,)
        Cost below which a problem counts as fitted exactly.

    Returns
    -------
    cost : ndarray of shape (S,)
    iterations : ndarray of shape (S,) of int64
    """
    S, N = ws.shape
    cost = np.empty(S)
    iterations = np.zeros(S, np.int64)
    r = np.empty(2 * N)
    J = np.empty((2 * N, 7))
    r_new = np.empty(2 * N)
    J_new = np.empty((2 * N, 7))
    JtJ = np.empty((7, 7))
    A = np.empty((7, 7))
    g = np.empty(7)
    delta = np.empty(7)
    dR = np.empty((3, 3))
    R_new = np.empty((3, 3))
    c_new = np.empty(3)
    for s in range(S):
        cost_s = _residuals(uv[s], P[s], ws[s], R[s], c[s], log_f[s], r, J)
        if not c[s, 2] > MIN_DEPTH_MM:
            cost_s = np.inf
        lam, nu = initial_lambda, 2.0
        active = np.isfinite(cost_s) and cost_s > floor[s]
        it = 0
        while active and it < max_iterations:
            it += 1
            _normal_equations(J, r, 2 * N, JtJ, g)
            worst = 0.0
            for i in range(7):
                worst = max(worst, abs(g[i]) / np.sqrt(max(JtJ[i, i], 1e-300)))
            small_gradient = worst <= gradient_tol * np.sqrt(cost_s)
            for i in range(7):
                for j in range(7):
                    A[i, j] = JtJ[i, j]
                A[i, i] += lam * (JtJ[i, i] + 1e-12)
            solved = _solve7(A, g, delta)
            if not solved:
                for i in range(7):
                    delta[i] = np.nan
            gd, dJd = 0.0, 0.0
            for i in range(7):
                gd += g[i] * delta[i]
                for j in range(7):
                    dJd += delta[i] * JtJ[i, j] * delta[j]
            predicted = -2.0 * gd - dJd
            logf_new = _apply_step(R[s], c[s], log_f[s], delta, dR, R_new, c_new)
            cost_new = _residuals(uv[s], P[s], ws[s], R_new, c_new, logf_new, r_new, J_new)
            better = cost_new < cost_s
            cost_old = cost_s
            gain = cost_old - cost_new if better else 0.0
            if better:
                R[s] = R_new
                c[s] = c_new
                log_f[s] = logf_new
                r[:] = r_new
                J[:, :] = J_new
                cost_s = cost_new
            rho = gain / max(predicted, 1e-300)
            shrink = max(1.0 / 3.0, 1.0 - (2.0 * min(rho, 1.0) - 1.0) ** 3)
            lam = max(lam * shrink if better else lam * nu, 1e-12)
            nu = 2.0 if better else nu * 2.0
            done = (
                (better and gain <= cost_tol * cost_old)
                or (not better and predicted <= cost_tol * cost_old)
                or cost_s <= floor[s]
                or small_gradient
                or lam > max_lambda
                or log_f[s] > log_f_stop
            )
            if done:
                active = False
        cost[s] = cost_s
        iterations[s] = it
    return cost, iterations


@njit
def sq_errors_kernel(uv, P, R, t, f):
    """Squared reprojection errors ``(S, N)`` of :func:`lilium.pose.residuals` (compiled).

    The compiled pinhole (:func:`lilium.geometry._projection_kernels.pinhole`; numpy's path
    multiplies matrices: the same to rounding); ``inf`` where a point is at or behind the
    camera or the error is NaN.

    Parameters
    ----------
    uv : ndarray of shape (S, N, 2)
        Observed points minus the principal point (pixels).
    P : ndarray of shape (S, N, 3)
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
    f : ndarray of shape (S,)
    """
    S, N = P.shape[0], P.shape[1]
    out = np.empty((S, N))
    for s in range(S):
        for n in range(N):
            u, v = pinhole(P[s, n, 0], P[s, n, 1], P[s, n, 2], R[s], t[s], f[s], 0.0, 0.0)
            du = u - uv[s, n, 0]  # NaN behind the camera: inf below
            dv = v - uv[s, n, 1]
            sq = du * du + dv * dv
            out[s, n] = np.inf if np.isnan(sq) else sq
    return out


@njit
def refine_kernel(
    uv,
    P,
    w,
    R,
    t,
    focal,
    min_rms_px,
    max_iterations,
    initial_lambda,
    cost_tol,
    gradient_tol,
    max_lambda,
    log_f_stop,
):
    """The whole of :func:`lilium.pose.refine.refine_batch`: ``R``, ``t``, ``focal`` in place.

    Centres each problem on the weighted centroid ``m`` of its used points (``c = R m + t``),
    runs :func:`lm_kernel` and returns to ``t = c - R m``, with the squared errors of the
    refined cameras (:func:`sq_errors_kernel`).

    Parameters
    ----------
    uv : ndarray of shape (S, N, 2)
    P : ndarray of shape (S, N, 3)
    w : ndarray of shape (S, N)
        Weights (0 = unused).
    R : ndarray of shape (S, 3, 3)
    t : ndarray of shape (S, 3)
    focal : ndarray of shape (S,)

    Returns
    -------
    cost : ndarray of shape (S,)
    iterations : ndarray of shape (S,) of int64
    sq_err_px2 : ndarray of shape (S, N)
    """
    S, N = w.shape
    ws = np.sqrt(w)
    m = np.zeros((S, 3))
    Pm = np.empty((S, N, 3))
    c = np.empty((S, 3))
    floor = np.empty(S)
    log_f = np.log(focal)
    for s in range(S):
        w_sum = 0.0
        used = 0
        for n in range(N):
            w_sum += w[s, n]
            used += ws[s, n] != 0.0
            for j in range(3):
                m[s, j] += w[s, n] * P[s, n, j]
        floor[s] = min_rms_px**2 * 2.0 * used
        for j in range(3):
            m[s, j] /= w_sum if w_sum > 0 else 1.0
        for n in range(N):
            for j in range(3):
                Pm[s, n, j] = P[s, n, j] - m[s, j]
        for i in range(3):
            c[s, i] = R[s, i, 0] * m[s, 0] + R[s, i, 1] * m[s, 1] + R[s, i, 2] * m[s, 2] + t[s, i]
    cost, iterations = lm_kernel(
        uv,
        Pm,
        ws,
        R,
        c,
        log_f,
        floor,
        max_iterations,
        initial_lambda,
        cost_tol,
        gradient_tol,
        max_lambda,
        log_f_stop,
    )
    for s in range(S):
        for i in range(3):
            t[s, i] = c[s, i] - (R[s, i, 0] * m[s, 0] + R[s, i, 1] * m[s, 1] + R[s, i, 2] * m[s, 2])
        focal[s] = np.exp(log_f[s])
    return cost, iterations, sq_errors_kernel(uv, P, R, t, focal)
