"""Standard craniometric measurements of a synthetic skull, and the adult population they target.

:func:`measure` takes the classic measurements (Martin's numbers, Howells' codes) from a
subject's skull mesh and cranial landmarks; :data:`PUBLISHED` holds the adult means and SDs the
generator's shape priors (:data:`~.shape.SHAPE_PRIORS`) are tuned to, with their sources in
``docs/population.md``. ``benchmarks/studies/population.py`` prints the two side by side.

Skull frame (mm): x = the subject's left, y = up, z = anterior; the midsagittal plane is x = 0
and y = 0 lies at porion height.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Reference:
    """A published adult value: mean and SD (mm), the two sexes pooled.

    Attributes
    ----------
    label : str
        Martin number / Howells code and name.
    mean_mm, sd_mm : float
        Pooled-sex mean and SD: the mean of the male and female means and
        ``sqrt(sd_within^2 + (male - female)^2 / 4)``.
    male_mm, female_mm, sd_within_mm : float
        The sex means and the (rounded) within-sex SD they come from.
    source : str
        Short key of the source (see ``docs/population.md``).
    """

    label: str
    male_mm: float
    female_mm: float
    sd_within_mm: float
    source: str

    @property
    def mean_mm(self):
        return 0.5 * (self.male_mm + self.female_mm)

    @property
    def sd_mm(self):
        return float(np.hypot(self.sd_within_mm, 0.5 * (self.male_mm - self.female_mm)))


#: Adult reference values (approximate, rounded; docs/population.md says where each is from).
PUBLISHED = {
    "cranial_length": Reference("M1 / GOL glabella-opisthocranion", 184.0, 176.0, 6.0, "howells"),
    "cranial_breadth": Reference("M8 / XCB maximum cranial breadth", 139.0, 134.0, 5.0, "howells"),
    "bizygomatic_breadth": Reference("M45 / ZYB zygion-zygion", 132.0, 123.0, 5.0, "howells"),
    "bigonial_breadth": Reference("M66 gonion-gonion", 99.0, 92.0, 5.5, "mandible"),
    "upper_face_height": Reference("M48 / NPH nasion-prosthion", 69.0, 64.0, 4.0, "howells"),
    "total_face_height": Reference("M47 nasion-gnathion", 120.0, 110.0, 6.0, "martin"),
    "nasal_breadth": Reference("M54 / NLB nasal aperture breadth", 25.5, 24.5, 2.0, "howells"),
    "orbital_breadth": Reference("M51a / OBB dacryon-ectoconchion", 41.0, 39.0, 1.8, "howells"),
}

#: Half-width (mm) of the slab about the midsagittal plane searched for opisthocranion.
MIDSAGITTAL_SLAB_MM = 3.0
#: Euryon is searched above this height (mm, skull frame y): above the zygomatic arches and
#: the supramastoid crests, as Martin's M8 prescribes.
EURYON_ABOVE_MM = 15.0


def _distance(a, b):
    return float(np.linalg.norm(np.asarray(a, float) - np.asarray(b, float)))


def measure(skull_vertices_mm, cranial_landmarks):
    """The craniometric measurements of one skull (mm).

    Parameters
    ----------
    skull_vertices_mm : array_like of shape (V, 3)
        Skull mesh vertices (skull frame).
    cranial_landmarks : dict of str -> array_like of shape (3,)

    Returns
    -------
    dict of str -> float
        The keys of :data:`PUBLISHED`:

        - ``cranial_length``: glabella to the farthest vertex within
          :data:`MIDSAGITTAL_SLAB_MM` of the midsagittal plane (opisthocranion);
        - ``cranial_breadth``: largest x extent of the vertices above :data:`EURYON_ABOVE_MM`
          (euryon to euryon);
        - ``bizygomatic_breadth``, ``bigonial_breadth``: zygion-zygion, gonion-gonion;
        - ``upper_face_height``, ``total_face_height``: nasion-prosthion, nasion-gnathion
          (the generator has no menton; gnathion is the usual stand-in);
        - ``nasal_breadth``: alare-alare (the widest points of the nasal aperture);
        - ``orbital_breadth``: dacryon-ectoconchion, mean of the two sides.
    """
    v = np.asarray(skull_vertices_mm, dtype=float)
    lm = cranial_landmarks
    mid = v[np.abs(v[:, 0]) <= MIDSAGITTAL_SLAB_MM]
    vault = v[v[:, 1] >= EURYON_ABOVE_MM]
    return {
        "cranial_length": float(np.max(np.linalg.norm(mid - np.asarray(lm["glabella"]), axis=1))),
        "cranial_breadth": float(np.ptp(vault[:, 0])),
        "bizygomatic_breadth": _distance(lm["zygion_l"], lm["zygion_r"]),
        "bigonial_breadth": _distance(lm["gonion_l"], lm["gonion_r"]),
        "upper_face_height": _distance(lm["nasion"], lm["prosthion"]),
        "total_face_height": _distance(lm["nasion"], lm["gnathion"]),
        "nasal_breadth": _distance(lm["alare_l"], lm["alare_r"]),
        "orbital_breadth": 0.5
        * (
            _distance(lm["dacryon_l"], lm["ectoconchion_l"])
            + _distance(lm["dacryon_r"], lm["ectoconchion_r"])
        ),
    }
