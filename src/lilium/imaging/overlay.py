"""Overlay pictures: the skull projected over the photo, with landmarks.

Pure functions returning ``(H, W, 3)`` uint8 RGB arrays; writing them is :mod:`lilium.io`'s job.
"""

import cv2
import numpy as np

from ._paint_kernels import nearest_face_index
from .raster import covered_box, skull_raster

#: Colours (RGB).
SKULL_RGB = np.array([235, 225, 190], dtype=float)
PHOTO_LANDMARK_RGB = (0, 200, 255)
ESTIMATE_RGB = (255, 40, 40)
OUTLINE_RGB = (255, 170, 0)
LIGHT_DIR_CAM = np.array([-0.3, -0.4, -1.0]) / np.linalg.norm([-0.3, -0.4, -1.0])

#: Pixels blended per block: the blend's float64 temporaries (about 120 bytes a pixel) stay near
#: 30 MB whatever the photo's size (the whole-image blend of a 12 MP photo took about 1.2 GB).
BLEND_BLOCK_PIXELS = 1 << 18


def render_mesh_shaded(vertices_mm, faces, camera, image_size_wh, *, topology=None):
    """Lambert-shaded render of a mesh: the exact silhouette, shaded by a depth buffer.

    The silhouette ``covered`` is the one mesh raster (:func:`lilium.imaging.raster.mesh_mask`,
    the exact union of the projected triangles, the ``S`` of P_skof); inside it each pixel shows
    the intensity of the nearest triangle at its centre
    (:func:`lilium.imaging._paint_kernels.nearest_face_index`).

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    camera : Camera
    image_size_wh : tuple (width, height)
    topology : EdgeTopology, optional
        ``mesh_edge_topology(faces)``, to skip recomputing it.

    Returns
    -------
    shade : ndarray of shape (H, W), float32
        Shading in [0, 1] where ``covered``, 0 elsewhere.
    covered : ndarray of shape (H, W), bool
        The union of the projected triangles (exact raster).
    """
    width, height = (int(s) for s in image_size_wh)
    faces = np.asarray(faces, dtype=np.int64)
    uv = camera.project(vertices_mm)
    covered = skull_raster(uv, faces, (height, width), topology=topology)
    X = camera.to_camera_frame(vertices_mm)
    # The nearest triangle at each pixel centre (a compiled depth buffer; depth = the mean of
    # the corners' depths).
    index = nearest_face_index(
        uv, faces, X[faces, 2].mean(axis=1), (height, width), covered=covered
    )
    shade = np.zeros((height, width), np.float32)
    box = covered_box(covered)
    if box is None:
        return shade, covered
    index = index[box]  # the per-pixel steps inside the skull's bounding box only
    # Lambert intensity of the triangles seen (the others are never looked up).
    marked = np.zeros(len(faces) + 1, bool)
    marked[index] = True  # -1 (no triangle) marks the extra last slot
    seen = np.flatnonzero(marked[:-1])  # as np.unique(index[index >= 0]), without the sort
    tri = X[faces[seen]]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    intensity = np.zeros(len(faces), np.float32)
    # Two-sided lighting: a skull mesh may be wound either way.
    intensity[seen] = (0.25 + 0.75 * np.abs(normal @ LIGHT_DIR_CAM)).astype(np.float32)
    shade[box] = np.where((index >= 0) & covered[box], intensity[index], np.float32(0.0))
    return shade, covered


def as_uint8_rgb(image):
    """An ``(H, W, 3)`` uint8 copy of ``image`` (uint8, or uint16 scaled by 255 / 65535)."""
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"image must be of shape (H, W, 3), got {image.shape}")
    if image.dtype == np.uint16:
        return (image // 257).astype(np.uint8)
    if image.dtype != np.uint8:
        raise ValueError(f"image must be uint8 or uint16 RGB, got {image.dtype}")
    return image.copy()


def blend_skull(image, shade, covered, opacity):
    """The photo with the shaded skull blended in at ``opacity``, block by block.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 or uint16
    shade : ndarray of shape (H, W), float
        Skull shading in [0, 1] (:func:`render_mesh_shaded`).
    covered : ndarray of shape (H, W), bool
    opacity : float

    Returns
    -------
    ndarray of shape (H, W, 3), uint8
        ``(1 - a) * photo + a * shade * SKULL_RGB`` with ``a = opacity`` on the skull, the photo
        elsewhere; computed in float64 over blocks of rows (:data:`BLEND_BLOCK_PIXELS`).
    """
    out = as_uint8_rgb(image)
    box = covered_box(covered)
    if box is None:
        return out
    rows, cols = box
    step = max(1, BLEND_BLOCK_PIXELS // max(1, cols.stop - cols.start))
    for r0 in range(rows.start, rows.stop, step):
        block = slice(r0, min(r0 + step, rows.stop)), cols
        alpha = opacity * covered[block][..., None]
        blend = (1 - alpha) * out[block] + alpha * (shade[block][..., None] * SKULL_RGB)
        out[block] = np.clip(blend, 0, 255).astype(np.uint8)
    return out


def draw_overlay(
    image,
    skull_vertices_mm,
    skull_faces,
    camera,
    photo_landmarks_uv=None,
    estimated_uv=None,
    opacity=0.55,
    curves=None,
    *,
    topology=None,
):
    """The photo with the projected skull drawn semi-transparent over it and landmarks marked.

    Parameters
    ----------
    image : ndarray of shape (H, W, 3), uint8 (or uint16, scaled by 255 / 65535)
    skull_vertices_mm : ndarray of shape (V, 3)
    skull_faces : ndarray of shape (F, 3)
    camera : Camera
    photo_landmarks_uv : ndarray of shape (N, 2), optional
        Facial landmarks marked in the photo, drawn as circles.
    estimated_uv : ndarray of shape (N, 2), optional
        Projections of the estimated 3D facial landmarks (same order), drawn as dots joined to
        their circles.
    opacity : float
        Skull opacity in [0, 1].
    curves : list of (ndarray of shape (K, 2), RGB tuple), optional
        Polylines to draw (e.g. skull and face chin-jaw curves).
    topology : EdgeTopology, optional
        ``mesh_edge_topology(skull_faces)``, to skip recomputing it.

    Returns
    -------
    ndarray of shape (H, W, 3), uint8
        Memory: the output, the shading (float32) and the raster, plus blocks of
        :data:`BLEND_BLOCK_PIXELS` pixels for the blend.
    """
    height, width = image.shape[:2]
    shade, covered = render_mesh_shaded(
        skull_vertices_mm, skull_faces, camera, (width, height), topology=topology
    )
    out = blend_skull(image, shade, covered, opacity)
    del shade
    scale = max(1, round(max(width, height) / 800))
    # The skull's silhouette (the exact raster, P_skof's S), to judge against the face's.
    contours, _ = cv2.findContours(
        covered.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )
    cv2.drawContours(out, contours, -1, OUTLINE_RGB, scale, cv2.LINE_AA)
    for curve, colour in curves or []:
        pts = np.round(np.asarray(curve)).astype(np.int32).reshape(-1, 1, 2)
        cv2.polylines(out, [pts], False, colour, scale, cv2.LINE_AA)
    if photo_landmarks_uv is not None:
        for k, (u, v) in enumerate(np.asarray(photo_landmarks_uv)):
            centre = (round(u), round(v))
            if estimated_uv is not None and np.all(np.isfinite(estimated_uv[k])):
                end = tuple(int(round(x)) for x in estimated_uv[k])
                cv2.line(out, centre, end, ESTIMATE_RGB, scale, cv2.LINE_AA)
            cv2.circle(out, centre, 5 * scale, PHOTO_LANDMARK_RGB, scale, cv2.LINE_AA)
    if estimated_uv is not None:
        for u, v in np.asarray(estimated_uv):
            if np.isfinite(u) and np.isfinite(v):
                cv2.circle(out, (round(u), round(v)), 2 * scale, ESTIMATE_RGB, -1, cv2.LINE_AA)
    return out
