"""Each landmark's own definition on the normalised mesh (skull frame, mm).

The rules are the generator's placement rules (:mod:`lilium.synthetic.anatomy.landmarks`) with
the search centres taken from the fitted template (``estimates``, ``anchors``) instead of the
generator's design points, except ectoconchion and dacryon, which follow the craniometric
definitions an examiner places them by: the generator puts ectoconchion on the rim's edge
inside the orbit, about 3.5 mm from the lateral border's crest on its skulls, and dacryon on
the medial margin, about 4 mm in front of and 4 mm above the craniometric point; on the real
heads' rounded rims both lay 5-6 mm from an examiner's points (decision 0028). A landmark whose
rule finds nothing keeps its template estimate. Written down (docs/method/skull.md lists them too):

- midline profile: the most anterior point of the mesh's cut by ``x = 0`` per
  :data:`PROFILE_STEP_MM` of height (cranium and mandible apart);
- ``glabella``: the most anterior profile point within ``GLABELLA_MM`` of its estimate's height;
- ``nasion``: the most posterior profile point from ``NASION_MM[0]`` below its estimate to
  3 mm below glabella (the deepest point of the nasal root);
- ``metopion``: the profile point 36 mm above glabella;
- ``bregma``: the highest point of the cut at the estimate's z;
- ``subspinale``: the most posterior profile point between the anterior nasal spine (within
  ``ANS_MM`` of the template's spine, the last profile point going up before a step back of
  ``ANS_STEP_MM``, else the most anterior one) and the prosthion estimate's height + 2 mm; on a
  flat wall (within :data:`WALL_MM` of the deepest) its lowest point (:func:`lowest_deepest`);
- ``pogonion``: the most anterior mandible profile point from 3 mm above menton to menton +
  20 mm; when that is the window's top (a receding chin), the point farthest in front of the
  chord from the window's top to menton; ``gnathion``: the mandible profile point furthest
  along ``(0, -1, 1)`` within ``CHIN_MM``;
- orbits (frontal height map, :class:`~lilium.skull.surface.FrontalMap`): the centre is the
  template's, re-centred once between the rim edges of scans up/down and in/out (the
  transverse axis: the row through that centre); ``orbitale``: the rim edge of the scan
  down (30 mm); ``ectoconchion``: the most anterior point of the lateral border on the
  transverse axis, the crest of the scan from the centre laterally (32 mm), the innermost
  point within :data:`PLATEAU_MM` of its highest (:func:`crest`); ``dacryon``, where frontal,
  lacrimal and maxilla meet on the medial wall: the mesh vertex nearest to
  :data:`DACRYON_BEHIND_MM` behind the medial margin, the rim edge of the scan on the
  transverse axis to 2 mm off the midline;
- ``alare``: the rim edge (0.9) of the scan from the aperture's centre laterally (25 mm) on
  each row within ``ALARE_ROWS_MM`` of the centre's height; of the rows whose edge lies within
  :data:`PLATEAU_MM` of the most lateral one, the middle one (the generator's scan runs at its
  aperture's centre height, where the aperture is widest: the widest rows' middle finds that
  height whatever the template's centre, where the single most lateral row wanders along a
  near-vertical margin);
- ``zygion``: the cranium vertex of largest ``|x|`` on the arch behind the orbit
  (:data:`ZYGION_ARCH_MM` about the located orbitale's height and ectoconchion's depth), or,
  without them, within ``ZYGION_BOX_MM`` (y, z) of its estimate (the generator's own window,
  fixed in its frame, put 10 of 20 generated zygia 8-26 mm off: its extreme lies on the
  window's edge, and the fitted frame is not the generator's to a few mm; the box about the
  estimate missed the real arches' extremes by 9-11 mm); ``gonion``: the mandible vertex
  furthest along ``(+-1, -0.22, -0.22)`` within ``GONION_MM`` of its estimate;
  ``frontotemporale``: the cranium vertex furthest along
  ``(+-1, 0, 0.8)`` in the generator's band (3 mm up and down, 6 mm along ``(-+0.8, 0, 1)``
  about ``(+-42, y, 60)`` template mm:
  :data:`~lilium.synthetic.anatomy.landmarks.FRONTOTEMPORALE`), its height ``y``
  :data:`FRONTOTEMPORALE_ABOVE_GLABELLA_MM` above the located glabella (the generator's is 18
  mm above its brow design height, which no mesh shows; with no bone in that band, a vault
  cut below it, none; without a glabella: within ``FRONTOTEMPORALE_MM`` of the estimate);

Left as the template places them: ``prosthion`` and ``infradentale`` (the alveolar crest
between the incisors: the teeth and the bone are one surface on a mesh), ``porion`` (the ear
canal's top) and the mental foramina (no hole on most meshes).
"""

import numpy as np

from ..synthetic.anatomy.landmarks import FRONTOTEMPORALE
from .surface import anterior_profile, frontal_map, midline_section, rim_edge

PROFILE_STEP_MM = 0.5
PROFILE_BAND_MM = 0.5
GLABELLA_MM = (-8.0, 12.0)
NASION_MM = 12.0
METOPION_ABOVE_GLABELLA_MM = 36.0
#: The anterior nasal spine: searched within ANS_MM (mm) of the template's; its tip is where the
#: profile steps back by more than ANS_STEP_MM from one row to the next (else the most anterior
#: point there).
ANS_MM = 6.0
ANS_STEP_MM = 3.0
CHIN_MM = 10.0
#: Pogonion: the chin's profile from this above menton (mm) up to CHIN_MM above the centre
#: (CHIN_ABOVE_MENTON_MM[1] above menton).
CHIN_ABOVE_MENTON_MM = (3.0, 10.0)
#: A most anterior point this close (mm) to the window's top is no bulge (a receding chin,
#: or a head pitched forward): pogonion is then the point farthest in front of the chord from
#: the window's top to menton.
CHIN_EDGE_MM = 1.5
GNATHION_SPAN_MM = 14.0
#: The face's midline profile: section points in front of this (mm) behind the orbits' centres.
FRONT_BEHIND_ORBIT_MM = 25.0
#: Extreme points: the centre of the points within this (mm) of the extreme (a flat crest's
#: middle, not its first vertex); the orbit's lateral border (:func:`crest`) takes the
#: innermost of them instead, the crest's orbital side.
PLATEAU_MM = 0.5
#: Subspinale: profile points within this (mm) of the deepest are equally deep (a flat wall,
#: as below the generator's spine), and the lowest of them is taken, as the generator's scan
#: from the prosthion upwards takes its first deepest row. Measured on 20 generated skulls
#: (``benchmarks/bench_skull_landmarks.py --subjects 5``): the deepest point alone lay 2.2 mm
#: (median; 90th percentile 8.4) from the generator's, on a wall whose depth varies by
#: hundredths of a millimetre, now 1.3 (6.5); the real heads' the same. With
#: :data:`PLATEAU_MM` the generated 0.9 (3.0), but headsq's 1.5 mm further from its hand
#: placement (its 3.2 mm CT's concavity is shallow).
WALL_MM = 0.1
#: Landmarks whose rule is the craniometric definition, not the generator's (module notes).
CRANIOMETRIC = ("ectoconchion", "dacryon")
ORBIT_SCANS_MM = {"ectoconchion": 32.0, "orbitale": 30.0, "dacryon_x": 2.0}
#: Dacryon lies in the lacrimal fossa behind the medial margin (the anterior lacrimal crest):
#: the vertex nearest to this far (mm) behind the margin's point; on a CT whose thin lacrimal
#: bone is below the bone level, the posterior edge of the maxilla's frontal process.
DACRYON_BEHIND_MM = 4.0
ALARE_SCAN_MM = 25.0
ALARE_FRACTION = 0.9
ALARE_ROWS_MM = 8.0
ZYGION_BOX_MM = (8.0, 12.0)
#: Zygion's window on the arch behind the orbit (mm): from ``below`` to ``above`` the located
#: orbitale's height, and from ``farthest`` to ``nearest`` behind the located ectoconchion:
#: ``((below, above), (farthest, nearest))``, as the hand placements of the real heads take it.
ZYGION_ARCH_MM = ((20.0, 5.0), (50.0, 5.0))
GONION_MM = 15.0
GONION_DIRECTION = (1.0, -0.22, -0.22)
FRONTOTEMPORALE_MM = 10.0
#: Height (template mm) of the generator's frontotemporale above its glabella: 12.0-13.5,
#: mean 12.7 (SD 0.5) on 24 generated skulls of three dataset seeds.
FRONTOTEMPORALE_ABOVE_GLABELLA_MM = 12.7


def _profile(points, lo, hi, z_min=-np.inf):
    points = points[points[:, 2] > z_min]
    ys = np.arange(lo, hi, PROFILE_STEP_MM)
    prof = anterior_profile(points, ys, PROFILE_BAND_MM)
    return prof[np.isfinite(prof[:, 2])]


def _midline(section, on_mandible, est, anchors):
    """The midline landmarks found (dict)."""
    pts, mand = section
    cranium, mandible = pts[~mand], pts[mand]
    # The face's profile: in front of the orbits' centres.
    front = 0.5 * (anchors["orbit_l"][2] + anchors["orbit_r"][2]) - FRONT_BEHIND_ORBIT_MM
    cranium_front = cranium[cranium[:, 2] > front]
    mandible_front = mandible[mandible[:, 2] > front]
    out = {}
    if "glabella" in est:
        g = est["glabella"][1]
        prof = _profile(cranium_front, g + GLABELLA_MM[0], g + GLABELLA_MM[1])
        if len(prof):
            out["glabella"] = prof[np.argmax(prof[:, 2])]
    top = out.get("glabella", est.get("glabella"))
    if "nasion" in est and top is not None:
        prof = _profile(cranium_front, est["nasion"][1] - NASION_MM, top[1] - 3.0)
        if len(prof):
            out["nasion"] = prof[np.argmin(prof[:, 2])]
    if "metopion" in est and "glabella" in out:
        y = out["glabella"][1] + METOPION_ABOVE_GLABELLA_MM
        prof = _profile(cranium_front, y - PROFILE_STEP_MM, y + PROFILE_STEP_MM)
        if len(prof):
            out["metopion"] = prof[np.argmin(np.abs(prof[:, 1] - y))]
    if "bregma" in est:
        near = cranium[np.abs(cranium[:, 2] - est["bregma"][2]) < PROFILE_BAND_MM]
        if len(near):
            out["bregma"] = near[np.argmax(near[:, 1])]
    if "subspinale" in est and "prosthion" in est:
        a = anchors["ans"][1]
        spine = _profile(cranium_front, a - ANS_MM, a + ANS_MM)
        ans = _spine(spine)
        if ans is None and len(spine):  # no step back: the most anterior point
            ans = spine[np.argmax(spine[:, 2])]
        if ans is not None:
            prof = _profile(cranium_front, est["prosthion"][1] + 2.0, ans[1] - 1.0)
            if len(prof):
                out["subspinale"] = lowest_deepest(prof)
    if "pogonion" in est and len(mandible_front):
        menton = mandible_front[np.argmin(mandible_front[:, 1])]
        centre = menton[1] + CHIN_ABOVE_MENTON_MM[1]
        prof = _profile(mandible_front, menton[1] + CHIN_ABOVE_MENTON_MM[0],
                        centre + CHIN_MM)  # fmt: skip
        if len(prof):
            top = prof[np.argmax(prof[:, 1])]
            p = plateau_point(prof, np.array([0.0, 0.0, 1.0]))
            if top[1] - p[1] < CHIN_EDGE_MM:  # the window's top, no bulge: a receding chin
                p = _behind_chord(prof, top, menton, posterior=False)
            out["pogonion"] = p
        chin = mandible_front[
            np.abs((mandible_front - (0, centre, menton[2])) @ (0, 1, 1)) / np.sqrt(2)
            < GNATHION_SPAN_MM
        ]
        if "gnathion" in est and len(chin):
            out["gnathion"] = plateau_point(chin, np.array([0.0, -1.0, 1.0]) / np.sqrt(2))
    return out


def lowest_deepest(profile):
    """The lowest of the most posterior points of a midline ``profile`` (N, 3), those within
    :data:`WALL_MM` of the deepest (subspinale on a flat wall)."""
    deep = profile[profile[:, 2] <= profile[:, 2].min() + WALL_MM]
    return deep[np.argmin(deep[:, 1])].copy()


def _spine(prof):
    """The anterior nasal spine's tip on a cranium profile (``(K, 3)``, bottom-up): the last
    point going up before the profile steps back by :data:`ANS_STEP_MM` (onto the nasal floor
    or into the aperture), or None."""
    step = prof[:-1, 2] - prof[1:, 2]
    gap = np.diff(prof[:, 1]) > 2 * PROFILE_STEP_MM
    k = np.flatnonzero((step > ANS_STEP_MM) | gap)
    return prof[k[0]].copy() if len(k) and k[0] > 0 else None


def _behind_chord(arc, a, b, posterior):
    """The point of ``arc`` ``(K, 3)`` farthest behind (``posterior``) or in front of the chord
    ``a -> b`` in the midsagittal view (y, z): the deepest point of a concavity, the top of a
    bulge, whatever the head's pitch."""
    chord = (b - a)[1:]
    normal = np.array([-chord[1], chord[0]]) / max(np.linalg.norm(chord), 1e-9)
    normal *= np.sign(normal[1]) or 1.0  # anterior (+z)
    h = (arc[:, 1:] - a[1:]) @ normal
    return arc[np.argmin(h) if posterior else np.argmax(h)].copy()


def _orbit(fm, vertices, centre, sx):
    """Ectoconchion, orbitale, dacryon of one side (``sx`` 1 left, -1 right)."""
    s = ORBIT_SCANS_MM
    c = np.asarray(centre, float)[:2]
    up = rim_edge(fm.scan(c, c + (0, s["orbitale"])))
    down = rim_edge(fm.scan(c, c - (0, s["orbitale"])))
    lateral = rim_edge(fm.scan(c, c + (sx * s["ectoconchion"], 0)))
    medial = rim_edge(fm.scan(c, (sx * s["dacryon_x"], c[1])))
    if up is not None and down is not None:
        c[1] = 0.5 * (up[1] + down[1])
    if lateral is not None and medial is not None:
        c[0] = 0.5 * (lateral[0] + medial[0])
    margin = rim_edge(fm.scan(c, (sx * s["dacryon_x"], c[1])))
    out = {
        "ectoconchion": crest(fm.scan(c, c + (sx * s["ectoconchion"], 0))),
        "orbitale": rim_edge(fm.scan(c, c - (0, s["orbitale"]))),
        "dacryon": None if margin is None else _nearest(
            vertices, margin - (0.0, 0.0, DACRYON_BEHIND_MM)
        ),
    }
    return {k: v for k, v in out.items() if v is not None and np.all(np.isfinite(v))}


def crest(points):
    """The crest of a scan from inside an opening outwards (``(N, 3)``, :meth:`FrontalMap.scan`):
    of its points within :data:`PLATEAU_MM` of the highest z, the innermost (the rim's orbital
    side of a flat crest); None when the scan has no surface."""
    z = np.where(np.isfinite(points[:, 2]), points[:, 2], -np.inf)
    if not np.isfinite(z).any():
        return None
    return points[int(np.argmax(z >= z.max() - PLATEAU_MM))].copy()


def _alare(fm, centre, sx):
    c = np.asarray(centre, float)[:2]
    edges = []
    for dy in np.arange(-ALARE_ROWS_MM, ALARE_ROWS_MM + 1e-9, fm.px):
        start = (0.0, c[1] + dy)
        p = rim_edge(fm.scan(start, (sx * ALARE_SCAN_MM, c[1] + dy)), ALARE_FRACTION)
        if p is not None and np.isfinite(p[2]):
            edges.append(p)
    if not edges:
        return None
    edges = np.array(edges)  # bottom-up
    widest = edges[sx * edges[:, 0] >= (sx * edges[:, 0]).max() - PLATEAU_MM]
    return widest[len(widest) // 2]


def plateau_point(points, direction):
    """The extreme point of ``points`` (N, 3) along the unit ``direction``, taken at the centre
    of its plateau: the point nearest to the centre of those within :data:`PLATEAU_MM` of the
    extreme. On a flat stretch (a zygomatic arch seen from the side) the single farthest vertex
    wanders by centimetres with a fraction of a degree of pose; the plateau's centre does not.
    The benchmarks' hand placements take their extreme points the same way."""
    h = points @ direction
    return _nearest(points, points[h >= h.max() - PLATEAU_MM].mean(axis=0))


def _nearest(points, point):
    """The point of ``points`` (N, 3) nearest to ``point`` (a copy)."""
    return points[np.argmin(np.linalg.norm(points - point, axis=1))].copy()


def _support(vertices, mask, centre, radius, direction):
    near = mask & (np.linalg.norm(vertices - centre, axis=1) < radius)
    if not near.any():
        return None
    d = np.asarray(direction, float)
    return plateau_point(vertices[near], d / np.linalg.norm(d))


def _frontotemporale(points, mask, sx, y):
    """The generator's frontotemporale
    (:data:`~lilium.synthetic.anatomy.landmarks.FRONTOTEMPORALE`) at height ``y``: the point
    furthest along its direction in its band (``points`` in template mm), or None."""
    ft = FRONTOTEMPORALE
    centre = np.array([sx * ft["centre_mm"][0], y, ft["centre_mm"][2]])
    e2 = np.array(ft["e2"]) * (sx, 1, 1)
    e2 /= np.linalg.norm(e2)
    rel = points - centre
    span_y, span_e2 = ft["spans_mm"]
    band = mask & (np.abs(rel[:, 1]) <= span_y) & (np.abs(rel @ e2) <= span_e2)
    if not band.any():
        return None
    d = np.array(ft["direction"]) * (sx, 1, 1)
    return plateau_point(points[band], d / np.linalg.norm(d))


def _zygion_box(vertices, estimate, orbitale, ectoconchion):
    """The vertices ``(V,)`` where zygion is looked for: the arch behind the orbit
    (:data:`ZYGION_ARCH_MM` about ``orbitale``'s height and ``ectoconchion``'s depth) when both
    are located, else :data:`ZYGION_BOX_MM` about the
    template's ``estimate``."""
    y, z = vertices[:, 1], vertices[:, 2]
    if orbitale is None or ectoconchion is None:
        return (np.abs(y - estimate[1]) < ZYGION_BOX_MM[0]) & (
            np.abs(z - estimate[2]) < ZYGION_BOX_MM[1]
        )
    (below, above), (farthest, nearest) = ZYGION_ARCH_MM
    return ((y > orbitale[1] - below) & (y < orbitale[1] + above)
            & (z > ectoconchion[2] - farthest) & (z < ectoconchion[2] - nearest))


def apply_rules(vertices, faces, on_mandible, estimates, anchors, scale=1.0):
    """The landmarks found by their own definitions (module notes).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        The mesh in the normalised frame, mm.
    faces : ndarray of shape (F, 3), int
    on_mandible : ndarray of shape (V,), bool
        The mandible's vertices.
    estimates : dict of str -> ndarray of shape (3,)
        The template's estimates (:func:`~lilium.skull.transfer.transfer_landmarks`); a
        landmark is looked for only when it has one.
    anchors : dict of str -> ndarray of shape (3,)
        The template's design points in the normalised frame
        (:attr:`~lilium.skull.template.Template.anchors`).
    scale : float
        Template size over mesh size: the generator's windows (template mm) over this are the
        mesh's.

    Returns
    -------
    dict of str -> ndarray of shape (3,)
    """
    est = estimates
    points, face = midline_section(vertices, faces)
    section = (points, on_mandible[faces[face]].all(axis=1))
    out = _midline(section, on_mandible, est, anchors)
    fm = frontal_map(vertices, faces)
    cranium = ~on_mandible
    for sx, sfx in ((1, "_l"), (-1, "_r")):
        orbit = _orbit(fm, vertices, anchors["orbit" + sfx], sx)
        out.update({k + sfx: v for k, v in orbit.items() if k + sfx in est})
        if "alare" + sfx in est:
            p = _alare(fm, anchors["aperture"], sx)
            if p is not None:
                out["alare" + sfx] = p
        name = "zygion" + sfx
        if name in est:
            box = _zygion_box(vertices, est[name], out.get("orbitale" + sfx),
                              out.get("ectoconchion" + sfx))
            if (box & cranium).any():
                out[name] = plateau_point(vertices[box & cranium], np.array([sx, 0.0, 0.0]))
        if "gonion" + sfx in est:
            d = np.array(GONION_DIRECTION) * (sx, 1, 1)
            p = _support(vertices, on_mandible, est["gonion" + sfx], GONION_MM, d)
            if p is not None:
                out["gonion" + sfx] = p
        name = "frontotemporale" + sfx
        if name in est:
            if "glabella" in out:  # the generator's band (template mm), back to the mesh's
                y = out["glabella"][1] * scale + FRONTOTEMPORALE_ABOVE_GLABELLA_MM
                p = _frontotemporale(vertices * scale, cranium, sx, y)
                p = None if p is None else p / scale  # no bone in the band: a cut vault
            else:  # no glabella: near the estimate
                d = np.array(FRONTOTEMPORALE["direction"]) * (sx, 1, 1)
                p = _support(vertices, cranium, est[name], FRONTOTEMPORALE_MM, d)
            if p is not None:
                out[name] = p
    return {k: np.asarray(v, float) for k, v in out.items() if np.all(np.isfinite(v))}
