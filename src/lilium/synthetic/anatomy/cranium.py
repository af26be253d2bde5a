"""The cranium and the upper face of the synthetic skull, as signed-distance parts.

Each function adds one part to the bone field (negative inside, skull frame, mm) of
:func:`lilium.synthetic.anatomy.bone.build_bone`, in this order: cranial vault with its
low-frequency bumps, temporal fossae, upper face block and maxilla, zygomatic bodies and
arches with the temporal roots and mastoids, brow ridges and glabella, orbits with their
entrances and margins, nasal bones, nasal aperture and cavity with the anterior nasal spine,
and (last, after the jaws) the external ear canals. The numbers of every part are the tables
below; a centre of a bilateral part is the left one (``x > 0``), mirrored with ``sx = -1``.
"""

import numpy as np

from ..volume_fields import (
    capsule,
    ellipsoid,
    elliptic_cylinder,
    plane,
    rotation_xyz,
    slab,
    superellipsoid,
)
from .parts import Blob, add_capsule, add_ellipsoid

# --------------------------------------------------------------------------------------------
# Tables (mm unless the name says otherwise)

#: Cranial vault, a boxy superellipsoid. Centre ``(0, y, forehead - L / 2 + offset)`` with
#: semi-axes ``(B / 2, height * vault_height, L / 2 - inset)`` (``L``, ``B``: cranial length and
#: breadth); the box is the superellipsoid's grown by ``box_margin_mm``.
VAULT = {
    "centre_y_mm": 30.0,
    "forehead_z_mm": 88.0,
    "centre_z_offset_mm": 2.0,
    "height_mm": 96.0,
    "length_inset_mm": 4.0,
    "exponents": (2.5, 2.2, 2.4),
    "box_margin_mm": 8,
}
#: Cranial base: the vault is intersected with an ellipsoid (narrower below the parietal
#: eminences) of centre ``(0, y, vault z)`` and semi-axes ``(B / 2 + extra, height, L)``, and
#: cut by the plane ``y = cut_y_mm``.
CRANIAL_BASE = {
    "centre_y_mm": 60.0,
    "breadth_extra_mm": 1.0,
    "height_mm": 110.0,
    "blend_mm": 6.0,
    "cut_y_mm": -26.0,
    "cut_blend_mm": 10.0,
}
#: Low-frequency bumps of the vault: plane waves of random direction and phase.
VAULT_WAVES = {"count": 6, "wavelength_mm": 70.0, "amplitude_mm": (0.15, 0.4)}
#: Temporal fossa (subtracted); centre x is ``B / 2 + centre_mm[0]``.
TEMPORAL_FOSSA = Blob((6.0, 14.0, 34.0), (22.0, 36.0, 34.0), 8, 6)
#: Upper face block; x radius scaled by the face width factor ``fw``.
FACE_BLOCK = Blob((0.0, 12.0, 52.0), (48.0, 34.0, 34.0), 10, 8)
#: Maxilla; centre y and y radius scaled by the face height factor ``fh``, x radius by ``fw``,
#: centre z plus half the prognathism.
MAXILLA = Blob((0.0, -22.0, 55.0), (32.0, 25.0, 33.0), 10, 8)
#: Zygomatic body; centre x scaled by ``fw``.
ZYGOMATIC_BODY = Blob((46.0, 2.0, 62.0), (12.0, 15.0, 13.0), 8, 6)
#: Zygomatic arch: a chain of slabs from the body (x scaled by ``fw``) back to the temporal
#: root; the last two x are measured inwards from zygion (half the face width).
ZYGOMATIC_ARCH = {
    "body_end_mm": (50.0, 0.0, 54.0),
    "zygion_inset_mm": (4.0, 7.0),
    "yz_mm": ((0.5, 26.0), (-1.0, 0.0)),
    "half_width_mm": 1.2,
    "half_height_mm": 3.0,
    "rounding_mm": 2.2,
    "box_margin_mm": 10,
    "blend_mm": 3,
}
#: Temporal root of the arch (centre x scaled by ``fw``, so it stays inside zygion: unscaled,
#: it made the zygion of every face narrower than 128.6 mm) and mastoid process.
TEMPORAL_ROOT = Blob((55.0, -3.0, -4.0), (11.0, 13.0, 15.0), 8, 6)
MASTOID = Blob((50.0, -22.0, -14.0), (8.0, 13.0, 10.0), 8, 5)
#: Brow ridge: a capsule from above the lateral orbit (x = orbit x + ``lateral_mm`` * fw) to
#: the glabella; y relative to the brow height; radii ``base + per_brow * brow``.
BROW_RIDGE = {
    "lateral_mm": 14.0,
    "lateral_yz_mm": (-3.0, 72.0),
    "medial_mm": (7.0, 1.5, 84.0),
    "radius_mm": ((3.0, 1.5), (3.5, 2.0)),
    "box_margin_mm": 12,
    "blend_mm": 6,
}
#: Glabella: centre ``(0, brow y + dy, z + per_brow * brow)``.
GLABELLA = {
    "dy_mm": 3.0,
    "z_mm": 80.0,
    "z_per_brow_mm": 2.0,
    "radii_mm": (13.0, 9.0, 7.0),
    "margin_mm": 8,
    "blend_mm": 6,
}
#: Orbit cavity (subtracted): the design ellipsoid turned by ``(x, y)`` degrees (y mirrored).
ORBIT_CAVITY = {"tilt_deg": (-8.0, 14.0), "margin_mm": 6, "blend_mm": 2.5}
#: Orbital margin: a ring of capsules around the opening, ``offset_mm`` (x, y) outside the
#: design ellipse (the transverse offset makes the orbital breadth M51a, dacryon to
#: ectoconchion, about 40 mm); the lateral side is set back, the lower half a little too;
#: thickness grows towards the lateral side.
ORBITAL_MARGIN = {
    "points": 19,
    "offset_mm": (3.5, 1.5),
    "front_z_mm": 81.0,
    "lateral_setback_mm": 11.0,
    "lower_setback_mm": 2.0,
    "thickness_mm": (2.6, 0.8),
    "box_margin_mm": 8,
    "blend_mm": 2.0,
}
#: Orbital entrance (subtracted): an elliptic cylinder along z, from ``back_z_mm`` to
#: ``front_z_mm``, whose edge is the inner edge of the margin's medial side (semi-axes: the
#: design ones plus the margin's offset less its medial thickness). It clears the face block
#: and the brow in front of the cavity, which otherwise closed the medial third of the opening
#: (dacryon about 23 mm off the midline instead of about 13).
ORBITAL_ENTRANCE = {"back_z_mm": 66.0, "front_z_mm": 110.0, "box_margin_mm": 6, "blend_mm": 4.0}
#: Nasal bones: a slab from below the brow (y = brow y + dy) to ``(0, y * fh, z + 0.3 * pr)``.
NASAL_BONES = {
    "top_dy_mm": -10.0,
    "top_z_mm": 83.0,
    "bottom_y_mm": 3.0,
    "bottom_z_mm": 93.0,
    "bottom_z_per_prognathism": 0.3,
    "half_width_mm": (3.0, 6.0),
    "half_height_mm": 1.5,
    "rounding_mm": 1.8,
    "box_margin_mm": 12,
    "blend_mm": 3,
}
#: Nasal aperture (the design ellipsoid, subtracted) and the cavity behind it (centre y
#: scaled by ``fh``, x radius by the nasal width factor like the aperture's: unscaled, the
#: cavity's side walls made the aperture's lateral margins, and alare-alare grew about 17 mm
#: per unit of the factor instead of about 21).
NASAL_APERTURE = {"margin_mm": 6, "blend_mm": 2}
NASAL_CAVITY = Blob((0.0, -6.0, 62.0), (13.0, 22.0, 26.0), 6, 3)
#: Anterior nasal spine: a capsule ``length_mm`` long ending at the design ANS point.
NASAL_SPINE = {"length_mm": 8.0, "radius_mm": (2.2, 1.2), "box_margin_mm": 8, "blend_mm": 2}
#: External ear canal (subtracted): a capsule through the design canal centre.
EAR_CANAL = {"medial_mm": 14.0, "lateral_mm": 20.0, "box_margin_mm": 8, "blend_mm": 1.5}

# --------------------------------------------------------------------------------------------
# Parts


def add_vault(bone, s, rng):
    """Cranial vault and base, with low-frequency bumps of about +-1 mm (in place).

    Parameters
    ----------
    bone : GridField
    s : SubjectShape
    rng : numpy.random.Generator
        Draws the bumps (directions, phases, amplitudes).

    Returns
    -------
    centre_mm : ndarray of shape (3,)
        Centre of the vault.
    """
    L, B, v = s.cranial_length, s.cranial_breadth, VAULT
    vc = np.array([0.0, v["centre_y_mm"], v["forehead_z_mm"] - L / 2 + v["centre_z_offset_mm"]])
    vr = np.array([B / 2, v["height_mm"] * s.vault_height, L / 2 - v["length_inset_mm"]])
    lo, hi = vc - vr - v["box_margin_mm"], vc + vr + v["box_margin_mm"]
    bone.combine(lambda p: superellipsoid(p, vc, vr, v["exponents"]), lo, hi, "union")
    base = CRANIAL_BASE
    bc = np.array([0.0, base["centre_y_mm"], vc[2]])
    br = np.array([B / 2 + base["breadth_extra_mm"], base["height_mm"], L])
    bone.combine(lambda p: ellipsoid(p, bc, br), lo, hi, "intersect", base["blend_mm"])
    cut = (0, base["cut_y_mm"], 0)
    bone.combine(lambda p: plane(p, cut, (0, -1, 0)), lo, hi, "intersect", base["cut_blend_mm"])
    w = VAULT_WAVES
    waves = [
        (rng.normal(size=3), rng.uniform(0, 2 * np.pi), rng.uniform(*w["amplitude_mm"]))
        for _ in range(w["count"])
    ]

    def bumps(p):
        out = 0.0
        for kvec, phase, amp in waves:
            kvec = kvec / np.linalg.norm(kvec) * (2 * np.pi / w["wavelength_mm"])
            out = out + amp * np.cos(p[0] * kvec[0] + p[1] * kvec[1] + p[2] * kvec[2] + phase)
        return out

    bone.combine(bumps, lo, hi, "add")
    return vc


def add_temporal_fossae(bone, s):
    """Hollow the temporal fossae on both sides of the vault (in place)."""
    f = TEMPORAL_FOSSA
    for sx in (1, -1):
        fc = np.array([sx * (s.cranial_breadth / 2 + f.centre_mm[0]), *f.centre_mm[1:]])
        fr = np.array(f.radii_mm)
        add_ellipsoid(bone, fc, fr, f.margin_mm, "subtract", f.blend_mm)


def add_face_block(bone, s):
    """Upper face block and maxilla (in place)."""
    fw, fh, pr = s.fw, s.fh, s.prognathism_mm
    fb, mx = FACE_BLOCK, MAXILLA
    for c, r, part in (
        (fb.centre_mm, (fb.radii_mm[0] * fw, *fb.radii_mm[1:]), fb),
        (
            (mx.centre_mm[0], mx.centre_mm[1] * fh, mx.centre_mm[2] + pr / 2),
            (mx.radii_mm[0] * fw, mx.radii_mm[1] * fh, mx.radii_mm[2]),
            mx,
        ),
    ):
        add_ellipsoid(bone, c, r, part.margin_mm, "union", part.blend_mm)


def add_zygomatics(bone, s, d):
    """Zygomatic bodies and arches, temporal roots of the arches and mastoids (in place).

    Parameters
    ----------
    bone : GridField
    s : SubjectShape
    d : dict
        Design positions (:func:`~lilium.synthetic.anatomy.bone.design_points`).
    """
    fw, zx = s.fw, d["zygion_x"]
    zb, arch = ZYGOMATIC_BODY, ZYGOMATIC_ARCH
    (in1, in2), ((y1, z1), (y2, z2)) = arch["zygion_inset_mm"], arch["yz_mm"]
    for sx in (1, -1):
        c = (sx * zb.centre_mm[0] * fw, *zb.centre_mm[1:])
        add_ellipsoid(bone, c, zb.radii_mm, zb.margin_mm, "union", zb.blend_mm)
        e = arch["body_end_mm"]
        chain = [(sx * e[0] * fw, e[1], e[2]), (sx * (zx - in1), y1, z1), (sx * (zx - in2), y2, z2)]
        for a, b in zip(chain[:-1], chain[1:], strict=True):
            m = arch["box_margin_mm"]
            lo_, hi_ = np.minimum(a, b) - m, np.maximum(a, b) + m
            bone.combine(
                lambda p, a=a, b=b: slab(
                    p,
                    a,
                    b,
                    (0, 1, 0),
                    arch["half_width_mm"],
                    arch["half_height_mm"],
                    arch["rounding_mm"],
                ),
                lo_,
                hi_,
                "union",
                arch["blend_mm"],
            )
        for part, x_scale in ((TEMPORAL_ROOT, fw), (MASTOID, 1.0)):
            c = (sx * part.centre_mm[0] * x_scale, *part.centre_mm[1:])
            add_ellipsoid(bone, c, part.radii_mm, part.margin_mm, "union", part.blend_mm)


def add_brow(bone, s, d):
    """Brow ridges and glabella, more prominent with ``s.brow`` (in place)."""
    by, br, gl = d["brow_y"], BROW_RIDGE, GLABELLA
    (ra0, ra1), (rb0, rb1) = br["radius_mm"]
    for sx in (1, -1):
        ly, lz = br["lateral_yz_mm"]
        a = (sx * (d["orbit"][0] + br["lateral_mm"] * s.fw), by + ly, lz)
        mx, my, mz = br["medial_mm"]
        b = (sx * mx, by + my, mz)
        m = br["box_margin_mm"]
        lo_, hi_ = np.minimum(a, b) - m, np.maximum(a, b) + m
        bone.combine(
            lambda p, a=a, b=b: capsule(p, a, b, ra0 + ra1 * s.brow, rb0 + rb1 * s.brow),
            lo_,
            hi_,
            "union",
            br["blend_mm"],
        )
    c = (0.0, by + gl["dy_mm"], gl["z_mm"] + gl["z_per_brow_mm"] * s.brow)
    add_ellipsoid(bone, c, gl["radii_mm"], gl["margin_mm"], "union", gl["blend_mm"])


def add_orbits(bone, d):
    """Orbit cavities, their entrances and their margins (in place)."""
    oc = ORBIT_CAVITY
    for sx in (1, -1):
        c, r = d["orbit"] * (sx, 1, 1), d["orbit_radii"]
        rot = rotation_xyz(oc["tilt_deg"][0], sx * oc["tilt_deg"][1], 0.0)
        add_ellipsoid(bone, c, r, oc["margin_mm"], "subtract", oc["blend_mm"], rot)
        _add_orbital_entrance(bone, c, r)
    for sx in (1, -1):
        _add_orbital_margin(bone, d["orbit"] * (sx, 1, 1), d["orbit_radii"], sx)


def _add_orbital_entrance(bone, o, r):
    """Clear the bone in front of one orbit cavity, inside its margin (in place)."""
    oe, (off_x, off_y) = ORBITAL_ENTRANCE, ORBITAL_MARGIN["offset_mm"]
    t = ORBITAL_MARGIN["thickness_mm"][0]
    radii = (r[0] + off_x - t, r[1] + off_y - t)
    z0, z1, m = oe["back_z_mm"], oe["front_z_mm"], oe["box_margin_mm"]
    lo = (o[0] - radii[0] - m, o[1] - radii[1] - m, z0 - m)
    hi = (o[0] + radii[0] + m, o[1] + radii[1] + m, z1 + m)
    bone.combine(
        lambda p: elliptic_cylinder(p, o, radii, z0, z1), lo, hi, "subtract", oe["blend_mm"]
    )


def _add_orbital_margin(bone, o, r, sx):
    """A ring of bars around one orbital opening, the lateral side set back (in place)."""
    om = ORBITAL_MARGIN
    off_x, off_y = om["offset_mm"]
    phi = np.linspace(0, 2 * np.pi, om["points"])
    lateral = 0.5 * (1 + np.cos(phi))  # 1 at the lateral margin, 0 at the medial one
    lower = (np.sin(phi) < 0) * np.abs(np.sin(phi))
    ring = np.column_stack(
        [
            o[0] + sx * (r[0] + off_x) * np.cos(phi),
            o[1] + (r[1] + off_y) * np.sin(phi),
            om["front_z_mm"] - om["lateral_setback_mm"] * lateral - om["lower_setback_mm"] * lower,
        ]
    )
    thick = om["thickness_mm"][0] + om["thickness_mm"][1] * lateral
    for a, b, ra, rb in zip(ring[:-1], ring[1:], thick[:-1], thick[1:], strict=True):
        add_capsule(bone, a, b, ra, rb, om["box_margin_mm"], "union", om["blend_mm"])


def add_nose(bone, s, d):
    """Nasal bones, nasal aperture and cavity, anterior nasal spine (in place)."""
    nb, fh, pr = NASAL_BONES, s.fh, s.prognathism_mm
    top = (0.0, d["brow_y"] + nb["top_dy_mm"], nb["top_z_mm"])
    bottom = (
        0.0,
        nb["bottom_y_mm"] * fh,
        nb["bottom_z_mm"] + nb["bottom_z_per_prognathism"] * pr,
    )
    m = nb["box_margin_mm"]
    bone.combine(
        lambda p: slab(
            p, top, bottom, (0, 0, 1), nb["half_width_mm"], nb["half_height_mm"], nb["rounding_mm"]
        ),
        np.minimum(top, bottom) - m,
        np.maximum(top, bottom) + m,
        "union",
        nb["blend_mm"],
    )
    na, cav = NASAL_APERTURE, NASAL_CAVITY
    c, r = d["nasal_aperture"], d["nasal_aperture_radii"]
    add_ellipsoid(bone, c, r, na["margin_mm"], "subtract", na["blend_mm"])
    c2 = (cav.centre_mm[0], cav.centre_mm[1] * fh, cav.centre_mm[2])
    r2 = (cav.radii_mm[0] * s.nasal_width, *cav.radii_mm[1:])
    add_ellipsoid(bone, c2, r2, cav.margin_mm, "subtract", cav.blend_mm)
    sp = NASAL_SPINE
    a, b = d["ans"] - (0, 0, sp["length_mm"]), d["ans"]
    add_capsule(bone, a, b, *sp["radius_mm"], sp["box_margin_mm"], "union", sp["blend_mm"])


def add_ear_canals(bone, d):
    """Drill the external ear canals through the temporal bones (in place)."""
    ec = EAR_CANAL
    for sx in (1, -1):
        cc = d["canal"] * (sx, 1, 1)
        a, b = cc - (sx * ec["medial_mm"], 0, 0), cc + (sx * ec["lateral_mm"], 0, 0)
        add_capsule(
            bone, a, b, d["canal_radius"], None, ec["box_margin_mm"], "subtract", ec["blend_mm"]
        )
