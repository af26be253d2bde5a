"""Shape parameters of a synthetic subject and the population they are drawn from.

:class:`SubjectShape` holds the independent between-subject parameters (vault length, breadth
and height, face width and height, jaw width and height, gonial angle, chin, brow ridges,
alveolar prognathism, orbits, nasal aperture, nose, ears); :data:`SHAPE_PRIORS` is the
truncated normal each is drawn from, and :func:`draw_shape` draws one subject.
"""

from dataclasses import dataclass, fields

import numpy as np

#: Bizygomatic breadth (mm) the design positions of :mod:`.bone` are drawn for;
#: :attr:`SubjectShape.fw` is relative to it (the population's mean is the prior's, 127.3 mm).
MEAN_FACE_WIDTH_MM = 130.0


@dataclass(frozen=True)
class TruncatedNormal:
    """``N(mean, sd)`` clipped to ``[lo, hi]`` (units of the parameter)."""

    mean: float
    sd: float
    lo: float
    hi: float


#: Population of each shape parameter, in the order they are drawn (the field order of
#: :class:`SubjectShape`). ``_mm``: millimetres, ``_deg``: degrees, others: unitless factors.
SHAPE_PRIORS = {
    # Tuned so that the craniometric spread matches the pooled-sex adult values of
    # :data:`~.craniometry.PUBLISHED` (docs/population.md). Bounds about +-2 SD: wider ones
    # let the skin lose a landmark (face_height 1.2 failed). The means differ from the
    # measured values by the offset of each measurement's landmarks from the design position
    # (e.g. glabella-opisthocranion = cranial_length - 4 mm, gonion-gonion = jaw_width + 8 mm;
    # alare-alare grows about 21 mm per unit of nasal_width: 20.3 to 29.7 mm from 0.85 to 1.3
    # on one skull).
    "cranial_length": TruncatedNormal(184.0, 7.6, 169.0, 199.0),
    "cranial_breadth": TruncatedNormal(139.7, 6.0, 128.0, 151.0),
    "vault_height": TruncatedNormal(1.0, 0.04, 0.92, 1.08),
    "face_width": TruncatedNormal(127.3, 7.1, 113.5, 141.0),
    "face_height": TruncatedNormal(0.99, 0.085, 0.82, 1.16),
    "jaw_width": TruncatedNormal(86.5, 6.9, 73.0, 100.0),
    "jaw_height": TruncatedNormal(1.0, 0.1, 0.8, 1.2),
    "gonial_deg": TruncatedNormal(0.0, 5.0, -9.0, 9.0),
    "chin_mm": TruncatedNormal(0.0, 2.0, -3.5, 3.5),
    "brow": TruncatedNormal(0.8, 0.3, 0.25, 1.4),
    "prognathism_mm": TruncatedNormal(0.0, 2.0, -3.5, 3.5),
    "orbit": TruncatedNormal(1.0, 0.05, 0.9, 1.1),
    "nasal_width": TruncatedNormal(1.07, 0.11, 0.85, 1.29),
    "nose_projection_mm": TruncatedNormal(18.0, 2.2, 14.0, 23.0),
    "ear": TruncatedNormal(1.0, 0.07, 0.88, 1.12),
}


@dataclass(frozen=True)
class SubjectShape:
    """Independent shape parameters of one subject.

    Attributes
    ----------
    cranial_length, cranial_breadth : float
        Maximum cranial length (glabella-opisthocranion) and breadth, mm.
    vault_height : float
        Height factor of the vault (1 = average).
    face_width : float
        Bizygomatic breadth, mm.
    face_height, jaw_height : float
        Height factors of the upper face and of the mandible (1 = average).
    jaw_width : float
        Bigonial breadth, mm.
    gonial_deg : float
        Change of the ramus tilt (degrees; positive = more inclined backwards).
    chin_mm, prognathism_mm : float
        Forward offsets (mm) of the chin and of the alveolar processes.
    brow : float
        Prominence of the brow ridges and glabella (unitless, 0.25 to 1.4).
    orbit, nasal_width, ear : float
        Size factors of the orbits, the nasal aperture's width and the ears (1 = average).
    nose_projection_mm : float
        Projection of the nasal tip in front of the subnasale, mm.
    """

    cranial_length: float
    cranial_breadth: float
    vault_height: float
    face_width: float
    face_height: float
    jaw_width: float
    jaw_height: float
    gonial_deg: float
    chin_mm: float
    brow: float
    prognathism_mm: float
    orbit: float
    nasal_width: float
    nose_projection_mm: float
    ear: float

    @property
    def fw(self):
        """Face width factor (bizygomatic breadth / :data:`MEAN_FACE_WIDTH_MM`)."""
        return self.face_width / MEAN_FACE_WIDTH_MM

    @property
    def fh(self):
        """Face height factor."""
        return self.face_height


def draw_shape(rng):
    """Draw the shape parameters of one subject (independent, truncated normals).

    Parameters
    ----------
    rng : anything :func:`numpy.random.default_rng` accepts
        One normal is drawn per parameter, in the order of :data:`SHAPE_PRIORS`.

    Returns
    -------
    SubjectShape
    """
    rng = np.random.default_rng(rng)
    values = {}
    for f in fields(SubjectShape):
        prior = SHAPE_PRIORS[f.name]
        values[f.name] = float(np.clip(rng.normal(prior.mean, prior.sd), prior.lo, prior.hi))
    return SubjectShape(**values)
