"""Compiled pinhole projection of :func:`lilium.geometry.camera.project_points` (numba, see
:mod:`lilium.jit`).

The projection written out element by element (``X = R[0, 0] x + R[0, 1] y + R[0, 2] z + t[0]``,
..., ``u = X * (f / Z) + c``), as :func:`lilium.fitness._skof_kernels.project_vertices` writes
it; numpy's path multiplies matrices, so the two agree to rounding (about 1e-13 relative).
"""

import numpy as np

from ..constants import MIN_DEPTH_MM
from ..jit import njit


@njit
def _project_one(x, y, z, R, t, f, c0, c1, out):
    X0 = R[0, 0] * x + R[0, 1] * y + R[0, 2] * z + t[0]
    X1 = R[1, 0] * x + R[1, 1] * y + R[1, 2] * z + t[1]
    X2 = R[2, 0] * x + R[2, 1] * y + R[2, 2] * z + t[2]
    if X2 <= MIN_DEPTH_MM:
        out[0] = np.nan
        out[1] = np.nan
    else:
        scale = f / X2
        out[0] = X0 * scale + c0
        out[1] = X1 * scale + c1


@njit
def project_kernel(P, R, t, f, c0, c1):
    """Pixel coordinates ``(S, N, 2)`` of points ``P`` ``(S, N, 3)``, set ``s`` under camera
    ``s`` (one set shared by all cameras: a broadcast view, stride 0 along S)."""
    S, N = P.shape[0], P.shape[1]
    uv = np.empty((S, N, 2))
    for s in range(S):
        for n in range(N):
            _project_one(P[s, n, 0], P[s, n, 1], P[s, n, 2], R[s], t[s], f[s], c0, c1, uv[s, n])
    return uv
