"""A focal-length prior (pixels) from a photo's EXIF data.

The focal length in pixels is ``focal_mm * pixels_per_mm_on_the_sensor``. In order of trust:

1. ``FocalLength`` with the sensor's pixel pitch from ``FocalPlaneXResolution`` and
   ``FocalPlaneResolutionUnit`` (scaled when the image was resized after shooting: by its width
   over ``PixelXDimension``);
2. ``FocalLength`` with a sensor width: given by the user, or from the small built-in table of
   camera models :data:`SENSOR_WIDTH_MM` (the sensor's long side matches the image's long side);
3. ``FocalLengthIn35mmFilm``: makers derive it from the diagonal (CIPA) or from the width of
   a 36 x 24 mm frame; the interval covers both readings.

``DigitalZoomRatio`` > 1 multiplies the focal length of 1 and 2. The interval is the estimate
``+- tolerance`` (5 % by default: the SPEC's focal prior width).

A ``FocalLength`` that none of these converts (no 35 mm value, no pixel pitch, an unknown camera)
is not dropped silently: :func:`exif_focal` says why, with the options that fix it (warning
``exif_focal_unusable`` of SPEC section 10).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: Relative half-width of the focal interval derived from EXIF.
FOCAL_TOLERANCE = 0.05

#: Diagonal and width (mm) of a 35 mm film frame (36 x 24 mm).
FILM_35MM_DIAGONAL_MM = float(np.hypot(36.0, 24.0))
FILM_35MM_WIDTH_MM = 36.0

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
_MODEL = 0x0110
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


def read_exif(path):
    """The EXIF fields this module uses, as plain numbers and strings (absent ones omitted).

    Returns
    -------
    dict
        Keys among ``model``, ``focal_mm``, ``focal_35mm``, ``plane_x_resolution``,
        ``plane_unit``, ``pixel_x``, ``pixel_y``, ``digital_zoom``, and ``image_size_wh``.
    """
    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    try:
        with Image.open(path) as im:
            exif = im.getexif()
            size = im.size
    except (UnidentifiedImageError, OSError, SyntaxError) as exc:
        raise ValueError(f"{path}: cannot read the image ({exc}); save it as PNG or JPEG") from exc
    ifd = exif.get_ifd(_EXIF_IFD) if exif else {}
    out = {"image_size_wh": size}
    model = exif.get(_MODEL) if exif else None
    if isinstance(model, str) and model.strip("\x00 "):
        out["model"] = model.strip("\x00 ")
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
    """
    info = read_exif(path)
    return focal_prior_from_fields(info, sensor_width_mm, tolerance)


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
        When the photo has a ``FocalLength`` but no way to convert it to pixels: what is missing
        and the options that fix it (``--sensor-width-mm``, ``--focal-px``); None otherwise.
    """
    info = read_exif(path)
    prior = focal_prior_from_fields(info, sensor_width_mm, tolerance)
    if prior is not None or "focal_mm" not in info:
        return prior, None
    model = info.get("model")
    camera = f"camera {model!r} is not in the built-in sensor table" if model else "no camera model"
    return None, (
        f"{path}: EXIF FocalLength {info['focal_mm']:g} mm cannot be converted to pixels (no "
        f"FocalLengthIn35mmFilm, no FocalPlaneXResolution, {camera}); give --sensor-width-mm MM "
        "(the sensor's long side) or --focal-px LO HI"
    )


def focal_prior_from_fields(info, sensor_width_mm=None, tolerance=FOCAL_TOLERANCE):
    """:func:`focal_prior_from_exif` on fields already read by :func:`read_exif`."""
    if sensor_width_mm is not None and not (_positive(sensor_width_mm)):
        raise ValueError(f"sensor width must be a positive number of mm, got {sensor_width_mm!r}")
    width, height = info["image_size_wh"]
    long_px = max(width, height)
    zoom = info.get("digital_zoom", 1.0)
    zoom_note = f" x digital zoom {zoom:g}" if zoom != 1.0 else ""
    focal_mm = info.get("focal_mm")
    estimates, source = None, None
    if focal_mm is not None:
        unit_mm = _UNIT_MM.get(int(info.get("plane_unit", 2)))
        res = info.get("plane_x_resolution")
        if sensor_width_mm is not None:
            px_per_mm = long_px / float(sensor_width_mm)
            source = (
                f"EXIF FocalLength {focal_mm:g} mm, sensor width {sensor_width_mm:g} mm (given)"
            )
        elif res is not None and unit_mm is not None:
            px_per_mm = res / unit_mm
            exif_w, exif_h = info.get("pixel_x"), info.get("pixel_y")
            if exif_w and exif_h:  # resized since shooting: scale by the long sides
                px_per_mm *= long_px / max(exif_w, exif_h)
            source = f"EXIF FocalLength {focal_mm:g} mm, FocalPlaneXResolution {res:g}/unit"
        elif info.get("model", "").lower() in SENSOR_WIDTH_MM:
            sensor = SENSOR_WIDTH_MM[info["model"].lower()]
            px_per_mm = long_px / sensor
            source = (
                f"EXIF FocalLength {focal_mm:g} mm, {info['model']} sensor width {sensor:g} mm "
                "(built-in table)"
            )
        else:
            px_per_mm = None
        if px_per_mm is not None:
            estimates = [focal_mm * zoom * px_per_mm]
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
