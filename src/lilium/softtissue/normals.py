"""Default cone axes: the outward skull-surface normal near a landmark."""

import numpy as np

from ..constants import NORMAL_NEIGHBOURHOOD_MM


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
