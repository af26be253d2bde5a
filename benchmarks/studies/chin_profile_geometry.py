"""The chin-jaw profile's measurement (the geometry of ``benchmarks/studies/chin_profile.py``).

:func:`chin_profile` measures one head in the chin region of :func:`subject_region` (a generated
subject) or :func:`ct_region` (the head CT), from the mesh geometry below it (plane sections,
the border point, the bone's patch normal, the ray's first hit on the skin);
:func:`profile_summary` condenses the profiles of one source. The script prints and plots them.

For lateral offsets ``x = -25, -20, ..., +25`` mm from the midline (about the span between the
mental foramina) the profile measures, in each source's head frame (mm; ``x`` = the subject's left,
``y`` = up, ``z`` = anterior):

1. ``bone_rise_mm``: the height of the mandible's inferior border in that column, relative to
   the border at ``x = 0`` (how much the bony chin outline rises sideways, seen from the front);
2. ``depth_mm``: the distance from that border point to the skin along the bone's outward
   normal there (straight down where the normal is unreliable; each row says which);
3. ``skin_rise_mm``: the height of the skin point hit by the ray of 2., relative to its value
   at ``x = 0`` (whether the skin outline follows the bone or stays flat).

Definitions (the names of the constants below hold the numbers):

- **Column** ``x``: the bone mesh cut by the sagittal plane ``x = x_mid + x`` (the points where
  its edges cross the plane), inside the *chin region*: anterior to ``z_back_mm`` and below
  ``y_top_mm``.
- **Border point** ``B(x)``: the lowest (least ``y``) crossing point of the column.
  ``bone_rise_mm = B_y(x) - B_y(0)``; ``back_mm = B_z(0) - B_z(x)`` says how far behind the
  midline border it lies. A border point within :data:`EDGE_MM` of ``z_back_mm`` is flagged
  ``e`` (the region's back edge, not the bone, may have set it).
- **Normal** ``n(x)``: the area-weighted mean of the outward face normals (the meshes' winding
  is outward) of the bone faces whose centroids lie within :data:`NORMAL_RADIUS_MM` of ``B``.
  It is *unreliable* when the patch is incoherent (``|sum of area vectors| / sum of areas``
  below :data:`MIN_COHERENCE`) or tilted more than :data:`MAX_TILT_DEG` from straight down; the
  ray then goes straight down, ``(0, -1, 0)``, and the row is marked ``d`` (``n`` otherwise).
- **Skin point** ``S(x)``: the first hit of the ray ``B + t * direction, t > 0`` with the skin
  mesh (Moller-Trumbore over every triangle). ``depth_mm = |S - B|``,
  ``skin_rise_mm = S_y(x) - S_y(0)``.
- **CT cut**: the head CT stops at the neck, a few mm below the chin; the skin mesh there is the
  cap closing the volume (below the centre of its last slice). A skin point within
  :data:`CUT_MARGIN_MM` of that slice is marked ``c``: its depth is a lower bound (the true
  skin is lower), and a skin rise measured from a cut ``x = 0`` is a lower bound too.

Chin region, generated subjects (landmarks, skull frame; midline ``x_mid = gnathion_x``):
``z_back_mm`` = the mental foramina's mean ``z`` minus :data:`SUBJECT_BACK_MM`,
``y_top_mm`` = their mean ``y`` (the foramina lie above the inferior border, below the teeth).

Chin region, head CT (no landmarks; :func:`lilium.ct.import_ct` writes LPS, here mapped to
``x = L``, ``y = S``, ``z = -P``): *menton* = the lowest bone vertex anterior to
``z_max - CT_FACE_DEPTH_MM`` (``z_max``: the most anterior bone; this keeps the spine out);
*pogonion* = the most anterior bone vertex below ``menton_y + CT_HEIGHT_MM``; ``z_back_mm`` =
``pogonion_z - CT_BACK_MM``; ``y_top_mm = menton_y + CT_HEIGHT_MM``; ``x_mid`` = the middle of
the lateral extent of the bone vertices of that region.

Frames: the CT's "up" is the scanner's (its orientation is assumed by the importer, left/right
included), the generated subjects' is their skull frame's (Frankfurt plane close to ``y = 0``).
A pitch difference ``a`` between them changes a rise by about ``back_mm * sin(a)``, so the
``back`` column says how much a rise depends on head orientation.
"""

from dataclasses import dataclass

import numpy as np

#: Lateral offsets of the columns from the midline, mm.
X_OFFSETS_MM = np.arange(-25.0, 26.0, 5.0)
#: Radius of the bone patch whose face normals give the border's normal, mm.
NORMAL_RADIUS_MM = 5.0
#: Largest angle between the normal and straight down for the ray to follow the normal, deg.
MAX_TILT_DEG = 60.0
#: Smallest |sum of area vectors| / sum of areas of the normal's patch.
MIN_COHERENCE = 0.5
#: A border point this close to the region's back limit is flagged, mm.
EDGE_MM = 2.0
#: A skin point this close to (or below) the CT's last slice lies on the volume's cut, mm.
CUT_MARGIN_MM = 0.5
#: Generated subjects: the region reaches this far behind the mental foramina, mm.
SUBJECT_BACK_MM = 20.0
#: CT: the face's bone lies within this depth of the most anterior bone (the spine behind), mm.
CT_FACE_DEPTH_MM = 70.0
#: CT: the region's top above the menton ("below the teeth"), mm.
CT_HEIGHT_MM = 25.0
#: CT: the region reaches this far behind the pogonion, mm.
CT_BACK_MM = 50.0
#: Offsets at which the summary compares the bone and skin rises, mm.
SUMMARY_X_MM = (-20.0, 20.0)

DOWN = np.array([0.0, -1.0, 0.0])


@dataclass(frozen=True)
class ChinRegion:
    """Where the mandible's inferior border is sought (head frame, mm).

    Attributes
    ----------
    x_mid_mm : float
        The midline's ``x``.
    z_back_mm : float
        Points anterior to this (``z > z_back_mm``) are in the region.
    y_top_mm : float
        Points below this (``y < y_top_mm``) are in the region.
    marks : dict of str -> ndarray of shape (3,)
        Points that placed the region (landmarks or the CT's menton / pogonion), for plots.
    """

    x_mid_mm: float
    z_back_mm: float
    y_top_mm: float
    marks: dict


@dataclass(frozen=True)
class ChinProfile:
    """The chin-jaw profile of one head, one row per column (head frame, mm).

    Attributes
    ----------
    x_mm : ndarray of shape (N,)
        Offsets from the midline.
    border_mm : ndarray of shape (N, 3)
        Border points ``B`` (NaN where the column holds no bone of the region).
    normal : ndarray of shape (N, 3)
        Unit bone normals ``n`` at ``B`` (NaN where no face is near).
    direction : ndarray of shape (N, 3)
        Unit ray directions (the normal, or straight down).
    along_normal : ndarray of shape (N,), bool
        Whether the ray follows the bone normal (False: straight down).
    skin_mm : ndarray of shape (N, 3)
        Skin points ``S`` (NaN where the ray misses the skin).
    at_edge : ndarray of shape (N,), bool
        ``B`` within :data:`EDGE_MM` of the region's back limit.
    cut : ndarray of shape (N,), bool
        ``S`` on the cut closing the CT volume (its depth is a lower bound).
    """

    x_mm: np.ndarray
    border_mm: np.ndarray
    normal: np.ndarray
    direction: np.ndarray
    along_normal: np.ndarray
    skin_mm: np.ndarray
    at_edge: np.ndarray
    cut: np.ndarray

    def _at_zero(self, values):
        zero = np.flatnonzero(np.isclose(self.x_mm, 0.0))
        return values[zero[0]] if len(zero) else np.nan

    @property
    def depth_mm(self):
        """ndarray of shape (N,): ``|S - B|``."""
        return np.linalg.norm(self.skin_mm - self.border_mm, axis=1)

    @property
    def bone_rise_mm(self):
        """ndarray of shape (N,): ``B_y(x) - B_y(0)``."""
        return self.border_mm[:, 1] - self._at_zero(self.border_mm[:, 1])

    @property
    def skin_rise_mm(self):
        """ndarray of shape (N,): ``S_y(x) - S_y(0)``."""
        return self.skin_mm[:, 1] - self._at_zero(self.skin_mm[:, 1])

    @property
    def tilt_deg(self):
        """ndarray of shape (N,): the normal's angle from straight down; negative when it leans
        towards the midline rather than away from it."""
        angle = np.degrees(np.arccos(np.clip(self.normal @ DOWN, -1.0, 1.0)))
        away = np.sign(self.normal[:, 0]) * np.sign(self.x_mm)
        return np.where(away < 0, -angle, angle)

    @property
    def back_mm(self):
        """ndarray of shape (N,): ``B_z(0) - B_z(x)``, how far behind the midline border."""
        return self._at_zero(self.border_mm[:, 2]) - self.border_mm[:, 2]


def lps_to_head(points_lps):
    """LPS points (x left, y posterior, z superior) in the head frame (x left, y up, z anterior).

    Parameters
    ----------
    points_lps : array_like of shape (N, 3)

    Returns
    -------
    ndarray of shape (N, 3)
        ``(L, S, -P)``: a rotation (right-handed both), so face winding is kept.
    """
    p = np.asarray(points_lps, dtype=float)
    return np.column_stack([p[:, 0], p[:, 2], -p[:, 1]])


def plane_section(vertices_mm, faces, x_mm):
    """Points where the mesh's edges cross the plane ``x = x_mm``.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    x_mm : float

    Returns
    -------
    ndarray of shape (K, 3)
        One point per crossing edge of each face (shared edges appear twice).
    """
    v = np.asarray(vertices_mm, dtype=float)
    f = np.asarray(faces)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    a, b = v[edges[:, 0]], v[edges[:, 1]]
    da, db = a[:, 0] - x_mm, b[:, 0] - x_mm
    crossing = (da < 0) != (db < 0)
    t = da[crossing] / (da[crossing] - db[crossing])
    return a[crossing] + t[:, None] * (b[crossing] - a[crossing])


def in_region(points_mm, region):
    """Mask of the points inside the chin region's ``z`` and ``y`` limits.

    Parameters
    ----------
    points_mm : ndarray of shape (N, 3)
    region : ChinRegion

    Returns
    -------
    ndarray of shape (N,), bool
    """
    p = np.asarray(points_mm, dtype=float)
    return (p[:, 2] > region.z_back_mm) & (p[:, 1] < region.y_top_mm)


def border_point(vertices_mm, faces, region, x_mm):
    """The mandible's inferior border point of one column: its lowest section point.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
        Bone mesh, head frame.
    faces : ndarray of shape (F, 3), int
    region : ChinRegion
    x_mm : float
        Offset from the midline.

    Returns
    -------
    ndarray of shape (3,)
        NaN when the column holds no bone of the region.
    """
    section = plane_section(vertices_mm, faces, region.x_mid_mm + x_mm)
    section = section[in_region(section, region)]
    if not len(section):
        return np.full(3, np.nan)
    return section[np.argmin(section[:, 1])]


def patch_normal(vertices_mm, faces, point_mm, radius_mm=NORMAL_RADIUS_MM):
    """Area-weighted mean outward normal of the faces near a point, and its coherence.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
        A mesh whose winding is outward (right-hand rule).
    faces : ndarray of shape (F, 3), int
    point_mm : ndarray of shape (3,)
    radius_mm : float
        Faces whose centroids lie within this distance count.

    Returns
    -------
    normal : ndarray of shape (3,)
        Unit vector (NaN when no face is near).
    coherence : float
        ``|sum of area vectors| / sum of areas`` in [0, 1]: 1 for a flat patch.
    """
    tri = np.asarray(vertices_mm, dtype=float)[np.asarray(faces)]
    near = np.linalg.norm(tri.mean(axis=1) - point_mm, axis=1) <= radius_mm
    if not near.any():
        return np.full(3, np.nan), 0.0
    t = tri[near]
    area2 = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])  # length = twice the area
    total = area2.sum(axis=0)
    length = np.linalg.norm(total)
    coherence = length / np.linalg.norm(area2, axis=1).sum()
    return total / length, float(coherence)


def ray_direction(normal, coherence):
    """The depth ray: the normal when reliable, straight down otherwise.

    Parameters
    ----------
    normal : ndarray of shape (3,)
    coherence : float

    Returns
    -------
    direction : ndarray of shape (3,)
    along_normal : bool
    """
    ok = (
        np.all(np.isfinite(normal))
        and coherence >= MIN_COHERENCE
        and float(normal @ DOWN) >= np.cos(np.deg2rad(MAX_TILT_DEG))
    )
    return (np.asarray(normal, float), True) if ok else (DOWN.copy(), False)


def first_hit(vertices_mm, faces, origin_mm, direction):
    """The first point where a ray meets a triangle mesh (Moller-Trumbore).

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    origin_mm : ndarray of shape (3,)
    direction : ndarray of shape (3,)
        Unit vector.

    Returns
    -------
    ndarray of shape (3,)
        ``origin + t * direction`` for the least ``t > 0``; NaN when the ray misses.
    """
    tri = np.asarray(vertices_mm, dtype=float)[np.asarray(faces)]
    o, d = np.asarray(origin_mm, float), np.asarray(direction, float)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = o - tri[:, 0]
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    # A small tolerance: a ray along a shared edge must not slip between its two triangles.
    eps = 1e-9
    hit = ok & (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps) & (t > 1e-6)
    if not hit.any():
        return np.full(3, np.nan)
    return o + t[hit].min() * d


def chin_profile(bone, skin, region, x_offsets_mm=X_OFFSETS_MM, cut_y_mm=None, ray="normal"):
    """The chin-jaw profile of one head (see the module's definitions).

    Parameters
    ----------
    bone, skin : (ndarray of shape (V, 3), ndarray of shape (F, 3))
        Meshes in the head frame, mm, outward winding.
    region : ChinRegion
    x_offsets_mm : array_like of shape (N,)
    cut_y_mm : float, optional
        ``y`` of the last slice of a cut volume (the CT); None: no cut.
    ray : {"normal", "down"}
        ``"normal"``: the depth ray follows the bone normal where it is reliable
        (:func:`ray_direction`), straight down elsewhere; ``"down"``: straight down always.

    Returns
    -------
    ChinProfile
    """
    if ray not in ("normal", "down"):
        raise ValueError(f"ray must be 'normal' or 'down', got {ray!r}")
    x = np.asarray(x_offsets_mm, dtype=float)
    n = len(x)
    border, normal = np.full((n, 3), np.nan), np.full((n, 3), np.nan)
    skin_pt = np.full((n, 3), np.nan)
    direction, along = np.tile(DOWN, (n, 1)), np.zeros(n, bool)
    for k, dx in enumerate(x):
        b = border_point(*bone, region, dx)
        if not np.all(np.isfinite(b)):
            continue
        border[k] = b
        normal[k], coherence = patch_normal(*bone, b)
        if ray == "normal":
            direction[k], along[k] = ray_direction(normal[k], coherence)
        skin_pt[k] = first_hit(*skin, b, direction[k])
    at_edge = border[:, 2] < region.z_back_mm + EDGE_MM
    cut = np.zeros(n, bool) if cut_y_mm is None else skin_pt[:, 1] < cut_y_mm + CUT_MARGIN_MM
    return ChinProfile(x, border, normal, direction, along, skin_pt, at_edge, cut)


def subject_region(cranial_landmarks):
    """The chin region of a generated subject, from its landmarks (skull frame).

    Parameters
    ----------
    cranial_landmarks : dict of str -> ndarray of shape (3,)
        Needs ``mental_foramen_l``, ``mental_foramen_r`` and ``gnathion``.

    Returns
    -------
    ChinRegion
    """
    foramina = np.array([cranial_landmarks[f"mental_foramen_{s}"] for s in "lr"], float)
    gnathion = np.asarray(cranial_landmarks["gnathion"], float)
    marks = {"mental_foramen_l": foramina[0], "mental_foramen_r": foramina[1]}
    marks["gnathion"] = gnathion
    return ChinRegion(
        x_mid_mm=float(gnathion[0]),
        z_back_mm=float(foramina[:, 2].mean() - SUBJECT_BACK_MM),
        y_top_mm=float(foramina[:, 1].mean()),
        marks=marks,
    )


def ct_region(bone_vertices_mm):
    """The chin region of a head CT without landmarks (head frame; see the module notes).

    Parameters
    ----------
    bone_vertices_mm : ndarray of shape (V, 3)

    Returns
    -------
    ChinRegion
        ``marks``: ``menton`` and ``pogonion`` (bone vertices).
    """
    v = np.asarray(bone_vertices_mm, dtype=float)
    face = v[v[:, 2] > v[:, 2].max() - CT_FACE_DEPTH_MM]
    menton = face[np.argmin(face[:, 1])]
    y_top = menton[1] + CT_HEIGHT_MM
    low = face[face[:, 1] < y_top]
    pogonion = low[np.argmax(low[:, 2])]
    z_back = pogonion[2] - CT_BACK_MM
    chin = low[low[:, 2] > z_back]
    x_mid = 0.5 * (chin[:, 0].min() + chin[:, 0].max())
    return ChinRegion(
        x_mid_mm=float(x_mid),
        z_back_mm=float(z_back),
        y_top_mm=float(y_top),
        marks={"menton": menton, "pogonion": pogonion},
    )


def _median(values):
    """Median of the finite values; NaN when there are none."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if len(v) else np.nan


def profile_summary(profiles):
    """Summary numbers of one source (one head or several), mm.

    Parameters
    ----------
    profiles : list of ChinProfile
        The same ``x_mm`` each.

    Returns
    -------
    dict
        ``depth_median_mm`` (over every head and column), ``depth_range_mm`` (min, max over
        ``x`` of the per-column median depth), and for each ``x`` of :data:`SUMMARY_X_MM`,
        ``bone_rise_mm[x]`` / ``skin_rise_mm[x]`` (medians over the heads); ``cut``: the
        number of cut skin points.
    """
    depth = np.array([p.depth_mm for p in profiles])
    column_depth = np.array([_median(column) for column in depth.T])
    column_depth = column_depth[np.isfinite(column_depth)]
    depth_range = (column_depth.min(), column_depth.max()) if len(column_depth) else (np.nan,) * 2
    x = profiles[0].x_mm
    out = {
        "depth_median_mm": _median(depth),
        "depth_range_mm": tuple(float(d) for d in depth_range),
        "bone_rise_mm": {},
        "skin_rise_mm": {},
        "cut": int(sum(p.cut.sum() for p in profiles)),
    }
    for xs in SUMMARY_X_MM:
        k = int(np.argmin(np.abs(x - xs)))
        out["bone_rise_mm"][xs] = _median([p.bone_rise_mm[k] for p in profiles])
        out["skin_rise_mm"][xs] = _median([p.skin_rise_mm[k] for p in profiles])
    return out
