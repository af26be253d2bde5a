"""The pictures of one SFO in the report: the photo region, the skull layer, the outside layer,
and the skull alone with its cranial landmarks.

The report shows a region of the photo (``box``: the skull, the face mask and the landmarks with
a margin, or the whole photo) as stacked pictures of the same size on the page, drawn at
:func:`picture_scale` (at least :data:`MIN_ACROSS_PX` across even for a face of 150 photo
pixels, :data:`MIN_LAYER_PX` on the longest side, at most :data:`MAX_REPORT_PX` unless the
first rule needs more):

- the photo region (JPEG), resampled to the picture's size with a Lanczos filter (a small
  face is upscaled, so the skull is judged against the photo at the same scale);
- the skull as a layer transparent off the skull (palette PNG), rendered at the picture's size
  with the detailed shading of :mod:`lilium.imaging.shading` (smooth normals, cavity shading
  and crease lines, so orbits, nasal aperture and teeth read) and outlined;
- with a face mask, the skull pixels outside it (PNG, same size as the skull layer).

Beside each SFO, the skull alone in a frontal and a lateral view (:func:`skull_view_pictures`,
JPEG, once per skull and view on a page) with its cranial landmarks, which
:func:`lilium.report.svg.skull_view_svg` marks and labels.

Boxes are ``(u0, v0, u1, v1)`` in photo pixels: columns ``u0 <= u < u1``, rows ``v0 <= v < v1``;
arrays are indexed ``[row, column]``.
"""

import io
from dataclasses import dataclass

import numpy as np

from ..imaging.overlay import SKULL_RGB
from ..imaging.shading import render_skull_detailed
from ..imaging.skull_views import skull_view

#: Longest side (pixels) of the pictures embedded in the report; larger photos are scaled down
#: (unless :data:`MIN_ACROSS_PX` needs more).
MAX_REPORT_PX = 2000

#: Smallest width and height (pixels) of the pictured region: a small face is upscaled.
MIN_ACROSS_PX = 1000

#: Margin around skull, mask and landmarks in the pictured region (fraction of its size), and
#: the area fraction above which the whole photo is shown instead.
VIEW_MARGIN = 0.12
FULL_VIEW_FRACTION = 0.6

#: Smallest longest side (pixels) of the pictures: small regions are rendered finer.
MIN_LAYER_PX = 1400

#: Size (width, height) of the skull-alone views, and their JPEG quality.
SKULL_VIEW_WH = (520, 600)
SKULL_VIEW_JPEG_QUALITY = 88

#: Skull outline drawn on the skull layer (RGB) and its width at report scale (pixels).
OUTLINE_RGB = (255, 214, 0)
OUTLINE_PX = 2

#: Shade levels of the skull layer's palette (96: no visible banding over a photo, 40 % smaller
#: than 250 levels): index 0 is transparent, ``1 .. SHADE_LEVELS``
#: the bone colour from black to full, :data:`OUTLINE_INDEX` the outline.
SHADE_LEVELS = 96
OUTLINE_INDEX = SHADE_LEVELS + 1

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


def skull_layer_indexed(result, skull, box, scale=1.0):
    """The shaded, outlined skull as palette indices (see :func:`layer_palette`).

    Shaded by :func:`lilium.imaging.shading.render_skull_detailed`; the silhouette is the
    exact skull raster (P_skof's ``S``) at the picture's resolution. The layer's colour is one
    hue times a shade, so :data:`SHADE_LEVELS` palette entries hold it and the PNG is a
    palette PNG, about a third of an RGBA one.

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
    index : ndarray of shape (round(scale * (v1 - v0)), round(scale * (u1 - u0))), uint8
        0 off the skull, ``1 + shade level`` on it, :data:`OUTLINE_INDEX` on the outline.
    """
    import cv2

    w, h = picture_size(box, scale)
    camera = result.camera.cropped(box[:2], scale)
    shade, surface = render_skull_detailed(skull.vertices_mm, skull.faces, camera, (w, h))
    level = np.round(np.clip(shade, 0, 1) * (SHADE_LEVELS - 1)).astype(np.uint8)
    index = np.where(surface.covered, 1 + level, 0).astype(np.uint8)
    contours, _ = cv2.findContours(
        surface.covered.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE
    )
    cv2.drawContours(index, contours, -1, OUTLINE_INDEX, OUTLINE_PX, cv2.LINE_8)
    return index


def layer_palette():
    """RGBA palette ``(OUTLINE_INDEX + 1, 4)`` uint8 of :func:`skull_layer_indexed`."""
    palette = np.zeros((OUTLINE_INDEX + 1, 4), dtype=np.uint8)
    shades = np.linspace(0, 1, SHADE_LEVELS)[:, None] * SKULL_RGB
    palette[1 : SHADE_LEVELS + 1, :3] = np.clip(np.round(shades), 0, 255)
    palette[1 : SHADE_LEVELS + 1, 3] = 255
    palette[OUTLINE_INDEX] = (*OUTLINE_RGB, 255)
    return palette


def skull_layer_rgba(result, skull, box, scale=1.0):
    """The shaded, outlined skull as an RGBA picture, transparent off the skull.

    Parameters
    ----------
    result : SfoResult
        Successful.
    skull : Skull
    box : tuple (u0, v0, u1, v1), int
    scale : float
        Picture pixels per photo pixel.

    Returns
    -------
    rgba : ndarray of shape (round(scale * (v1 - v0)), round(scale * (u1 - u0)), 4), uint8
        :func:`skull_layer_indexed` through :func:`layer_palette`.
    """
    return layer_palette()[skull_layer_indexed(result, skull, box, scale)]


def encode_indexed(index, palette):
    """A palette PNG (bytes) of ``index`` (H, W) uint8 with an RGBA ``palette`` (K, 4)."""
    from PIL import Image

    image = Image.fromarray(np.asarray(index, dtype=np.uint8), mode="P")
    image.putpalette(palette[:, :3].astype(np.uint8).ravel().tobytes())
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", optimize=True, transparency=palette[:, 3].tobytes())
    return buffer.getvalue()


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
    if len(pts):  # the extremes only (a skull's projected vertices are hundreds of thousands)
        us += [pts[:, 0].min(), pts[:, 0].max()]
        vs += [pts[:, 1].min(), pts[:, 1].max()]
    if not us:
        return 0, 0, w, h
    margin = VIEW_MARGIN * max(max(us) - min(us), max(vs) - min(vs))
    u0, u1 = max(0, int(min(us) - margin)), min(w, int(np.ceil(max(us) + margin)) + 1)
    v0, v1 = max(0, int(min(vs) - margin)), min(h, int(np.ceil(max(vs) + margin)) + 1)
    if (u1 - u0) * (v1 - v0) > FULL_VIEW_FRACTION * w * h:
        return 0, 0, w, h
    return u0, v0, u1, v1


def picture_scale(box):
    """Picture pixels per photo pixel for a box (photo and skull layer alike).

    At least :data:`MIN_ACROSS_PX` on the shorter side and :data:`MIN_LAYER_PX` on the longer
    side (small regions are upscaled), never below the photo's own resolution unless the
    longer side would pass :data:`MAX_REPORT_PX`.

    Parameters
    ----------
    box : tuple (u0, v0, u1, v1), int

    Returns
    -------
    float
    """
    short_px = max(1, min(box[2] - box[0], box[3] - box[1]))
    long_px = max(1, box[2] - box[0], box[3] - box[1])
    wanted = min(MAX_REPORT_PX / long_px, max(1.0, MIN_LAYER_PX / long_px))
    return max(wanted, MIN_ACROSS_PX / short_px)


def picture_size(box, scale):
    """``(width, height)`` of the picture of ``box`` at ``scale``."""
    u0, v0, u1, v1 = box
    return max(1, round(scale * (u1 - u0))), max(1, round(scale * (v1 - v0)))


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


def encode(array, fmt, quality=JPEG_QUALITY):
    """An image array as ``"png"`` or ``"jpeg"`` bytes (``quality``: JPEG only)."""
    from PIL import Image

    buffer = io.BytesIO()
    if fmt == "jpeg":
        Image.fromarray(array).save(buffer, format="JPEG", quality=quality)
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
        The photo and the layers share one size, :func:`picture_size` at :func:`picture_scale`.
    """
    u0, v0, u1, v1 = box
    scale = picture_scale(box)
    size_wh = picture_size(box, scale)
    photo_jpeg = encode(resize(photo.image[v0:v1, u0:u1], size_wh), "jpeg")
    if not result:
        return Pictures(tuple(box), photo_jpeg)
    index = skull_layer_indexed(result, skull, box, scale)
    palette = layer_palette()
    outside = None
    if show_outside and photo.face_mask is not None:
        outside = encode(outside_layer_rgba(palette[index], photo.face_mask, box), "png")
    return Pictures(tuple(box), photo_jpeg, encode_indexed(index, palette), outside)


@dataclass(frozen=True)
class SkullViewPicture:
    """The skull alone in one view, encoded, with its cranial landmarks projected.

    Attributes
    ----------
    key : str
        Unique on the page (an HTML id): the picture is embedded once and reused.
    view : str
        ``"frontal"``, ``"lateral_left"`` or ``"lateral_right"``.
    size_wh : tuple (width, height), int
    jpeg : bytes
    names : tuple of str
        Cranial landmarks.
    uv : tuple of (float, float)
        Their positions in the picture (pixels; NaN when not projectable).
    visible : tuple of bool
        Whether each is seen (False: hidden behind bone, e.g. the far side in a lateral view).
    """

    key: str
    view: str
    size_wh: tuple
    jpeg: bytes
    names: tuple
    uv: tuple
    visible: tuple


def skull_view_pictures(skull, views, key_prefix="skv"):
    """The skull alone in each of ``views``, encoded (see :class:`SkullViewPicture`).

    The views are oriented by the skull's anatomical frame
    (:func:`lilium.fitness.regions.anatomical_frame`: Frankfurt plane from porion and
    orbitale, or its documented midline fallback).

    Parameters
    ----------
    skull : Skull
    views : sequence of str
    key_prefix : str
        Prefix of the pictures' keys.

    Returns
    -------
    tuple of SkullViewPicture
        Empty when the landmarks cannot orient the skull (too few of them).
    """
    from ..fitness.regions import anatomical_frame
    from ..imaging.raster import cached_topology

    try:
        frame = anatomical_frame(skull.landmarks_mm)
    except ValueError:
        return ()
    topology = cached_topology(skull.faces)
    pictures = []
    for view in views:
        sv = skull_view(
            skull.vertices_mm,
            skull.faces,
            skull.landmarks_mm,
            frame.anterior,
            frame.up,
            view,
            SKULL_VIEW_WH,
            topology=topology,
        )
        pictures.append(
            SkullViewPicture(
                key=f"{key_prefix}-{view}",
                view=view,
                size_wh=SKULL_VIEW_WH,
                jpeg=encode(sv.image, "jpeg", SKULL_VIEW_JPEG_QUALITY),
                names=sv.names,
                uv=tuple((float(u), float(v)) for u, v in sv.uv),
                visible=tuple(bool(x) for x in sv.visible),
            )
        )
    return tuple(pictures)


def skull_views_for(view):
    """The two skull-alone views shown beside an SFO of a photo in ``view``: the frontal one
    and the lateral one of the photo's side (the left for a frontal photo)."""
    return ("frontal", view if view.startswith("lateral") else "lateral_left")
