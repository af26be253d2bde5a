"""Checks of plain values shared by every layer (files, command line, dataclasses).

Each ``check_*`` returns the clean value or raises a ``ValueError`` that starts with ``name``,
so a caller gives the context as the name: a file and field (``"photo.json: priors.scd_mm"``),
an option (``"command line: --focal-px"``) or an attribute (``"focal_px"``).
"""

import numpy as np

from .constants import PRIOR_RANGES


def _show(value):
    if isinstance(value, str):
        return repr(value)
    try:
        return "[" + ", ".join(f"{float(x):g}" for x in value) + "]"
    except (TypeError, ValueError):
        return repr(value)


def is_real(x):
    """True for one real number (``True``/``False`` are not numbers here)."""
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, bool)


def is_numeric(value):
    """True when ``value`` (a number, or nested lists of numbers, or an array) holds only real
    numbers and ``None`` (JSON ``null``, read as NaN): no booleans and no strings.

    ``numpy`` converts ``True`` to 1.0 and ``"12"`` to 12.0, so a JSON ``[true, false]`` would
    otherwise pass as the point (1, 0).

    Examples
    --------
    >>> is_numeric([[1, 2.5], [None, 3]]), is_numeric([True, False]), is_numeric(["1", 2])
    (True, False, False)
    """
    stack = [value]
    while stack:  # no recursion: a file's nesting must not reach Python's recursion limit
        item = stack.pop()
        kind = type(item)
        if kind is float or kind is int or item is None:
            continue
        if kind is list or kind is tuple:
            stack.extend(item)
        elif isinstance(item, np.ndarray):
            if item.dtype.kind not in "iuf":
                return False
        elif not is_real(item):
            return False
    return True


def check_interval(value, name, limits=None, unit=""):
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
    ok = len(items) == 2 and all(is_real(x) for x in items)
    if ok:
        lo, hi = float(items[0]), float(items[1])
        ok = bool(np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi)
    if not ok:
        raise ValueError(
            f"{name} must be a finite interval [lo, hi] with 0 < lo <= hi, got {_show(value)}"
        )
    if limits is not None and not (limits[0] <= lo and hi <= limits[1]):
        raise ValueError(
            f"{name} = [{fmt_number(lo)}, {fmt_number(hi)}]{unit and ' ' + unit} lies outside "
            f"the physical range {fmt_range(*limits, unit)}; check the value and its unit"
        )
    return lo, hi


def check_prior(value, key, name):
    """:func:`check_interval` with the physical range of the prior ``key``
    (:data:`~lilium.constants.PRIOR_RANGES`: ``focal_px``, ``scd_mm``).

    Examples
    --------
    >>> check_prior([1e300, 1e301], "focal_px", "photo.json: priors.focal_px")
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: photo.json: priors.focal_px = [1e+300, 1e+301] px lies outside the physical...
    """
    limits, unit = PRIOR_RANGES[key]
    return check_interval(value, name, limits, unit)


def fmt_number(x):
    """A number for a message: whole units from 100 to 10 million, else 3-4 significant digits;
    never 300 digits, never a tiny value shown as 0.

    Examples
    --------
    >>> fmt_number(1e300), fmt_number(24334.6), fmt_number(1e-9), fmt_number(0.25), fmt_number(0)
    ('1e+300', '24335', '1e-09', '0.25', '0')
    """
    x = float(x)
    if not np.isfinite(x) or x == 0:
        return f"{x:g}"
    if abs(x) >= 1e7 or abs(x) < 0.01:
        return f"{x:.3g}"
    return f"{x:.0f}" if abs(x) >= 100 else f"{x:.4g}"


def fmt_range(lo, hi, unit=""):
    """``"lo-hi unit"`` with :func:`fmt_number` (``fmt_range(2470, 2730, "px")`` is
    ``'2470-2730 px'``)."""
    return f"{fmt_number(lo)}-{fmt_number(hi)}" + (f" {unit}" if unit else "")
