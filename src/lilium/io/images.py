"""Photos and face masks as arrays: bounded in size, 16-bit and alpha channels read as meant.

Rules (docs/checks.md):

- A photo or mask over :data:`~lilium.constants.MAX_PHOTO_PIXELS` is a ``ValueError`` that says
  the limit and how to downscale, raised from the file's header before any pixel is decoded
  (Pillow's own decompression-bomb check is replaced by this one).
- The EXIF Orientation tag is applied (as image viewers do).
- A photo becomes ``(H, W, 3)`` uint8. 16-bit grey (``I;16``) and 32-bit integer or float
  images are scaled to 8 bits (65535 -> 255; a float image in [0, 1] -> [0, 255]) instead of
  being clipped to white; an alpha channel is dropped.
- A mask becomes ``(H, W)`` bool, non-zero = face. With an alpha channel (RGBA, LA, or a palette
  or grey image with a transparent colour), a transparent pixel is never face, and when every
  pixel has the same colour the alpha channel alone is the mask (masks exported as "face
  opaque, rest transparent"). A mask that is empty, or that covers every pixel of the photo
  (no background: almost surely an export mistake, as the mask is the head as seen), is an error.
"""

import re
import warnings
from contextlib import contextmanager

import numpy as np

from ..constants import MAX_PHOTO_PIXELS

#: EXIF Orientation values that swap width and height (rotations by 90 degrees).
_TRANSPOSING_ORIENTATIONS = (5, 6, 7, 8)

_BOMB_SIZE = re.compile(r"\((\d+) pixels\)")


def _too_large(path, pixels, size_wh=None):
    shape = f"{size_wh[0]}x{size_wh[1]} px, " if size_wh else ""
    return ValueError(
        f"{path}: the image is too large ({shape}{pixels / 1e6:.0f} megapixels; at most "
        f"{MAX_PHOTO_PIXELS / 1e6:.0f}); downscale it, e.g. to 4000 px on its longer side, and "
        "scale its landmarks, mask and curve by the same factor s (u' = (u + 0.5) s - 0.5)"
    )


@contextmanager
def open_image(path):
    """Open an image lazily (header only), checking that it can be read and its size.

    Yields
    ------
    PIL.Image.Image
        Not yet decoded.

    Raises
    ------
    ValueError
        Not an image Pillow reads, or more than :data:`MAX_PHOTO_PIXELS` pixels.
    """
    from PIL import Image, UnidentifiedImageError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            im = Image.open(path)
    except Image.DecompressionBombError as exc:
        found = _BOMB_SIZE.search(str(exc))
        raise _too_large(path, int(found.group(1)) if found else 2 * MAX_PHOTO_PIXELS) from None
    except (UnidentifiedImageError, OSError, SyntaxError) as exc:
        raise ValueError(f"{path}: cannot read the image ({exc}); save it as PNG or JPEG") from exc
    with im:
        w, h = im.size
        if w * h > MAX_PHOTO_PIXELS:
            raise _too_large(path, w * h, (w, h))
        yield im


def _orientation(im):
    try:
        return int(im.getexif().get(0x0112, 1))
    except Exception:  # a broken EXIF block: Pillow's exif_transpose ignores it too
        return 1


def image_size_wh(path):
    """``(width, height)`` of an image as viewed (EXIF orientation applied), from its header."""
    with open_image(path) as im:
        w, h = im.size
        return (h, w) if _orientation(im) in _TRANSPOSING_ORIENTATIONS else (w, h)


def _decode(path, im):
    from PIL import ImageOps

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            im.load()
            # exif_transpose copies even an upright image: only call it to turn one.
            return ImageOps.exif_transpose(im) if _orientation(im) != 1 else im
    except (OSError, SyntaxError, ValueError) as exc:
        raise ValueError(f"{path}: cannot read the image ({exc}); save it as PNG or JPEG") from exc


def _to_uint8(values):
    """A high-bit-depth grey array scaled to uint8 (see the module notes)."""
    values = np.asarray(values)
    if values.dtype.kind == "f":
        values = np.nan_to_num(values.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
        peak = float(values.max(initial=0.0))
        scale = 255.0 if peak <= 1.0 else (255.0 / 65535.0 if peak <= 65535.0 else 255.0 / peak)
        return np.clip(np.round(values * scale), 0, 255).astype(np.uint8)
    peak = int(values.max(initial=0))
    if peak <= 255:
        return np.clip(values, 0, 255).astype(np.uint8)
    if peak <= 65535:
        return (np.clip(values, 0, 65535) // 257).astype(np.uint8)
    return (np.clip(values, 0, None).astype(np.float64) * (255.0 / peak)).astype(np.uint8)


def read_image(path):
    """Read a photo as ``(H, W, 3)`` uint8 RGB, upright (EXIF orientation applied).

    Raises
    ------
    ValueError
        Unreadable or too large (see the module notes), naming the file and the fix.
    """
    with open_image(path) as im:
        im = _decode(path, im)
        if im.mode.startswith("I") or im.mode == "F":  # 16/32-bit grey: scale, don't clip
            grey = _to_uint8(np.asarray(im))
            return np.repeat(grey[..., None], 3, axis=2)
        if im.mode != "RGB":
            im = im.convert("RGB")
        return np.asarray(im)


def _mask_pixels(im):
    """Face pixels of a decoded mask image, ``(H, W)`` bool (see the module notes)."""
    has_alpha = im.mode in ("RGBA", "LA", "PA", "RGBa", "La") or "transparency" in im.info
    if has_alpha:
        rgba = np.asarray(im.convert("RGBA"))
        alpha = rgba[..., 3] > 0
        colour = rgba[..., :3].reshape(-1, 3)
        if np.all(colour == colour[0]):
            return alpha
        return alpha & (rgba[..., :3].max(axis=2) > 0)
    if im.mode in ("1", "L") or im.mode.startswith("I") or im.mode == "F":
        return np.asarray(im) > 0
    return np.asarray(im.convert("RGB")).max(axis=2) > 0


#: Largest share of a photo's pixels a face mask may cover: a head that fills even a tight
#: portrait leaves the corners as background; a mask of (nearly) every pixel is a blank or
#: inverted file, and with it the skull could never leave the head (P_skof silently 0).
MASK_MAX_SHARE = 0.99


def read_mask(path, image_size_wh):
    """Read a face mask (non-zero = face) as ``(H, W)`` bool, checking size and coverage.

    Parameters
    ----------
    path : str or Path
        PNG (any mode; alpha channels as in the module notes).
    image_size_wh : tuple (width, height)
        The photo's size, which the mask must have.

    Raises
    ------
    ValueError
        Unreadable, too large, another size than the photo, empty, or covering every pixel.
    """
    with open_image(path) as im:
        mask = _mask_pixels(_decode(path, im))
    w, h = image_size_wh
    if mask.shape != (h, w):
        raise ValueError(
            f"{path}: the mask is {mask.shape[1]}x{mask.shape[0]} px but the photo is {w}x{h}; "
            "make the mask the photo's size"
        )
    face = np.count_nonzero(mask)
    if face == 0:
        raise ValueError(f"{path}: the face mask is empty; paint the face/head pixels non-zero")
    if face >= MASK_MAX_SHARE * mask.size:
        left = mask.size - face
        whole = (
            f"all but {left} px of the photo" if left else "the whole photo (every pixel non-zero)"
        )
        raise ValueError(
            f"{path}: the face mask covers {whole}, leaving no background to tell the head "
            "from; the mask is the head as seen on a zero background: paint the background "
            "black (0), or, for a mask drawn in its alpha channel, make the background "
            "transparent"
        )
    return mask
