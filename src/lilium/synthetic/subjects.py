"""Procedural subjects: a skull, a face and their landmarks, with known soft tissue.

Each subject is built the way a CT scan would give it: a synthetic volume (smooth unions of
ellipsoids, capsules and swept bars with low-frequency noise) whose bone and skin iso-surfaces
are extracted by the CT pipeline (:func:`lilium.ct.mesh.volume_to_mesh`: marching cubes, largest
component). The parts live in :mod:`lilium.synthetic.anatomy` (bone, landmarks, soft tissue,
skin); this module assembles them. Between-subject variation comes from independent shape parameters
(:class:`SubjectShape`: vault length, breadth and height, face width and height, jaw width and
height, gonial angle, chin, brow ridges, alveolar prognathism, orbits, nasal aperture, nose, ears).

Skull frame (the frame of every mesh and landmark here), written once:
millimetres; ``x`` = the subject's left, ``y`` = superior (up), ``z`` = anterior (the face looks
along ``+z``); the origin is near the centre of the head, at the midpoint of the ear canals
(porion height, so the Frankfurt plane is close to ``y = 0``). A camera frame is x right, y down,
z forward (docs/contract.md), so a frontal photo camera looks along ``-z`` of the skull frame.

Soft tissue, per subject: for each cranial landmark of a correspondence, a depth drawn from the
population table (``N(mean, sd)`` clipped inside ``[min, max]``) and a direction within
:data:`~.anatomy.soft_tissue.MAX_DIRECTION_DEG` of the outward bone normal, or at the eye
corners and the alae of the axis beside them (:func:`~.anatomy.soft_tissue.direction_centre`;
twins nearly mirror-symmetric). The target facial point ``F = C + depth * direction`` is then
made to lie exactly on the skin: the skin is the "soft-tissue support" (bone, eyeballs, muscles,
neck) offset by a depth field interpolated from the drawn depths, plus nose, lips and ears built
around the targets, and finally corrected by small Gaussian bumps so that its zero level passes
through every target.

``soft_tissue_axes`` holds these true directions (the axes given to the methods; Exp. C perturbs
them); ``bone_normals`` holds the default axes a method would compute from the skull mesh (the
outward bone normals the directions are drawn about).

Incomplete skulls (``make_subject(..., mandible=False)``): a skull found without its mandible.
The person is the same (same shape, bone field, soft tissue, face and photos as with
``mandible=True`` from the same seed: the face keeps its chin and lips); only the skull mesh is
the cranium's alone (the bone field built again without the mandible and the lower teeth, the
same vault bumps) and the mandible's landmarks (:data:`MANDIBLE_LANDMARKS`) are absent from
``cranial_landmarks``. Ground truth stays whole: every facial landmark, the true soft tissue of
every correspondence; the mandible's true landmarks are kept in ``removed_landmarks``.
"""

import copy
from dataclasses import dataclass, field

import numpy as np

from ..ct.mesh import volume_to_mesh
from ..ct.volume import Volume
from ..softtissue.landmarks import CORRESPONDENCES, FACIAL_NAMES, MANDIBLE_LANDMARKS
from ..softtissue.normals import landmark_normals
from .anatomy.bone import build_bone
from .anatomy.landmarks import locate_cranial_landmarks, place_cheilia
from .anatomy.shape import SubjectShape, draw_shape
from .anatomy.skin import build_skin
from .anatomy.soft_tissue import draw_soft_tissue

__all__ = [
    "MANDIBLE_LANDMARKS",
    "SubjectShape",
    "SyntheticSubject",
    "distance_to_mesh",
    "draw_shape",
    "make_skull",
    "make_subject",
    "make_subjects",
    "write_subject",
]


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
        Every name of :data:`~lilium.softtissue.landmarks.CRANIAL_NAMES` (but the
        :data:`MANDIBLE_LANDMARKS` when the skull has no mandible).
    facial_landmarks : dict of str -> ndarray of shape (3,)
        Every name of :data:`~lilium.softtissue.landmarks.FACIAL_NAMES`, on the skin.
    soft_tissue_axes : dict of str -> ndarray of shape (3,)
        True unit soft-tissue direction of each cranial landmark of a correspondence.
    soft_tissue_depths_mm : dict of str -> float
        True depth ``|F - C|`` of each of them.
    bone_normals : dict of str -> ndarray of shape (3,)
        Outward skull-surface normal (area-weighted over a few mm) at each cranial landmark,
        on the complete skull.
    shape : SubjectShape
    mandible : bool
        Whether the skull mesh has its mandible.
    removed_landmarks : dict of str -> ndarray of shape (3,)
        True positions of the cranial landmarks the skull lacks (the mandible's).
    head_skull_vertices_mm : ndarray of shape (V'', 3) or None
        The complete skull the head was built on, when ``skull_vertices_mm`` is not it (no
        mandible): the photos' neck cut clears it (:func:`~.head.prepare_head`).
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
    mandible: bool = True
    removed_landmarks: dict = field(default_factory=dict)
    head_skull_vertices_mm: np.ndarray | None = None


#: Faces of the decimated skull and skin meshes.
SKULL_FACES = 50_000
SKIN_FACES = 40_000
#: Largest distance (mm) from a facial landmark to the skin mesh; a subject whose meshing lost
#: a landmark's piece of skin (a cavity or an island dropped as a small component) is rebuilt
#: with new soft tissue, at most :data:`SOFT_TISSUE_TRIES` times.
ON_SKIN_MM = 0.8
SOFT_TISSUE_TRIES = 4

#: Shapes drawn at most per subject: a shape whose skin cannot carry its facial landmarks
#: (measured: 1 subject in 12 at seed 0 with the published craniometric spread) is redrawn.
SHAPE_TRIES = 3



def _mesh(field, target_faces):
    """Iso-surface (level 0) of a field through the CT pipeline: vertices (V, 3) mm, faces."""
    volume = Volume(-field.values, np.full(3, field.voxel), field.lo, source="synthetic volume")
    return volume_to_mesh(volume, 0.0, target_faces=target_faces)


def distance_to_mesh(vertices, faces, points, radius_mm=10.0, resolution=13):
    """Approximate distance from each point to a triangle mesh.

    Nearby triangles (centroid within ``radius_mm``) are sampled on a barycentric grid of
    ``resolution`` steps per edge.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
        mm.
    faces : array_like of shape (F, 3), int
    points : array_like of shape (N, 3)
        mm.
    radius_mm : float
    resolution : int

    Returns
    -------
    ndarray of shape (N,)
        mm; inf where no triangle is near.
    """
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


def _skull(shape, rng):
    """Bone field, design, skull mesh, cranial landmarks and bone normals of one subject."""
    bone, design = build_bone(shape, rng)
    skull_v, skull_f = _mesh(bone, SKULL_FACES)
    cranial = locate_cranial_landmarks(bone, design)
    normals = landmark_normals(skull_v, skull_f, cranial)
    return bone, design, skull_v, skull_f, cranial, normals


def _face(bone, design, shape, cranial, normals, rng):
    """Soft tissue, skin field and mesh, and facial landmarks of one subject.

    Soft tissue is redrawn (at most :data:`SOFT_TISSUE_TRIES` times) until every facial target
    lies within :data:`ON_SKIN_MM` of the skin mesh.
    """
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
    facial.update(place_cheilia(skin, stomion_y, shape.fw))
    missing = [n for n in FACIAL_NAMES if n not in facial or not np.all(np.isfinite(facial[n]))]
    if missing:
        raise RuntimeError(f"synthetic face: could not place {missing}")
    return skin_v, skin_f, facial, depths, directions


def make_skull(rng=None, mandible=True):
    """A generated skull alone (no face): the skull of a :func:`make_subject` drawn from the
    same kind of generator, quicker, for tests and benchmarks of skull-only tools
    (``lilium skull``).

    Parameters
    ----------
    rng : anything :func:`numpy.random.default_rng` accepts
    mandible : bool
        False: the same skull without its mandible (the same vault), and none of its landmarks.

    Returns
    -------
    vertices : ndarray of shape (V, 3)
        mm, skull frame.
    faces : ndarray of shape (F, 3), int
    cranial_landmarks : dict of str -> ndarray of shape (3,)
        The true landmarks (skull frame).
    """
    rng = np.random.default_rng(rng)
    shape = draw_shape(rng)
    vault_rng = copy.deepcopy(rng)
    _, _, vertices, faces, cranial, _ = _skull(shape, rng)
    if not mandible:
        bone, _ = build_bone(shape, vault_rng, mandible=False)
        vertices, faces = _mesh(bone, SKULL_FACES)
        cranial = {n: p for n, p in cranial.items() if n not in MANDIBLE_LANDMARKS}
    return vertices, faces, cranial


def make_subject(subject_id, rng=None, mandible=True):
    """Generate one synthetic subject.

    Parameters
    ----------
    subject_id : str
    rng : anything :func:`numpy.random.default_rng` accepts
        The same seed gives the identical subject.
    mandible : bool
        False: the skull without its mandible (see the module notes); the same seed gives the
        same person, face and photos either way.

    Returns
    -------
    SyntheticSubject

    Raises
    ------
    RuntimeError
        If a landmark could not be placed or stays off the skin (rare).
    """
    rng = np.random.default_rng(rng)
    for attempt in range(SHAPE_TRIES):
        shape = draw_shape(rng)
        vault_rng = None if mandible else copy.deepcopy(rng)  # the same vault without the jaw
        bone, design, skull_v, skull_f, cranial, normals = _skull(shape, rng)
        try:
            skin_v, skin_f, facial, depths, directions = _face(
                bone, design, shape, cranial, normals, rng
            )
            break
        except RuntimeError:
            # A rare combination of extreme shape parameters defeats the skin fit: draw the
            # person again (deterministic: the same seed takes the same path).
            if attempt == SHAPE_TRIES - 1:
                raise
    removed, head_skull = {}, None
    if not mandible:
        cranium, _ = build_bone(shape, vault_rng, mandible=False)
        head_skull = skull_v
        skull_v, skull_f = _mesh(cranium, SKULL_FACES)
        removed = {n: cranial.pop(n) for n in MANDIBLE_LANDMARKS}
        normals = {n: v for n, v in normals.items() if n in cranial}
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
        mandible=bool(mandible),
        removed_landmarks=removed,
        head_skull_vertices_mm=head_skull,
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
    """Write a subject folder (docs/contract.md).

    ``skull.ply``, ``cranial_landmarks.json``, ``soft_tissue_axes.json`` (the true directions
    of the cranial landmarks the skull has), and the ground truth ``face.ply``,
    ``facial_landmarks.json`` (facial = cranial + true soft tissue) and ``subject.json`` (shape
    parameters, true depths, bone normals; for a skull without its mandible also
    ``"incomplete": {"mandible": false, "removed_landmarks": {name: [x, y, z]}}``).
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
    write_json(folder / "soft_tissue_axes.json", {"axes": axes_on_skull(subject)})
    record = {
        "subject": subject.subject_id,
        "frame": "mm; x = subject's left, y = up, z = anterior",
        "soft_tissue_depths_mm": subject.soft_tissue_depths_mm,
        "bone_normals": subject.bone_normals,
        "shape": asdict(subject.shape) if subject.shape is not None else None,
    }
    if not getattr(subject, "mandible", True):  # only then: complete subjects stay as they were
        record["incomplete"] = {
            "mandible": False,
            "removed_landmarks": subject.removed_landmarks,
        }
    write_json(folder / "subject.json", record)
    return folder


def axes_on_skull(subject, axes=None):
    """The soft-tissue axes (``axes``, default the subject's true ones) of the cranial
    landmarks its skull has: what a subject folder gives the methods."""
    axes = subject.soft_tissue_axes if axes is None else axes
    return {c: v for c, v in axes.items() if c in subject.cranial_landmarks}
