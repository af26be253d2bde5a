"""The facial curve file of SPEC section 8: ``face_curve.json``.

``{"chin_jaw": [[u, v], ...]}`` for a frontal photo, ``{"forehead": [[u, v], ...]}`` for a
lateral one (pixels, ``u`` = column, ``v`` = row). P_pll compares the skull's chin-jaw or
forehead contour with it; without it, the curve is derived from the face mask (SPEC section 5).
A file that holds no curve for the photo's view is an error, not silently ignored: the SFO
would otherwise run on the mask's curve while the user believes it ran on theirs.
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
        ``K >= 2`` points ``(u, v)``, pixels.

    Raises
    ------
    ValueError
        Naming the file: not found, not an object, no curve for the view, fewer than two finite
        ``[u, v]`` points, or a point off the image.
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
    return curve


def _short(value, limit=40):
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
