"""Population soft-tissue depth intervals (SPEC section 3).

The built-in table holds approximate adult values on the scale of published meta-analyses; a
user's own table (CSV with columns ``landmark,mean,sd,min,max``, see
:func:`lilium.io.read_depth_table`) replaces it.
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


def check_depth_table(table, source="depth table"):
    """Validate a ``{name: DepthStats}`` table and return it keyed by cranial base name.

    Keys may be cranial base names (``zygion``), sided cranial names (``zygion_l``, whose side is
    dropped) or facial names of the correspondence (``exocanthion``).

    Raises
    ------
    ValueError
        Unknown landmark, non-finite value, ``not 0 <= min <= mean <= max``, a depth beyond
        :data:`~lilium.constants.MAX_DEPTH_MM` or an SD outside
        ``[0, MAX_DEPTH_SD_MM]``.
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
