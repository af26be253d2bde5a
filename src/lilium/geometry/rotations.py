"""Batched rotations: rotation vectors, matrices and the geodesic angle.

All functions accept leading batch axes: rotation vectors ``(..., 3)``, matrices ``(..., 3, 3)``.
"""

import numpy as np

from ..validation import is_numeric

_SMALL_ANGLE = 1e-8


def rotvec_to_matrix(rotvec):
    """Rodrigues' formula.

    Parameters
    ----------
    rotvec : array_like of shape (..., 3)
        Axis times angle (radians).

    Returns
    -------
    R : ndarray of shape (..., 3, 3)
    """
    rotvec = np.asarray(rotvec, dtype=float)
    theta_sq = np.einsum("...i,...i->...", rotvec, rotvec)
    theta = np.sqrt(theta_sq)
    small = theta < _SMALL_ANGLE
    safe = np.where(small, 1.0, theta)
    # R = I + a [v]x + b v v^T - b theta^2 I, with a = sin(theta)/theta, b = (1 - cos)/theta^2.
    a = np.where(small, 1.0 - theta_sq / 6.0, np.sin(safe) / safe)
    b = np.where(small, 0.5 - theta_sq / 24.0, (1.0 - np.cos(safe)) / safe**2)
    R = (b[..., None, None] * rotvec[..., :, None]) * rotvec[..., None, :]
    diag = 1.0 - b * theta_sq
    x, y, z = a * rotvec[..., 0], a * rotvec[..., 1], a * rotvec[..., 2]
    R[..., 0, 0] += diag
    R[..., 1, 1] += diag
    R[..., 2, 2] += diag
    R[..., 0, 1] -= z
    R[..., 1, 0] += z
    R[..., 0, 2] += y
    R[..., 2, 0] -= y
    R[..., 1, 2] -= x
    R[..., 2, 1] += x
    return R


def matrix_to_rotvec(R):
    """Inverse of :func:`rotvec_to_matrix` (angle in [0, pi]).

    Parameters
    ----------
    R : array_like of shape (..., 3, 3)

    Returns
    -------
    rotvec : ndarray of shape (..., 3)
    """
    R = np.asarray(R, dtype=float)
    q = _matrix_to_quaternion(R.reshape(-1, 3, 3))  # (N, 4): x, y, z, w with w >= 0
    sin_half = np.linalg.norm(q[:, :3], axis=1)
    angle = 2.0 * np.arctan2(sin_half, q[:, 3])
    small = angle < 1e-3  # angle / sin(angle / 2) by its series near 0
    scale = np.where(small, 2.0 + angle**2 / 12.0, angle / np.where(small, 1.0, sin_half))
    return (q[:, :3] * scale[:, None]).reshape(R.shape[:-2] + (3,))


def _matrix_to_quaternion(R):
    """Unit quaternions ``(x, y, z, w)``, ``w >= 0``, of rotation matrices (N, 3, 3): from the
    largest of ``w`` and the diagonal (Shepperd's method, as scipy's ``Rotation.from_matrix``;
    scipy.spatial costs a command 0.17 s to import)."""
    trace = R[:, 0, 0] + R[:, 1, 1] + R[:, 2, 2]
    choice = np.argmax(np.column_stack([R[:, 0, 0], R[:, 1, 1], R[:, 2, 2], trace]), axis=1)
    q = np.empty((len(R), 4))
    for i in range(3):
        rows = np.flatnonzero(choice == i)
        j, k = (i + 1) % 3, (i + 2) % 3
        r = R[rows]
        q[rows, i] = 1.0 - trace[rows] + 2.0 * r[:, i, i]
        q[rows, j] = r[:, j, i] + r[:, i, j]
        q[rows, k] = r[:, k, i] + r[:, i, k]
        q[rows, 3] = r[:, k, j] - r[:, j, k]
    rows = np.flatnonzero(choice == 3)
    r = R[rows]
    q[rows, 0] = r[:, 2, 1] - r[:, 1, 2]
    q[rows, 1] = r[:, 0, 2] - r[:, 2, 0]
    q[rows, 2] = r[:, 1, 0] - r[:, 0, 1]
    q[rows, 3] = 1.0 + trace[rows]
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return np.where(q[:, 3:] < 0, -q, q)


def matrix_to_euler_xyz_deg(R):
    """Extrinsic x-y-z Euler angles (degrees) of a rotation matrix (3, 3): ``R = Rz(c) Ry(b)
    Rx(a)``, ``b`` in [-90, 90] (scipy's ``as_euler("xyz")``; at ``b = +-90`` degrees, where
    only ``a -+ c`` is defined, ``c = 0``).

    Returns
    -------
    ndarray of shape (3,)
        ``(a, b, c)``.
    """
    R = np.asarray(R, dtype=float)
    b = np.arcsin(np.clip(-R[2, 0], -1.0, 1.0))
    if abs(R[2, 0]) < 1.0 - 1e-12:
        a = np.arctan2(R[2, 1], R[2, 2])
        c = np.arctan2(R[1, 0], R[0, 0])
    else:  # gimbal lock
        a = np.arctan2(-np.sign(R[2, 0]) * R[0, 1], R[1, 1])
        c = 0.0
    return np.degrees([a, b, c])


def geodesic_angle_deg(R_a, R_b):
    """Angle (degrees) of the rotation taking ``R_b`` to ``R_a``: ``angle(R_a @ R_b.T)``.

    Parameters
    ----------
    R_a, R_b : array_like of shape (..., 3, 3)

    Returns
    -------
    angle_deg : ndarray of shape (...)
        In [0, 180].
    """
    R_a = np.asarray(R_a, dtype=float)
    R_b = np.asarray(R_b, dtype=float)
    Q = R_a @ np.swapaxes(R_b, -1, -2)
    # atan2(sin, cos) keeps full precision near 0 and 180 degrees, unlike arccos(cos).
    cos = (Q[..., 0, 0] + Q[..., 1, 1] + Q[..., 2, 2] - 1.0) / 2.0
    x, y, z = Q[..., 2, 1] - Q[..., 1, 2], Q[..., 0, 2] - Q[..., 2, 0], Q[..., 1, 0] - Q[..., 0, 1]
    sin = np.sqrt(x * x + y * y + z * z) / 2.0
    return np.degrees(np.arctan2(sin, cos))


def check_rotation(R, name="rotation", tol=1e-6):
    """Validate a 3x3 rotation matrix and return it as a float array.

    Raises
    ------
    ValueError
        If ``R`` is not a finite, orthonormal, right-handed 3x3 matrix.
    """
    if not is_numeric(R):
        raise ValueError(f"{name} must be a 3x3 matrix of numbers (not true/false or text)")
    R = np.asarray(R, dtype=float)
    if R.shape != (3, 3):
        raise ValueError(f"{name} must be a 3x3 matrix, got shape {R.shape}")
    if not np.all(np.isfinite(R)):
        raise ValueError(f"{name} contains NaN or infinite values")
    if np.abs(R @ R.T - np.eye(3)).max() > tol or np.linalg.det(R) < 0:
        raise ValueError(
            f"{name} is not a rotation (orthonormal with determinant +1); "
            "give the 3x3 rotation part of a rigid transform"
        )
    return R
