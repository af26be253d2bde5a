"""Procedural subjects: a skull, a face and their landmarks, with known soft tissue.

Each subject is built the way a CT scan would give it: a synthetic volume (smooth unions of
ellipsoids, capsules and swept bars with low-frequency noise) whose bone and skin iso-surfaces
are extracted by the CT pipeline (:func:`lilium.ct.mesh.volume_to_mesh`: marching cubes, largest
component). Between-subject variation comes from independent shape parameters
(:class:`SubjectShape`: vault length, breadth and height, face width and height, jaw width and
height, gonial angle, chin, brow ridges, alveolar prognathism, orbits, nasal aperture, nose, ears).

Skull frame (the frame of every mesh and landmark here), written once:
millimetres; ``x`` = the subject's left, ``y`` = superior (up), ``z`` = anterior (the face looks
along ``+z``); the origin is near the centre of the head, at the midpoint of the ear canals
(porion height, so the Frankfurt plane is close to ``y = 0``). A camera frame is x right, y down,
z forward (SPEC section 8), so a frontal photo camera looks along ``-z`` of the skull frame.

Soft tissue, per subject: for each cranial landmark of a correspondence, a depth drawn from the
population table (``N(mean, sd)`` clipped inside ``[min, max]``) and a direction within
:data:`MAX_DIRECTION_DEG` of the outward bone normal (twins nearly mirror-symmetric). The target
facial point ``F = C + depth * direction`` is then made to lie exactly on the skin: the skin is the
"soft-tissue support" (bone, eyeballs, muscles, neck) offset by a depth field interpolated from
the drawn depths, plus nose, lips and ears built around the targets, and finally corrected by
small Gaussian bumps so that its zero level passes through every target.

``soft_tissue_axes`` holds these true directions (the axes given to the methods; Exp. C perturbs
them); ``bone_normals`` holds the default axes a method would compute from the skull mesh.
"""

from dataclasses import dataclass, field

import numpy as np

from ..ct.mesh import volume_to_mesh
from ..ct.volume import Volume
from ..softtissue.depths import BUILTIN_DEPTHS
from ..softtissue.landmarks import CORRESPONDENCES, CRANIAL_NAMES, FACIAL_NAMES, base_name, twin
from ..softtissue.normals import surface_normals_at
from .volume_fields import (
    GridField,
    capsule,
    ellipsoid,
    plane,
    rotation_xyz,
    slab,
    superellipsoid,
    sweep,
)

#: Voxel size (mm) of the synthetic CT volume.
VOXEL_MM = 2.0
#: Box of the synthetic volume (skull frame, mm).
GRID_LO_MM = (-102.0, -172.0, -118.0)
GRID_HI_MM = (102.0, 142.0, 140.0)
#: Largest angle (degrees) between a true soft-tissue direction and the bone normal.
MAX_DIRECTION_DEG = 18.0
#: Scale (degrees) of the half-normal distribution of that angle.
DIRECTION_SD_DEG = 8.0
#: Drawn depths stay this far (mm) inside the population [min, max].
DEPTH_MARGIN_MM = 0.25
#: Soft-tissue depth (mm) far from every landmark (scalp of the vault).
DEFAULT_DEPTH_MM = 5.5
#: Width (mm) of the Gaussian kernels that interpolate depths between landmarks.
DEPTH_KERNEL_MM = 16.0
#: Width (mm) of the Gaussian bumps that make the skin pass through the facial targets.
BUMP_MM = 5.0
#: Rise (mm per mm forward) of the lower border of the nose from the subnasale to the tip.
NOSE_RISE = 0.42
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
#: Facial landmarks whose lines of sight are cleared (see :func:`_sight_lines`).
SIGHT_NAMES = (
    "zygion_l",
    "zygion_r",
    "gonion_l",
    "gonion_r",
    "subnasale",
    "labiale_superius",
    "pogonion",
    "gnathion",
)
#: Far-side yaw (degrees) up to which the zygia and gonia stay visible in frontal views.
SIGHT_YAW_DEG = 13.0
#: Lowest skin point (mm): the neck is cut here.
NECK_CUT_Y_MM = -165.0


@dataclass(frozen=True)
class SubjectShape:
    """Independent shape parameters of one subject (mm unless said otherwise)."""

    cranial_length: float
    cranial_breadth: float
    vault_height: float
    face_width: float
    face_height: float
    jaw_width: float
    jaw_height: float
    gonial_deg: float
    chin_mm: float
    brow: float
    prognathism_mm: float
    orbit: float
    nasal_width: float
    nose_projection_mm: float
    ear: float

    @property
    def fw(self):
        """Face width factor (bizygomatic breadth / 130 mm)."""
        return self.face_width / 130.0

    @property
    def fh(self):
        """Face height factor."""
        return self.face_height


def draw_shape(rng):
    """Draw the shape parameters of one subject (independent, truncated normals)."""
    rng = np.random.default_rng(rng)

    def tn(mean, sd, lo, hi):
        return float(np.clip(rng.normal(mean, sd), lo, hi))

    return SubjectShape(
        cranial_length=tn(187.0, 6.0, 177.0, 198.0),
        cranial_breadth=tn(140.0, 4.5, 131.0, 149.0),
        vault_height=tn(1.0, 0.04, 0.92, 1.08),
        face_width=tn(130.0, 4.5, 121.0, 139.0),
        face_height=tn(1.0, 0.05, 0.9, 1.1),
        jaw_width=tn(98.0, 5.0, 88.0, 108.0),
        jaw_height=tn(1.0, 0.06, 0.88, 1.12),
        gonial_deg=tn(0.0, 5.0, -9.0, 9.0),
        chin_mm=tn(0.0, 2.0, -3.5, 3.5),
        brow=tn(0.8, 0.3, 0.25, 1.4),
        prognathism_mm=tn(0.0, 2.0, -3.5, 3.5),
        orbit=tn(1.0, 0.05, 0.9, 1.1),
        nasal_width=tn(1.0, 0.08, 0.85, 1.15),
        nose_projection_mm=tn(18.0, 2.2, 14.0, 23.0),
        ear=tn(1.0, 0.07, 0.88, 1.12),
    )


@dataclass(frozen=True)
class SyntheticSubject:
    """A synthetic subject with its ground truth (skull frame, mm).

    Attributes
    ----------
    subject_id : str
    skull_vertices_mm : ndarray of shape (V, 3)
    skull_faces : ndarray of shape (F, 3), int
    skin_vertices_mm : ndarray of shape (V', 3)
    skin_faces : ndarray of shape (F', 3), int
    cranial_landmarks : dict of str -> ndarray of shape (3,)
        Every name of :data:`~lilium.softtissue.landmarks.CRANIAL_NAMES`.
    facial_landmarks : dict of str -> ndarray of shape (3,)
        Every name of :data:`~lilium.softtissue.landmarks.FACIAL_NAMES`, on the skin.
    soft_tissue_axes : dict of str -> ndarray of shape (3,)
        True unit soft-tissue direction of each cranial landmark of a correspondence.
    soft_tissue_depths_mm : dict of str -> float
        True depth ``|F - C|`` of each of them.
    bone_normals : dict of str -> ndarray of shape (3,)
        Outward skull-surface normal (area-weighted over a few mm) at each cranial landmark.
    shape : SubjectShape
    """

    subject_id: str
    skull_vertices_mm: np.ndarray
    skull_faces: np.ndarray
    skin_vertices_mm: np.ndarray
    skin_faces: np.ndarray
    cranial_landmarks: dict = field(default_factory=dict)
    facial_landmarks: dict = field(default_factory=dict)
    soft_tissue_axes: dict = field(default_factory=dict)
    soft_tissue_depths_mm: dict = field(default_factory=dict)
    bone_normals: dict = field(default_factory=dict)
    shape: SubjectShape | None = None


# --------------------------------------------------------------------------------------------
# Bone


def _arch(half_width, z_front, z_back, n=17):
    """Points ``(x, z)`` of a dental/mandibular arch (half ellipse), left end to right end."""
    theta = np.linspace(-np.pi / 2, np.pi / 2, n)
    return np.column_stack(
        [half_width * np.sin(theta), z_back + (z_front - z_back) * np.cos(theta)]
    )


def _body_arch(half_width, z_front, z_back, n=21, power=1.4):
    """Points ``(x, z)`` of the mandibular body, gonion to gonion: ``z`` falls as ``|x|^power``,
    so the two halves converge towards the chin (about 24 deg off the sagittal plane at the
    gonia) and the gonia are the widest points of the lower jaw."""
    t = np.linspace(-1.0, 1.0, n)
    return np.column_stack([half_width * t, z_front - (z_front - z_back) * np.abs(t) ** power])


def _sweep(bone, xz, y_centre, half_width, half_height, radius, k=1.5):
    """Union of a bar swept along an arch polyline, cross-section varying per point."""
    pts = np.column_stack([xz[:, 0], y_centre, xz[:, 1]])
    reach = max(np.max(half_width), np.max(half_height)) + radius + k + 2
    bone.combine(
        lambda p: sweep(p, pts, half_width, half_height, radius),
        pts.min(axis=0) - reach,
        pts.max(axis=0) + reach,
        "union",
        k,
    )


def _teeth(bone, xz, y_centre, height, n_teeth=16):
    """One ellipsoid per tooth along an arch (crowns of an upper or lower dentition)."""
    seg = np.linalg.norm(np.diff(xz, axis=0), axis=1)
    s = np.concatenate([[0], np.cumsum(seg)])
    at = np.linspace(0, s[-1], n_teeth + 1)
    at = (at[:-1] + at[1:]) / 2
    x = np.interp(at, s, xz[:, 0])
    z = np.interp(at, s, xz[:, 1])
    spacing = s[-1] / n_teeth
    for xi, zi, ai in zip(x, z, at, strict=True):
        molar = abs(ai - s[-1] / 2) / (s[-1] / 2)  # 0 at the incisors, 1 at the molars
        c = (xi, y_centre, zi)
        r = (0.62 * spacing, height / 2, 2.6 + 2.4 * molar)
        tangent = np.arctan2(
            np.interp(ai + 1, s, xz[:, 0]) - xi, np.interp(ai + 1, s, xz[:, 1]) - zi
        )
        rot = rotation_xyz(0.0, np.degrees(tangent) - 90.0, 0.0)
        bone.combine(
            lambda p, c=c, r=r, rot=rot: ellipsoid(p, c, r, rot), *_box(c, r, 3), "union", 0.8
        )


def _box(centre, radii, margin=4.0):
    c = np.asarray(centre, float)
    r = np.max(radii) + margin
    return c - r, c + r


def _design(s):
    """Design positions (skull frame, mm) derived from the shape parameters."""
    fw, fh = s.fw, s.fh
    d = {}
    d["orbit"] = np.array([33.0 * fw, 16.0, 62.0])
    d["orbit_radii"] = np.array([19.5, 16.5, 27.0]) * s.orbit
    d["nasal_aperture"] = np.array([0.0, -10.0 * fh, 83.0])
    d["nasal_aperture_radii"] = np.array([12.0 * s.nasal_width, 17.0 * fh, 16.0])
    d["ans"] = np.array([0.0, -27.5 * fh, 90.0 + 0.5 * s.prognathism_mm])
    d["prosthion_y"] = -41.0 * fh
    d["occlusal_y"] = -51.0 * fh
    d["infradentale_y"] = -61.0 * fh
    d["menton_y"] = -61.0 * fh - 31.0 * s.jaw_height
    d["chin_z"] = 86.0 + 0.5 * s.prognathism_mm + s.chin_mm
    d["gonion"] = np.array([s.jaw_width / 2, d["menton_y"] + 25.0 * s.jaw_height, 6.0])
    d["zygion_x"] = s.face_width / 2
    d["canal"] = np.array([58.0, -1.0, -4.0])
    d["canal_radius"] = 4.0
    d["brow_y"] = 16.0 + 18.0 * s.orbit
    return d


def build_bone(s, rng):
    """The bone field of a subject (negative inside) and its design positions.

    Parameters
    ----------
    s : SubjectShape
    rng : numpy.random.Generator

    Returns
    -------
    bone : GridField
    design : dict
    """
    d = _design(s)
    fw, fh = s.fw, s.fh
    bone = GridField(GRID_LO_MM, GRID_HI_MM, VOXEL_MM)
    L, B = s.cranial_length, s.cranial_breadth

    # Cranial vault: a boxy superellipsoid, front at the forehead, back at opisthocranion.
    vc = np.array([0.0, 30.0, 88.0 - L / 2 + 2.0])
    vr = np.array([B / 2, 96.0 * s.vault_height, L / 2 - 4.0])
    lo, hi = vc - vr - 8, vc + vr + 8
    bone.combine(lambda p: superellipsoid(p, vc, vr, (2.5, 2.2, 2.4)), lo, hi, "union")
    # Narrower below the parietal eminences (temporal region, cranial base).
    bc, br = np.array([0.0, 60.0, vc[2]]), np.array([B / 2 + 1.0, 110.0, L])
    bone.combine(lambda p: ellipsoid(p, bc, br), lo, hi, "intersect", 6.0)
    bone.combine(lambda p: plane(p, (0, -26.0, 0), (0, -1, 0)), lo, hi, "intersect", 10.0)
    # Low-frequency bumps of the vault (about +-1 mm).
    waves = [
        (rng.normal(size=3), rng.uniform(0, 2 * np.pi), rng.uniform(0.15, 0.4)) for _ in range(6)
    ]

    def bumps(p):
        out = 0.0
        for kvec, phase, amp in waves:
            kvec = kvec / np.linalg.norm(kvec) * (2 * np.pi / 70.0)
            out = out + amp * np.cos(p[0] * kvec[0] + p[1] * kvec[1] + p[2] * kvec[2] + phase)
        return out

    bone.combine(bumps, lo, hi, "add")
    # Temporal fossae.
    for sx in (1, -1):
        fc = np.array([sx * (B / 2 + 6.0), 14.0, 34.0])
        fr = np.array([22.0, 36.0, 34.0])
        bone.combine(lambda p, fc=fc, fr=fr: ellipsoid(p, fc, fr), *_box(fc, fr, 8), "subtract", 6)

    # Upper face block and maxilla.
    pr = s.prognathism_mm
    for c, r in (
        ((0.0, 12.0, 52.0), (48.0 * fw, 34.0, 34.0)),
        ((0.0, -22.0 * fh, 55.0 + pr / 2), (32.0 * fw, 25.0 * fh, 33.0)),
    ):
        bone.combine(lambda p, c=c, r=r: ellipsoid(p, c, r), *_box(c, r, 10), "union", 8)
    # Zygomatic bodies and arches, mastoids, temporal bone roots of the arches.
    zx = d["zygion_x"]
    for sx in (1, -1):
        c, r = (sx * 46.0 * fw, 2.0, 62.0), (12.0, 15.0, 13.0)
        bone.combine(lambda p, c=c, r=r: ellipsoid(p, c, r), *_box(c, r, 8), "union", 6)
        chain = [
            (sx * 50.0 * fw, 0.0, 54.0),
            (sx * (zx - 4.0), 0.5, 26.0),
            (sx * (zx - 7.0), -1.0, 0.0),
        ]
        for a, b in zip(chain[:-1], chain[1:], strict=True):
            lo_, hi_ = np.minimum(a, b) - 10, np.maximum(a, b) + 10
            bone.combine(
                lambda p, a=a, b=b: slab(p, a, b, (0, 1, 0), 1.2, 3.0, 2.2), lo_, hi_, "union", 3
            )
        c, r = (sx * 55.0, -3.0, -4.0), (11.0, 13.0, 15.0)
        bone.combine(lambda p, c=c, r=r: ellipsoid(p, c, r), *_box(c, r, 8), "union", 6)
        c, r = (sx * 50.0, -22.0, -14.0), (8.0, 13.0, 10.0)
        bone.combine(lambda p, c=c, r=r: ellipsoid(p, c, r), *_box(c, r, 8), "union", 5)
    # Brow ridges and glabella.
    by = d["brow_y"]
    for sx in (1, -1):
        a, b = (sx * (d["orbit"][0] + 14.0 * fw), by - 3.0, 72.0), (sx * 7.0, by + 1.5, 84.0)
        lo_, hi_ = np.minimum(a, b) - 12, np.maximum(a, b) + 12
        bone.combine(
            lambda p, a=a, b=b: capsule(p, a, b, 3.0 + 1.5 * s.brow, 3.5 + 2.0 * s.brow),
            lo_,
            hi_,
            "union",
            6,
        )
    c, r = (0.0, by + 3.0, 80.0 + 2.0 * s.brow), (13.0, 9.0, 7.0)
    bone.combine(lambda p: ellipsoid(p, c, r), *_box(c, r, 8), "union", 6)
    # Orbits.
    for sx in (1, -1):
        c, r = d["orbit"] * (sx, 1, 1), d["orbit_radii"]
        rot = rotation_xyz(-8.0, sx * 14.0, 0.0)
        bone.combine(
            lambda p, c=c, r=r, rot=rot: ellipsoid(p, c, r, rot), *_box(c, r, 6), "subtract", 2.5
        )
    # Orbital margins: a ring of bars around each opening, the lateral side set back.
    for sx in (1, -1):
        o, r = d["orbit"] * (sx, 1, 1), d["orbit_radii"]
        phi = np.linspace(0, 2 * np.pi, 19)
        lateral = 0.5 * (1 + np.cos(phi))  # 1 at the lateral margin, 0 at the medial one
        ring = np.column_stack(
            [
                o[0] + sx * (r[0] + 1.5) * np.cos(phi),
                o[1] + (r[1] + 1.5) * np.sin(phi),
                81.0 - 11.0 * lateral - 2.0 * (np.sin(phi) < 0) * np.abs(np.sin(phi)),
            ]
        )
        thick = 2.6 + 0.8 * lateral
        for a, b, ra, rb in zip(ring[:-1], ring[1:], thick[:-1], thick[1:], strict=True):
            bone.combine(
                lambda p, a=a, b=b, ra=ra, rb=rb: capsule(p, a, b, ra, rb),
                np.minimum(a, b) - 8,
                np.maximum(a, b) + 8,
                "union",
                2.0,
            )
    # Nasal bones (a bar from nasion down and forward).
    nb_top, nb_bottom = (0.0, by - 10.0, 83.0), (0.0, 3.0 * fh, 93.0 + 0.3 * pr)
    bone.combine(
        lambda p: slab(p, nb_top, nb_bottom, (0, 0, 1), (3.0, 6.0), 1.5, 1.8),
        np.minimum(nb_top, nb_bottom) - 12,
        np.maximum(nb_top, nb_bottom) + 12,
        "union",
        3,
    )
    # Nasal aperture and cavity.
    c, r = d["nasal_aperture"], d["nasal_aperture_radii"]
    bone.combine(lambda p: ellipsoid(p, c, r), *_box(c, r, 6), "subtract", 2)
    c2, r2 = (0.0, -6.0 * fh, 62.0), (13.0, 22.0, 26.0)
    bone.combine(lambda p: ellipsoid(p, c2, r2), *_box(c2, r2, 6), "subtract", 3)
    # Anterior nasal spine.
    a, b = d["ans"] - (0, 0, 8.0), d["ans"]
    bone.combine(lambda p: capsule(p, a, b, 2.2, 1.2), a - 8, b + 8, "union", 2)

    # Upper alveolar process and teeth.
    n = 17
    up = _arch(29.0 * fw, 87.0 + pr, 40.0)
    yy = d["prosthion_y"]
    _sweep(bone, up, np.full(n, yy + 9.0), np.full(n, 4.0), np.full(n, 8.0), 2.0, 4)
    oc = d["occlusal_y"]
    _teeth(bone, _arch(27.5 * fw, 86.0 + pr, 42.0), (yy + oc) / 2 + 0.5, yy - oc + 2.0)
    _teeth(
        bone,
        _arch(26.0 * fw, 84.0 + 0.6 * pr, 42.0),
        (oc + d["infradentale_y"]) / 2 - 0.5,
        oc - d["infradentale_y"] + 2.0,
    )

    # Mandible: body swept along an arch from gonion to gonion, chin, rami, condyles, coronoids.
    g = d["gonion"]
    body = _body_arch(g[0], d["chin_z"] - 4.0, g[2] + 2.0, 21)
    w = np.abs(np.linspace(-1, 1, 21))  # 0 at the chin, 1 at the gonia
    top = d["infradentale_y"] + 3.0 * w
    bottom = d["menton_y"] + 3.0 + (g[1] - d["menton_y"] - 2.0) * w
    _sweep(bone, body, (top + bottom) / 2, 4.5 - 1.5 * w, (top - bottom) / 2 - 2.5, 2.5, 3)
    c, r = (0.0, d["menton_y"] + 10.0, d["chin_z"] - 3.0), (15.0, 10.0, 6.0)
    bone.combine(lambda p: ellipsoid(p, c, r), *_box(c, r, 6), "union", 5)
    tilt = np.radians(12.0 + s.gonial_deg)
    for sx in (1, -1):
        base = np.array([sx * g[0], g[1] + 8.0, g[2] + 14.0])
        top_pt = np.array([sx * (g[0] + 3.0), -34.0, g[2] + 14.0 - 40.0 * np.tan(tilt) * 0.0])
        top_pt[2] = base[2] - (top_pt[1] - base[1]) * np.tan(tilt)
        bone.combine(
            lambda p, a=base, b=top_pt: slab(p, a, b, (0, 0, 1), 2.0, (14.0, 12.0), 2.0),
            np.minimum(base, top_pt) - 20,
            np.maximum(base, top_pt) + 20,
            "union",
            4,
        )
        neck_a = np.array([sx * (g[0] + 3.0), -34.0, top_pt[2] - 10.0])
        condyle = np.array([sx * 54.0, -10.0, 3.0])
        bone.combine(
            lambda p, a=neck_a, b=condyle: capsule(p, a, b, 4.0, 3.5),
            condyle - 16,
            condyle + 16,
            "union",
            3,
        )
        bone.combine(
            lambda p, c=condyle: ellipsoid(p, c, (10.0, 5.0, 6.0)),
            condyle - 14,
            condyle + 14,
            "union",
            2,
        )
        cor_a = np.array([sx * (g[0] + 1.0), -38.0, top_pt[2] + 10.0])
        cor_b = np.array([sx * (g[0] - 2.0), -17.0, top_pt[2] + 14.0])
        bone.combine(
            lambda p, a=cor_a, b=cor_b: capsule(p, a, b, 4.0, 2.5),
            np.minimum(cor_a, cor_b) - 10,
            np.maximum(cor_a, cor_b) + 10,
            "union",
            3,
        )
    # External ear canals.
    for sx in (1, -1):
        cc = d["canal"] * (sx, 1, 1)
        a, b = cc - (sx * 14.0, 0, 0), cc + (sx * 20.0, 0, 0)
        bone.combine(
            lambda p, a=a, b=b: capsule(p, a, b, d["canal_radius"]),
            np.minimum(a, b) - 8,
            np.maximum(a, b) + 8,
            "subtract",
            1.5,
        )
    d["body_arch"] = body
    d["body_y"] = (top + bottom) / 2
    d["ramus_top"] = top_pt
    return bone, d


# --------------------------------------------------------------------------------------------
# Cranial landmarks


def _support(field, centre, direction, e1, e2=None, span1=10.0, span2=0.0, step=1.0):
    """Surface point that is most extreme along ``direction`` near ``centre``.

    Rays come from outside along ``-direction``, their origins spread over ``e1`` (and ``e2``);
    the hit furthest along ``direction`` wins.
    """
    direction = np.asarray(direction, float)
    direction = direction / np.linalg.norm(direction)
    a = np.arange(-span1, span1 + 1e-9, step)
    b = np.arange(-span2, span2 + 1e-9, step) if e2 is not None else np.zeros(1)
    A, Bv = np.meshgrid(a, b, indexing="ij")
    e2v = np.zeros(3) if e2 is None else np.asarray(e2, float)
    origins = (
        np.asarray(centre, float)
        + 120.0 * direction
        + A.reshape(-1, 1) * np.asarray(e1, float)
        + Bv.reshape(-1, 1) * e2v
    )
    hits = field.ray_hit(origins, -direction, max_mm=240.0)
    score = np.where(np.isnan(hits[:, 0]), -np.inf, hits @ direction)
    return hits[np.argmax(score)]


def _front_profile(field, x, ys, z_from=135.0):
    """Hits of rays along ``-z`` at ``(x, y)`` for each ``y`` (anterior surface profile)."""
    origins = np.column_stack([np.full(len(ys), x), ys, np.full(len(ys), z_from)])
    return field.ray_hit(origins, (0, 0, -1), max_mm=260.0)


def _rim_edge(field, start, end, frac=0.75, n=80):
    """Edge of an opening (orbit, nasal aperture) along a scan line of frontal rays.

    Frontal rays at points from ``start`` (inside the opening) to ``end`` (on the rim) hit deep
    inside the opening and then on the rim; the edge is the first hit whose depth passes 75 %
    of the way from the deepest to the most anterior hit.
    """
    start, end = np.asarray(start, float), np.asarray(end, float)
    s = np.linspace(0, 1, n)[:, None]
    pts = start + s * (end - start)
    origins = np.column_stack([pts[:, 0], pts[:, 1], np.full(n, 135.0)])
    hits = field.ray_hit(origins, (0, 0, -1), max_mm=260.0)
    z = np.where(np.isnan(hits[:, 2]), -np.inf, hits[:, 2])
    top = int(np.argmax(z))
    crest, deep = z[top], np.min(z[: top + 1])
    k = int(np.argmax(z[: top + 1] >= deep + frac * (crest - deep)))
    return hits[k]


def locate_cranial_landmarks(bone, design):
    """Every cranial landmark of SPEC section 2, on the bone surface (skull frame, mm)."""
    d = design
    lm = {}
    ys = np.arange(d["brow_y"] - 25.0, d["brow_y"] + 20.0, 0.5)
    prof = _front_profile(bone, 0.0, ys)
    ok = ~np.isnan(prof[:, 2])
    z = np.where(ok, prof[:, 2], -np.inf)
    g = int(np.argmax(np.where(ys >= d["brow_y"] - 2.0, z, -np.inf)))
    lm["glabella"] = prof[g]
    below = (ys < ys[g] - 3.0) & (ys > d["orbit"][1])
    n_idx = int(np.argmin(np.where(below & ok, prof[:, 2], np.inf)))
    lm["nasion"] = prof[n_idx]
    top = _front_profile(bone, 0.0, np.array([lm["glabella"][1] + 36.0]))[0]
    lm["metopion"] = top
    lm["bregma"] = _support(bone, (0, 100, d["canal"][2] + 8.0), (0, 1, 0), (0, 0, 1), span1=0.0)
    ys = np.arange(d["prosthion_y"] + 2.0, d["ans"][1] - 1.0, 0.5)
    prof = _front_profile(bone, 0.0, ys)
    lm["subspinale"] = prof[int(np.nanargmin(prof[:, 2]))]
    lm["prosthion"] = _front_profile(bone, 0.0, np.array([d["prosthion_y"] + 1.0]))[0]
    lm["infradentale"] = _front_profile(bone, 0.0, np.array([d["infradentale_y"] - 1.5]))[0]
    chin = (0.0, d["menton_y"] + 10.0, d["chin_z"])
    lm["pogonion"] = _support(bone, chin, (0, 0, 1), (0, 1, 0), span1=10.0, step=0.5)
    lm["gnathion"] = _support(bone, chin, (0, -1, 1), (0, 1, 1) / np.sqrt(2), span1=14.0, step=0.5)
    for sx, sfx in ((1, "_l"), (-1, "_r")):
        o = d["orbit"] * (sx, 1, 1)
        lm["ectoconchion" + sfx] = _rim_edge(bone, o, o + (sx * 32.0, 0, 0))
        lm["dacryon" + sfx] = _rim_edge(bone, o + (0, 4, 0), (sx * 2.0, o[1] + 4, 0))
        lm["orbitale" + sfx] = _rim_edge(bone, o, o - (0, 30.0, 0))
        na = d["nasal_aperture"]
        lm["alare" + sfx] = _rim_edge(bone, na, na + (sx * 25.0, 0, 0), frac=0.9)
        lm["zygion" + sfx] = _support(
            bone, (sx * d["zygion_x"], 0.0, 24.0), (sx, 0, 0), (0, 1, 0), (0, 0, 1), 6.0, 20.0
        )
        # Gonion: the corner of the angle, extreme laterally-down-back (the soft tissue over it
        # is measured laterally, on the masseter).
        g0 = d["gonion"] * (sx, 1, 1)
        g_dir = np.array([sx * 1.0, -0.22, -0.22])
        g_e1 = np.array([0.0, 1.0, -1.0]) / np.sqrt(2)
        g_e2 = np.cross(g_dir / np.linalg.norm(g_dir), g_e1)
        lm["gonion" + sfx] = _support(bone, g0, g_dir, g_e1, g_e2, 14.0, 4.0, 0.5)
        lm["frontotemporale" + sfx] = _support(
            bone,
            (sx * 42.0, d["brow_y"] + 18.0, 60.0),
            (sx * 1.0, 0.0, 0.8),
            (0, 1, 0),
            (-0.8 * sx, 0, 1.0) / np.hypot(0.8, 1.0),
            3.0,
            6.0,
            0.5,
        )
        c = d["canal"] * (sx, 1, 1)
        lm["porion" + sfx] = bone.ray_hit(
            [(sx * 100.0, c[1] + d["canal_radius"] + 0.8, c[2])], (-sx, 0, 0)
        )[0]
        # Mental foramen: lateral surface of the body below the premolars (~24 mm off midline).
        arch, y_body = d["body_arch"], d["body_y"]
        right_half = arch[:, 0] * sx > 0
        k = np.argmin(np.where(right_half, np.abs(np.abs(arch[:, 0]) - 24.0), np.inf))
        tangent = arch[min(k + 1, len(arch) - 1)] - arch[max(k - 1, 0)]
        normal = np.array([tangent[1], -tangent[0]])
        normal *= np.sign(normal[0] * sx) or 1.0
        normal /= np.linalg.norm(normal)
        p0 = np.array([arch[k, 0], y_body[k] - 2.0, arch[k, 1]])
        dirn = np.array([normal[0], 0.0, normal[1]])
        lm["mental_foramen" + sfx] = bone.ray_hit([p0 + 40.0 * dirn], -dirn)[0]
    missing = [n for n in CRANIAL_NAMES if n not in lm or not np.all(np.isfinite(lm[n]))]
    if missing:
        raise RuntimeError(f"synthetic skull: could not place {missing}")
    return {n: np.asarray(lm[n], float) for n in CRANIAL_NAMES}


# --------------------------------------------------------------------------------------------
# Soft tissue and skin


def _rotate_towards(axis, angle_rad, azimuth_rad):
    """Unit vector at ``angle_rad`` from ``axis``, azimuth measured in a fixed basis."""
    a = axis / np.linalg.norm(axis)
    e = np.zeros(3)
    e[np.argmin(np.abs(a))] = 1.0
    u = np.cross(a, e)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    return np.cos(angle_rad) * a + np.sin(angle_rad) * (
        np.cos(azimuth_rad) * u + np.sin(azimuth_rad) * v
    )


def _align(a, b):
    """Smallest rotation taking unit vector ``a`` to unit vector ``b`` (3x3)."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v, c = np.cross(a, b), float(a @ b)
    if c < -0.999999:
        return -np.eye(3)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + K + K @ K / (1 + c)


def draw_soft_tissue(cranial, normals, bone, rng):
    """True depth and direction of each cranial landmark of a correspondence.

    Depths: ``N(mean, sd)`` of the built-in table clipped inside ``[min, max]``; the right twin
    is the left depth plus a small difference. Directions: the bone normal tilted by a
    half-normal angle (scale :data:`DIRECTION_SD_DEG`, at most :data:`MAX_DIRECTION_DEG`) towards
    a uniform azimuth; the right twin mirrors the left one, plus a few degrees. A draw whose
    facial point would fall inside the bone is redrawn.

    Returns
    -------
    depths_mm : dict of str -> float
    directions : dict of str -> ndarray of shape (3,)
    """
    mirror = np.diag([-1.0, 1.0, 1.0])
    depths, directions = {}, {}
    for cranial_name, _ in CORRESPONDENCES:
        stats = BUILTIN_DEPTHS[base_name(cranial_name)]
        lo, hi = stats.min_mm + DEPTH_MARGIN_MM, stats.max_mm - DEPTH_MARGIN_MM
        mirrored = cranial_name.endswith("_r") and twin(cranial_name) in depths
        for _attempt in range(20):
            if mirrored:
                depth = depths[twin(cranial_name)] + rng.normal(0.0, 0.25 * stats.sd_mm)
                # The left tilt from its normal, mirrored onto the right normal.
                base_dir = _align(mirror @ normals[twin(cranial_name)], normals[cranial_name]) @ (
                    mirror @ directions[twin(cranial_name)]
                )
                tilt = np.radians(min(abs(rng.normal(0.0, 2.0)), 5.0))
                direction = _rotate_towards(base_dir, tilt, rng.uniform(0, 2 * np.pi))
            else:
                depth = rng.normal(stats.mean_mm, stats.sd_mm)
                tilt = np.radians(min(abs(rng.normal(0.0, DIRECTION_SD_DEG)), MAX_DIRECTION_DEG))
                direction = _rotate_towards(normals[cranial_name], tilt, rng.uniform(0, 2 * np.pi))
            depth = float(np.clip(depth, lo, hi))
            angle = np.degrees(np.arccos(np.clip(direction @ normals[cranial_name], -1, 1)))
            target = cranial[cranial_name] + depth * direction
            if angle <= MAX_DIRECTION_DEG + 2.0 and bone.sample(target[None])[0] > 1.0:
                break
        depths[cranial_name] = depth
        directions[cranial_name] = direction
    return depths, directions


def _support_field(bone, d, s):
    """Bone plus the soft parts that carry the skin: eyeballs, muscles, mouth, neck."""
    sup = bone.copy()
    fw, B = s.fw, s.cranial_breadth
    parts = []
    for sx in (1, -1):
        o = d["orbit"] * (sx, 1, 1)
        parts.append((("e", o + (0, 0, 11.0), (12.0, 12.0, 12.0)), 2.0))  # eyeball
        # Temporalis: fills the temporal fossa above the arch, never wider than the zygia.
        parts.append(
            (("e", (sx * (B / 2 - 13.0), 24.0, 32.0), (10.0, 24.0, 24.0)), 6.0)
        )  # temporalis
        g = d["gonion"] * (sx, 1, 1)
        # Masseter: medial of the line zygion-gonion, so that both stay the widest points.
        a = np.array([sx * (d["zygion_x"] - 13.0), -8.0, 26.0])
        b = np.array([g[0] - sx * 7.0, g[1] + 14.0, g[2] + 16.0])
        parts.append((("c", a, b, 5.0, 4.0), 8.0))  # masseter
        parts.append((("e", (sx * 33.0 * fw, -32.0, 52.0), (12.0, 20.0, 22.0)), 12.0))  # cheek
    parts.append((("e", (0.0, d["occlusal_y"], 66.0), (26.0 * fw, 12.0, 20.0)), 6.0))  # mouth
    parts.append((("e", d["nasal_aperture"] - (0, 0, 6.0), d["nasal_aperture_radii"]), 2.0))
    parts.append((("e", (0.0, d["menton_y"] + 6.0, 38.0), (34.0, 14.0, 40.0)), 12.0))  # floor
    parts.append((("c", (0.0, -60.0, -22.0), (0.0, -200.0, -30.0), 44.0, 46.0), 20.0))  # neck
    for spec, k in parts:
        if spec[0] == "e":
            c, r = np.asarray(spec[1], float), np.asarray(spec[2], float)
            sup.combine(lambda p, c=c, r=r: ellipsoid(p, c, r), *_box(c, r, k + 4), "union", k)
        else:
            a, b, ra, rb = np.asarray(spec[1]), np.asarray(spec[2]), spec[3], spec[4]
            reach = max(ra, rb) + k + 4
            sup.combine(
                lambda p, a=a, b=b, ra=ra, rb=rb: capsule(p, a, b, ra, rb),
                np.minimum(a, b) - reach,
                np.maximum(a, b) + reach,
                "union",
                k,
            )
    return sup


def _depth_field(grid, anchors, depths_mm):
    """Depth (mm) at every voxel: Gaussian-weighted mean of anchor depths, a default far away."""
    from scipy.ndimage import zoom

    step = 4
    axes = [a[::step] for a in grid.axes]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    num = np.full(z.shape, DEFAULT_DEPTH_MM * 0.02)
    den = np.full(z.shape, 0.02)
    for p, dep in zip(anchors, depths_mm, strict=True):
        w = np.exp(
            -((x - p[0]) ** 2 + (y - p[1]) ** 2 + (z - p[2]) ** 2) / (2 * DEPTH_KERNEL_MM**2)
        )
        num += w * dep
        den += w
    coarse = num / den
    factors = [n / c for n, c in zip(grid.values.shape, coarse.shape, strict=True)]
    return zoom(coarse, factors, order=1)[tuple(slice(0, n) for n in grid.values.shape)]


def _distance_outside(field):
    """Distance (mm) from each voxel outside ``field`` to its zero level, smoothed.

    The Euclidean distance transform gives the nearest inside voxel ``q``; the field value there
    (how deep ``q`` lies) is added, so the distance varies smoothly rather than in voxel steps.
    """
    from scipy.ndimage import distance_transform_edt, gaussian_filter

    inside = field.values < 0
    dist, idx = distance_transform_edt(~inside, return_indices=True)
    depth_q = field.values[idx[0], idx[1], idx[2]]
    dist = dist.astype(np.float32) * field.voxel + np.maximum(depth_q, -field.voxel)
    dist = np.where(inside, np.maximum(field.values, -field.voxel), dist)
    return gaussian_filter(dist, 1.0)


def _pad(field, target, direction, flat_axis, radius, margin=1.0):
    """Make ``target`` the tip of a rounded pad of the skin (in place).

    The pad's outward normal at the target is ``direction`` with its ``flat_axis`` component
    removed (0 = x for the profile, 2 = z for the frontal outline), so the target lies on the
    silhouette of views along that axis. The skin around is first pushed ``margin`` mm behind
    the target (a Gaussian of width ``radius``), then a sphere of ``radius`` touching the
    target from inside is added.
    """
    n = np.array(direction, float)
    n[flat_axis] = 0.0
    n /= np.linalg.norm(n)
    sigma = float(radius)
    need = margin - float(field.sample(target[None])[0])
    if need > 0:
        _add_gaussian(field, target, need, sigma)
    c = target - radius * n
    field.combine(
        lambda p: ellipsoid(p, c, (radius,) * 3), c - radius - 4, c + radius + 4, "union", 1.0
    )


def _add_gaussian(field, centre, height, sigma):
    """Add ``height * exp(-|p - centre|^2 / (2 sigma^2))`` to ``field`` (in place), evaluated
    within 3.5 sigma of ``centre``."""
    centre = np.asarray(centre, dtype=float)
    field.combine(
        lambda p: (
            height
            * np.exp(
                -((p[0] - centre[0]) ** 2 + (p[1] - centre[1]) ** 2 + (p[2] - centre[2]) ** 2)
                / (2 * sigma**2)
            )
        ),
        centre - 3.5 * sigma,
        centre + 3.5 * sigma,
        "add",
    )


def _sight_lines(name, target):
    """Directions (skull frame, towards the camera) along which ``name`` must be seen."""
    t10, t9 = np.tan(np.radians(10.0)), np.tan(np.radians(SIGHT_YAW_DEG))
    if name.startswith(("zygion", "gonion")):  # frontal outline, far-side yaw included
        sx = 1.0 if target[0] > 0 else -1.0
        return [(-sx * a, b, 1.0) for a in (0.0, t9) for b in (-t10, 0.0, t10)]
    if name == "subnasale":  # frontal, pitched either way
        return [(a, b, 1.0) for a in (-t9, 0.0, t9) for b in (-t10, 0.0, t10)]
    # Profile landmarks, seen from either side.
    return [(sx, b, 0.0) for sx in (1.0, -1.0) for b in (-t10, 0.0, t10)]


def _clear_sight(field, target, directions, start_mm=3.5, length_mm=32.0, sigma=3.0):
    """Push the skin off the lines of sight from ``target`` (in place).

    Every point of the segments ``target + t * d`` (``t`` from ``start_mm`` to ``length_mm``)
    that lies inside the skin gets a Gaussian of width ``sigma`` that moves the skin just
    behind it, so a camera along ``d`` sees the target within the visibility tolerance.
    """
    t = np.arange(start_mm, length_mm, 1.0)
    for d in directions:
        d = np.asarray(d, float) / np.linalg.norm(d)
        pts = target + t[:, None] * d
        f = field.sample(pts)
        for q, fq in zip(pts, f, strict=True):
            need = min(0.6 - float(fq), 6.0)
            if fq >= 0.3:
                continue
            _add_gaussian(field, q, need, sigma)


def _ear(field, porion, sx, scale):
    """Add an external ear (auricle) lateral to ``porion`` (in place).

    A shell about 60 mm tall and 34 mm wide whose rim (helix) stands 15-20 mm off the side of
    the head, flaring backwards, with a hollow concha in front of the canal and a lobule.
    """
    hit = field.ray_hit([(sx * 101.0, porion[1], porion[2])], (-sx, 0, 0))[0]
    side = hit[0] if np.isfinite(hit[0]) else porion[0] + sx * 8.0
    # Local frame: n = outward normal of the ear plane, u = up (tilted back), w = backwards.
    rot = rotation_xyz(-12.0, sx * -32.0, 0.0)
    n, u, w = rot @ (sx, 0.0, 0.0), rot @ (0.0, 1.0, 0.0), rot @ (0.0, 0.0, -1.0)
    h, b = 30.0 * scale, 17.0 * scale
    centre = np.array([side + sx * 7.0, porion[1] + 4.0, porion[2] - 12.0])
    frame = np.column_stack([n, u, w])
    field.combine(
        lambda p: ellipsoid(p, centre, (4.0, h, b), frame), centre - 40, centre + 40, "union", 4.0
    )
    # Helix: a rolled rim along the upper and back border.
    phi = np.linspace(-0.35 * np.pi, 1.25 * np.pi, 12)
    ring = (
        centre + 1.8 * n + np.outer(0.92 * h * np.sin(phi), u) + np.outer(0.92 * b * np.cos(phi), w)
    )
    ring = ring[::-1]
    for a_, b_ in zip(ring[:-1], ring[1:], strict=True):
        field.combine(
            lambda p, a_=a_, b_=b_: capsule(p, a_, b_, 2.6),
            np.minimum(a_, b_) - 7,
            np.maximum(a_, b_) + 7,
            "union",
            1.5,
        )
    # Concha: the bowl in front of the canal; the stalk joining the ear to the head.
    cc = centre + 4.5 * n - 0.15 * h * u - 0.2 * b * w
    field.combine(
        lambda p: ellipsoid(p, cc, (4.0, 0.38 * h, 0.42 * b), frame),
        cc - 20,
        cc + 20,
        "subtract",
        1.5,
    )
    st_a = np.array([side - sx * 4.0, porion[1] - 2.0, porion[2] - 6.0])
    st_b = centre - 2.0 * n - 0.1 * h * u
    field.combine(
        lambda p: capsule(p, st_a, st_b, 7.0, 6.0),
        np.minimum(st_a, st_b) - 14,
        np.maximum(st_a, st_b) + 14,
        "union",
        4.0,
    )


def _fit_targets(skin, names, targets):
    """Gaussian bumps so that the skin's zero level passes through every target (in place)."""
    # Gaussian bumps so that the skin passes through every target. A target far from the
    # surface gets a wider bump (sigma >= 0.8 * its distance), so that the dent or bulge stays
    # open to the surface instead of making a cavity or an island.
    pts = np.array([targets[n] for n in names])
    sigma = np.maximum(BUMP_MM, 0.8 * np.abs(skin.sample(pts)))
    diff = pts[:, None, :] - pts[None, :, :]
    W = np.exp(-np.einsum("ijk,ijk->ij", diff, diff) / (2 * sigma[None, :] ** 2))
    for _ in range(3):
        coef = np.linalg.solve(W, skin.sample(pts))
        for p0, ci, si in zip(pts, coef, sigma, strict=True):
            _add_gaussian(skin, p0, -ci, si)


def build_skin(bone, d, s, targets, depths, cranial_of):
    """The skin field (negative inside) passing through every facial target.

    Parameters
    ----------
    targets : dict of facial name -> ndarray of shape (3,)
    depths : dict of facial name -> float (mm)
    cranial_of : dict of facial name -> ndarray of shape (3,)
        The cranial landmark of each target (the soft-tissue direction is target - cranial).
    """
    sup = _support_field(bone, d, s)
    skin = sup.copy()
    names = list(targets)
    anchors = [targets[n] for n in names]
    anchor_depths = [depths[n] for n in names]
    for sx in (1, -1):  # thin eyelids over the eyeballs
        anchors.append(d["orbit"] * (sx, 1, 1) + (0, 0, 24.0))
        anchor_depths.append(2.0)
    skin.values = _distance_outside(sup) - _depth_field(skin, anchors, anchor_depths)

    # Pads: the facial landmarks that lie on a silhouette (zygion and gonion on the face's
    # lateral outline in frontal views; labiale superius, pogonion and gnathion on the profile)
    # are made the tip of a small rounded pad whose surface normal there lies in the image
    # plane of that view; the skin around is first pushed behind the target.
    for nm, flat_axis, radius in PADS:
        _pad(skin, targets[nm], targets[nm] - cranial_of[nm], flat_axis, radius)

    # Nose: dorsum from the nasion to the tip, tip lobule, alae, columella. The lower border
    # rises from the subnasale towards the tip (nasolabial angle > 90 deg), so the subnasale
    # is seen from the front.
    fn, fsn = targets["nasion"], targets["subnasale"]
    proj = s.nose_projection_mm
    rise = NOSE_RISE
    tip = fsn + np.array([0.0, 7.0 + rise * proj, proj])
    dorsum_a, dorsum_b = fn - (0, 5.0, 5.0), tip - (0, -3.0, 7.0)
    skin.combine(
        lambda p: capsule(p, dorsum_a, dorsum_b, 5.0, 6.5),
        np.minimum(dorsum_a, dorsum_b) - 14,
        np.maximum(dorsum_a, dorsum_b) + 14,
        "union",
        5.0,
    )
    c_tip = tip - (0, 0, 7.0)
    skin.combine(lambda p: ellipsoid(p, c_tip, (9.5, 7.0, 7.0)), c_tip - 18, c_tip + 18, "union", 3)
    for sx, nm in ((1, "alare_l"), (-1, "alare_r")):
        fa = targets[nm]
        c = fa - (sx * 6.0, -1.5, 4.0)
        skin.combine(lambda p, c=c: ellipsoid(p, c, (7.0, 6.5, 9.0)), c - 16, c + 16, "union", 3)
    col_a = fsn + (0.0, 2.6, 1.0)
    col_b = fsn + (0.0, 2.6 + rise * (proj - 6.0), proj - 6.0)
    skin.combine(lambda p: capsule(p, col_a, col_b, 2.6, 3.2), col_a - 16, col_b + 16, "union", 1.5)
    # Lips, centred on the upper-lip target (which may lie a little off the midline).
    fls = targets["labiale_superius"]
    c_up = fls + (0, 1.5, -9.5)
    skin.combine(lambda p: ellipsoid(p, c_up, (22.0, 7.0, 9.5)), c_up - 30, c_up + 30, "union", 3)
    c_lo = fls + (0, -11.5, -11.5)
    skin.combine(lambda p: ellipsoid(p, c_lo, (20.0, 6.5, 9.5)), c_lo - 30, c_lo + 30, "union", 3)
    stomion_y = fls[1] - 5.0
    m_a = np.array([fls[0] - 25.0, stomion_y, fls[2] - 8.0])
    m_b = np.array([fls[0] + 25.0, stomion_y, fls[2] - 8.0])
    skin.combine(lambda p: capsule(p, m_a, m_b, 1.2), m_a - 6, m_b + (0, 6, 20), "subtract", 1.0)
    # The upper-lip tubercle: labiale superius is its most anterior point.
    _pad(skin, fls, fls - cranial_of["labiale_superius"], 0, 4.0)
    # Ears, lateral to porion.
    for sx in (1, -1):
        _ear(skin, d["canal"] * (sx, 1, 1), sx, s.ear)
    skin.combine(
        lambda p: plane(p, (0, NECK_CUT_Y_MM, 0), (0, -1, 0)),
        skin.lo,
        skin.lo + 1e4,
        "intersect",
        0,
    )

    for _round in range(2):
        if _round:
            for nm in SIGHT_NAMES:
                _clear_sight(skin, targets[nm], _sight_lines(nm, targets[nm]))
        _fit_targets(skin, names, targets)
    return skin, stomion_y


# --------------------------------------------------------------------------------------------
# Subjects

#: Faces of the decimated skull and skin meshes.
SKULL_FACES = 50_000
SKIN_FACES = 40_000


def _mesh(field, target_faces):
    volume = Volume(-field.values, np.full(3, field.voxel), field.lo, source="synthetic volume")
    return volume_to_mesh(volume, 0.0, target_faces=target_faces)


#: Largest distance (mm) from a facial landmark to the skin mesh; a subject whose meshing lost
#: a landmark's piece of skin (a cavity or an island dropped as a small component) is rebuilt
#: with new soft tissue.
ON_SKIN_MM = 0.8
SOFT_TISSUE_TRIES = 4


def distance_to_mesh(vertices, faces, points, radius_mm=10.0, resolution=13):
    """Approximate distance (mm) from each point to a triangle mesh (nearby triangles sampled
    on a barycentric grid of ``resolution`` steps per edge; inf when none is near)."""
    from scipy.spatial import cKDTree

    tri = np.asarray(vertices, float)[np.asarray(faces)]
    tree = cKDTree(tri.mean(axis=1))
    a, b = np.meshgrid(np.linspace(0, 1, resolution), np.linspace(0, 1, resolution))
    w = np.column_stack([a.ravel(), b.ravel()])
    w = w[w.sum(axis=1) <= 1.0 + 1e-9]
    out = np.full(len(points), np.inf)
    for k, p in enumerate(np.atleast_2d(points)):
        t = tri[tree.query_ball_point(p, radius_mm)]
        if len(t):
            q = t[:, None, 0] + w[None, :, :1] * (t[:, None, 1] - t[:, None, 0])
            q = q + w[None, :, 1:] * (t[:, None, 2] - t[:, None, 0])
            out[k] = np.sqrt(np.min(np.sum((q - p) ** 2, axis=2)))
    return out


def make_subject(subject_id, rng=None):
    """Generate one synthetic subject.

    Parameters
    ----------
    subject_id : str
    rng : anything :func:`numpy.random.default_rng` accepts
        The same seed gives the identical subject.

    Returns
    -------
    SyntheticSubject
    """
    rng = np.random.default_rng(rng)
    shape = draw_shape(rng)
    bone, design = build_bone(shape, rng)
    skull_v, skull_f = _mesh(bone, SKULL_FACES)
    cranial = locate_cranial_landmarks(bone, design)
    names = list(cranial)
    normals = dict(
        zip(
            names,
            surface_normals_at(skull_v, skull_f, np.array([cranial[n] for n in names])),
            strict=True,
        )
    )
    cranial_of = {facial: cranial[c] for c, facial in CORRESPONDENCES}
    for _attempt in range(SOFT_TISSUE_TRIES):
        depths, directions = draw_soft_tissue(cranial, normals, bone, rng)
        targets = {f: cranial[c] + depths[c] * directions[c] for c, f in CORRESPONDENCES}
        facial_depths = {facial: depths[c] for c, facial in CORRESPONDENCES}
        skin, stomion_y = build_skin(bone, design, shape, targets, facial_depths, cranial_of)
        skin_v, skin_f = _mesh(skin, SKIN_FACES)
        off = distance_to_mesh(skin_v, skin_f, np.array(list(targets.values())))
        if np.max(off) <= ON_SKIN_MM:
            break
    else:
        raise RuntimeError(f"synthetic face: landmarks {np.max(off):.1f} mm off the skin")
    facial = dict(targets)
    for sx, nm in ((1, "cheilion_l"), (-1, "cheilion_r")):
        x = sx * 21.0 * shape.fw
        facial[nm] = skin.ray_hit([(x, stomion_y, 140.0)], (0, 0, -1))[0]
    missing = [n for n in FACIAL_NAMES if n not in facial or not np.all(np.isfinite(facial[n]))]
    if missing:
        raise RuntimeError(f"synthetic face: could not place {missing}")
    return SyntheticSubject(
        subject_id=str(subject_id),
        skull_vertices_mm=skull_v,
        skull_faces=skull_f,
        skin_vertices_mm=skin_v,
        skin_faces=skin_f,
        cranial_landmarks=cranial,
        facial_landmarks={n: np.asarray(facial[n], float) for n in FACIAL_NAMES},
        soft_tissue_axes={c: directions[c] for c, _ in CORRESPONDENCES},
        soft_tissue_depths_mm={c: depths[c] for c, _ in CORRESPONDENCES},
        bone_normals=normals,
        shape=shape,
    )


def make_subjects(n, seed=0, prefix="s"):
    """``n`` subjects with ids ``s00, s01, ...``; subject ``i`` uses its own child seed.

    The child seeds come from :class:`numpy.random.SeedSequence` ``(seed)``, so subject ``i`` is
    the same whatever ``n``.
    """
    children = np.random.SeedSequence(seed).spawn(int(n))
    width = max(2, len(str(int(n) - 1)))
    return [
        make_subject(f"{prefix}{i:0{width}d}", np.random.default_rng(child))
        for i, child in enumerate(children)
    ]


def write_subject(folder, subject):
    """Write a subject folder (SPEC section 8).

    ``skull.ply``, ``cranial_landmarks.json``, ``soft_tissue_axes.json`` (the true directions),
    and the ground truth ``face.ply``, ``facial_landmarks.json`` (facial = cranial + true soft
    tissue) and ``subject.json`` (shape parameters, true depths, bone normals).
    """
    from dataclasses import asdict
    from pathlib import Path

    from ..io.jsonio import write_json
    from ..io.mesh import write_mesh

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    write_mesh(folder / "skull.ply", subject.skull_vertices_mm, subject.skull_faces)
    write_mesh(folder / "face.ply", subject.skin_vertices_mm, subject.skin_faces)
    write_json(folder / "cranial_landmarks.json", {"landmarks": subject.cranial_landmarks})
    write_json(folder / "facial_landmarks.json", {"landmarks": subject.facial_landmarks})
    write_json(folder / "soft_tissue_axes.json", {"axes": subject.soft_tissue_axes})
    write_json(
        folder / "subject.json",
        {
            "subject": subject.subject_id,
            "frame": "mm; x = subject's left, y = up, z = anterior",
            "soft_tissue_depths_mm": subject.soft_tissue_depths_mm,
            "bone_normals": subject.bone_normals,
            "shape": asdict(subject.shape) if subject.shape is not None else None,
        },
    )
    return folder
