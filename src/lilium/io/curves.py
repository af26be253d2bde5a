"""The facial curve file of docs/contract.md: ``face_curve.json``.

``{"chin_jaw": [[u, v], ...]}`` for a frontal photo, ``{"forehead": [[u, v], ...]}`` for a
lateral one (pixels, ``u`` = column, ``v`` = row). P_pll compares the skull's chin-jaw or
forehead contour with it; without it, the curve is derived from the face mask
(docs/method/lilium.md).
A file that holds no curve for the photo's view is an error, not silently ignored: the SFO
would otherwise run on the mask's curve while the user believes it ran on theirs. A file that
holds the other view's curve (``forehead`` for a photo declared frontal) names the view to
check: the photo's declared view is the likelier mistake.
"""

from pathlib import Path

import numpy as np

from ..validation import is_numeric
from .jsonio import read_json

#: The curve key of each view.
CURVE_KEYS = {"frontal": "chin_jaw", "lateral_left": "forehead", "lateral_right": "forehead"}


def read_face_curve(path, view, image_size_wh=None):
    """Read the facial curve of a photo in ``view``.

    Parameters
    ----------
    path : str or Path
        ``face_curve.json`` (or a user's file of the same format).
    view : {"frontal", "lateral_left", "lateral_right"}
    image_size_wh : tuple (width, height), optional
        When given, every point must lie in the image (P_pll's nearest-point table spans the
        curve, so a point far outside would make it huge).

    Returns
    -------
    ndarray of shape (K, 2)
        ``K >= 2`` points ``(u, v)``, pixels; with ``image_size_wh``, whole pixels along an
        8-connected path (at most the photo's perimeter long).

    Raises
    ------
    ValueError
        Naming the file: not found, not an object, no curve for the view, fewer than two finite
        ``[u, v]`` points, a point off the image, or (with ``image_size_wh``) a curve longer
        than the photo's perimeter (a zig-zag).
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found; check the face curve's path")
    key = CURVE_KEYS[view]
    data = read_json(path)
    if not isinstance(data, dict):
        raise ValueError(
            f"{path}: must be a JSON object {{{key!r}: [[u, v], ...]}}, got "
            f"{type(data).__name__}; fix the file or remove it (the mask gives the curve then)"
        )
    if key not in data:
        _check_other_view(path, data, view)
        other = ", ".join(repr(k) for k in data) or "nothing"
        raise ValueError(
            f"{path}: no {key!r} curve for this {view} photo (the file holds {other}); give "
            f'{{"{key}": [[u, v], ...]}} in pixels, or remove the file (the mask gives the curve '
            "then)"
        )
    raw = data[key]
    try:
        curve = np.asarray(raw, dtype=float) if is_numeric(raw) else np.empty((0,))
    except (TypeError, ValueError):
        curve = np.empty((0,))
    if isinstance(raw, str) or curve.ndim != 2 or curve.shape[1] != 2 or len(curve) < 2:
        raise ValueError(
            f"{path}: {key} must be a list of at least two [u, v] points (numbers, in pixels), got "
            f"{_short(raw)}"
        )
    if not np.all(np.isfinite(curve)):
        raise ValueError(f"{path}: {key} must be a list of finite [u, v] pairs (no NaN)")
    if image_size_wh is not None:
        w, h = image_size_wh
        outside = ~((curve >= -0.5) & (curve <= np.array([w, h]) - 0.5)).all(axis=1)
        if outside.any():
            k = int(np.argmax(outside))
            raise ValueError(
                f"{path}: {key}[{k}] = ({curve[k, 0]:g}, {curve[k, 1]:g}) lies outside the "
                f"{w}x{h} photo ({int(outside.sum())} of {len(curve)} points do); the curve is "
                "in the photo's pixels, u = column, v = row"
            )
        curve = _pixel_curve(path, key, curve, image_size_wh)
    return curve


def _check_other_view(path, data, view):
    """Raise when the file holds the curve of the other view: the photo's view is wrong."""
    key = CURVE_KEYS[view]
    other = next((k for k in set(CURVE_KEYS.values()) - {key} if k in data), None)
    if other is None:
        return
    kind = "frontal" if other == "chin_jaw" else "lateral"
    raise ValueError(
        f"{path}: no {key!r} curve for this {view} photo: the file holds {other!r}, the curve "
        f'of a {kind} photo; check the photo\'s view ("view" in photo.json, or --view), or, '
        f'if the photo is {view}, give {{"{key}": [[u, v], ...]}} in pixels instead or remove '
        "the file (the mask gives the curve then)"
    )


def _pixel_curve(path, key, curve, image_size_wh):
    """The curve resampled to the photo's pixel grid (what P_pll uses: an 8-connected path of
    whole pixels), its length bounded by the photo's perimeter.

    The work P_pll does per camera grows with the curve's length in pixels, not with the
    file's number of points: a 2-million-point smooth curve becomes a few hundred pixels, while
    a zig-zag across the photo would be millions of pixels long (hours of fitting). A facial
    outline runs once along the face, so a curve longer than the photo's perimeter is refused.
    """
    from ..fitness.curves import join_fragments

    w, h = image_size_wh
    limit = 2.0 * (w + h)
    length = float(np.linalg.norm(np.diff(curve, axis=0), axis=1).sum())
    if length > limit:
        raise ValueError(
            f"{path}: {key} is {length:.0f} px long, longer than the {w}x{h} photo's perimeter "
            f"({limit:.0f} px): it runs back and forth; give the outline once, from one end to "
            "the other, in the photo's pixels"
        )
    pixels = join_fragments(np.rint(curve))
    keep = np.ones(len(pixels), bool)
    keep[1:] = np.any(pixels[1:] != pixels[:-1], axis=1)
    return pixels[keep]


def _short(value, limit=40):
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
