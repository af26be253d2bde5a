"""A subject's head prepared for photographing (:func:`prepare_head`): its skin mesh, which
triangles lie above the neck (the face mask) and above the jaw line (the face's own outline).

Two cuts of the skin (see :func:`head_faces_of`): in front of the gonia a plane through the facial
gnathion and both facial gonia (the lower border of the jaw), behind them the horizontal plane
through the gonia. The *jaw-line cut* lowers them by :data:`NECK_CUT_MARGIN_MM`, and under the chin
(in front of the gonia, more than :data:`JAW_BELOW_MOUTH_MM` below the mouth corners, at most
:data:`JAW_BEYOND_MOUTH_MM` beyond them sideways) it follows the mandible instead of the plane: skin
hanging below the bone farther than the subject's chin depth + :data:`JAW_CUT_MARGIN_MM` is neck
(:data:`JAW_BELOW_ANGLE_DEG`).
The skin above it is the face's own outline, from which the chin-jaw curve of ``face_curve.json`` is
taken (docs/method/lilium.md's mask rule applied to that outline). A plane there would be seen
nearly edge-on from
the front, so the facial chin-jaw curve would be a flat line whatever the jaw's shape, while the
bony chin's outline is a U: the true skull's own P_pll was then large (issue 20, measured in
docs/decisions/0011-generator-chin-jaw-curve.md); following the bone keeps the skin's chin outline
as curved as the real one
(``benchmarks/studies/chin_profile.py``).

The *face mask* keeps the upper neck too: its cut lies :data:`NECK_SKULL_CLEARANCE_MM` below the
whole skull, so that, as in a real photo of a head, the true skull projects inside the mask from
every camera of the ranges (P_skof 0 at the truth). Both cuts are properties of the subject, the
same in every photo.
"""

from dataclasses import dataclass

import numpy as np

from ..io.mesh import import_trimesh
from ..softtissue.depths import BUILTIN_DEPTHS

#: How far (mm) the jaw-line cut is lowered below the jaw border / the gonia (the face outline).
NECK_CUT_MARGIN_MM = 4.0

#: Under the chin the jaw-line cut follows the mandible: a skin point more than
#: ``JAW_BELOW_MOUTH_MM`` below the mouth corners and at most ``JAW_BEYOND_MOUTH_MM`` beyond them
#: sideways (the chin, where the facial curve is taken) is neck when it lies below its nearest bone
#: vertex (within ``JAW_BELOW_ANGLE_DEG`` of straight down) and farther from it than the
#: subject's own chin depth (facial gnathion to the nearest bone vertex, ``JAW_DEPTH_FALLBACK_MM``
#: without a facial gnathion) plus ``JAW_CUT_MARGIN_MM``: the outline then follows the bone, as
#: in a real head (``benchmarks/studies/chin_profile.py``), one chin depth below it under the
#: midline and up to the margin deeper at the sides.
#: The 4 mm margin: closer, the cut runs through the chin's own skin and its triangles leave a
#: ragged outline (at 2 mm the true skull had P_int > 0 at its true camera on 3 of 8 frontal
#: photos of seed 0, at 1 mm on 2; none at 4 mm).
JAW_BELOW_ANGLE_DEG = 60.0
JAW_BELOW_MOUTH_MM = 10.0
JAW_BEYOND_MOUTH_MM = 5.0
JAW_CUT_MARGIN_MM = 4.0
JAW_DEPTH_FALLBACK_MM = BUILTIN_DEPTHS["gnathion"].mean_mm

#: How far (mm) below the skull the face mask's neck cut lies: with pitch, the skin under the
#: jaw covers the mandible's lower border in the image, so a cut just under the bone would drop
#: pixels the true skull projects onto.
NECK_SKULL_CLEARANCE_MM = 20.0


@dataclass(frozen=True)
class HeadModel:
    """A subject's skin mesh prepared for photographing.

    Attributes
    ----------
    skin_vertices_mm : ndarray of shape (V, 3)
    skin_faces : ndarray of shape (F, 3)
    head_faces : ndarray of shape (F,), bool
        Triangles above the neck cut (they make the face mask).
    jaw_faces : ndarray of shape (F,), bool or None
        Triangles above the jaw-line cut (the face's own outline, for the chin-jaw curve);
        None = ``head_faces``.
    hull_points_mm : ndarray of shape (K, 3)
        Convex-hull vertices of the head part (their projection bounds the head's).
    facial_names : tuple of str
    facial_points_mm : ndarray of shape (L, 3)
    nasion_mm : ndarray of shape (3,)
        Facial nasion (centroid of the facial landmarks when absent): the SCD reference.
    outward_wound : bool
        The skin faces are consistently wound with outward normals (flipped here if they were
        inward), so back faces can be culled when rendering.
    """

    skin_vertices_mm: np.ndarray
    skin_faces: np.ndarray
    head_faces: np.ndarray
    hull_points_mm: np.ndarray
    facial_names: tuple
    facial_points_mm: np.ndarray
    nasion_mm: np.ndarray
    outward_wound: bool = False
    jaw_faces: np.ndarray | None = None


def _neck_planes(facial_landmarks):
    """Signed heights (mm) above the jaw plane and above the gonion plane, as functions."""
    gl = np.asarray(facial_landmarks["gonion_l"], dtype=float)
    gr = np.asarray(facial_landmarks["gonion_r"], dtype=float)
    gonion_y = 0.5 * (gl[1] + gr[1])
    gonion_z = 0.5 * (gl[2] + gr[2])
    if "gnathion" in facial_landmarks:
        gn = np.asarray(facial_landmarks["gnathion"], dtype=float)
        normal = np.cross(gl - gn, gr - gn)
        if normal[1] < 0:
            normal = -normal
        normal /= np.linalg.norm(normal)
    else:
        gn, normal = np.array([0.0, gonion_y, 0.0]), np.array([0.0, 1.0, 0.0])

    def heights(points):
        points = np.asarray(points, dtype=float)
        anterior = points[:, 2] > gonion_z
        return anterior, (points - gn) @ normal, points[:, 1] - gonion_y

    return heights


def head_faces_of(
    skin_vertices_mm,
    skin_faces,
    facial_landmarks,
    margin_mm=NECK_CUT_MARGIN_MM,
    skull_vertices_mm=None,
    jaw_bone_mm=None,
):
    """Which skin triangles belong to the head (above the neck cut, see the module notes).

    Parameters
    ----------
    skin_vertices_mm : array_like of shape (V, 3)
    skin_faces : array_like of shape (F, 3), int
    facial_landmarks : dict
        Needs ``gonion_l``, ``gonion_r`` (and ``gnathion`` for the jaw plane); without the gonia
        every triangle counts as head.
    margin_mm : float
        How far the cut planes are lowered at least.
    skull_vertices_mm : array_like of shape (K, 3), optional
        When given, each plane is lowered further where needed so that the whole skull lies
        at least ``margin_mm`` above it.
    jaw_bone_mm : array_like of shape (K, 3), optional
        The complete skull's vertices: under the chin the cut follows this bone (the jaw-line
        cut, see the module notes; needs both cheilions).

    Returns
    -------
    head : ndarray of shape (F,), bool
    """
    vertices = np.asarray(skin_vertices_mm, dtype=float)
    faces = np.asarray(skin_faces, dtype=np.int64)
    centroids = vertices[faces].mean(axis=1)
    if "gonion_l" not in facial_landmarks or "gonion_r" not in facial_landmarks:
        return np.ones(len(faces), dtype=bool)
    heights = _neck_planes(facial_landmarks)
    margin_jaw = margin_gonia = margin_mm
    if skull_vertices_mm is not None:
        anterior, jaw, gonia = heights(skull_vertices_mm)
        if anterior.any():
            margin_jaw = max(margin_mm, margin_mm - jaw[anterior].min())
        if (~anterior).any():
            margin_gonia = max(margin_mm, margin_mm - gonia[~anterior].min())
    anterior, jaw, gonia = heights(centroids)
    neck = np.where(anterior, jaw < -margin_jaw, gonia < -margin_gonia)
    has_bone = jaw_bone_mm is not None and len(jaw_bone_mm) > 0
    if has_bone and {"cheilion_l", "cheilion_r"} <= set(facial_landmarks):
        left, right = (np.asarray(facial_landmarks[n], float) for n in ("cheilion_l", "cheilion_r"))
        half_width_mm = 0.5 * abs(left[0] - right[0]) + JAW_BEYOND_MOUTH_MM
        chin = (
            anterior
            & (centroids[:, 1] < min(left[1], right[1]) - JAW_BELOW_MOUTH_MM)
            & (np.abs(centroids[:, 0] - 0.5 * (left[0] + right[0])) < half_width_mm)
        )
        neck[chin] = _below_jaw_bone(centroids[chin], jaw_bone_mm, facial_landmarks)
    return ~neck


def _below_jaw_bone(points_mm, bone_vertices_mm, facial_landmarks):
    """Which points hang below the bone deeper than the chin's soft tissue (the jaw-line cut
    under the chin, see :data:`JAW_BELOW_ANGLE_DEG`).

    Parameters
    ----------
    points_mm : ndarray of shape (N, 3)
    bone_vertices_mm : array_like of shape (K, 3), K >= 1
    facial_landmarks : dict
        Its ``gnathion`` sets the chin depth (distance to the nearest bone vertex).

    Returns
    -------
    ndarray of shape (N,), bool
    """
    from scipy.spatial import cKDTree

    bone = np.asarray(bone_vertices_mm, dtype=float)
    tree = cKDTree(bone)
    depth_mm = JAW_DEPTH_FALLBACK_MM
    if "gnathion" in facial_landmarks:
        depth_mm = float(tree.query(np.asarray(facial_landmarks["gnathion"], dtype=float))[0])
    distance_mm, index = tree.query(points_mm)
    offset_mm = points_mm - bone[index]
    below = -offset_mm[:, 1] > np.cos(np.radians(JAW_BELOW_ANGLE_DEG)) * distance_mm
    return below & (distance_mm > depth_mm + JAW_CUT_MARGIN_MM)


def prepare_head(subject):
    """A :class:`HeadModel` from a subject (``skin_vertices_mm``, ``skin_faces``,
    ``facial_landmarks``; the mask's neck cut clears ``head_skull_vertices_mm``, the complete
    skull of a subject whose skull lacks the mandible, or else ``skull_vertices_mm``)."""
    from scipy.spatial import ConvexHull

    trimesh = import_trimesh()

    vertices = np.asarray(subject.skin_vertices_mm, dtype=float)
    faces = np.asarray(subject.skin_faces, dtype=np.int64)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    outward = bool(mesh.is_winding_consistent)
    if outward and mesh.volume < 0:
        faces = faces[:, ::-1].copy()
    facial = {k: np.asarray(v, dtype=float) for k, v in subject.facial_landmarks.items()}
    if not facial:
        raise ValueError("the subject has no facial landmarks; a photo needs them")
    skull = getattr(subject, "head_skull_vertices_mm", None)  # the complete skull, if not given
    skull = getattr(subject, "skull_vertices_mm", None) if skull is None else skull
    jaw = head_faces_of(vertices, faces, facial, jaw_bone_mm=skull)
    head = jaw
    if skull is not None:
        head = head_faces_of(vertices, faces, facial, NECK_SKULL_CLEARANCE_MM, skull)
        jaw = jaw & head  # the facial curve's skin lies inside the face mask
    head_points = vertices[np.unique(faces[head])]
    hull = head_points[ConvexHull(head_points).vertices]
    names = tuple(facial)
    points = np.array([facial[n] for n in names])
    nasion = facial["nasion"] if "nasion" in facial else points.mean(axis=0)
    return HeadModel(vertices, faces, head, hull, names, points, nasion, outward, jaw)
