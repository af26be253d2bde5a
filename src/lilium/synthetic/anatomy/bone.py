"""The synthetic skull as a signed-distance field, and its design positions.

:func:`design_points` turns the shape parameters into the positions the parts are built
around (orbits, nasal aperture, dental heights, chin, gonia, ear canals, brow; table
:data:`DESIGN`); :func:`build_bone` fills a :class:`~lilium.synthetic.volume_fields.GridField`
(:data:`GRID_LO_MM` to :data:`GRID_HI_MM` at :data:`VOXEL_MM`) with the parts of
:mod:`.cranium` and :mod:`.jaws`, in a fixed order (the smooth unions do not commute bit for
bit). Skull frame, mm; the field is negative inside the bone.
"""

import numpy as np

from ..volume_fields import GridField
from .cranium import (
    add_brow,
    add_ear_canals,
    add_face_block,
    add_nose,
    add_orbits,
    add_temporal_fossae,
    add_vault,
    add_zygomatics,
)
from .jaws import add_dentition, add_mandible

#: Voxel size (mm) of the synthetic CT volume.
VOXEL_MM = 2.0
#: Box of the synthetic volume (skull frame, mm).
GRID_LO_MM = (-102.0, -172.0, -118.0)
GRID_HI_MM = (102.0, 142.0, 140.0)

#: Design positions (skull frame, mm) of an average subject, and how the shape scales them:
#: ``fw`` / ``fh`` = face width / height factors, ``pr`` = prognathism (mm).
DESIGN = {
    # Orbit centre (x times fw) and semi-axes (times the orbit factor).
    "orbit_centre_mm": (33.0, 16.0, 62.0),
    "orbit_radii_mm": (19.5, 16.5, 27.0),
    # Nasal aperture centre (y times fh) and semi-axes (x times nasal_width, y times fh).
    "nasal_aperture_centre_mm": (0.0, -10.0, 83.0),
    "nasal_aperture_radii_mm": (12.0, 17.0, 16.0),
    # Anterior nasal spine: y times fh, z plus pr times the factor.
    "ans_y_mm": -27.5,
    "ans_z_mm": 90.0,
    "ans_z_per_prognathism": 0.5,
    # Midline heights of the dentition (times fh).
    "prosthion_y_mm": -41.0,
    "occlusal_y_mm": -51.0,
    "infradentale_y_mm": -61.0,
    # Menton below the infradentale (times jaw_height); chin z (plus pr times the factor, plus
    # the chin offset).
    "symphysis_height_mm": 31.0,
    "chin_z_mm": 86.0,
    "chin_z_per_prognathism": 0.5,
    # Gonion: x = half the jaw width, y above the menton (times jaw_height), z.
    "gonion_above_menton_mm": 25.0,
    "gonion_z_mm": 6.0,
    # Ear canal centre (left) and radius.
    "canal_centre_mm": (58.0, -1.0, -4.0),
    "canal_radius_mm": 4.0,
    # Brow ridge height: base plus the factor times the orbit factor.
    "brow_y_mm": 16.0,
    "brow_y_per_orbit_mm": 18.0,
}


def design_points(s):
    """Design positions (skull frame, mm) derived from the shape parameters.

    Parameters
    ----------
    s : SubjectShape

    Returns
    -------
    dict
        ``orbit``, ``orbit_radii``, ``nasal_aperture``, ``nasal_aperture_radii``, ``ans``,
        ``gonion``, ``canal`` (ndarray of shape (3,); bilateral ones for the left side), and
        ``prosthion_y``, ``occlusal_y``, ``infradentale_y``, ``menton_y``, ``chin_z``,
        ``zygion_x``, ``canal_radius``, ``brow_y`` (float).
    """
    fw, fh, t = s.fw, s.fh, DESIGN
    pr = s.prognathism_mm
    ox, oy, oz = t["orbit_centre_mm"]
    nx, ny, nz = t["nasal_aperture_centre_mm"]
    nrx, nry, nrz = t["nasal_aperture_radii_mm"]
    d = {}
    d["orbit"] = np.array([ox * fw, oy, oz])
    d["orbit_radii"] = np.array(t["orbit_radii_mm"]) * s.orbit
    d["nasal_aperture"] = np.array([nx, ny * fh, nz])
    d["nasal_aperture_radii"] = np.array([nrx * s.nasal_width, nry * fh, nrz])
    d["ans"] = np.array([0.0, t["ans_y_mm"] * fh, t["ans_z_mm"] + t["ans_z_per_prognathism"] * pr])
    d["prosthion_y"] = t["prosthion_y_mm"] * fh
    d["occlusal_y"] = t["occlusal_y_mm"] * fh
    d["infradentale_y"] = t["infradentale_y_mm"] * fh
    d["menton_y"] = d["infradentale_y"] - t["symphysis_height_mm"] * s.jaw_height
    d["chin_z"] = t["chin_z_mm"] + t["chin_z_per_prognathism"] * pr + s.chin_mm
    gy = d["menton_y"] + t["gonion_above_menton_mm"] * s.jaw_height
    d["gonion"] = np.array([s.jaw_width / 2, gy, t["gonion_z_mm"]])
    d["zygion_x"] = s.face_width / 2
    d["canal"] = np.array(t["canal_centre_mm"])
    d["canal_radius"] = t["canal_radius_mm"]
    d["brow_y"] = t["brow_y_mm"] + t["brow_y_per_orbit_mm"] * s.orbit
    return d


def build_bone(s, rng, mandible=True):
    """The bone field of a subject (negative inside) and its design positions.

    Parameters
    ----------
    s : SubjectShape
    rng : numpy.random.Generator
        Draws the low-frequency bumps of the vault (its only draws: the same generator state
        gives the same vault with or without the mandible).
    mandible : bool
        False: the cranium alone, without the mandible and the lower teeth (a skull found
        without its jaw); the other parts are built as with it, in the same order.

    Returns
    -------
    bone : GridField
        Skull frame, mm.
    design : dict
        :func:`design_points`, plus (with the mandible) ``body_arch`` (ndarray of shape
        (M, 2), the mandibular body's arch ``(x, z)``), ``body_y`` (ndarray of shape (M,)) and
        ``ramus_top`` (ndarray of shape (3,)).
    """
    d = design_points(s)
    bone = GridField(GRID_LO_MM, GRID_HI_MM, VOXEL_MM)
    add_vault(bone, s, rng)
    add_temporal_fossae(bone, s)
    add_face_block(bone, s)
    add_zygomatics(bone, s, d)
    add_brow(bone, s, d)
    add_orbits(bone, d)
    add_nose(bone, s, d)
    add_dentition(bone, s, d, lower=mandible)
    if mandible:
        d["body_arch"], d["body_y"], d["ramus_top"] = add_mandible(bone, s, d)
    add_ear_canals(bone, d)
    return bone, d
