"""Cone axes of a skull: the outward skull-surface normal near a landmark, and the axes a
fitted head frame gives.

A cone axis is the direction from a cranial landmark to its facial one. Where a case gives none
(no axes file, or a landmark the file lacks) it is the outward bone normal
(:func:`landmark_normals`, the file contract's default). ``lilium skull`` knows more: its fit
orients the head, and :func:`fitted_axes` writes the normal except for the landmarks of
:data:`LATERAL_OFFSET_MM`, whose skin point lies beside the bone's landmark rather than over it
(craniofacial reconstruction's placement guidelines): the lateral eye corner some 5 mm medial of
the lateral orbital margin (the lateral canthal tendon inserts on Whitnall's tubercle, inside the
orbit), the medial one about 2 mm lateral of the medial orbital wall, and each ala about 5 mm
lateral of the nasal aperture's margin (the nose some 10 mm wider than the aperture). Their
axis is that offset along the head's lateral direction plus what is left of the built-in mean
depth (:data:`~lilium.softtissue.depths.BUILTIN_DEPTHS`) towards the front. Measured on the two
real CT heads of the benchmarks (the Cranium and headsq, their true axes from their own skin):
the bone normal lies 13-107 degrees from the true axis at these landmarks (46-107 at
ectoconchion), this axis 5-34 degrees; at the other landmarks the normal lies 4-53 degrees off
(subspinale 13-53, prosthion 30-35: left to the normal, no guideline offset here). The generator
draws its faces' soft tissue about these axes at the eye corners and the alae
(:func:`lilium.synthetic.anatomy.soft_tissue.direction_centre`), about the normal elsewhere; its
subjects carry their own axes files.
docs/method/identification.md has the cases measured with each.
"""

import numpy as np

from ..constants import NORMAL_NEIGHBOURHOOD_MM
from .depths import BUILTIN_DEPTHS
from .landmarks import base_name, side

#: Cranial landmarks whose facial landmark lies beside, not over, them: the facial landmark's
#: offset (mm) along the head's lateral direction (positive: away from the midline).
LATERAL_OFFSET_MM = {"ectoconchion": -5.0, "dacryon": 2.0, "alare": 5.0}


def surface_normals_at(vertices_mm, faces, points_mm, radius_mm=NORMAL_NEIGHBOURHOOD_MM):
    """Area-weighted mean face normal within ``radius_mm`` of each point.

    The sign is chosen outward: pointing away from the mesh centroid (a skull's landmarks all lie
    on its outer surface, so this also fixes meshes with inconsistent winding). Where no face
    centroid lies within the radius, the nearest face's normal is used.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    points_mm : ndarray of shape (N, 3)
    radius_mm : float

    Returns
    -------
    normals : ndarray of shape (N, 3)
        Unit vectors.
    """
    from scipy.spatial import cKDTree

    tri = np.asarray(vertices_mm, float)[np.asarray(faces)]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # length = 2 * area
    centroids = tri.mean(axis=1)
    centre = np.asarray(vertices_mm, float).mean(axis=0)
    tree = cKDTree(centroids)
    points = np.asarray(points_mm, float)
    normals = np.empty_like(points)
    for k, p in enumerate(points):
        idx = tree.query_ball_point(p, radius_mm)
        if not idx:
            idx = [tree.query(p)[1]]
        n_face = cross[idx]
        # Orient each face outward before averaging, so mixed winding does not cancel.
        outward = np.sign(np.einsum("ij,ij->i", n_face, centroids[idx] - centre))
        n = (n_face * np.where(outward == 0, 1, outward)[:, None]).sum(axis=0)
        norm = np.linalg.norm(n)
        normals[k] = n / norm if norm > 0 else (p - centre) / np.linalg.norm(p - centre)
    return normals


def landmark_normals(vertices_mm, faces, landmarks_mm, radius_mm=NORMAL_NEIGHBOURHOOD_MM):
    """:func:`surface_normals_at` of named points: ``{name: (3,) unit vector}`` for each of
    ``landmarks_mm`` (``{name: (3,) mm}``), in its order."""
    names = list(landmarks_mm)
    points = np.array([landmarks_mm[n] for n in names], float).reshape(-1, 3)
    normals = surface_normals_at(vertices_mm, faces, points, radius_mm)
    return dict(zip(names, normals, strict=True))


def beside_axis(name, left, anterior):
    """The axis of a landmark of :data:`LATERAL_OFFSET_MM` (module notes): its offset along the
    head's lateral direction plus the rest of the built-in mean depth towards the front, or None
    for any other landmark.

    Parameters
    ----------
    name : str
        A cranial landmark, e.g. ``ectoconchion_l``.
    left, anterior : ndarray of shape (3,)
        The head's unit left and anterior directions.

    Returns
    -------
    ndarray of shape (3,) or None
        A unit vector.
    """
    offset = LATERAL_OFFSET_MM.get(base_name(name))
    if offset is None or side(name) is None:
        return None
    depth = BUILTIN_DEPTHS[base_name(name)].mean_mm
    lateral = np.asarray(left, float) * (1.0 if side(name) == "l" else -1.0)
    axis = offset * lateral + np.sqrt(depth**2 - offset**2) * np.asarray(anterior, float)
    return axis / np.linalg.norm(axis)


def fitted_axes(vertices_mm, faces, landmarks_mm, left=None, anterior=None):
    """Cone axes of named cranial landmarks in an oriented head (module notes): the bone normal,
    but :func:`beside_axis` where it applies.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    landmarks_mm : dict of str -> ndarray of shape (3,)
    left, anterior : ndarray of shape (3,), optional
        The head's unit left and anterior directions in the mesh's frame (``lilium skull``'s
        fit); without them every axis is the bone normal.

    Returns
    -------
    dict of str -> ndarray of shape (3,)
        Unit vectors, in the order of ``landmarks_mm``.
    """
    axes = landmark_normals(vertices_mm, faces, landmarks_mm) if landmarks_mm else {}
    if left is None or anterior is None:
        return axes
    for name in axes:
        axis = beside_axis(name, left, anterior)
        if axis is not None:
            axes[name] = axis
    return axes
