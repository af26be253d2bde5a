"""The pictures of one SFO in the report: the photo region, the skull layer, the outside layer.

The report shows a region of the photo (``box``: the skull, the face mask and the landmarks with
a margin, or the whole photo) as stacked pictures of the same size on the page:

- the photo region (JPEG), at most :data:`MAX_REPORT_PX` on its longest side;
- the shaded, outlined skull as an RGBA layer, transparent off the skull (PNG), rendered at
  least :data:`MIN_LAYER_PX` on its longest side (a drawing gains from finer pixels);
- with a face mask, the skull pixels outside it (PNG, same size as the skull layer).

Boxes are ``(u0, v0, u1, v1)`` in photo pixels: columns ``u0 <= u < u1``, rows ``v0 <= v < v1``;
arrays are indexed ``[row, column]``.
"""

import io
from dataclasses import dataclass

import numpy as np

from ..imaging.overlay import SKULL_RGB, render_mesh_shaded

#: Longest side (pixels) of the pictures embedded in the report; larger photos are scaled down.
MAX_REPORT_PX = 2000

#: Margin around skull, mask and landmarks in the pictured region (fraction of its size), and
#: the area fraction above which the whole photo is shown instead.
VIEW_MARGIN = 0.12
FULL_VIEW_FRACTION = 0.6

#: Smallest longest side (pixels) of the skull layer: small regions are rendered finer.
MIN_LAYER_PX = 1400

#: Skull outline drawn on the skull layer (RGB) and its width at report scale (pixels).
OUTLINE_RGB = (255, 214, 0)
OUTLINE_PX = 2

#: Skull pixels outside the face mask (RGBA).
OUTSIDE_RGBA = (255, 0, 200, 170)

#: JPEG quality of the photo picture.
JPEG_QUALITY = 92


@dataclass(frozen=True)
class Pictures:
    """The encoded pictures of one SFO.

    Attributes
    ----------
    box : tuple (u0, v0, u1, v1), int
        The pictured region of the photo.
    photo_jpeg : bytes
        The photo region, JPEG.
    skull_png : bytes or None
        The skull layer (RGBA PNG, transparent off the skull); None when the SFO failed.
    outside_png : bytes or None
        The skull pixels outside the face mask (RGBA PNG, the skull layer's size); None when
        there is no skull layer, no face mask or no skull pixel outside it.
    """

    box: tuple
    photo_jpeg: bytes
    skull_png: bytes | None = None
    outside_png: bytes | None = None


def skull_layer_rgba(result, skull, box, scale=1.0):
    """The shaded, outlined skull as an RGBA picture, transparent off the skull.

    Parameters
    ----------
    result : SfoResult
        Successful.
    skull : Skull
    box : tuple (u0, v0, u1, v1), int
        The region of the photo to picture: columns ``u0 <= u < u1``, rows ``v0 <= v < v1``
        (``(0, 0, W, H)`` for the whole photo).
    scale : float
        Picture pixels per photo pixel (the camera is scaled with it).

    Returns
    -------
    rgba : ndarray of shape (round(scale * (v1 - v0)), round(scale * (u1 - u0)), 4), uint8
    """
    import cv2

    u0, v0, u1, v1 = box
    w, h = max(1, round(scale * (u1 - u0))), max(1, round(scale * (v1 - v0)))
    camera = result.camera.cropped((u0, v0), scale)
    shade, covered = render_mesh_shaded(skull.vertices_mm, skull.faces, camera, (w, h))
    rgba = np.zeros(covered.shape + (4,), dtype=np.uint8)
    rgba[..., :3] = np.clip(shade[..., None] * SKULL_RGB, 0, 255).astype(np.uint8)
    rgba[..., 3] = np.where(covered, 255, 0)
    contours, _ = cv2.findContours(
        covered.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )
    cv2.drawContours(rgba, contours, -1, (*OUTLINE_RGB, 255), OUTLINE_PX, cv2.LINE_AA)
    return rgba


def view_box(size_wh, covered=None, mask=None, points_uv=()):
    """The region of the photo a report shows: skull, face mask and landmarks with a margin.

    Returns the whole photo when that region covers most of it anyway.

    Parameters
    ----------
    size_wh : tuple (width, height), int
    covered, mask : ndarray of shape (height, width), bool, optional
        Regions to show (e.g. the skull's pixels, the face mask).
    points_uv : array_like of shape (N, 2)
        Points to show (pixels); non-finite rows are ignored.

    Returns
    -------
    tuple (u0, v0, u1, v1), int
    """
    w, h = size_wh
    us, vs = [], []
    for region in (covered, mask):
        if region is not None and region.any():
            rows, cols = np.nonzero(region)
            us += [cols.min(), cols.max()]
            vs += [rows.min(), rows.max()]
    pts = np.asarray(points_uv, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    us += list(pts[:, 0])
    vs += list(pts[:, 1])
    if not us:
        return 0, 0, w, h
    margin = VIEW_MARGIN * max(max(us) - min(us), max(vs) - min(vs))
    u0, u1 = max(0, int(min(us) - margin)), min(w, int(np.ceil(max(us) + margin)) + 1)
    v0, v1 = max(0, int(min(vs) - margin)), min(h, int(np.ceil(max(vs) + margin)) + 1)
    if (u1 - u0) * (v1 - v0) > FULL_VIEW_FRACTION * w * h:
        return 0, 0, w, h
    return u0, v0, u1, v1


def layer_scale(box):
    """Skull-layer pixels per photo pixel for a box: finer for small regions, capped.

    Parameters
    ----------
    box : tuple (u0, v0, u1, v1), int

    Returns
    -------
    float
    """
    long_px = max(box[2] - box[0], box[3] - box[1])
    return min(MAX_REPORT_PX, max(long_px, MIN_LAYER_PX)) / long_px


def outside_layer_rgba(layer, face_mask, box):
    """The skull-layer pixels outside the face mask, coloured :data:`OUTSIDE_RGBA`.

    Parameters
    ----------
    layer : ndarray of shape (h, w, 4), uint8
        The skull layer of ``box``.
    face_mask : ndarray of shape (H, W), bool
        Of the whole photo.
    box : tuple (u0, v0, u1, v1), int

    Returns
    -------
    rgba : ndarray of shape (h, w, 4), uint8
    """
    u0, v0, u1, v1 = box
    mask_crop = face_mask[v0:v1, u0:u1].astype(np.uint8) * 255
    mask_small = resize(mask_crop, layer.shape[1::-1]) > 127
    hot = (layer[..., 3] > 0) & ~mask_small
    rgba = np.zeros(hot.shape + (4,), dtype=np.uint8)
    rgba[hot] = OUTSIDE_RGBA
    return rgba


def resize(array, size_wh):
    """Lanczos resize of an image array to ``size_wh = (width, height)`` (a no-op if equal)."""
    from PIL import Image

    if (array.shape[1], array.shape[0]) == tuple(size_wh):
        return array
    return np.asarray(Image.fromarray(array).resize(size_wh, Image.Resampling.LANCZOS))


def encode(array, fmt):
    """An image array as ``"png"`` or ``"jpeg"`` bytes."""
    from PIL import Image

    buffer = io.BytesIO()
    if fmt == "jpeg":
        Image.fromarray(array).save(buffer, format="JPEG", quality=JPEG_QUALITY)
    elif fmt == "png":
        Image.fromarray(array).save(buffer, format="PNG", optimize=True)
    else:
        raise ValueError(f"unknown picture format {fmt!r}; use 'png' or 'jpeg'")
    return buffer.getvalue()


def sfo_pictures(result, skull, photo, box, show_outside):
    """Encode the pictures of one SFO.

    Parameters
    ----------
    result : SfoResult
    skull : Skull
    photo : Photo
        Read with its image.
    box : tuple (u0, v0, u1, v1), int
        The region to picture (:func:`view_box`).
    show_outside : bool
        Whether to add the outside layer (the SFO has skull pixels outside the face mask).

    Returns
    -------
    Pictures
    """
    u0, v0, u1, v1 = box
    box_wh = (u1 - u0, v1 - v0)
    photo_scale = min(1.0, MAX_REPORT_PX / max(box_wh))
    small_wh = tuple(max(1, round(s * photo_scale)) for s in box_wh)
    photo_jpeg = encode(resize(photo.image[v0:v1, u0:u1], small_wh), "jpeg")
    if not result:
        return Pictures(tuple(box), photo_jpeg)
    layer = skull_layer_rgba(result, skull, box, layer_scale(box))
    outside = None
    if show_outside and photo.face_mask is not None:
        outside = encode(outside_layer_rgba(layer, photo.face_mask, box), "png")
    return Pictures(tuple(box), photo_jpeg, encode(layer, "png"), outside)
