"""Checks of plain values shared by every layer (files, command line, dataclasses).

Each ``check_*`` returns the clean value or raises a ``ValueError`` that starts with ``name``,
so a caller gives the context as the name: a file and field (``"photo.json: priors.scd_mm"``),
an option (``"command line: --focal-px"``) or an attribute (``"focal_px"``).
"""

import numpy as np


def _show(value):
    if isinstance(value, str):
        return repr(value)
    try:
        return "[" + ", ".join(f"{float(x):g}" for x in value) + "]"
    except (TypeError, ValueError):
        return repr(value)


def _is_real(x):
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, bool)


def check_interval(value, name):
    """Validate a positive interval ``[lo, hi]`` (a prior on the focal length, the SCD, ...).

    Parameters
    ----------
    value : sequence of 2 numbers
    name : str
        What it is, for the message (file and field, option, or attribute).

    Returns
    -------
    (float, float)
        ``(lo, hi)`` with ``0 < lo <= hi``, both finite.

    Raises
    ------
    ValueError
        Not two real numbers, NaN or infinite, ``lo <= 0`` or ``lo > hi``.

    Examples
    --------
    >>> check_interval([800, 1200], "focal_px")
    (800.0, 1200.0)
    >>> check_interval((1200, 800), "focal_px")
    Traceback (most recent call last):
    ...
    ValueError: focal_px must be a finite interval [lo, hi] with 0 < lo <= hi, got [1200, 800]
    """
    try:
        items = [] if isinstance(value, str) else list(value)
    except TypeError:
        items = []
    ok = len(items) == 2 and all(_is_real(x) for x in items)
    if ok:
        lo, hi = float(items[0]), float(items[1])
        ok = bool(np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi)
    if not ok:
        raise ValueError(
            f"{name} must be a finite interval [lo, hi] with 0 < lo <= hi, got {_show(value)}"
        )
    return lo, hi
