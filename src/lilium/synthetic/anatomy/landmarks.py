"""Placing the landmarks of a synthetic subject on its bone and skin fields.

Cranial landmarks (docs/method/skull.md; ectoconchion and dacryon on the rim's edge, not at
their craniometric points: decision 0028) are found on the bone field by casting rays: midline ones
from a frontal profile of the face (:func:`front_profile`) or as the most extreme surface point
in a direction (:func:`support_point`); the edges of the orbits and the nasal aperture by
:func:`rim_edge`. :func:`locate_cranial_landmarks` places them all; :func:`place_cheilia`
places the two facial landmarks that are not targets of a soft-tissue vector (the mouth
corners). Skull frame, mm; the search numbers are the tables below.
"""

import numpy as np

from ...softtissue.landmarks import CRANIAL_NAMES

#: Rays of :func:`support_point` start this far (mm) outside the search centre, and run at most
#: :data:`SUPPORT_RAY_MM`.
SUPPORT_START_MM = 120.0
SUPPORT_RAY_MM = 240.0
#: Frontal rays (along ``-z``) start at this z (mm) and run at most :data:`FRONTAL_RAY_MM`.
FRONTAL_START_Z_MM = 135.0
FRONTAL_RAY_MM = 260.0
#: Rim edge: the first hit whose depth passes this fraction from the deepest to the crest,
#: scanned with this many rays.
RIM_FRACTION = 0.75
RIM_RAYS = 80

#: Midline searches (mm, relative to the design positions): the glabella and nasion profile
#: (brow height plus ``profile_mm``, step ``profile_step_mm``; glabella at or above
#: ``glabella_above_mm``, nasion ``nasion_below_glabella_mm`` below it); metopion above the
#: glabella; bregma above the canals; subspinale between the prosthion and the ANS; prosthion,
#: infradentale; pogonion and gnathion around the chin.
MIDLINE = {
    "profile_mm": (-25.0, 20.0),
    "profile_step_mm": 0.5,
    "glabella_above_mm": -2.0,
    "nasion_below_glabella_mm": 3.0,
    "metopion_above_glabella_mm": 36.0,
    "bregma_centre_y_mm": 100,
    "bregma_dz_mm": 8.0,
    "subspinale_mm": (2.0, -1.0),
    "prosthion_dy_mm": 1.0,
    "infradentale_dy_mm": -1.5,
    "chin_dy_mm": 10.0,
    "pogonion_span_mm": 10.0,
    "gnathion_span_mm": 14.0,
    "chin_step_mm": 0.5,
}
#: Bilateral rim edges: scan lengths (mm) from the orbit centre laterally (ectoconchion) and
#: down (orbitale), from the aperture centre laterally (alare, at :data:`ALARE_FRACTION`); the
#: dacryon scan runs ``dacryon_dy_mm`` above the orbit centre to ``dacryon_x_mm`` off midline.
RIMS = {
    "ectoconchion_mm": 32.0,
    "orbitale_mm": 30.0,
    "alare_mm": 25.0,
    "dacryon_dy_mm": 4,
    "dacryon_x_mm": 2.0,
}
ALARE_FRACTION = 0.9
#: Support searches of the bilateral landmarks (left side; x of directions and axes mirrored):
#: ``centre`` (zygion: x = zygion x; frontotemporale: y above the brow), ``direction``, the
#: spread axes ``e1``, ``e2`` (normalised by ``e1_norm``, ``e2_norm``), spans and step (mm).
ZYGION = {"centre_yz_mm": (0.0, 24.0), "spans_mm": (6.0, 20.0)}
GONION = {
    "direction": (1.0, -0.22, -0.22),
    "e1": (0.0, 1.0, -1.0),
    "spans_mm": (14.0, 4.0),
    "step_mm": 0.5,
}
FRONTOTEMPORALE = {
    "centre_mm": (42.0, 18.0, 60.0),
    "direction": (1.0, 0.0, 0.8),
    "e2": (-0.8, 0.0, 1.0),
    "spans_mm": (3.0, 6.0),
    "step_mm": 0.5,
}
#: Porion: a lateral ray from ``x = start_x_mm``, this far (mm) above the canal's top.
PORION = {"start_x_mm": 100.0, "above_canal_mm": 0.8}
#: Mental foramen: lateral surface of the body below the premolars, ``off_midline_mm`` off the
#: midline and ``below_body_mm`` below its centre line; the ray starts ``ray_start_mm`` out.
MENTAL_FORAMEN = {"off_midline_mm": 24.0, "below_body_mm": 2.0, "ray_start_mm": 40.0}
#: Cheilion: where a frontal ray at ``x = +-x_mm * fw``, stomion height, from ``start_z_mm``
#: meets the skin.
CHEILION = {"x_mm": 21.0, "start_z_mm": 140.0}


def support_point(field, centre, direction, e1, e2=None, span1=10.0, span2=0.0, step=1.0):
    """Surface point that is most extreme along ``direction`` near ``centre``.

    Rays come from outside along ``-direction``, their origins spread over ``e1`` (and ``e2``);
    the hit furthest along ``direction`` wins.

    Parameters
    ----------
    field : GridField
    centre, direction, e1, e2 : array_like of shape (3,)
        Skull frame (mm for ``centre``).
    span1, span2, step : float
        Half extents of the spread along ``e1`` and ``e2``, and its step, mm.

    Returns
    -------
    ndarray of shape (3,)
        mm; NaN when no ray hits.
    """
    direction = np.asarray(direction, float)
    direction = direction / np.linalg.norm(direction)
    a = np.arange(-span1, span1 + 1e-9, step)
    b = np.arange(-span2, span2 + 1e-9, step) if e2 is not None else np.zeros(1)
    A, Bv = np.meshgrid(a, b, indexing="ij")
    e2v = np.zeros(3) if e2 is None else np.asarray(e2, float)
    origins = (
        np.asarray(centre, float)
        + SUPPORT_START_MM * direction
        + A.reshape(-1, 1) * np.asarray(e1, float)
        + Bv.reshape(-1, 1) * e2v
    )
    hits = field.ray_hit(origins, -direction, max_mm=SUPPORT_RAY_MM)
    score = np.where(np.isnan(hits[:, 0]), -np.inf, hits @ direction)
    return hits[np.argmax(score)]


def front_profile(field, x, ys, z_from=FRONTAL_START_Z_MM):
    """Hits of frontal rays (along ``-z``) at ``(x, y)`` for each ``y``.

    Parameters
    ----------
    field : GridField
    x : float
        mm.
    ys : ndarray of shape (N,)
        mm.
    z_from : float
        Start of the rays, mm.

    Returns
    -------
    ndarray of shape (N, 3)
        The anterior surface profile, mm; NaN rows where a ray misses.
    """
    origins = np.column_stack([np.full(len(ys), x), ys, np.full(len(ys), z_from)])
    return field.ray_hit(origins, (0, 0, -1), max_mm=FRONTAL_RAY_MM)


def rim_edge(field, start, end, frac=RIM_FRACTION, n=RIM_RAYS):
    """Edge of an opening (orbit, nasal aperture) along a scan line of frontal rays.

    Frontal rays at points from ``start`` (inside the opening) to ``end`` (on the rim) hit deep
    inside the opening and then on the rim; the edge is the first hit whose depth passes
    ``frac`` of the way from the deepest to the most anterior hit.

    Parameters
    ----------
    field : GridField
    start, end : array_like of shape (3,)
        mm (only x and y matter).
    frac : float
    n : int
        Rays along the scan line.

    Returns
    -------
    ndarray of shape (3,)
        mm.
    """
    start, end = np.asarray(start, float), np.asarray(end, float)
    s = np.linspace(0, 1, n)[:, None]
    pts = start + s * (end - start)
    origins = np.column_stack([pts[:, 0], pts[:, 1], np.full(n, FRONTAL_START_Z_MM)])
    hits = field.ray_hit(origins, (0, 0, -1), max_mm=FRONTAL_RAY_MM)
    z = np.where(np.isnan(hits[:, 2]), -np.inf, hits[:, 2])
    top = int(np.argmax(z))
    crest, deep = z[top], np.min(z[: top + 1])
    k = int(np.argmax(z[: top + 1] >= deep + frac * (crest - deep)))
    return hits[k]


def _midline_landmarks(bone, d):
    """Glabella to gnathion on the midline (dict name -> ndarray of shape (3,), mm)."""
    m, lm = MIDLINE, {}
    lo, hi = m["profile_mm"]
    ys = np.arange(d["brow_y"] + lo, d["brow_y"] + hi, m["profile_step_mm"])
    prof = front_profile(bone, 0.0, ys)
    ok = ~np.isnan(prof[:, 2])
    z = np.where(ok, prof[:, 2], -np.inf)
    g = int(np.argmax(np.where(ys >= d["brow_y"] + m["glabella_above_mm"], z, -np.inf)))
    lm["glabella"] = prof[g]
    below = (ys < ys[g] - m["nasion_below_glabella_mm"]) & (ys > d["orbit"][1])
    n_idx = int(np.argmin(np.where(below & ok, prof[:, 2], np.inf)))
    lm["nasion"] = prof[n_idx]
    metopion_y = lm["glabella"][1] + m["metopion_above_glabella_mm"]
    lm["metopion"] = front_profile(bone, 0.0, np.array([metopion_y]))[0]
    bregma_c = (0, m["bregma_centre_y_mm"], d["canal"][2] + m["bregma_dz_mm"])
    lm["bregma"] = support_point(bone, bregma_c, (0, 1, 0), (0, 0, 1), span1=0.0)
    lo, hi = m["subspinale_mm"]
    ys = np.arange(d["prosthion_y"] + lo, d["ans"][1] + hi, m["profile_step_mm"])
    prof = front_profile(bone, 0.0, ys)
    lm["subspinale"] = prof[int(np.nanargmin(prof[:, 2]))]
    y = np.array([d["prosthion_y"] + m["prosthion_dy_mm"]])
    lm["prosthion"] = front_profile(bone, 0.0, y)[0]
    y = np.array([d["infradentale_y"] + m["infradentale_dy_mm"]])
    lm["infradentale"] = front_profile(bone, 0.0, y)[0]
    chin = (0.0, d["menton_y"] + m["chin_dy_mm"], d["chin_z"])
    step = m["chin_step_mm"]
    lm["pogonion"] = support_point(
        bone, chin, (0, 0, 1), (0, 1, 0), span1=m["pogonion_span_mm"], step=step
    )
    lm["gnathion"] = support_point(
        bone, chin, (0, -1, 1), (0, 1, 1) / np.sqrt(2), span1=m["gnathion_span_mm"], step=step
    )
    return lm


def _bilateral_landmarks(bone, d, sx, sfx):
    """The landmarks of one side (``sx`` = 1 left, -1 right; names end with ``sfx``)."""
    lm, r = {}, RIMS
    o = d["orbit"] * (sx, 1, 1)
    lm["ectoconchion" + sfx] = rim_edge(bone, o, o + (sx * r["ectoconchion_mm"], 0, 0))
    dy = r["dacryon_dy_mm"]
    lm["dacryon" + sfx] = rim_edge(bone, o + (0, dy, 0), (sx * r["dacryon_x_mm"], o[1] + dy, 0))
    lm["orbitale" + sfx] = rim_edge(bone, o, o - (0, r["orbitale_mm"], 0))
    na = d["nasal_aperture"]
    lm["alare" + sfx] = rim_edge(bone, na, na + (sx * r["alare_mm"], 0, 0), frac=ALARE_FRACTION)
    zy, zz = ZYGION["centre_yz_mm"]
    lm["zygion" + sfx] = support_point(
        bone, (sx * d["zygion_x"], zy, zz), (sx, 0, 0), (0, 1, 0), (0, 0, 1), *ZYGION["spans_mm"]
    )
    # Gonion: the corner of the angle, extreme laterally-down-back (the soft tissue over it
    # is measured laterally, on the masseter).
    go = GONION
    g0 = d["gonion"] * (sx, 1, 1)
    g_dir = np.array([sx * go["direction"][0], *go["direction"][1:]])
    g_e1 = np.array(go["e1"]) / np.sqrt(2)
    g_e2 = np.cross(g_dir / np.linalg.norm(g_dir), g_e1)
    lm["gonion" + sfx] = support_point(bone, g0, g_dir, g_e1, g_e2, *go["spans_mm"], go["step_mm"])
    ft = FRONTOTEMPORALE
    (cx, cy, cz), (ux, uy, uz), (vx, vy, vz) = ft["centre_mm"], ft["direction"], ft["e2"]
    lm["frontotemporale" + sfx] = support_point(
        bone,
        (sx * cx, d["brow_y"] + cy, cz),
        (sx * ux, uy, uz),
        (0, 1, 0),
        (vx * sx, vy, vz) / np.hypot(vx, vz),
        *ft["spans_mm"],
        ft["step_mm"],
    )
    c = d["canal"] * (sx, 1, 1)
    start = (sx * PORION["start_x_mm"], c[1] + d["canal_radius"] + PORION["above_canal_mm"], c[2])
    lm["porion" + sfx] = bone.ray_hit([start], (-sx, 0, 0))[0]
    lm["mental_foramen" + sfx] = _mental_foramen(bone, d["body_arch"], d["body_y"], sx)
    return lm


def _mental_foramen(bone, arch, y_body, sx):
    """Mental foramen of one side: lateral surface of the mandibular body below the premolars.

    Parameters
    ----------
    bone : GridField
    arch : ndarray of shape (M, 2)
        The body's arch ``(x, z)``, mm.
    y_body : ndarray of shape (M,)
        Height of its centre line, mm.
    sx : {1, -1}

    Returns
    -------
    ndarray of shape (3,)
        mm.
    """
    mf = MENTAL_FORAMEN
    right_half = arch[:, 0] * sx > 0
    k = np.argmin(np.where(right_half, np.abs(np.abs(arch[:, 0]) - mf["off_midline_mm"]), np.inf))
    tangent = arch[min(k + 1, len(arch) - 1)] - arch[max(k - 1, 0)]
    normal = np.array([tangent[1], -tangent[0]])
    normal *= np.sign(normal[0] * sx) or 1.0
    normal /= np.linalg.norm(normal)
    p0 = np.array([arch[k, 0], y_body[k] - mf["below_body_mm"], arch[k, 1]])
    dirn = np.array([normal[0], 0.0, normal[1]])
    return bone.ray_hit([p0 + mf["ray_start_mm"] * dirn], -dirn)[0]


def locate_cranial_landmarks(bone, design):
    """Every cranial landmark of docs/method/skull.md, on the bone surface (ectoconchion and
    dacryon on the rim's edge: decision 0028).

    Parameters
    ----------
    bone : GridField
        Skull frame, mm, negative inside.
    design : dict
        Design positions of :func:`~lilium.synthetic.anatomy.bone.build_bone`.

    Returns
    -------
    dict of str -> ndarray of shape (3,)
        Every name of :data:`~lilium.softtissue.landmarks.CRANIAL_NAMES`, in that order, mm.

    Raises
    ------
    RuntimeError
        If a landmark could not be placed (a ray missed the bone).
    """
    lm = _midline_landmarks(bone, design)
    for sx, sfx in ((1, "_l"), (-1, "_r")):
        lm.update(_bilateral_landmarks(bone, design, sx, sfx))
    missing = [n for n in CRANIAL_NAMES if n not in lm or not np.all(np.isfinite(lm[n]))]
    if missing:
        raise RuntimeError(f"synthetic skull: could not place {missing}")
    return {n: np.asarray(lm[n], float) for n in CRANIAL_NAMES}


def place_cheilia(skin, stomion_y, fw):
    """The mouth corners on the skin field, at the stomion's height.

    Parameters
    ----------
    skin : GridField
        Skull frame, mm, negative inside.
    stomion_y : float
        mm.
    fw : float
        Face width factor.

    Returns
    -------
    dict
        ``cheilion_l``, ``cheilion_r`` -> ndarray of shape (3,), mm (NaN where a ray missed).
    """
    out = {}
    for sx, nm in ((1, "cheilion_l"), (-1, "cheilion_r")):
        x = sx * CHEILION["x_mm"] * fw
        out[nm] = skin.ray_hit([(x, stomion_y, CHEILION["start_z_mm"])], (0, 0, -1))[0]
    return out
