"""The landmark pairs of one SFO: the skull's cranial landmarks that the photo shows, each with
its facial counterpart (the first step of every method, and of the checks before one runs)."""

from dataclasses import dataclass

import numpy as np

from ..constants import MIN_CORRESPONDENCES
from ..softtissue.landmarks import CRANIAL_TO_FACIAL


@dataclass(frozen=True)
class Correspondences:
    """Landmarks usable for one SFO: present on the skull and visible in the photo.

    Attributes
    ----------
    cranial_names, facial_names : tuple of str, length N
    cranial_mm : ndarray of shape (N, 3)
    axes : ndarray of shape (N, 3)
    uv_px : ndarray of shape (N, 2)
    """

    cranial_names: tuple
    facial_names: tuple
    cranial_mm: np.ndarray
    axes: np.ndarray
    uv_px: np.ndarray


def correspondences(skull, photo, min_count=MIN_CORRESPONDENCES):
    """Pair the skull's cranial landmarks with the photo's facial landmarks.

    Raises
    ------
    ValueError
        Fewer than ``min_count`` landmarks present on both, with the names of what is missing.
    """
    pairs = [
        (c, f)
        for c, f in CRANIAL_TO_FACIAL.items()
        if c in skull.landmarks_mm and f in photo.landmarks_uv
    ]
    if len(pairs) < min_count:
        only_photo = sorted(
            f
            for c, f in CRANIAL_TO_FACIAL.items()
            if f in photo.landmarks_uv and c not in skull.landmarks_mm
        )
        raise ValueError(
            f"only {len(pairs)} usable landmark pairs between skull {skull.id!r} and photo "
            f"{photo.id!r}, at least {min_count} are needed; add cranial landmarks "
            f"(missing on the skull: {', '.join(only_photo) or 'none'}) or mark more facial "
            "landmarks in the photo"
        )
    cranial, facial = zip(*pairs, strict=True)
    return Correspondences(
        cranial,
        facial,
        np.array([skull.landmarks_mm[c] for c in cranial], dtype=float),
        np.array([skull.axes[c] for c in cranial], dtype=float),
        np.array([photo.landmarks_uv[f] for f in facial], dtype=float),
    )
