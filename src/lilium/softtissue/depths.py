"""Population soft-tissue depth intervals (docs/method/lilium.md).

The built-in table holds approximate adult values on the scale of published meta-analyses; a
user's own table (CSV with columns ``landmark,mean,sd,min,max``, see
:func:`lilium.io.read_depth_table`) replaces it.

A user's mean depth above :data:`IMPLAUSIBLE_DEPTH_FACTOR` times the built-in mean of its
landmark (:data:`IMPLAUSIBLE_DEPTH_MM` where the built-in table has none) is implausible: still
inside the 0-100 mm range, but it moves the facial landmarks so far off the skull that the SFO
fits a camera of about twice the true focal length and the identification excludes the true
person. A few such landmarks make a warning, worded by :func:`depth_table_warning` for the
caller to attach; most of a table's landmarks (at least :data:`NOT_DEPTHS_MIN_LANDMARKS`) make
it an error in :func:`check_depth_table`: the file then holds no soft-tissue depths in mm.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import MAX_DEPTH_MM, MAX_DEPTH_SD_MM
from ..validation import fmt_number
from .landmarks import CRANIAL_TO_FACIAL, base_name


@dataclass(frozen=True)
class DepthStats:
    """Soft-tissue depth of one landmark in a population (mm)."""

    mean_mm: float
    sd_mm: float
    min_mm: float
    max_mm: float


#: Built-in table, keyed by the cranial base name (no side suffix).
BUILTIN_DEPTHS = {
    "glabella": DepthStats(5.5, 1.3, 3.0, 8.5),
    "nasion": DepthStats(6.5, 1.4, 3.5, 10.0),
    "metopion": DepthStats(4.8, 1.0, 2.5, 7.5),
    "bregma": DepthStats(5.5, 1.3, 3.0, 8.5),
    "frontotemporale": DepthStats(5.0, 1.2, 2.5, 8.0),
    "ectoconchion": DepthStats(10.5, 2.0, 6.0, 15.0),
    "dacryon": DepthStats(9.0, 2.0, 5.0, 13.5),
    "zygion": DepthStats(7.0, 2.0, 3.0, 12.0),
    "alare": DepthStats(12.0, 2.5, 7.0, 17.0),
    "subspinale": DepthStats(15.0, 2.5, 10.0, 20.0),
    "prosthion": DepthStats(12.5, 2.3, 8.0, 17.5),
    "pogonion": DepthStats(11.5, 2.2, 7.0, 16.5),
    "gnathion": DepthStats(8.5, 2.0, 4.5, 13.0),
    "gonion": DepthStats(13.5, 4.0, 6.0, 22.0),
}


#: A mean depth above this many times the built-in mean of its landmark is implausible.
IMPLAUSIBLE_DEPTH_FACTOR = 3.0

#: A mean depth above this (mm) is implausible for a landmark the built-in table lacks.
IMPLAUSIBLE_DEPTH_MM = 40.0

#: A table whose implausible landmarks are more than half of it and at least this many holds no
#: soft-tissue depths at all (another unit, another measure, shifted columns): an error.
NOT_DEPTHS_MIN_LANDMARKS = 3


def implausible_depths(table):
    """The landmarks of a depth table whose mean depth is implausible.

    Parameters
    ----------
    table : dict of str -> DepthStats
        Keyed by cranial base name (:func:`check_depth_table`'s result).

    Returns
    -------
    dict of str -> (float, float)
        ``name -> (mean_mm, limit_mm)`` for each mean above its limit:
        :data:`IMPLAUSIBLE_DEPTH_FACTOR` times the built-in mean, or :data:`IMPLAUSIBLE_DEPTH_MM`.
    """
    out = {}
    for name, stats in table.items():
        builtin = BUILTIN_DEPTHS.get(base_name(name))
        limit = IMPLAUSIBLE_DEPTH_MM
        if builtin is not None:
            limit = IMPLAUSIBLE_DEPTH_FACTOR * builtin.mean_mm
        if stats.mean_mm > limit:
            out[name] = (float(stats.mean_mm), float(limit))
    return out


def _implausible_text(found, limit=6):
    """``nasion 80 > 19.5 mm, ...`` for :func:`implausible_depths`' result."""
    items = [
        f"{name} {fmt_number(mean)} > {fmt_number(most)} mm" for name, (mean, most) in found.items()
    ]
    more = f" and {len(items) - limit} more" if len(items) > limit else ""
    return ", ".join(items[:limit]) + more


def depth_table_warning(table, source="depth table"):
    """The message of warning ``implausible_depth`` for a table with implausible depths.

    Parameters
    ----------
    table : dict of str -> DepthStats
        Keyed by cranial base name (:func:`check_depth_table`'s result).
    source : str
        The file, named in the message.

    Returns
    -------
    str or None
        What is implausible and what to check (the caller makes it a warning with code
        ``implausible_depth``: this layer knows no warning type); None when every mean depth
        is plausible.
    """
    found = implausible_depths(table)
    if not found:
        return None
    return (
        f"{source}: implausible soft-tissue depths, above {IMPLAUSIBLE_DEPTH_FACTOR:g} times the "
        f"built-in mean: {_implausible_text(found)}; a landmark that deep moves the face off "
        "the skull and the camera with it: check these values (millimetres, measured from the "
        "bone to the skin surface)"
    )


def _check_depths_plausible(table, source):
    """Raise when most of the table's mean depths are implausible (module docstring)."""
    found = implausible_depths(table)
    if len(found) < NOT_DEPTHS_MIN_LANDMARKS or 2 * len(found) <= len(table):
        return
    raise ValueError(
        f"{source}: {len(found)} of {len(table)} landmarks have a mean depth above "
        f"{IMPLAUSIBLE_DEPTH_FACTOR:g} times their built-in mean ({_implausible_text(found)}): "
        "these are not facial soft-tissue depths in millimetres (another unit or another "
        "measure?); check the file, or leave out --depth-table to use the built-in table"
    )


def check_depth_table(table, source="depth table"):
    """Validate a ``{name: DepthStats}`` table and return it keyed by cranial base name.

    Keys may be cranial base names (``zygion``), sided cranial names (``zygion_l``, whose side is
    dropped) or facial names of the correspondence (``exocanthion``).

    Raises
    ------
    ValueError
        Unknown landmark, non-finite value, ``not 0 <= min <= mean <= max``, a depth beyond
        :data:`~lilium.constants.MAX_DEPTH_MM` or an SD outside
        ``[0, MAX_DEPTH_SD_MM]``; or most landmarks with an implausible mean depth (at
        least :data:`NOT_DEPTHS_MIN_LANDMARKS` and more than half of them above their limit,
        :func:`implausible_depths`): the file holds no soft-tissue depths. Fewer implausible
        means pass here; :func:`depth_table_warning` words their warning.
    """
    facial_base = {base_name(f): base_name(c) for c, f in CRANIAL_TO_FACIAL.items()}
    out = {}
    for key, stats in table.items():
        name = base_name(key)
        name = name if name in BUILTIN_DEPTHS else facial_base.get(name)
        if name is None:
            raise ValueError(
                f"{source}: unknown landmark {key!r}; use a cranial name such as "
                f"{', '.join(sorted(BUILTIN_DEPTHS))}"
            )
        values = np.array([stats.mean_mm, stats.sd_mm, stats.min_mm, stats.max_mm], dtype=float)
        if not np.all(np.isfinite(values)):
            raise ValueError(f"{source}: landmark {key!r} has a NaN or infinite value")
        if stats.max_mm > MAX_DEPTH_MM or not 0 <= stats.sd_mm <= MAX_DEPTH_SD_MM:
            raise ValueError(
                f"{source}: landmark {key!r} has max={fmt_number(stats.max_mm)} mm and "
                f"sd={fmt_number(stats.sd_mm)} mm; facial soft tissue is at most "
                f"{MAX_DEPTH_MM:g} mm deep (sd 0 to {MAX_DEPTH_SD_MM:g} mm): check the "
                "values and that they are in millimetres"
            )
        if not 0 <= stats.min_mm <= stats.mean_mm <= stats.max_mm:
            raise ValueError(
                f"{source}: landmark {key!r} needs 0 <= min <= mean <= max, got "
                f"min={stats.min_mm}, mean={stats.mean_mm}, max={stats.max_mm}"
            )
        out[name] = stats
    _check_depths_plausible(out, source)
    return out


def depth_stats(cranial_name, table=None):
    """Depth statistics of a cranial landmark; the user table first, then the built-in one.

    Raises
    ------
    KeyError
        If neither table has the landmark (extra landmarks carry no soft tissue).
    """
    key = base_name(cranial_name)
    if table and key in table:
        return table[key]
    return BUILTIN_DEPTHS[key]
