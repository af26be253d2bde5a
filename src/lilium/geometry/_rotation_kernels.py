"""Compiled rotation helper (numba, see :mod:`lilium.jit`): the geodesic angle between two
rotations, :func:`lilium.geometry.rotations.geodesic_angle_deg` written out element by element
(the same operations, so the same rounding), with the rotation's axis for derivatives."""

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
