"""The overlay picture of an SFO result (glue between methods and imaging)."""

import numpy as np

from ..imaging.overlay import draw_overlay

#: Colours (RGB) of the skull's and the face's chin-jaw / forehead curves.
SKULL_CURVE_RGB = (255, 220, 0)
FACE_CURVE_RGB = (60, 255, 60)


def region_curves(result, skull, photo):
    """The skull's and the face's chin-jaw (frontal) or forehead (lateral) curves under the
    result's camera, as drawn by the overlay; ``[]`` when the skull lacks the landmarks that
    cut the region or the photo has neither a face curve nor a mask."""
    from .lilium_terms import PllTerm

    try:
        term = PllTerm(skull, photo, result.camera.principal_point_px)
    except ValueError:
        return []
    skull_curve, face_curve = term.curves(result.camera)
    return [(face_curve, FACE_CURVE_RGB), (skull_curve, SKULL_CURVE_RGB)]


def result_overlay(result, skull, photo, opacity=0.55, curves=None):
    """Overlay of a successful SFO: photo, projected skull with its outline, the skull and face
    curves of the P_pll region, facial and estimated landmarks.

    ``curves`` defaults to :func:`region_curves` (drawn for every method, so POSEST-SFO and
    Lilium overlays compare alike).

    Returns
    -------
    ndarray of shape (H, W, 3), uint8, or the plain photo if the SFO failed.
    """
    if photo.image is None:
        raise ValueError(f"photo {photo.id!r} was read without its image; read it with pixels")
    if not result:
        return photo.image.copy()
    if curves is None:
        curves = region_curves(result, skull, photo)
    names = list(result.facial_landmarks_mm)
    est3d = np.array([result.facial_landmarks_mm[n] for n in names])
    est_uv = result.camera.project(est3d)
    photo_uv = np.array([photo.landmarks_uv[n] for n in names])
    return draw_overlay(
        photo.image,
        skull.vertices_mm,
        skull.faces,
        result.camera,
        photo_landmarks_uv=photo_uv,
        estimated_uv=est_uv,
        opacity=opacity,
        curves=curves,
    )
