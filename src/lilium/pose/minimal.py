"""P4Pf minimal solver: pose and focal length from four 2D-3D correspondences.

Wraps PoseLib's ``p4pf`` (Larsson et al., a kept, fast implementation of the Bujnak-Kukelova-Pajdla
P4Pf problem). Convention as everywhere in Lilium: ``X_cam = R X + t``,
``uv - principal_point = focal * X_cam[:2] / X_cam[2]``.
"""

import numpy as np
import poselib

_NONE = (np.empty((0, 3, 3)), np.empty((0, 3)), np.empty(0))


def p4pf(uv_centred_px, points_mm):
    """All real solutions of the P4Pf problem.

    Parameters
    ----------
    uv_centred_px : ndarray of shape (4, 2)
        Image points minus the principal point (pixels).
    points_mm : ndarray of shape (4, 3)
        The matching 3D points.

    Returns
    -------
    R : ndarray of shape (K, 3, 3)
    t : ndarray of shape (K, 3)
    focal_px : ndarray of shape (K,)
        ``K >= 0`` candidate cameras with positive focal length.
    """
    poses, focals = poselib.p4pf(
        np.ascontiguousarray(uv_centred_px, dtype=float),
        np.ascontiguousarray(points_mm, dtype=float),
        True,
    )
    keep = [i for i, f in enumerate(focals) if 0 < f < np.inf]
    if not keep:
        return _NONE
    R = np.array([poses[i].R for i in keep])
    t = np.array([poses[i].t for i in keep])
    return R, t, np.array([focals[i] for i in keep])
