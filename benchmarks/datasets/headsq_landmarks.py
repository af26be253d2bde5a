"""Landmark placement on the headsq meshes (issue 27): one written rule per landmark.

:func:`place_landmarks` places the cranial landmarks on the complete skull and the facial ones on
the skin of the headsq CT (``benchmarks/datasets/headsq_ct.py`` extracts the meshes,
``headsq_case.py`` writes the dataset). Frame: the generator's skull frame, mm (x = the subject's
left, y = up, z = anterior; the origin at the centre of the complete skull's bounding box).

Landmark placement rules (frame above). The orbits' and the aperture's landmarks follow the
craniometric definitions with the rules of ``cranium_landmarks`` (its "frontal height map",
"deep region", "rim edge" and pixel-to-vertex conversion; its helpers are called): before,
ectoconchion, dacryon and alare were the first bone pixel beside a deep region, i.e. 8 mm
behind the rim inside the orbit or the aperture (ec-ec 84.8 mm, soft tissue 20 mm at
ectoconchion, 20.5 mm at alare).

- orbits: the largest deep region on each side whose centroid lies more than 12 mm off the
  bounding box's centre in x, in the upper half of the map and not open to the cut vault; the
  midline is x = the mean of their centroids' x (the frame is shifted so that it is x = 0);
  the superior and inferior margins, the transverse axis: as ``cranium_landmarks``;
- ``ectoconchion``: on the transverse axis, the most anterior point of the lateral border
  (the crest of the lateral scan, ``cranium_landmarks``);
- ``dacryon``: the medial margin (rim edge of the scan to the midline) and the skull vertex
  nearest to 4 mm behind it (``cranium_landmarks``). At 3.2 mm the medial margins on the
  transverse axis lie 35-38 mm apart on the mesh itself (the height map drops from 67-73 to
  33-39 mm at x = +17 and -21), so d-d stays above the adult norm: the CT's, not the rule's;
- ``orbitale``: the lowest rim edge of the scans down the orbit's middle columns
  (``cranium_landmarks``);
- nasal aperture: the deep region holding the midline column nearest below the orbits'
  transverse axis; ``alare``: the most lateral rim edge (at 0.9) of the scans from the midline
  outwards (``cranium_landmarks``);
- midsagittal profile: vertices within 2.5 mm of the midline, the front-most one per 1.5 mm
  of height (the slice spacing); the cranium's (no mandible vertex) and the mandible's apart
  (mandible vertices: those of the complete skull more than 2 mm from the mandible-less one);
- ``nasion``: the most posterior cranium profile point between the orbits' transverse axis and
  3 mm below the top cut; ``glabella`` (the profile is a plateau up to the cut), ``metopion``,
  ``bregma``, ``frontotemporale``, ``porion`` and ``mental_foramen`` are not placed;
- ``prosthion``: the most anterior cranium profile point below the aperture (at 3.2 mm the
  incisors and the alveolar bone are one surface); ``subspinale``: the most posterior cranium
  profile point between the aperture's lowest row and ``prosthion``;
- ``infradentale``: the most anterior mandible profile point in the mandible's top 12 mm;
  menton (not written): the lowest mandible profile point; ``pogonion``: the mandible profile
  point (more than 3 mm above menton) farthest in front of the chord infradentale-menton (this
  chin recedes, so "most anterior" alone would give infradentale); ``gnathion``: the profile
  point midway (in profile steps) between pogonion and menton;
- ``gonion`` (Martin's construction): in the side view (y, z) of one side's mandible vertices,
  the ramus tangent is the support line of the convex hull along the length-weighted mean
  outward normal of the hull edges facing back (normal within 26 degrees of -z), the base
  tangent the longest hull edge facing down and back (outside those); the angle's point is the
  first vertex (within 1.5 mm) along the bisector of the two tangents from their intersection
  into the bone; gonion the most lateral vertex within 3 mm (y, z) of it (the outer surface of
  the angle). Before, "the largest -y - z in the posterior 35 %" fell on the body's lower
  border (go-go 67.4 mm): in this CT's frame the head is bent forward and the lower border
  runs 40 degrees from the horizontal;
- ``zygion``: the most lateral (largest |x|) cranium point at most 20 mm below and 5 mm above
  ``orbitale``, 5-50 mm behind ``ectoconchion``, at the centre of its plateau
  (``lilium.skull.rules.plateau_point``: the single farthest vertex of a flat arch wanders
  along it; zygion_l moved 3.5 mm, zygion_r not at all).

Facial (skin) landmarks; "over C along d": the skin vertex within 2 mm of the ray
``C + t d``, ``0 < t < 35 mm`` (the radius grows by 1 mm until there is one), the first one
(smallest ``t``) for rays from the bone surface outwards, the outermost one (largest ``t``)
for rays from inside the face, which cross airway surfaces first:

- ``nasion``, ``pogonion``, ``gnathion``: first over the cranial one along its bone normal
  (``surface_normals_at``) with the x component removed (in the midsagittal plane);
- ``zygion``: first over the cranial one along its bone normal; ``gonion``: first over it
  along the bisector of its bone normal and the lateral direction (the normal alone points
  down and back into the neck, where the skin is more than 35 mm away);
- ``alare``: outermost over the cranial one along +z (the ala in front of the aperture
  margin; ``cranium_landmarks``' outline rule finds no ala on this 3.2 mm skin: its largest
  step across a row is 3 mm, as large as the noise);
- ``exocanthion``: outermost along +z (up to 60 mm) from 5 mm medial of and 15 mm behind
  ``ectoconchion``; ``endocanthion``: the same from 3 mm lateral of and 15 mm behind
  ``dacryon`` (as ``cranium_landmarks``; the eyes are closed in this CT: these are the lid
  line's ends, about);
- skin profile: skin vertices within 2 mm of the midline, the front-most per 1.5 mm of height;
  ``subnasale``: its most posterior point from 5 mm above ``subspinale`` down to 5 mm above
  ``prosthion`` (the columella-lip junction; the nose of this head is short and flat);
  ``labiale_superius``: its most anterior point 3-20 mm below ``subnasale``; stomion (not
  written): its most posterior point 3-15 mm below ``labiale_superius``;
- ``cheilion``: outermost along +z (up to 60 mm) from 30 mm behind stomion at x = +-0.4 x
  (|x| of exocanthion + |x| of endocanthion), about the pupils' columns (an estimate: the mouth
  corners do not show on a 3.2 mm skin; used only to cut the chin-jaw region). On the
  pictures they fall on the mouth corners.

Sanity figures (``cranium_landmarks.sanity_figures``; distances in 3D, mm; before these rules
in brackets): ec-ec 90.5 (84.8; norm 93-100: the lateral rim's crest is a 6 mm plateau here,
its most medial point is taken), d-d 34.9 (37.5; 20-25: the CT's, see ``dacryon``), al-al 26.8
(23.0; 23-26), zy-zy 129.6 (128.7; 120-135), go-go 95.2 (67.4; 90-100), n-pr 70.2 (65-72),
n-ss 49.2 (52-58). Soft tissue ``|F - C|`` against ``lilium.softtissue.depths`` (mean +- SD):
ectoconchion 17.2 / 16.6 (20.2 / 19.4; 10.5 +- 2.0: the closed lids lie 15 mm in front of the
rim), dacryon 14.3 / 12.9 (13.2 / 6.0; 9.0 +- 2.0), alare 15.5 / 18.0 (20.5 / 20.5; 12.0 +-
2.5), gonion 17.5 / 13.5 (15.4 / 15.0; 13.5 +- 4.0), zygion 6.7 / 6.0 (7.0 +- 2.0); the
midline ones are unchanged.
"""

import numpy as np

from frontal_maps import (
    _alare,
    _aperture,
    _Map,
    _orbit_landmarks,
    _over,
)
from lilium.skull.rules import plateau_point

#: Orbit candidates: deep regions whose centroid lies this far off the bounding box's centre.
ORBIT_OFF_MIDLINE_MM = 12.0
#: Gonion: the hull edges of the ramus' posterior border have an outward normal within
#: acos(this) of -z; the bisector ray's half-width; the vertices within this distance (y, z)
#: of the angle's outline point.
GONION_RAMUS_COS = 0.9
GONION_RAY_MM = 1.5
GONION_NEAR_MM = 3.0
#: Exo- and endocanthion rays (as ``cranium_landmarks``).
CANTHUS_RAY_MM = 60.0


def _profile(vertices, band_mm, bin_mm, x0=0.0):
    """Front-most vertex per height bin within ``band_mm`` of x = x0: (K, 3) sorted top-down."""
    near = vertices[np.abs(vertices[:, 0] - x0) < band_mm]
    bins = np.round((near[:, 1] - vertices[:, 1].max()) / bin_mm).astype(int)
    out = []
    for b in np.unique(bins):
        sel = near[bins == b]
        out.append(sel[np.argmax(sel[:, 2])])
    out = np.array(out)
    return out[np.argsort(-out[:, 1])]


def _orbit_regions(m):
    """The two orbits' regions (u, v) on the map ``m`` of the complete skull and the midline x
    (see the module notes)."""
    rows_in = np.flatnonzero(np.isfinite(m.height).any(axis=1))
    top_row, mid_row = rows_in[0], 0.5 * (rows_in[0] + rows_in[-1])
    regions = []
    for lab in range(1, m.n + 1):
        u, v = m.region(lab)
        if v.min() > top_row + 2:  # not the open bowl of the cut vault
            regions.append((u, v))
    centre_x = 0.5 * (m.skull[:, 0].min() + m.skull[:, 0].max())
    orbits = {}
    for side, sign in (("l", 1.0), ("r", -1.0)):
        cands = [
            (u, v)
            for u, v in regions
            if sign * (m.xy(u.mean(), 0)[0] - centre_x) > ORBIT_OFF_MIDLINE_MM
            and v.mean() < mid_row
        ]
        orbits[side] = max(cands, key=lambda r: len(r[0]))
    x_mid = float(np.mean([m.xy(u.mean(), 0)[0] for u, _ in orbits.values()]))
    return orbits, x_mid


def _gonion(mandible, x_mid, sign):
    """The gonion of one side (see the module notes)."""
    from scipy.spatial import ConvexHull

    side = mandible[sign * (mandible[:, 0] - x_mid) > 0]
    yz = side[:, 1:]
    hull = ConvexHull(yz)
    inside = yz[hull.vertices].mean(axis=0)
    edges = []
    for a, b in hull.simplices:
        d = yz[b] - yz[a]
        n = np.array([d[1], -d[0]]) / np.linalg.norm(d)  # (y, z) normal
        n = n if n @ (yz[a] - inside) > 0 else -n  # outward
        edges.append((np.linalg.norm(d), n, yz[a]))
    posterior = [e for e in edges if e[1][1] < -GONION_RAMUS_COS]
    ramus = sum(e[0] * e[1] for e in posterior)
    ramus /= np.linalg.norm(ramus)
    ramus_c = max(yz[hull.vertices] @ ramus)  # the support line n . p = c
    lower = [e for e in edges if e[1][0] < 0 and e[1][1] < 0 and e[1][1] >= -GONION_RAMUS_COS]
    _, base, on_base = max(lower, key=lambda e: e[0])
    apex = np.linalg.solve(np.array([ramus, base]), [ramus_c, base @ on_base])
    inward = -(ramus + base) / np.linalg.norm(ramus + base)
    rel = yz - apex
    t = rel @ inward
    perp = np.abs(rel @ np.array([inward[1], -inward[0]]))
    on_ray = (t > 0) & (perp < GONION_RAY_MM)
    corner = yz[on_ray][np.argmin(t[on_ray])]
    near = side[np.linalg.norm(yz - corner, axis=1) < GONION_NEAR_MM]
    return near[np.argmax(sign * (near[:, 0] - x_mid))].copy()


def place_landmarks(skull, skull_faces, skin, skin_faces, mandible_mask):
    """Cranial and facial landmarks by the rules of the module notes (skull frame, mm).

    Parameters
    ----------
    skull : ndarray of shape (V, 3)
        The complete skull.
    skull_faces : ndarray of shape (F, 3)
    skin : ndarray of shape (V', 3)
    skin_faces : ndarray of shape (F', 3)
    mandible_mask : ndarray of shape (V,), bool
        Which skull vertices are the mandible's.

    Returns
    -------
    cranial, facial : dict of str -> ndarray of shape (3,)
    x_mid : float
        The midline's x (between the orbits).
    """
    from lilium.softtissue.normals import landmark_normals

    m = _Map(skull, skull_faces)
    orbits, x_mid = _orbit_regions(m)
    cranial, _, orbit_axis_y = _orbit_landmarks(m, orbits, x_mid)
    aperture = _aperture(m, x_mid, orbit_axis_y)
    cranial.update(_alare(m, aperture, x_mid))
    ap_bottom_y = m.xy(0, aperture[1].max())[1]

    cranium = skull[~mandible_mask]
    mandible = skull[mandible_mask]
    prof = _profile(cranium, 2.5, 1.5, x_mid)
    upper = prof[(prof[:, 1] > orbit_axis_y) & (prof[:, 1] < skull[:, 1].max() - 3.0)]
    cranial["nasion"] = upper[np.argmin(upper[:, 2])]
    below = prof[prof[:, 1] < ap_bottom_y]
    cranial["prosthion"] = below[np.argmax(below[:, 2])]
    between = prof[(prof[:, 1] < ap_bottom_y) & (prof[:, 1] > cranial["prosthion"][1])]
    cranial["subspinale"] = between[np.argmin(between[:, 2])]
    mprof = _profile(mandible, 2.5, 1.5, x_mid)
    top = mprof[mprof[:, 1] > mprof[:, 1].max() - 12.0]
    cranial["infradentale"] = top[np.argmax(top[:, 2])]
    menton = mprof[np.argmin(mprof[:, 1])]
    chord = cranial["infradentale"][1:] - menton[1:]
    normal = np.array([-chord[1], chord[0]]) / np.linalg.norm(chord)
    normal *= np.sign(normal[1])  # anterior
    chin = mprof[mprof[:, 1] > menton[1] + 3.0]
    cranial["pogonion"] = chin[np.argmax((chin[:, 1:] - menton[1:]) @ normal)]
    arc = mprof[(mprof[:, 1] < cranial["pogonion"][1]) & (mprof[:, 1] >= menton[1])]
    cranial["gnathion"] = arc[len(arc) // 2]  # midway (in profile steps) to menton
    for side, sign in (("l", 1.0), ("r", -1.0)):
        cranial[f"gonion_{side}"] = _gonion(mandible, x_mid, sign)
        o, e = cranial[f"orbitale_{side}"], cranial[f"ectoconchion_{side}"]
        c = cranium[
            (cranium[:, 1] > o[1] - 20.0)
            & (cranium[:, 1] < o[1] + 5.0)
            & (cranium[:, 2] < e[2] - 5.0)
            & (cranium[:, 2] > e[2] - 50.0)
        ]
        cranial[f"zygion_{side}"] = plateau_point(c, np.array([sign, 0.0, 0.0]))

    # facial
    normals = landmark_normals(skull, skull_faces, cranial)
    facial = {}
    z_axis = np.array([0.0, 0.0, 1.0])
    for name in ("nasion", "pogonion", "gnathion"):
        d = normals[name] * np.array([0.0, 1.0, 1.0])
        facial[name] = _over(skin, cranial[name], d, outermost=False)
    for side, sign in (("l", 1.0), ("r", -1.0)):
        key = f"zygion_{side}"
        facial[key] = _over(skin, cranial[key], normals[key], outermost=False)
        key = f"gonion_{side}"
        d = normals[key] + np.array([sign, 0.0, 0.0])  # bisector of the normal and lateral
        facial[key] = _over(skin, cranial[key], d, outermost=False)
        facial[f"alare_{side}"] = _over(skin, cranial[f"alare_{side}"], z_axis)
        e = cranial[f"ectoconchion_{side}"] - np.array([sign * 5.0, 0.0, -15.0])
        facial[f"exocanthion_{side}"] = _over(skin, e, z_axis, max_t_mm=CANTHUS_RAY_MM)
        d = cranial[f"dacryon_{side}"] + np.array([sign * 3.0, 0.0, -15.0])
        facial[f"endocanthion_{side}"] = _over(skin, d, z_axis, max_t_mm=CANTHUS_RAY_MM)
    sprof = _profile(skin, 2.0, 1.5, x_mid)
    window = (sprof[:, 1] < cranial["subspinale"][1] + 5.0) & (
        sprof[:, 1] > cranial["prosthion"][1] + 5.0
    )
    facial["subnasale"] = sprof[window][np.argmin(sprof[window][:, 2])]
    sn = facial["subnasale"]
    lip = sprof[(sprof[:, 1] < sn[1] - 3.0) & (sprof[:, 1] > sn[1] - 20.0)]
    facial["labiale_superius"] = lip[np.argmax(lip[:, 2])]
    ls = facial["labiale_superius"]
    gap = sprof[(sprof[:, 1] < ls[1] - 3.0) & (sprof[:, 1] > ls[1] - 15.0)]
    stomion = gap[np.argmin(gap[:, 2])]
    for side, sign in (("l", 1.0), ("r", -1.0)):
        half = 0.4 * sum(
            abs(facial[f"{n}_{side}"][0] - x_mid) for n in ("exocanthion", "endocanthion")
        )
        start = np.array([x_mid + sign * half, stomion[1], stomion[2] - 30.0])
        facial[f"cheilion_{side}"] = _over(skin, start, z_axis, max_t_mm=60.0)
    return cranial, facial, x_mid
