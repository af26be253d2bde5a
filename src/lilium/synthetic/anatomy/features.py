"""Features of the synthetic skin built around the facial targets: pads, nose, lips, ears.

Each function changes the skin field (negative inside, skull frame, mm) of
:func:`lilium.synthetic.anatomy.skin.build_skin` in place: :func:`add_pad` makes a target the
tip of a rounded pad (so it lies on a silhouette), :func:`add_nose` the dorsum, tip, alae and
columella, :func:`add_lips` the lips and the mouth slit, :func:`add_ear` an auricle lateral to
porion. The numbers are the tables below; offsets are from the named target.
"""

import numpy as np

from ..volume_fields import capsule, ellipsoid, rotation_xyz
from .parts import add_gaussian

#: Silhouette pads: (facial landmark, axis removed from its normal, radius mm). x (0) for the
#: profile, z (2) for the frontal outline.
PADS = (
    ("zygion_l", 2, 9.0),
    ("zygion_r", 2, 9.0),
    ("gonion_l", 2, 9.0),
    ("gonion_r", 2, 9.0),
    ("pogonion", 0, 7.0),
    ("gnathion", 0, 6.0),
)
#: Pad of the upper-lip tubercle: labiale superius is its most anterior point (profile).
LIP_TUBERCLE_PAD = ("labiale_superius", 0, 4.0)
#: A pad's skin is first pushed this far (mm) behind its target; the sphere's box margin (mm)
#: and blend (mm).
PAD_MARGIN_MM = 1.0
PAD_BOX_MM = 4
PAD_BLEND_MM = 1.0
#: Rise (mm per mm forward) of the lower border of the nose from the subnasale to the tip.
NOSE_RISE = 0.42
#: Nose: tip ``subnasale + (0, tip_y_mm + rise * projection, projection)``; the dorsum runs from
#: behind the nasion to behind the tip; the alae sit medial-behind-below the alare targets; the
#: columella runs from the subnasale forwards to ``projection - columella_short_mm``.
NOSE = {
    "tip_y_mm": 7.0,
    "dorsum_from_nasion_mm": (0, 5.0, 5.0),
    "dorsum_from_tip_mm": (0, -3.0, 7.0),
    "dorsum_radius_mm": (5.0, 6.5),
    "dorsum_box_mm": 14,
    "dorsum_blend_mm": 5.0,
    "tip_back_mm": (0, 0, 7.0),
    "tip_radii_mm": (9.5, 7.0, 7.0),
    "tip_box_mm": 18,
    "tip_blend_mm": 3,
    "ala_from_alare_mm": (6.0, -1.5, 4.0),
    "ala_radii_mm": (7.0, 6.5, 9.0),
    "ala_box_mm": 16,
    "ala_blend_mm": 3,
    "columella_start_mm": (0.0, 2.6, 1.0),
    "columella_short_mm": 6.0,
    "columella_radius_mm": (2.6, 3.2),
    "columella_box_mm": 16,
    "columella_blend_mm": 1.5,
}
#: Lips around the upper-lip target: upper and lower lip ellipsoids, and the mouth slit
#: (a thin capsule subtracted at the stomion, ``stomion_dy_mm`` below the target).
LIPS = {
    "upper_mm": (0, 1.5, -9.5),
    "upper_radii_mm": (22.0, 7.0, 9.5),
    "lower_mm": (0, -11.5, -11.5),
    "lower_radii_mm": (20.0, 6.5, 9.5),
    "box_mm": 30,
    "blend_mm": 3,
    "stomion_dy_mm": -5.0,
    "slit_half_width_mm": 25.0,
    "slit_dz_mm": -8.0,
    "slit_radius_mm": 1.2,
    "slit_box_lo_mm": 6,
    "slit_box_hi_mm": (0, 6, 20),
    "slit_blend_mm": 1.0,
}
#: External ear: a shell about 60 mm tall and 34 mm wide (semi-axes times the ear factor),
#: turned by ``tilt_deg`` (y mirrored), standing out from the side of the head, with a
#: rolled helix, a hollow concha and a stalk joining it to the head.
EAR = {
    "ray_start_x_mm": 101.0,
    "side_fallback_mm": 8.0,
    "tilt_deg": (-12.0, -32.0),
    "half_height_mm": 30.0,
    "half_width_mm": 17.0,
    "centre_mm": (7.0, 4.0, -12.0),
    "shell_thickness_mm": 4.0,
    "shell_box_mm": 40,
    "shell_blend_mm": 4.0,
    "helix_phi_pi": (-0.35, 1.25),
    "helix_points": 12,
    "helix_out_mm": 1.8,
    "helix_reach": 0.92,
    "helix_radius_mm": 2.6,
    "helix_box_mm": 7,
    "helix_blend_mm": 1.5,
    "concha_out_mm": 4.5,
    "concha_offset": (0.15, 0.2),
    "concha_radii": (4.0, 0.38, 0.42),
    "concha_box_mm": 20,
    "concha_blend_mm": 1.5,
    "stalk_head_mm": (-4.0, -2.0, -6.0),
    "stalk_ear_mm": -2.0,
    "stalk_ear_up": 0.1,
    "stalk_radius_mm": (7.0, 6.0),
    "stalk_box_mm": 14,
    "stalk_blend_mm": 4.0,
}


def add_pad(field, target, direction, flat_axis, radius, margin=PAD_MARGIN_MM):
    """Make ``target`` the tip of a rounded pad of the skin (in place).

    The pad's outward normal at the target is ``direction`` with its ``flat_axis`` component
    removed (0 = x for the profile, 2 = z for the frontal outline), so the target lies on the
    silhouette of views along that axis. The skin around is first pushed ``margin`` mm behind
    the target (a Gaussian of width ``radius``), then a sphere of ``radius`` touching the
    target from inside is added.

    Parameters
    ----------
    field : GridField
    target, direction : ndarray of shape (3,)
        mm; the soft-tissue direction (need not be unit).
    flat_axis : {0, 2}
    radius, margin : float
        mm.
    """
    n = np.array(direction, float)
    n[flat_axis] = 0.0
    n /= np.linalg.norm(n)
    sigma = float(radius)
    need = margin - float(field.sample(target[None])[0])
    if need > 0:
        add_gaussian(field, target, need, sigma)
    c = target - radius * n
    field.combine(
        lambda p: ellipsoid(p, c, (radius,) * 3),
        c - radius - PAD_BOX_MM,
        c + radius + PAD_BOX_MM,
        "union",
        PAD_BLEND_MM,
    )


def add_nose(skin, targets, projection_mm):
    """Dorsum from the nasion to the tip, tip lobule, alae and columella (in place).

    The lower border rises from the subnasale towards the tip (:data:`NOSE_RISE`; nasolabial
    angle > 90 deg), so the subnasale is seen from the front.

    Parameters
    ----------
    skin : GridField
    targets : dict of str -> ndarray of shape (3,)
        Facial targets (``nasion``, ``subnasale``, ``alare_l``, ``alare_r``), mm.
    projection_mm : float
        Tip projection in front of the subnasale.
    """
    no, fn, fsn = NOSE, targets["nasion"], targets["subnasale"]
    proj, rise = projection_mm, NOSE_RISE
    tip = fsn + np.array([0.0, no["tip_y_mm"] + rise * proj, proj])
    dorsum_a, dorsum_b = fn - no["dorsum_from_nasion_mm"], tip - no["dorsum_from_tip_mm"]
    m = no["dorsum_box_mm"]
    skin.combine(
        lambda p: capsule(p, dorsum_a, dorsum_b, *no["dorsum_radius_mm"]),
        np.minimum(dorsum_a, dorsum_b) - m,
        np.maximum(dorsum_a, dorsum_b) + m,
        "union",
        no["dorsum_blend_mm"],
    )
    c_tip, m = tip - no["tip_back_mm"], no["tip_box_mm"]
    skin.combine(
        lambda p: ellipsoid(p, c_tip, no["tip_radii_mm"]),
        c_tip - m,
        c_tip + m,
        "union",
        no["tip_blend_mm"],
    )
    ax, ay, az = no["ala_from_alare_mm"]
    for sx, nm in ((1, "alare_l"), (-1, "alare_r")):
        c, m = targets[nm] - (sx * ax, ay, az), no["ala_box_mm"]
        skin.combine(
            lambda p, c=c: ellipsoid(p, c, no["ala_radii_mm"]),
            c - m,
            c + m,
            "union",
            no["ala_blend_mm"],
        )
    col_a = fsn + no["columella_start_mm"]
    col_y, short = no["columella_start_mm"][1], no["columella_short_mm"]
    col_b = fsn + (0.0, col_y + rise * (proj - short), proj - short)
    m = no["columella_box_mm"]
    skin.combine(
        lambda p: capsule(p, col_a, col_b, *no["columella_radius_mm"]),
        col_a - m,
        col_b + m,
        "union",
        no["columella_blend_mm"],
    )


def add_lips(skin, fls):
    """Upper and lower lips and the mouth slit, around the upper-lip target (in place).

    Parameters
    ----------
    skin : GridField
    fls : ndarray of shape (3,)
        Labiale superius target (may lie a little off the midline), mm.

    Returns
    -------
    stomion_y : float
        Height of the mouth slit, mm.
    """
    li, m = LIPS, LIPS["box_mm"]
    for offset, radii in (
        (li["upper_mm"], li["upper_radii_mm"]),
        (li["lower_mm"], li["lower_radii_mm"]),
    ):
        c = fls + offset
        skin.combine(
            lambda p, c=c, radii=radii: ellipsoid(p, c, radii),
            c - m,
            c + m,
            "union",
            li["blend_mm"],
        )
    stomion_y = fls[1] + li["stomion_dy_mm"]
    half, dz = li["slit_half_width_mm"], li["slit_dz_mm"]
    m_a = np.array([fls[0] - half, stomion_y, fls[2] + dz])
    m_b = np.array([fls[0] + half, stomion_y, fls[2] + dz])
    skin.combine(
        lambda p: capsule(p, m_a, m_b, li["slit_radius_mm"]),
        m_a - li["slit_box_lo_mm"],
        m_b + li["slit_box_hi_mm"],
        "subtract",
        li["slit_blend_mm"],
    )
    return stomion_y


def add_ear(field, porion, sx, scale):
    """Add an external ear (auricle) lateral to ``porion`` (in place).

    A shell about 60 mm tall and 34 mm wide whose rim (helix) stands 15-20 mm off the side of
    the head, flaring backwards, with a hollow concha in front of the canal and a lobule.

    Parameters
    ----------
    field : GridField
        The skin field.
    porion : ndarray of shape (3,)
        The design ear canal of that side, mm.
    sx : {1, -1}
        Side (1 = left).
    scale : float
        Ear size factor.
    """
    e = EAR
    start = (sx * e["ray_start_x_mm"], porion[1], porion[2])
    hit = field.ray_hit([start], (-sx, 0, 0))[0]
    side = hit[0] if np.isfinite(hit[0]) else porion[0] + sx * e["side_fallback_mm"]
    # Local frame: n = outward normal of the ear plane, u = up (tilted back), w = backwards.
    rot = rotation_xyz(e["tilt_deg"][0], sx * e["tilt_deg"][1], 0.0)
    n, u, w = rot @ (sx, 0.0, 0.0), rot @ (0.0, 1.0, 0.0), rot @ (0.0, 0.0, -1.0)
    h, b = e["half_height_mm"] * scale, e["half_width_mm"] * scale
    cx, cy, cz = e["centre_mm"]
    centre = np.array([side + sx * cx, porion[1] + cy, porion[2] + cz])
    frame = np.column_stack([n, u, w])
    m = e["shell_box_mm"]
    field.combine(
        lambda p: ellipsoid(p, centre, (e["shell_thickness_mm"], h, b), frame),
        centre - m,
        centre + m,
        "union",
        e["shell_blend_mm"],
    )
    _add_helix(field, centre, n, u, w, h, b)
    # Concha: the bowl in front of the canal; the stalk joining the ear to the head.
    (du, dw), (r0, ru, rw) = e["concha_offset"], e["concha_radii"]
    cc = centre + e["concha_out_mm"] * n - du * h * u - dw * b * w
    m = e["concha_box_mm"]
    field.combine(
        lambda p: ellipsoid(p, cc, (r0, ru * h, rw * b), frame),
        cc - m,
        cc + m,
        "subtract",
        e["concha_blend_mm"],
    )
    ax, ay, az = e["stalk_head_mm"]
    st_a = np.array([side + sx * ax, porion[1] + ay, porion[2] + az])
    st_b = centre + e["stalk_ear_mm"] * n - e["stalk_ear_up"] * h * u
    m = e["stalk_box_mm"]
    field.combine(
        lambda p: capsule(p, st_a, st_b, *e["stalk_radius_mm"]),
        np.minimum(st_a, st_b) - m,
        np.maximum(st_a, st_b) + m,
        "union",
        e["stalk_blend_mm"],
    )


def _add_helix(field, centre, n, u, w, h, b):
    """Helix: a rolled rim along the upper and back border of the ear (in place)."""
    e = EAR
    lo, hi = e["helix_phi_pi"]
    phi = np.linspace(lo * np.pi, hi * np.pi, e["helix_points"])
    reach = e["helix_reach"]
    ring = (
        centre
        + e["helix_out_mm"] * n
        + np.outer(reach * h * np.sin(phi), u)
        + np.outer(reach * b * np.cos(phi), w)
    )
    ring = ring[::-1]
    m = e["helix_box_mm"]
    for a_, b_ in zip(ring[:-1], ring[1:], strict=True):
        field.combine(
            lambda p, a_=a_, b_=b_: capsule(p, a_, b_, e["helix_radius_mm"]),
            np.minimum(a_, b_) - m,
            np.maximum(a_, b_) + m,
            "union",
            e["helix_blend_mm"],
        )
