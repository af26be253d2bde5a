"""Real-size SFO inputs for the speed benchmark: a skull at a chosen face count, a photo at a
chosen resolution (issue 26).

Both keep the case's geometry: the skull is the same surface (quadric-decimated to a quarter,
sixteenth, ... of the target, then midpoint-subdivided back up: every new vertex lies on the
decimated surface, so silhouettes and regions stay where they were), the photo the same scene
(image and mask resampled, landmarks, facial curve and focal prior scaled with pixel centres at
integer coordinates: ``u' = (u + 1/2) s - 1/2``).
"""

from dataclasses import replace

import cv2
import numpy as np
import trimesh

from lilium.fitness.camera_penalty import CameraPriors
from lilium.geometry.mesh import decimate


def skull_at(skull, n_faces):
    """``skull`` with about ``n_faces`` faces (decimated, then subdivided 1 -> 4 as needed).

    Parameters
    ----------
    skull : Skull
    n_faces : int
        Target face count; the result has ``base * 4**k`` faces with ``base`` about
        ``n_faces / 4**k`` and no more than the skull's own count.
    """
    k = 0
    while n_faces / 4**k > len(skull.faces):
        k += 1
    vertices, faces = decimate(skull.vertices_mm, skull.faces, max(4, round(n_faces / 4**k)))
    for _ in range(k):
        vertices, faces = trimesh.remesh.subdivide(vertices, faces)
    return replace(
        skull,
        vertices_mm=np.ascontiguousarray(vertices, float),
        faces=np.ascontiguousarray(faces, np.int64),
    )


def _scale_uv(uv, s):
    return (np.asarray(uv, float) + 0.5) * s - 0.5


def photo_at(photo, megapixels):
    """``photo`` resampled to about ``megapixels`` million pixels (same aspect ratio).

    Image: area/linear interpolation; mask: nearest; landmarks and facial curve scaled
    (:func:`_scale_uv`); the focal prior scaled; the SCD and head priors unchanged.
    """
    width, height = photo.image_size_wh
    s = np.sqrt(megapixels * 1e6 / (width * height))
    size_wh = (round(width * s), round(height * s))
    s = size_wh[0] / width
    image = photo.image
    if image is not None:
        interpolation = cv2.INTER_AREA if s < 1 else cv2.INTER_LINEAR
        image = cv2.resize(image, size_wh, interpolation=interpolation)
    mask = photo.face_mask
    if mask is not None:
        mask = cv2.resize(mask.astype(np.uint8), size_wh, interpolation=cv2.INTER_NEAREST) > 0
    curve = None if photo.face_curve_uv is None else _scale_uv(photo.face_curve_uv, s)
    priors = photo.priors
    if priors.focal_px is not None:
        priors = CameraPriors(
            focal_px=tuple(s * np.asarray(priors.focal_px)),
            scd_mm=priors.scd_mm,
            head_rotation_skull2cam=priors.head_rotation_skull2cam,
            head_tolerance_deg=priors.head_tolerance_deg,
        )
    return replace(
        photo,
        id=f"{photo.id}@{megapixels:g}MP",
        image_size_wh=size_wh,
        landmarks_uv={k: _scale_uv(v, s) for k, v in photo.landmarks_uv.items()},
        face_mask=mask,
        face_curve_uv=curve,
        priors=priors,
        image=image,
    )
