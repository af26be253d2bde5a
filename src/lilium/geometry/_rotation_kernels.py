"""Compiled rotation helpers (numba, see :mod:`lilium.jit`): Rodrigues' formula and the geodesic
angle between two rotations, :func:`lilium.geometry.rotations.rotvec_to_matrix` and
:func:`~lilium.geometry.rotations.geodesic_angle_deg` written out element by element (the same
operations, so the same rounding), the angle with the rotation's axis for derivatives."""

import numpy as np

from ..jit import njit

#: Degrees per radian (the angle's unit; the prior-aware refinement's derivative too).
DEG_PER_RAD = 180.0 / np.pi


@njit(inline="always")
def relative_angle_axis(R, P):
    """Angle (degrees) of the rotation ``Q = R @ P.T`` taking ``P`` to ``R``, and its axis.

    Parameters
    ----------
    R, P : ndarray of shape (3, 3)

    Returns
    -------
    angle_deg : float
        In [0, 180].
    x, y, z : float
        ``(Q[2, 1] - Q[1, 2], Q[0, 2] - Q[2, 0], Q[1, 0] - Q[0, 1])``: the axis times
        ``2 sin(angle)``.
    norm : float
        Its length, ``2 sin(angle)``.
    """
    Q = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            Q[i, j] = R[i, 0] * P[j, 0] + R[i, 1] * P[j, 1] + R[i, 2] * P[j, 2]
    cos = (Q[0, 0] + Q[1, 1] + Q[2, 2] - 1.0) / 2.0
    x, y, z = Q[2, 1] - Q[1, 2], Q[0, 2] - Q[2, 0], Q[1, 0] - Q[0, 1]
    norm = np.sqrt(x * x + y * y + z * z)
    return np.arctan2(norm / 2.0, cos) * DEG_PER_RAD, x, y, z, norm


#: Below this angle (radians) Rodrigues' coefficients are their Taylor series (as
#: :mod:`lilium.geometry.rotations`).
_SMALL_ANGLE = 1e-8


@njit
def rotvec_to_matrix_kernel(w0, w1, w2, out):
    """Rodrigues' formula into ``out`` (3, 3), as :func:`lilium.geometry.rotations.rotvec_to_matrix`
    writes it (the same operations)."""
    theta_sq = w0 * w0 + w1 * w1 + w2 * w2
    theta = np.sqrt(theta_sq)
    if theta < _SMALL_ANGLE:
        a = 1.0 - theta_sq / 6.0
        b = 0.5 - theta_sq / 24.0
    else:
        a = np.sin(theta) / theta
        b = (1.0 - np.cos(theta)) / (theta * theta)
    w = (w0, w1, w2)
    for i in range(3):
        for j in range(3):
            out[i, j] = (b * w[i]) * w[j]
    diag = 1.0 - b * theta_sq
    x, y, z = a * w0, a * w1, a * w2
    out[0, 0] += diag
    out[1, 1] += diag
    out[2, 2] += diag
    out[0, 1] -= z
    out[1, 0] += z
    out[0, 2] += y
    out[2, 0] -= y
    out[1, 2] -= x
    out[2, 1] += x
