"""The facial curve file of SPEC section 8: ``face_curve.json``.

``{"chin_jaw": [[u, v], ...]}`` for a frontal photo, ``{"forehead": [[u, v], ...]}`` for a
lateral one (pixels, ``u`` = column, ``v`` = row). P_pll compares the skull's chin-jaw or
forehead contour with it; without it, the curve is derived from the face mask (SPEC section 5).
A file that holds no curve for the photo's view is an error, not silently ignored: the SFO
would otherwise run on the mask's curve while the user believes it ran on theirs.
"""

from pathlib import Path

import numpy as np

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
        When given, every point must lie in the image.

    Returns
    -------
    ndarray of shape (K, 2)
        ``K >= 2`` points ``(u, v)``, pixels.

    Raises
    ------
    ValueError
        Naming the file: not found, no curve for the view, malformed, or off the image.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found; check the face curve's path")
    data = read_json(path)
    key = CURVE_KEYS[view]
    if not isinstance(data, dict) or key not in data:
        found = ", ".join(sorted(data)) if isinstance(data, dict) and data else "nothing"
        raise ValueError(
            f"{path}: no {key!r} curve for this {view} photo (the file holds {found}); give "
            f'{{"{key}": [[u, v], ...]}} in pixels'
        )
    try:
        curve = np.asarray(data[key], dtype=float)
    except (TypeError, ValueError):
        curve = np.zeros((0, 0))
    if curve.ndim != 2 or curve.shape[1] != 2 or not np.all(np.isfinite(curve)):
        raise ValueError(f"{path}: {key} must be a list of finite [u, v] pairs (pixels)")
    if len(curve) < 2:
        raise ValueError(f"{path}: {key} has {len(curve)} point(s); a curve needs at least 2")
    if image_size_wh is not None:
        w, h = image_size_wh
        off = (curve[:, 0] < -0.5) | (curve[:, 0] > w - 0.5)
        off |= (curve[:, 1] < -0.5) | (curve[:, 1] > h - 0.5)
        if off.any():
            u, v = curve[np.argmax(off)]
            raise ValueError(
                f"{path}: {key} point ({u:g}, {v:g}) lies outside the {w}x{h} image; u is the "
                "column and v the row, in pixels"
            )
    return curve
