"""Landmark placement on the Cranium meshes: one written rule per landmark.

:func:`place_landmarks` places the cranial landmarks on the skull and the facial ones on the
skin of the InVesalius Cranium CT (``benchmarks/datasets/cranium_ct.py`` extracts the meshes,
``cranium_case.py`` writes the dataset); :func:`sanity_figures` measures them against adult
norms. Frame: the generator's skull frame, mm (x = the subject's left, y = up, z = anterior;
the origin at the centre of the skull's bounding box). The CT has about 1 mm voxels, so the
rules follow the craniometric definitions (Martin; Buikstra & Ubelaker; Howells), using the
frontal height map, the midline profiles and, for the teeth, the CT numbers.

Tools (frame above): the "frontal height map" is the skull rendered by the project's
rasteriser from straight in front, 1 mm per pixel, the height of a pixel the z of the triangle
seen there (``headsq_landmarks``); a "deep region" is a connected region lying more than 8 mm
behind a grey closing of the height map with a disk of radius 20 mm (orbits, nasal aperture,
temporal fossae, the frontal defect); a chosen pixel gives the vertex of its triangle nearest to
it in x, y. A "rim edge" of a scan line of the height map (the generator's rule,
``lilium.synthetic.anatomy.landmarks.rim_edge``): with crest = the largest height on the scan
and deep = the smallest before it, the first pixel whose height reaches
``deep + 0.75 (crest - deep)``. A "midline profile": the vertex of every row's pixel on the
midline column of a frontal height map (of the skull or of the skin), top-down.

Cranial landmarks:

- orbits: on each side the largest deep region whose centroid lies 12-45 mm off the bounding
  box's centre in x and below its centre in y (the CT runs from the teeth to the vertex; this
  keeps the right frontal defect out); the midline is x = the mean of their centroids' x (the
  frame is shifted so that it is x = 0); the superior and inferior margins: the rim edges of
  the scans up and down the orbit's centroid column (30 mm); the transverse axis: the row
  midway between them (horizontal: the slight lateral tilt of the orbit is ignored);
- ``ectoconchion``: on the transverse axis, the most anterior point of the lateral border
  (Buikstra & Ubelaker: "the most anterior surface of the lateral border"): the highest pixel
  of the 40 mm scan from the orbit's centroid laterally, the most medial one of a plateau
  within 0.5 mm of it (the orbital side of the crest);
- ``dacryon``: on the transverse axis, the medial margin (the anterior lacrimal crest) is the
  rim edge of the scan from the orbit's centroid to the midline; dacryon, the meeting of
  frontal, lacrimal and maxilla on the medial wall, lies in the lacrimal fossa behind it: the
  skull vertex nearest to the point 4 mm behind that margin vertex. The lacrimal bone and the
  lamina papyracea are 100-150 HU here, below the bone level, so the mesh has no medial wall
  behind the frontal process of the maxilla: the vertex found is that process's posterior edge
  (where the lacrimal bone joins it), 3 mm behind the margin;
- ``orbitale``: the lowest of the rim edges of the scans down the columns of the orbit's middle
  half (30 mm each);
- nasal aperture: the deep region holding the midline column nearest below the orbits;
  ``alare``: the rim edges (at 0.9, the generator's fraction for the aperture) of the 25 mm scans
  from the midline outwards on every row of the aperture, the most lateral one on each side
  (the middle row of a vertical stretch of the margin);
- ``nasion``: the most posterior midline profile point between the transverse axis and 10 mm
  above the superior margins (the deepest point of the frontonasal concavity, where the
  frontonasal suture meets the midline within about a millimetre);
- ``glabella``: the most anterior midline profile point from nasion to 35 mm above it;
  ``metopion``: the midline profile point 36 mm above glabella (the generator's rule, about
  the height of the frontal eminences);
- ``ANS`` (anterior nasal spine, not written): the most anterior midline profile point within
  4 mm of the aperture's lowest row; ``prosthion``: going down the midline profile from ANS,
  the last point before the incisor crowns, i.e. before the first point where the largest CT
  number 1, 2 and 3 mm inside the surface (along -z) reaches 1900 HU (enamel; the alveolar bone
  and the roots stay below 1850 here); ``subspinale``: the midline profile point between ANS
  and prosthion farthest behind their chord (the deepest point of the concavity);
- ``zygion``: the most lateral (largest |x|) skull point at most 20 mm below and 5 mm above
  ``orbitale``, 5-50 mm behind ``ectoconchion`` (the arch), taken, as ``frontotemporale`` is,
  at the centre of its plateau (``lilium.skull.rules.plateau_point``: the vertices within 0.5 mm
  of the extreme), not the single farthest vertex, which on the flat arch wanders along it
  (zygion_r moved 4.5 mm, z 39.9 -> 35.7, zygion_l and frontotemporale_l 1.2 mm);
- ``frontotemporale``: the support point (its plateau's centre) of the frontal bone in the direction
  ``(+-1, 0, 0.8)`` (the anterolateral corner where the temporal line turns, the generator's
  direction) among the skull vertices 15-21 mm above the superior orbital margin, 25-60 mm off
  the midline, in front of ``ectoconchion``;
- not placed: ``bregma`` (the coronal suture cannot be traced by a rule on this mesh), the
  ``porion`` (the bony meatus merges with the emptied glenoid fossa and the mastoid cells at
  300 HU), and the mandible's landmarks (not scanned).

Facial (skin) landmarks; "over C along d": the skin vertex within 2 mm of the ray
``C + t d``, ``0 < t < 35 mm`` (radius grown by 1 mm until there is one), the first one for rays
from the bone outwards, the outermost one for rays from inside the face (``headsq_landmarks``):

- ``nasion``, ``glabella``, ``metopion``: first over the cranial one along its bone normal
  with the x component removed; ``zygion``, ``frontotemporale``: first along the bone normal;
- ``alare``: the outer edge of the ala in the frontal view: on the skin's frontal height map,
  rows from 5 mm above the higher cranial alare down to ``subspinale``, scanned from the
  midline outwards (30 mm): the last pixel before the first drop of more than 4 mm to the
  next (the ala's side wall, seen edge-on, falling to the cheek); the most lateral one on each
  side, the middle row of a vertical stretch;
- ``exocanthion``: outermost along +z from 5 mm medial of and 15 mm behind ``ectoconchion``;
  ``endocanthion``: the same from 3 mm lateral of and 15 mm behind ``dacryon`` (eyes closed:
  the lid line's ends, about);
- skin midline profile: pronasale (not written) its most anterior point below nasion;
  ``labiale_superius``: the lowest local maximum of z (the highest within 2 mm of height, and
  not flat there) of the profile from 8 mm below pronasale to 1 mm above the skin's cut (the
  CT ends at the upper teeth: the upper lip's vermilion is the last bulge before the cut; not
  placed without one); ``subnasale``: the profile point between pronasale and
  ``labiale_superius`` (else the lowest profile point) farthest behind their chord (the
  columella-lip junction);
- not placed: the cheilia (below the scan; so the frontal photos have no chin-jaw curve).

Sanity figures (:func:`sanity_figures`, ``python benchmarks/datasets/cranium_ct.py``) against adult
norms, measured on this CT (distances in 3D, mm):

- biorbital breadth ec-ec 94.8 (norm 93-100);
- interorbital breadth d-d 20.0 (20-25): low end; the medial walls at the lacrimal fossa lie
  19-20 mm apart on the CT itself (slice 41, columns 120 and 140), a narrow interorbital space;
- nasal breadth al-al 20.8 (23-26): below the norm, and so is the CT: at slice 20 the medial
  faces of the aperture's margins are 20.5 mm apart (columns 120.7 and 142.1 at 300 HU); a
  narrow (leptorrhine) aperture, not a misplaced rule (the margin steps are sharp; the widest
  rows lie in the aperture's middle third);
- bizygomatic breadth zy-zy 128.9 (120-135);
- nasion-prosthion 64.8 (65-72): low end (prosthion stops at the alveolar crest above the
  enamel, the crowns would add 3-4 mm);
- nasion-subspinale 53.9 (52-58).

The soft tissue the pairs give (``|F - C|``, mm; ``lilium.softtissue.depths`` means in
brackets): glabella 4.8 (5.5), nasion 6.1 (6.5), metopion 4.3 (4.8), frontotemporale 5.5 / 4.6
(5.0), ectoconchion 12.8 / 9.1 (10.5), dacryon 9.8 / 7.9 (9.0), zygion 9.4 / 7.2 (7.0),
prosthion 12.8 (12.5), subspinale 18.7 (15.0), alare 18.2 / 19.3 (12.0: the ala's outer point
lies 6-7 mm lateral of and 15-17 mm in front of this narrow bony aperture, beyond the table's
17 mm maximum).
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

ENAMEL_HU = 1900.0
ENAMEL_PROBE_MM = (1.0, 2.0, 3.0)
METOPION_ABOVE_GLABELLA_MM = 36.0
LIP_BULGE_MM = 2.0
ALA_ABOVE_MM = 5.0
ALA_SCAN_MM = 30.0
ALA_STEP_MM = 4.0

#: Adult norms (mm) of :func:`sanity_figures`: (low, high).
NORMS = {
    "biorbital ec-ec": (93.0, 100.0),
    "interorbital d-d": (20.0, 25.0),
    "nasal breadth al-al": (23.0, 26.0),
    "bizygomatic zy-zy": (120.0, 135.0),
    "nasion-prosthion": (65.0, 72.0),
    "nasion-subspinale": (52.0, 58.0),
}
PAIRS = {
    "biorbital ec-ec": ("ectoconchion_l", "ectoconchion_r"),
    "interorbital d-d": ("dacryon_l", "dacryon_r"),
    "nasal breadth al-al": ("alare_l", "alare_r"),
    "bizygomatic zy-zy": ("zygion_l", "zygion_r"),
    "nasion-prosthion": ("nasion", "prosthion"),
    "nasion-subspinale": ("nasion", "subspinale"),
}


def sanity_figures(cranial):
    """Craniometric distances of the placed landmarks with their adult norms.

    Returns
    -------
    dict of str -> (float, float, float)
        ``name -> (distance_mm, low_mm, high_mm)`` for every pair that is placed.
    """
    out = {}
    for name, (a, b) in PAIRS.items():
        if a in cranial and b in cranial:
            d = float(np.linalg.norm(np.asarray(cranial[a]) - np.asarray(cranial[b])))
            out[name] = (d, *NORMS[name])
    return out


def _orbits(m):
    """The two orbits' regions (u, v) and the midline x (see the module notes)."""
    centre = 0.5 * (m.skull.min(axis=0) + m.skull.max(axis=0))
    orbits = {}
    for side, sign in (("l", 1.0), ("r", -1.0)):
        cands = []
        for lab in range(1, m.n + 1):
            u, v = m.region(lab)
            x, y = m.xy(u.mean(), v.mean())
            if 12.0 < sign * (x - centre[0]) < 45.0 and y < centre[1]:
                cands.append((len(u), u, v))
        _, u, v = max(cands, key=lambda c: c[0])
        orbits[side] = (u, v)
    x_mid = float(np.mean([m.xy(u.mean(), 0)[0] for u, _ in orbits.values()]))
    return orbits, x_mid


def _midline(m, x_mid, top_y, axis_y, aperture, hu_at):
    """Nasion, glabella, metopion, subspinale, prosthion (see the module notes)."""
    prof = m.profile(x_mid)
    out = {}
    upper = prof[(prof[:, 1] > axis_y) & (prof[:, 1] < top_y + 10.0)]
    out["nasion"] = upper[np.argmin(upper[:, 2])]
    n_y = out["nasion"][1]
    brow = prof[(prof[:, 1] >= n_y) & (prof[:, 1] <= n_y + 35.0)]
    out["glabella"] = brow[np.argmax(brow[:, 2])]
    target = out["glabella"][1] + METOPION_ABOVE_GLABELLA_MM
    out["metopion"] = prof[np.argmin(np.abs(prof[:, 1] - target))]
    ap_bottom = m.xy(0, aperture[1].max())[1]
    spine = prof[np.abs(prof[:, 1] - ap_bottom) <= 4.0]
    ans = spine[np.argmax(spine[:, 2])]
    below = prof[prof[:, 1] < ans[1]]  # top-down
    probe = np.max([hu_at(below - np.array([0.0, 0.0, d])) for d in ENAMEL_PROBE_MM], axis=0)
    enamel = np.flatnonzero(probe >= ENAMEL_HU)
    out["prosthion"] = below[max(enamel[0] - 1, 0)]
    arc = below[: max(enamel[0] - 1, 1)]
    chord = out["prosthion"][1:] - ans[1:]
    normal = np.array([chord[1], -chord[0]]) / np.linalg.norm(chord)
    normal *= -np.sign(normal[1])  # posterior
    out["subspinale"] = arc[np.argmax((arc[:, 1:] - ans[1:]) @ normal)]
    return out


def _zygion_frontotemporale(skull, cranial, top_y, x_mid):
    """Zygion and frontotemporale of both sides (see the module notes)."""
    out = {}
    for side, sign in (("l", 1.0), ("r", -1.0)):
        o, e = cranial[f"orbitale_{side}"], cranial[f"ectoconchion_{side}"]
        c = skull[
            (skull[:, 1] > o[1] - 20.0)
            & (skull[:, 1] < o[1] + 5.0)
            & (skull[:, 2] < e[2] - 5.0)
            & (skull[:, 2] > e[2] - 50.0)
        ]
        out[f"zygion_{side}"] = plateau_point(c, np.array([sign, 0.0, 0.0]))
        off = sign * (skull[:, 0] - x_mid)
        c = skull[
            (skull[:, 1] > top_y + 15.0)
            & (skull[:, 1] < top_y + 21.0)
            & (off > 25.0)
            & (off < 60.0)
            & (skull[:, 2] > e[2])
        ]
        direction = np.array([sign, 0.0, 0.8]) / np.hypot(1.0, 0.8)
        out[f"frontotemporale_{side}"] = plateau_point(c, direction)
    return out


def _ala(skin_map, cranial, x_mid, sign):
    """The facial alare of one side (see the module notes)."""
    m, u_mid = skin_map, skin_map.u_of(x_mid)
    top = max(cranial["alare_l"][1], cranial["alare_r"][1]) + ALA_ABOVE_MM
    edges = []
    for row in range(m.v_of(top), m.v_of(cranial["subspinale"][1])):
        us, _, h = m.scan(u_mid, row, 1 if sign > 0 else -1, 0, ALA_SCAN_MM)
        drop = np.flatnonzero(h[:-1] - h[1:] > ALA_STEP_MM)
        if len(drop):
            edges.append((int(drop[0]), int(us[drop[0]]), row))
    widest = max(e[0] for e in edges)
    rows = [e for e in edges if e[0] == widest]
    _, col, row = rows[len(rows) // 2]
    return m.vertex(col, row)


def _facial(skull, skull_faces, skin, skin_faces, cranial, x_mid):
    from lilium.softtissue.normals import landmark_normals

    normals = landmark_normals(skull, skull_faces, cranial)
    skin_map = _Map(skin, skin_faces, regions=False)
    facial = {}
    z_axis = np.array([0.0, 0.0, 1.0])
    for name in ("nasion", "glabella", "metopion"):
        d = normals[name] * np.array([0.0, 1.0, 1.0])
        facial[name] = _over(skin, cranial[name], d, outermost=False)
    for side, sign in (("l", 1.0), ("r", -1.0)):
        for base in ("zygion", "frontotemporale"):
            key = f"{base}_{side}"
            if key in cranial:
                facial[key] = _over(skin, cranial[key], normals[key], outermost=False)
        facial[f"alare_{side}"] = _ala(skin_map, cranial, x_mid, sign)
        e = cranial[f"ectoconchion_{side}"] + np.array([-sign * 5.0, 0.0, -15.0])
        facial[f"exocanthion_{side}"] = _over(skin, e, z_axis, max_t_mm=60.0)
        d = cranial[f"dacryon_{side}"] + np.array([sign * 3.0, 0.0, -15.0])
        facial[f"endocanthion_{side}"] = _over(skin, d, z_axis, max_t_mm=60.0)
    sprof = skin_map.profile(x_mid)
    face = sprof[sprof[:, 1] < cranial["nasion"][1]]
    tip = face[np.argmax(face[:, 2])]
    cut = skin[:, 1].min() + 1.0
    lip = face[(face[:, 1] < tip[1] - 8.0) & (face[:, 1] > cut)]
    bulge = [
        k
        for k in range(len(lip))
        if lip[k, 2] >= lip[np.abs(lip[:, 1] - lip[k, 1]) <= LIP_BULGE_MM, 2].max()
        and lip[k, 2] > lip[np.abs(lip[:, 1] - lip[k, 1]) <= LIP_BULGE_MM, 2].min()
    ]
    if bulge:
        facial["labiale_superius"] = lip[bulge[-1]]
        end = facial["labiale_superius"]
    else:
        end = lip[-1]
    arc = face[(face[:, 1] < tip[1]) & (face[:, 1] > end[1])]
    chord = end[1:] - tip[1:]
    normal = np.array([chord[1], -chord[0]]) / np.linalg.norm(chord)
    normal *= -np.sign(normal[1])  # posterior
    facial["subnasale"] = arc[np.argmax((arc[:, 1:] - tip[1:]) @ normal)]
    return facial


def place_landmarks(skull, skull_faces, skin, skin_faces, hu_at):
    """Cranial and facial landmarks by the rules of the module notes (skull frame, mm).

    Parameters
    ----------
    skull : ndarray of shape (V, 3)
    skull_faces : ndarray of shape (F, 3)
    skin : ndarray of shape (V', 3)
    skin_faces : ndarray of shape (F', 3)
    hu_at : callable
        ``hu_at(points (N, 3)) -> (N,)``: the CT number at skull-frame points (for the enamel
        of the incisors at prosthion).

    Returns
    -------
    cranial, facial : dict of str -> ndarray of shape (3,)
    x_mid : float
        The midline's x (between the orbits).
    """
    m = _Map(skull, skull_faces)
    orbits, x_mid = _orbits(m)
    cranial, top_y, axis_y = _orbit_landmarks(m, orbits, x_mid)
    aperture = _aperture(m, x_mid, axis_y)
    cranial.update(_alare(m, aperture, x_mid))
    cranial.update(_midline(m, x_mid, top_y, axis_y, aperture, hu_at))
    cranial.update(_zygion_frontotemporale(skull, cranial, top_y, x_mid))
    facial = _facial(skull, skull_faces, skin, skin_faces, cranial, x_mid)
    return cranial, facial, x_mid
