"""The jaws of the synthetic skull: alveolar processes, teeth and mandible.

Arches are polylines ``(x, z)`` (skull frame, mm) along which a bar is swept
(:func:`~lilium.synthetic.volume_fields.sweep`) or teeth are placed. :func:`add_dentition` adds
the upper alveolar process and both rows of teeth, :func:`add_mandible` the mandibular body,
chin, rami, condyles and coronoid processes. Their numbers are the tables below (mm unless
the name says otherwise; ``fw``: face width factor, ``pr``: alveolar prognathism, mm).
"""

import numpy as np

from ..volume_fields import capsule, ellipsoid, rotation_xyz, slab, sweep
from .parts import add_capsule, add_ellipsoid

#: Upper alveolar process: a bar swept along a half-ellipse arch of half width
#: ``half_width_mm * fw``, front ``front_z_mm + pr``, back ``back_z_mm``; centred
#: ``dy_mm`` above the prosthion.
UPPER_ALVEOLAR = {
    "points": 17,
    "half_width_mm": 29.0,
    "front_z_mm": 87.0,
    "back_z_mm": 40.0,
    "dy_mm": 9.0,
    "half_width_bar_mm": 4.0,
    "half_height_bar_mm": 8.0,
    "rounding_mm": 2.0,
    "blend_mm": 4,
}
#: Tooth rows (arches as above, front ``front_z_mm + per_pr * pr``); the crowns stand between
#: the prosthion and the occlusal plane (upper) or the occlusal plane and the infradentale
#: (lower), ``dy_mm`` off their middle and ``extra_height_mm`` taller than the gap.
UPPER_TEETH = {
    "half_width_mm": 27.5,
    "front_z_mm": 86.0,
    "front_z_per_prognathism": 1.0,
    "back_z_mm": 42.0,
    "dy_mm": 0.5,
}
LOWER_TEETH = {
    "half_width_mm": 26.0,
    "front_z_mm": 84.0,
    "front_z_per_prognathism": 0.6,
    "back_z_mm": 42.0,
    "dy_mm": -0.5,
}
TEETH_EXTRA_HEIGHT_MM = 2.0
#: One crown: an ellipsoid ``(width * spacing, height / 2, depth + per_molar * molar)``
#: (``molar`` 0 at the incisors, 1 at the molars), turned along the arch.
TOOTH = {
    "count": 16,
    "width_per_spacing": 0.62,
    "depth_mm": (2.6, 2.4),
    "tangent_step_mm": 1.0,
    "margin_mm": 3,
    "blend_mm": 0.8,
}
#: Mandibular body: a bar swept gonion to gonion (``points`` along the arch), from
#: ``chin_z - front_inset_mm`` to ``gonion z + back_z_mm``; ``w`` = 0 at the chin, 1 at the
#: gonia. Top ``infradentale + top_rise_mm * w``; bottom ``menton + bottom_lift_mm`` rising to
#: ``gonion y - gonion_drop_mm``; half width ``a - b * w``; half height = half the span minus
#: ``height_inset_mm``.
MANDIBLE_BODY = {
    "points": 21,
    "front_inset_mm": 4.0,
    "back_z_mm": 2.0,
    "power": 1.4,
    "top_rise_mm": 3.0,
    "bottom_lift_mm": 3.0,
    "gonion_drop_mm": 2.0,
    "half_width_mm": (4.5, 1.5),
    "height_inset_mm": 2.5,
    "rounding_mm": 2.5,
    "blend_mm": 3,
}
#: Chin: centre ``(0, menton + dy, chin_z + dz)``.
CHIN = {"dy_mm": 10.0, "dz_mm": -3.0, "radii_mm": (15.0, 10.0, 6.0), "margin_mm": 6, "blend_mm": 5}
#: Ramus: a slab from ``base_dyz_mm`` above and in front of the gonion to ``y = top_y_mm``
#: (``top_dx_mm`` lateral of the gonion), tilted back by ``tilt_deg + gonial_deg``.
RAMUS = {
    "base_dyz_mm": (8.0, 14.0),
    "top_dx_mm": 3.0,
    "top_y_mm": -34.0,
    "tilt_deg": 12.0,
    "half_width_mm": 2.0,
    "half_height_mm": (14.0, 12.0),
    "rounding_mm": 2.0,
    "box_margin_mm": 20,
    "blend_mm": 4,
}
#: Condylar neck (from ``dz_mm`` behind the ramus top) and condyle.
CONDYLE = {
    "neck_dz_mm": -10.0,
    "centre_mm": (54.0, -10.0, 3.0),
    "neck_radius_mm": (4.0, 3.5),
    "neck_box_mm": 16,
    "neck_blend_mm": 3,
    "radii_mm": (10.0, 5.0, 6.0),
    "box_mm": 14,
    "blend_mm": 2,
}
#: Coronoid process: a capsule between two points given relative to the gonion x and the
#: ramus top z.
CORONOID = {
    "a_mm": (1.0, -38.0, 10.0),
    "b_mm": (-2.0, -17.0, 14.0),
    "radius_mm": (4.0, 2.5),
    "box_margin_mm": 10,
    "blend_mm": 3,
}


def arch(half_width, z_front, z_back, n=17):
    """Points of a dental or alveolar arch (half ellipse), left end to right end.

    Parameters
    ----------
    half_width, z_front, z_back : float
        mm.
    n : int

    Returns
    -------
    xz : ndarray of shape (n, 2)
        ``(x, z)``, mm.
    """
    theta = np.linspace(-np.pi / 2, np.pi / 2, n)
    return np.column_stack(
        [half_width * np.sin(theta), z_back + (z_front - z_back) * np.cos(theta)]
    )


def body_arch(half_width, z_front, z_back, n=21, power=1.4):
    """Points of the mandibular body, gonion to gonion.

    ``z`` falls as ``|x|^power``, so the two halves converge towards the chin (about 24 deg off
    the sagittal plane at the gonia) and the gonia are the widest points of the lower jaw.

    Returns
    -------
    xz : ndarray of shape (n, 2)
        ``(x, z)``, mm.
    """
    t = np.linspace(-1.0, 1.0, n)
    return np.column_stack([half_width * t, z_front - (z_front - z_back) * np.abs(t) ** power])


def add_sweep(bone, xz, y_centre, half_width, half_height, radius, k=1.5):
    """Union (in place) of a bar swept along an arch, cross-section varying per point.

    Parameters
    ----------
    bone : GridField
    xz : ndarray of shape (M, 2)
        Arch, mm.
    y_centre, half_width, half_height : ndarray of shape (M,)
        Height of the centre line and half sizes of the cross-section at each point, mm.
    radius, k : float
        Rounding and blend radius, mm.
    """
    pts = np.column_stack([xz[:, 0], y_centre, xz[:, 1]])
    reach = max(np.max(half_width), np.max(half_height)) + radius + k + 2
    bone.combine(
        lambda p: sweep(p, pts, half_width, half_height, radius),
        pts.min(axis=0) - reach,
        pts.max(axis=0) + reach,
        "union",
        k,
    )


def add_teeth(bone, xz, y_centre, height):
    """One ellipsoid per tooth along an arch (crowns of one dentition, in place).

    Parameters
    ----------
    bone : GridField
    xz : ndarray of shape (M, 2)
        Arch, mm.
    y_centre, height : float
        Height of the crowns' centres and their height, mm.
    """
    t = TOOTH
    seg = np.linalg.norm(np.diff(xz, axis=0), axis=1)
    s = np.concatenate([[0], np.cumsum(seg)])
    at = np.linspace(0, s[-1], t["count"] + 1)
    at = (at[:-1] + at[1:]) / 2
    x = np.interp(at, s, xz[:, 0])
    z = np.interp(at, s, xz[:, 1])
    spacing = s[-1] / t["count"]
    step = t["tangent_step_mm"]
    for xi, zi, ai in zip(x, z, at, strict=True):
        molar = abs(ai - s[-1] / 2) / (s[-1] / 2)  # 0 at the incisors, 1 at the molars
        c = (xi, y_centre, zi)
        r = (
            t["width_per_spacing"] * spacing,
            height / 2,
            t["depth_mm"][0] + t["depth_mm"][1] * molar,
        )
        tangent = np.arctan2(
            np.interp(ai + step, s, xz[:, 0]) - xi, np.interp(ai + step, s, xz[:, 1]) - zi
        )
        rot = rotation_xyz(0.0, np.degrees(tangent) - 90.0, 0.0)
        add_ellipsoid(bone, c, r, t["margin_mm"], "union", t["blend_mm"], rot)


def add_dentition(bone, s, d, lower=True):
    """Upper alveolar process and the upper and lower teeth (in place).

    Parameters
    ----------
    bone : GridField
    s : SubjectShape
    d : dict
        Design positions (:func:`~lilium.synthetic.anatomy.bone.design_points`).
    lower : bool
        Add the lower teeth too (they go with the mandible: False for a skull without it).
    """
    fw, pr, ua = s.fw, s.prognathism_mm, UPPER_ALVEOLAR
    n = ua["points"]
    up = arch(ua["half_width_mm"] * fw, ua["front_z_mm"] + pr, ua["back_z_mm"], n)
    yy, oc, inf = d["prosthion_y"], d["occlusal_y"], d["infradentale_y"]
    add_sweep(
        bone,
        up,
        np.full(n, yy + ua["dy_mm"]),
        np.full(n, ua["half_width_bar_mm"]),
        np.full(n, ua["half_height_bar_mm"]),
        ua["rounding_mm"],
        ua["blend_mm"],
    )
    rows = ((UPPER_TEETH, (yy, oc)), (LOWER_TEETH, (oc, inf)))
    for row, (high, low) in rows if lower else rows[:1]:
        per_pr = row["front_z_per_prognathism"]
        front = row["front_z_mm"] + per_pr * pr  # per_pr = 1: exactly + pr
        add_teeth(
            bone,
            arch(row["half_width_mm"] * fw, front, row["back_z_mm"]),
            (high + low) / 2 + row["dy_mm"],
            high - low + TEETH_EXTRA_HEIGHT_MM,
        )


def add_mandible(bone, s, d):
    """Mandibular body, chin, rami, condyles and coronoid processes (in place).

    Parameters
    ----------
    bone : GridField
    s : SubjectShape
    d : dict
        Design positions (:func:`~lilium.synthetic.anatomy.bone.design_points`).

    Returns
    -------
    body_xz : ndarray of shape (M, 2)
        Arch of the body, gonion to gonion, mm.
    body_y : ndarray of shape (M,)
        Height of the body's centre line at each arch point, mm.
    ramus_top : ndarray of shape (3,)
        Top of the right ramus (the last one built), mm.
    """
    g, mb, menton = d["gonion"], MANDIBLE_BODY, d["menton_y"]
    n = mb["points"]
    body = body_arch(
        g[0], d["chin_z"] - mb["front_inset_mm"], g[2] + mb["back_z_mm"], n, mb["power"]
    )
    w = np.abs(np.linspace(-1, 1, n))  # 0 at the chin, 1 at the gonia
    top = d["infradentale_y"] + mb["top_rise_mm"] * w
    bottom = menton + mb["bottom_lift_mm"] + (g[1] - menton - mb["gonion_drop_mm"]) * w
    hw0, hw1 = mb["half_width_mm"]
    half_height = (top - bottom) / 2 - mb["height_inset_mm"]
    add_sweep(
        bone,
        body,
        (top + bottom) / 2,
        hw0 - hw1 * w,
        half_height,
        mb["rounding_mm"],
        mb["blend_mm"],
    )
    ch = CHIN
    c = (0.0, menton + ch["dy_mm"], d["chin_z"] + ch["dz_mm"])
    add_ellipsoid(bone, c, ch["radii_mm"], ch["margin_mm"], "union", ch["blend_mm"])
    tilt = np.radians(RAMUS["tilt_deg"] + s.gonial_deg)
    for sx in (1, -1):
        top_pt = _add_ramus(bone, g, sx, tilt)
    return body, (top + bottom) / 2, top_pt


def _add_ramus(bone, g, sx, tilt):
    """Ramus, condyle and coronoid process of one side (in place); returns the ramus top."""
    ra, co, cd = RAMUS, CORONOID, CONDYLE
    dy, dz = ra["base_dyz_mm"]
    base = np.array([sx * g[0], g[1] + dy, g[2] + dz])
    top_pt = np.array([sx * (g[0] + ra["top_dx_mm"]), ra["top_y_mm"], 0.0])
    top_pt[2] = base[2] - (top_pt[1] - base[1]) * np.tan(tilt)
    m = ra["box_margin_mm"]
    bone.combine(
        lambda p: slab(
            p, base, top_pt, (0, 0, 1), ra["half_width_mm"], ra["half_height_mm"], ra["rounding_mm"]
        ),
        np.minimum(base, top_pt) - m,
        np.maximum(base, top_pt) + m,
        "union",
        ra["blend_mm"],
    )
    neck_a = np.array([sx * (g[0] + ra["top_dx_mm"]), ra["top_y_mm"], top_pt[2] + cd["neck_dz_mm"]])
    condyle = np.array([sx * cd["centre_mm"][0], *cd["centre_mm"][1:]])
    bone.combine(
        lambda p: capsule(p, neck_a, condyle, *cd["neck_radius_mm"]),
        condyle - cd["neck_box_mm"],
        condyle + cd["neck_box_mm"],
        "union",
        cd["neck_blend_mm"],
    )
    bone.combine(
        lambda p: ellipsoid(p, condyle, cd["radii_mm"]),
        condyle - cd["box_mm"],
        condyle + cd["box_mm"],
        "union",
        cd["blend_mm"],
    )
    (ax, ay, az), (bx, by, bz) = co["a_mm"], co["b_mm"]
    cor_a = np.array([sx * (g[0] + ax), ay, top_pt[2] + az])
    cor_b = np.array([sx * (g[0] + bx), by, top_pt[2] + bz])
    add_capsule(bone, cor_a, cor_b, *co["radius_mm"], co["box_margin_mm"], "union", co["blend_mm"])
    return top_pt
