"""Is the mesh a skull in millimetres? The checks before and after the template fit.

Each failed check is a ``ValueError`` of one line naming the mesh, what it looks like and the
fix; nothing is placed on a mesh that fails.
"""

import numpy as np

#: Largest side (mm) of a whole skull's bounding box (with or without the mandible; a CT's cut
#: vault or a missing face keeps it above the lower bound).
SKULL_EXTENT_MM = (120.0, 300.0)
#: A mesh whose largest side, times these factors, is a skull's: metres, centimetres, inches.
UNIT_FACTORS = {"metres": 1000.0, "centimetres": 10.0, "inches": 25.4}
#: After the fit: largest trimmed RMS distance (mm) to the template, and the smallest share of
#: the template's face landmarks (orbits, nasal aperture, nasion) that must find their surface.
FIT_RMS_MM = 7.5
FACE_FOUND_SHARE = 0.7
FACE_LANDMARKS = (
    "nasion",
    "ectoconchion_l",
    "ectoconchion_r",
    "dacryon_l",
    "dacryon_r",
    "orbitale_l",
    "orbitale_r",
    "alare_l",
    "alare_r",
    "zygion_l",
    "zygion_r",
)


def check_skull_extent(vertices, source="mesh"):
    """Raise when the mesh's size is not a skull's in millimetres.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    source : str
        Names the mesh in the message.
    """
    extent = float(np.ptp(vertices, axis=0).max())
    lo, hi = SKULL_EXTENT_MM
    if lo <= extent <= hi:
        return
    for unit, factor in UNIT_FACTORS.items():
        if lo <= extent * factor <= hi:
            raise ValueError(
                f"{source}: the mesh spans {extent:.3g} units, a skull in {unit} (a skull spans "
                f"{lo:.0f}-{hi:.0f} mm); rescale it to millimetres (x {factor:g})"
            )
    what = "a fragment or a part of a skull" if extent < lo else "larger than a skull"
    raise ValueError(
        f"{source}: the mesh spans {extent:.3g} mm, {what} (a whole skull spans {lo:.0f}-"
        f"{hi:.0f} mm); give the whole skull in millimetres"
    )


def check_skull_fit(rms_mm, found, source="mesh"):
    """Raise when the template fit says the mesh is not a skull.

    Parameters
    ----------
    rms_mm : float
        Trimmed RMS distance of the global fit.
    found : collection of str
        The landmarks whose template patch found its surface.
    """
    share = np.mean([n in found for n in FACE_LANDMARKS])
    if rms_mm > FIT_RMS_MM or share < FACE_FOUND_SHARE:
        raise ValueError(
            f"{source}: does not look like a skull (template fit {rms_mm:.1f} mm RMS, "
            f"{share:.0%} of the orbits, nasal aperture and cheek bones found); give a bone "
            "surface of a skull (not a face scan or another object) with its face"
        )
