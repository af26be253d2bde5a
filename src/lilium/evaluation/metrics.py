"""Scores of the paper's evaluation protocol (docs/method/evaluation.md), as pure functions.

- :func:`back_projection_error` (BPE, mm): for every ground-truth facial landmark ``F_i`` (visible
  or not), the distance from ``F_i`` to the ray that the *estimated* camera back-projects through
  the landmark's noise-free ground-truth image point; mean over the landmarks. The ground-truth
  camera scores 0.
- :func:`rank_of_true`: rank of the true skull among the scores of one photo against every skull
  (1 = best, ties share the mean rank).
- :func:`implausible_sfo`: skull pixels outside the face mask, from a skull raster;
  :func:`outside_face` the same for an SFO's camera and skull mesh (the one count every caller
  uses: the experiment runner, the report, the contact sheet), rasterised by
  :func:`lilium.imaging.raster.mesh_mask`, the ``S`` of P_skof.
"""

from dataclasses import dataclass

import numpy as np

from ..geometry.camera import point_ray_distance
from ..imaging.raster import mesh_mask


def back_projection_errors(facial_points_mm, uv_true, camera):
    """Per-landmark back-projection errors (mm).

    Parameters
    ----------
    facial_points_mm : array_like of shape (N, 3)
        Ground-truth 3D facial landmarks ``F_i`` (skull frame).
    uv_true : array_like of shape (N, 2)
        Their noise-free ground-truth image points (pixels).
    camera : Camera
        The *estimated* camera.

    Returns
    -------
    errors_mm : ndarray of shape (N,)
    """
    points = np.asarray(facial_points_mm, dtype=float).reshape(-1, 3)
    uv = np.asarray(uv_true, dtype=float).reshape(-1, 2)
    if len(points) != len(uv):
        raise ValueError(
            f"facial_points_mm has {len(points)} points but uv_true {len(uv)}; "
            "give one image point per 3D landmark, in the same order"
        )
    if not camera.focal_px > 0:
        raise ValueError(f"focal_px must be positive, got {camera.focal_px}")
    origin, directions = camera.rays(uv)
    return point_ray_distance(points, origin, directions)


def back_projection_error(facial_points_mm, uv_true, camera):
    """BPE (mm): the mean of :func:`back_projection_errors` over all landmarks."""
    errors = back_projection_errors(facial_points_mm, uv_true, camera)
    if len(errors) == 0:
        raise ValueError("no landmarks: BPE needs at least one ground-truth facial landmark")
    return float(np.mean(errors))


def back_projection_error_from_dicts(facial_landmarks_mm, landmarks_noise_free, camera):
    """BPE over the landmark names present in both dicts (``facial_landmarks.json`` and the
    ``ground_truth.landmarks_noise_free`` of ``photo.json``)."""
    names = sorted(set(facial_landmarks_mm) & set(landmarks_noise_free))
    if not names:
        raise ValueError("the 3D facial landmarks and the image points share no landmark name")
    return back_projection_error(
        [facial_landmarks_mm[n] for n in names],
        [landmarks_noise_free[n] for n in names],
        camera,
    )


def rank_of_true(scores, true_index, lower_is_better=True):
    """Rank of the true candidate among ``scores`` (1 = best; ties share the mean rank).

    NaN scores (failed SFOs) count as worse than every finite score.

    Parameters
    ----------
    scores : array_like of shape (K,)
        One score per candidate skull.
    true_index : int
        Index of the true skull in ``scores``.
    lower_is_better : bool
        True for fitness / mean pixel error.

    Returns
    -------
    rank : float
        In ``[1, K]``; e.g. 1.5 when the true skull ties with one other for the best score.

    Examples
    --------
    >>> rank_of_true([3.0, 1.0, 1.0, 5.0], 1)
    1.5
    """
    s = np.asarray(scores, dtype=float).ravel()
    if not 0 <= true_index < len(s):
        raise ValueError(f"true_index {true_index} is outside the {len(s)} scores")
    if not lower_is_better:
        s = -s
    s = np.where(np.isnan(s), np.inf, s)
    target = s[true_index]
    better = np.count_nonzero(s < target)
    tied = np.count_nonzero(s == target)  # includes the true one
    return better + (tied + 1) / 2.0


@dataclass(frozen=True)
class ImplausibleSFO:
    """Skull pixels outside the face mask.

    Attributes
    ----------
    outside_px : int
        ``|S \\ F|``.
    skull_px : int
        ``|S|``.
    percent_outside : float
        ``100 |S \\ F| / |S|`` (0 for an empty skull raster).
    """

    outside_px: int
    skull_px: int
    percent_outside: float

    @property
    def implausible(self):
        """Any skull pixel outside the face mask."""
        return self.outside_px > 0

    @classmethod
    def of(cls, outside_px, skull_px):
        """From the two counts (``percent_outside`` 0 for an empty skull raster)."""
        percent = 100.0 * outside_px / skull_px if skull_px else 0.0
        return cls(int(outside_px), int(skull_px), percent)


def implausible_sfo(skull_mask, face_mask):
    """Count the projected-skull pixels that fall outside the face mask.

    Parameters
    ----------
    skull_mask : array_like of shape (H, W)
        Non-zero where the projected skull covers the pixel (the union of its triangles).
    face_mask : array_like of shape (H, W)
        Non-zero = face/head pixels.

    Returns
    -------
    ImplausibleSFO
    """
    s = np.asarray(skull_mask) != 0
    f = np.asarray(face_mask) != 0
    if s.shape != f.shape:
        raise ValueError(
            f"skull_mask {s.shape} and face_mask {f.shape} differ in shape; rasterise the skull "
            "at the photo's resolution"
        )
    return ImplausibleSFO.of(np.count_nonzero(s & ~f), np.count_nonzero(s))


def outside_depth_px(skull_mask, face_mask):
    """How far outside the face mask each projected-skull pixel outside it lies.

    Parameters
    ----------
    skull_mask, face_mask : array_like of shape (H, W)
        Non-zero = skull / face (head) pixels.

    Returns
    -------
    ndarray of shape (M,)
        For each of the M skull pixels outside the mask, the Euclidean distance (pixels) from
        its centre to the nearest mask pixel's (1 for a pixel touching the mask's edge).
    """
    from scipy import ndimage as ndi

    s = np.asarray(skull_mask) != 0
    f = np.asarray(face_mask) != 0
    outside = s & ~f
    if not outside.any():
        return np.empty(0)
    if not f.any():
        return np.full(int(outside.sum()), np.inf)
    return ndi.distance_transform_edt(~f)[outside]


def outside_face(camera, vertices_mm, faces, face_mask, topology=None):
    """Skull pixels outside the face mask for a camera and a skull mesh (docs/method/evaluation.md).

    The skull is projected by ``camera`` and rasterised at the mask's resolution by the one
    mesh raster (:func:`lilium.imaging.raster.mesh_mask`: the exact union of the projected
    triangles, clipped to the photo), so ``outside_px`` is the ``|S \\ F|`` of P_skof.

    Parameters
    ----------
    camera : Camera
        The SFO's (estimated) camera.
    vertices_mm : array_like of shape (V, 3)
        Skull vertices, skull frame (mm).
    faces : array_like of shape (F, 3), optional if ``topology`` is given
    face_mask : array_like of shape (H, W)
        Non-zero = face/head pixels of the photo, indexed ``[row, column]``.
    topology : EdgeTopology, optional
        ``mesh_edge_topology(faces)``, cached by callers that score many SFOs of one skull.

    Returns
    -------
    ImplausibleSFO
    """
    face_mask = face_mask_2d(face_mask)
    height, width = face_mask.shape
    skull_mask = mesh_mask(vertices_mm, faces, camera, (width, height), topology=topology)
    return implausible_sfo(skull_mask, face_mask)


def face_mask_2d(face_mask):
    """``face_mask`` as an array of shape (H, W); a ``ValueError`` that says so otherwise (a
    colour mask)."""
    face_mask = np.asarray(face_mask)
    if face_mask.ndim != 2:
        raise ValueError(
            f"face_mask must be a 2D (rows, columns) array, got shape {face_mask.shape}; "
            "convert a colour mask to one channel first"
        )
    return face_mask
