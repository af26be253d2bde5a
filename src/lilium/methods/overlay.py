"""The overlay picture of an SFO result (glue between methods and imaging)."""

import numpy as np

from ..geometry.camera import project
from ..imaging.overlay import draw_overlay


def result_overlay(result, skull, photo, opacity=0.55, curves=None):
    """Overlay of a successful SFO: photo, projected skull, facial and estimated landmarks.

    Returns
    -------
    ndarray of shape (H, W, 3), uint8, or the plain photo if the SFO failed.
    """
    if photo.image is None:
        raise ValueError(f"photo {photo.id!r} was read without its image; read it with pixels")
    if not result:
        return photo.image.copy()
    names = list(result.facial_landmarks_mm)
    est3d = np.array([result.facial_landmarks_mm[n] for n in names])
    est_uv = project(est3d, result.skull2cam, result.focal_px, result.principal_point_px)
    photo_uv = np.array([photo.landmarks_uv[n] for n in names])
    return draw_overlay(
        photo.image,
        skull.vertices_mm,
        skull.faces,
        result.skull2cam,
        result.focal_px,
        result.principal_point_px,
        photo_landmarks_uv=photo_uv,
        estimated_uv=est_uv,
        opacity=opacity,
        curves=curves,
    )
