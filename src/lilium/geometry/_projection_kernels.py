"""The compiled pinhole: :func:`pinhole`, the one formula of every compiled projection (the
projection of :func:`lilium.geometry.camera.project_points`, P_skof's outside count, the
reprojection errors of the camera refinement), numba, see :mod:`lilium.jit`.

Written out element by element (``X = R[0, 0] x + R[0, 1] y + R[0, 2] z + t[0]``, ...,
``u = X * (f / Z) + c``), as :func:`lilium.fitness._skof_kernels.project_vertices` writes it
in numpy; numpy's ``project_points`` multiplies matrices, so the two agree to rounding (about
1e-13 relative).
"""

import numpy as np

from ..constants import MIN_DEPTH_MM
from ..jit import njit


@njit(inline="always")
def pinhole(x, y, z, R, t, f, c0, c1):
    """``(u, v)`` of the skull-frame point ``(x, y, z)`` under one camera; NaN at depth <=
    ``MIN_DEPTH_MM`` (the formula of every compiled projection of the package; inlined)."""
    X0 = R[0, 0] * x + R[0, 1] * y + R[0, 2] * z + t[0]
    X1 = R[1, 0] * x + R[1, 1] * y + R[1, 2] * z + t[1]
    X2 = R[2, 0] * x + R[2, 1] * y + R[2, 2] * z + t[2]
    if X2 <= MIN_DEPTH_MM:
        return np.nan, np.nan
    scale = f / X2
    return X0 * scale + c0, X1 * scale + c1


@njit
def project_kernel(P, R, t, f, c0, c1):
    """Pixel coordinates ``(S, N, 2)`` of points ``P`` ``(S, N, 3)``, set ``s`` under camera
    ``s`` (one set shared by all cameras: a broadcast view, stride 0 along S)."""
    S, N = P.shape[0], P.shape[1]
    uv = np.empty((S, N, 2))
    for s in range(S):
        for n in range(N):
            u, v = pinhole(P[s, n, 0], P[s, n, 1], P[s, n, 2], R[s], t[s], f[s], c0, c1)
            uv[s, n, 0] = u
            uv[s, n, 1] = v
    return uv
