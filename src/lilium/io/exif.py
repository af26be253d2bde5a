"""A focal-length prior (pixels) from a photo's EXIF data.

The focal length in pixels is ``focal_mm * pixels_per_mm_on_the_sensor``. In order of trust:

1. ``FocalLength`` with a sensor width: given by the user (``--sensor-width-mm``), else the
   sensor's pixel pitch from ``FocalPlaneXResolution`` and ``FocalPlaneResolutionUnit``, else
   the small built-in table of camera models :data:`SENSOR_WIDTH_MM` (the sensor's long side
   matches the image's long side);
2. ``FocalLengthIn35mmFilm``: makers derive it from the diagonal (CIPA) or from the width of
   a 36 x 24 mm frame; the interval covers both readings.

``DigitalZoomRatio`` > 1 multiplies the focal length of 1. The interval is the estimate
``+- tolerance`` (5 % by default: the protocol's focal prior width).

EXIF describes the camera's pixel grid, not necessarily the file's (docs/method/photo.md): a photo
cropped or resized after the shot converts to the wrong number of pixels. The focal is used only
when the tags agree that the file is the camera's full frame at its own resolution
(:func:`full_frame_problem`): ``PixelXDimension``/``PixelYDimension`` and ``ImageWidth``/
``ImageLength`` equal the decoded size; ``Software`` names no editing program; the sensor that
``FocalPlaneXResolution`` implies for this many pixels agrees with the camera's (built-in table,
``--sensor-width-mm``) and with ``FocalLengthIn35mmFilm`` over ``FocalLength``; each focal
length lies in :data:`EXIF_FOCAL_RANGE_MM`. Otherwise, and when a ``FocalLength`` cannot be
converted at all (no 35 mm value, no pixel pitch, an unknown camera), :func:`exif_focal` says
which tag and what fixes it (warning ``exif_focal_unusable`` of docs/checks.md), and no prior
is taken.
"""

import os
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: Relative half-width of the focal interval derived from EXIF.
FOCAL_TOLERANCE = 0.05

#: Diagonal and width (mm) of a 35 mm film frame (36 x 24 mm).
FILM_35MM_DIAGONAL_MM = float(np.hypot(36.0, 24.0))
FILM_35MM_WIDTH_MM = 36.0

#: Physical range (mm) of an EXIF focal length, actual or 35 mm equivalent (a phone's 1.5 mm
#: ultra-wide to the 3000 mm equivalent of a superzoom compact); outside it the tag is wrong.
EXIF_FOCAL_RANGE_MM = (1.0, 3000.0)

#: Physical range (mm) of a camera sensor's long side (a phone's 1/4" to medium format).
SENSOR_WIDTH_RANGE_MM = (2.0, 60.0)

#: Relative disagreement beyond which two tags describe different pixel grids (the 35 mm
#: equivalent's two conventions differ by up to 8 % on a 4:3 sensor).
EXIF_AGREEMENT = 0.12

#: Words in ``Software`` that name an editing program (lower case): the file was re-saved by an
#: editor, most often cropped or resized, so its pixels are not the camera's.
EDITING_SOFTWARE = (
    "photoshop", "lightroom", "gimp", "paint.net", "affinity", "pixelmator", "snapseed",
    "picasa", "irfanview", "acdsee", "luminar", "paintshop", "krita", "imagemagick",
    "graphicsmagick", "darktable", "rawtherapee", "capture one", "photoscape", "faststone",
    "xnview", "photopea", "canva", "fotor", "befunky", "digikam", "shotwell", "pillow",
)  # fmt: skip

#: Sensor width (long side, mm) of some common cameras, keyed by the EXIF ``Model`` in lower case.
SENSOR_WIDTH_MM = {
    "canon eos 5d mark ii": 36.0,
    "canon eos 5d mark iii": 36.0,
    "canon eos 5d mark iv": 36.0,
    "canon eos 6d": 35.8,
    "canon eos 7d": 22.3,
    "canon eos 80d": 22.5,
    "canon eos 600d": 22.3,
    "canon eos 700d": 22.3,
    "canon eos rebel t3i": 22.3,
    "canon eos rebel t5i": 22.3,
    "nikon d750": 35.9,
    "nikon d800": 35.9,
    "nikon d810": 35.9,
    "nikon d850": 35.9,
    "nikon d3200": 23.2,
    "nikon d3300": 23.5,
    "nikon d5300": 23.5,
    "nikon d7200": 23.5,
    "ilce-7m3": 35.6,
    "ilce-6000": 23.5,
    "x-t3": 23.5,
}

# EXIF tag numbers (Exif 2.3 / CIPA DC-008).
_IMAGE_WIDTH = 0x0100
_IMAGE_LENGTH = 0x0101
_MODEL = 0x0110
_SOFTWARE = 0x0131
_EXIF_IFD = 0x8769
_FOCAL_LENGTH = 0x920A
_FOCAL_PLANE_X_RESOLUTION = 0xA20E
_FOCAL_PLANE_RESOLUTION_UNIT = 0xA210
_PIXEL_X_DIMENSION = 0xA002
_PIXEL_Y_DIMENSION = 0xA003
_DIGITAL_ZOOM_RATIO = 0xA404
_FOCAL_LENGTH_35MM = 0xA405

#: Millimetres per ``FocalPlaneResolutionUnit`` (2 = inch, 3 = cm, 4 = mm, 5 = micrometre).
_UNIT_MM = {1: 25.4, 2: 25.4, 3: 10.0, 4: 1.0, 5: 1e-3}


@dataclass(frozen=True)
class FocalPrior:
    """A focal-length interval derived from EXIF.

    Attributes
    ----------
    focal_px : tuple (lo, hi)
        Pixels, for the image as stored.
    estimate_px : float
    source : str
        How it was derived, for the report (e.g. ``"EXIF FocalLength 50 mm, sensor 36 mm"``).
    """

    focal_px: tuple
    estimate_px: float
    source: str


def _positive(value):
    try:
        value = float(value)
    except (TypeError, ValueError, ZeroDivisionError):
        return None
    return value if np.isfinite(value) and value > 0 else None


def _png_exif_chunk(path):
    """The EXIF block of a PNG's ``eXIf`` chunk, found by walking the chunk headers (no pixel
    is decoded: Pillow's ``getexif`` decodes the whole image to look for one after the pixel
    data, 0.5 s at 24 MP); None without one. As Pillow keeps it: ``b"Exif\\0\\0" + data``."""
    with open(path, "rb") as file:
        if file.read(8) != b"\x89PNG\r\n\x1a\n":
            return None
        while len(head := file.read(8)) == 8:
            length, kind = struct.unpack(">I4s", head)
            if kind == b"eXIf":
                return b"Exif\x00\x00" + file.read(length)
            if kind == b"IEND":
                return None
            file.seek(length + 4, os.SEEK_CUR)  # the data and its CRC
    return None


def read_exif(path):
    """The EXIF fields this module uses, as plain numbers and strings (absent ones omitted).

    Returns
    -------
    dict
        Keys among ``model``, ``software``, ``image_width``, ``image_length`` (IFD0),
        ``focal_mm``, ``focal_35mm``, ``plane_x_resolution``, ``plane_unit``, ``pixel_x``,
        ``pixel_y``, ``digital_zoom``, and ``image_size_wh`` (the stored size, before any
        EXIF orientation).
    """
    from PIL import Image

    from .images import open_image

    path = Path(path)
    with open_image(path) as im:  # the size limit, without Pillow's DecompressionBombWarning
        try:
            if im.format == "PNG":  # Pillow decodes the pixels to look past them: not needed
                exif = Image.Exif()
                data = im.info.get("exif") or _png_exif_chunk(path)
                if data:
                    exif.load(data)
            else:
                exif = im.getexif()
        except Exception:  # a broken EXIF block: no EXIF, as image viewers read it
            exif = None
        size = im.size
    ifd = exif.get_ifd(_EXIF_IFD) if exif else {}
    out = {"image_size_wh": size}
    for key, tag in (("model", _MODEL), ("software", _SOFTWARE)):
        text = exif.get(tag) if exif else None
        if isinstance(text, bytes):
            text = text.decode("latin-1")
        if isinstance(text, str) and text.strip("\x00 "):
            out[key] = text.strip("\x00 ")
    for key, tag in (("image_width", _IMAGE_WIDTH), ("image_length", _IMAGE_LENGTH)):
        value = _positive(exif.get(tag)) if exif else None
        if value is not None:
            out[key] = value
    fields = {
        "focal_mm": _FOCAL_LENGTH,
        "focal_35mm": _FOCAL_LENGTH_35MM,
        "plane_x_resolution": _FOCAL_PLANE_X_RESOLUTION,
        "plane_unit": _FOCAL_PLANE_RESOLUTION_UNIT,
        "pixel_x": _PIXEL_X_DIMENSION,
        "pixel_y": _PIXEL_Y_DIMENSION,
        "digital_zoom": _DIGITAL_ZOOM_RATIO,
    }
    for key, tag in fields.items():
        value = _positive(ifd.get(tag))
        if value is not None:
            out[key] = value
    return out


def focal_prior_from_exif(path, sensor_width_mm=None, tolerance=FOCAL_TOLERANCE):
    """A focal-length prior for a photo from its EXIF data, or None when EXIF cannot give one.

    Parameters
    ----------
    path : str or Path
        JPEG (or any image Pillow reads with EXIF).
    sensor_width_mm : float, optional
        The sensor's long side, when known; used before the built-in table.
    tolerance : float
        Relative half-width of the interval.

    Returns
    -------
    FocalPrior or None
        None also when the tags do not describe the file's own pixels (:func:`exif_focal`
        says why).
    """
    return exif_focal(path, sensor_width_mm, tolerance)[0]


#: The fix named when the EXIF focal cannot be trusted for this file.
_GIVE_FOCAL = (
    "give the focal prior yourself if you know it (lilium case --focal-px LO HI, or "
    '"focal_px" in photo.json\'s priors)'
)


def exif_focal(path, sensor_width_mm=None, tolerance=FOCAL_TOLERANCE):
    """The EXIF focal prior of a photo, or why its EXIF focal length cannot be used.

    Parameters
    ----------
    path : str or Path
    sensor_width_mm : float, optional
    tolerance : float

    Returns
    -------
    prior : FocalPrior or None
    unusable : str or None
        When the photo has a focal length in EXIF that cannot be used: the tag that disagrees
        (:func:`full_frame_problem`) or what is missing, and the options that fix it
        (``--sensor-width-mm``, ``--focal-px``); None otherwise.
    """
    _check_sensor_width(sensor_width_mm)
    info = read_exif(path)
    if "focal_mm" not in info and "focal_35mm" not in info:
        return None, None
    problem = full_frame_problem(info, sensor_width_mm)
    if problem:
        return None, (
            f"{path}: EXIF focal not used: {problem}; the focal in pixels would be wrong, so no "
            f"focal or distance prior is taken from it; {_GIVE_FOCAL}"
        )
    prior = focal_prior_from_fields(info, sensor_width_mm, tolerance)
    if prior is not None:
        return prior, None
    model = info.get("model")
    camera = f"camera {model!r} is not in the built-in sensor table" if model else "no camera model"
    return None, (
        f"{path}: EXIF FocalLength {info['focal_mm']:g} mm cannot be converted to pixels (no "
        f"FocalLengthIn35mmFilm, no FocalPlaneXResolution, {camera}); give --sensor-width-mm MM "
        "(the sensor's long side) or --focal-px LO HI"
    )


def _check_sensor_width(sensor_width_mm):
    if sensor_width_mm is None:
        return
    lo, hi = SENSOR_WIDTH_RANGE_MM
    if not (_positive(sensor_width_mm) and lo <= float(sensor_width_mm) <= hi):
        raise ValueError(
            f"--sensor-width-mm: the sensor width must be a positive number of mm from {lo:g} "
            f"to {hi:g} (the sensor's long side), got {sensor_width_mm!r}"
        )


def _disagree(a, b):
    return abs(a - b) > EXIF_AGREEMENT * max(a, b)


def _same_size(tag_wh, size_wh):
    """Whether EXIF's ``(w, h)`` (either may be None) is the stored size, in either order."""
    w, h = size_wh
    tw, th = tag_wh
    for a, b in ((w, h), (h, w)):
        if (tw is None or round(tw) == a) and (th is None or round(th) == b):
            return True
    return False


def _plane_sensor_mm(info):
    """The sensor's long side (mm) that ``FocalPlaneXResolution`` implies for the file's pixels."""
    unit_mm = _UNIT_MM.get(int(info.get("plane_unit", 2)))
    res = info.get("plane_x_resolution")
    if res is None or unit_mm is None:
        return None
    return max(info["image_size_wh"]) / (res / unit_mm)


def full_frame_problem(info, sensor_width_mm=None):
    """Why the EXIF tags do not describe this file as the camera's full frame ("" when they do).

    Parameters
    ----------
    info : dict
        :func:`read_exif`.
    sensor_width_mm : float, optional
        The sensor's long side, given by the user.

    Returns
    -------
    str
        One clause naming the tag that disagrees (docs/method/photo.md), or "".
    """
    w, h = info["image_size_wh"]
    size = f"the file's {w}x{h} px"
    lo, hi = EXIF_FOCAL_RANGE_MM
    for key, tag in (("focal_mm", "FocalLength"), ("focal_35mm", "FocalLengthIn35mmFilm")):
        value = info.get(key)
        if value is not None and not lo <= value <= hi:
            return f"{tag} {value:g} mm is outside the physical {lo:g}-{hi:g} mm of a camera lens"
    software = info.get("software", "")
    editor = next((name for name in EDITING_SOFTWARE if name in software.lower()), None)
    if editor:
        return (
            f"Software {software!r} is an editing program (the photo was re-saved after the "
            "shot, most often cropped or resized)"
        )
    for (kw, kh), (nw, nh) in (
        (("pixel_x", "pixel_y"), ("PixelXDimension", "PixelYDimension")),
        (("image_width", "image_length"), ("ImageWidth", "ImageLength")),
    ):
        tag_wh = (info.get(kw), info.get(kh))
        if tag_wh != (None, None) and not _same_size(tag_wh, (w, h)):
            shown = "x".join("?" if v is None else f"{v:g}" for v in tag_wh)
            return f"{nw}/{nh} {shown} differ from {size} (cropped or resized after the shot)"
    sensors = []  # (sensor long side mm, where from)
    if sensor_width_mm is not None:
        sensors.append((float(sensor_width_mm), f"--sensor-width-mm {sensor_width_mm:g}"))
    model = info.get("model", "")
    if model.lower() in SENSOR_WIDTH_MM:
        sensors.append((SENSOR_WIDTH_MM[model.lower()], f"the {model}'s sensor"))
    plane = _plane_sensor_mm(info)
    if plane is not None:
        res = info["plane_x_resolution"]
        what = f"FocalPlaneXResolution {res:g}/unit implies a {plane:.1f} mm sensor for {size}"
        s_lo, s_hi = SENSOR_WIDTH_RANGE_MM
        if not s_lo <= plane <= s_hi:
            return f"{what}, outside the {s_lo:g}-{s_hi:g} mm of camera sensors"
        for width, where in sensors:
            if _disagree(plane, width):
                return f"{what}, but {where} is {width:g} mm (resized after the shot)"
        sensors.append((plane, "FocalPlaneXResolution"))
    f35, focal = info.get("focal_35mm"), info.get("focal_mm")
    if f35 is not None and focal is not None:
        crop = f35 / (focal * info.get("digital_zoom", 1.0))
        diagonal = float(np.hypot(w, h)) / max(w, h)  # sensor diagonal per mm of long side
        for width, where in sensors:
            expected = FILM_35MM_DIAGONAL_MM / (width * diagonal)
            widthwise = FILM_35MM_WIDTH_MM / width
            if min(abs(crop - expected), abs(crop - widthwise)) > EXIF_AGREEMENT * crop:
                return (
                    f"FocalLengthIn35mmFilm {f35:g} mm over FocalLength {focal:g} mm is a crop "
                    f"factor of {crop:.2f}, but {where} ({width:.1f} mm) gives {expected:.2f}"
                )
    return ""


def focal_prior_from_fields(info, sensor_width_mm=None, tolerance=FOCAL_TOLERANCE):
    """The focal prior from fields already read by :func:`read_exif` (the tags are trusted:
    :func:`exif_focal` checks :func:`full_frame_problem` first), or None."""
    _check_sensor_width(sensor_width_mm)
    width, height = info["image_size_wh"]
    long_px = max(width, height)
    zoom = info.get("digital_zoom", 1.0)
    zoom_note = f" x digital zoom {zoom:g}" if zoom != 1.0 else ""
    focal_mm = info.get("focal_mm")
    estimates, source = None, None
    if focal_mm is not None:
        plane = _plane_sensor_mm(info)
        if sensor_width_mm is not None:
            sensor = float(sensor_width_mm)
            source = f"EXIF FocalLength {focal_mm:g} mm, sensor width {sensor:g} mm (given)"
        elif plane is not None:
            sensor = plane
            source = (
                f"EXIF FocalLength {focal_mm:g} mm, FocalPlaneXResolution "
                f"{info['plane_x_resolution']:g}/unit"
            )
        elif info.get("model", "").lower() in SENSOR_WIDTH_MM:
            sensor = SENSOR_WIDTH_MM[info["model"].lower()]
            source = (
                f"EXIF FocalLength {focal_mm:g} mm, {info['model']} sensor width {sensor:g} mm "
                "(built-in table)"
            )
        else:
            sensor = None
        if sensor is not None:
            estimates = [focal_mm * zoom * long_px / sensor]
            source += zoom_note
    if estimates is None and "focal_35mm" in info:
        f35 = info["focal_35mm"]
        estimates = [
            f35 * float(np.hypot(width, height)) / FILM_35MM_DIAGONAL_MM,
            f35 * long_px / FILM_35MM_WIDTH_MM,
        ]
        source = f"EXIF FocalLengthIn35mmFilm {f35:g} mm (diagonal and width conventions)"
    if estimates is None:
        return None
    lo, hi = min(estimates) * (1 - tolerance), max(estimates) * (1 + tolerance)
    return FocalPrior((float(lo), float(hi)), float(np.mean(estimates)), source)
