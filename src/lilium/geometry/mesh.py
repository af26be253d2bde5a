"""Triangle-mesh operations: largest connected component, compaction, quadric decimation.

Pure functions over ``vertices (V, 3)`` and ``faces (F, 3)``, used by the CT importer, the
synthetic generator and the fitness terms alike.
"""

import numpy as np

from .. import jit
from ._mesh_kernels import cluster_kernel


def keep_largest_component(vertices, faces):
    """Keep the connected component with the most faces (vertices re-indexed).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int

    Returns
    -------
    vertices : ndarray of shape (V', 3)
    faces : ndarray of shape (F', 3)
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    if len(faces) == 0:
        return vertices, faces
    n = len(vertices)
    rows = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2]])
    cols = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    face_labels = labels[faces[:, 0]]
    keep_label = np.argmax(np.bincount(face_labels))
    return compact(vertices, faces[face_labels == keep_label])


def compact(vertices, faces):
    """Drop unreferenced vertices and re-index the faces."""
    used, inverse = np.unique(faces, return_inverse=True)
    return vertices[used], inverse.reshape(faces.shape).astype(np.int64)


def decimate(vertices, faces, target_faces):
    """Quadric decimation to about ``target_faces`` faces (needs ``fast-simplification``).

    Returns the input unchanged when it already has at most ``target_faces`` faces.
    """
    target_faces = int(target_faces)
    if target_faces < 4:
        raise ValueError(f"target_faces must be at least 4, got {target_faces}")
    if len(faces) <= target_faces:
        return vertices, faces
    try:
        import fast_simplification
    except ImportError as exc:
        raise ValueError(
            "decimation (target_faces) needs the optional package fast-simplification: "
            "pip install fast-simplification, or leave target_faces unset"
        ) from exc
    reduction = 1.0 - target_faces / len(faces)
    v, f = fast_simplification.simplify(
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64),
        target_reduction=reduction,
    )
    return compact(np.asarray(v, dtype=float), np.asarray(f, dtype=np.int64))


def cluster_vertices(vertices_mm, faces, cell_mm):
    """Vertex clustering: merge the vertices of each cubic cell into their mean.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    cell_mm : float

    Returns
    -------
    vertices_mm : ndarray of shape (V', 3)
    faces : ndarray of shape (F', 3), int64
        The faces whose corners stay in three different cells (orientation kept).
    """
    v = np.asarray(vertices_mm, float)
    dense_limit = 4 * len(v) + 1e6  # cells of the bounding box numbered through a table
    if jit.compiled() and len(v):  # the same steps, compiled (geometry/_mesh_kernels.py)
        faces = np.ascontiguousarray(faces, dtype=np.int64)
        return cluster_kernel(np.ascontiguousarray(v), faces, float(cell_mm), dense_limit)
    key = np.floor((v - v.min(axis=0)) / cell_mm).astype(np.int64)
    dims = key.max(axis=0) + 1
    flat = (key[:, 0] * dims[1] + key[:, 1]) * dims[2] + key[:, 2]
    if np.prod(dims.astype(float)) <= dense_limit:
        # Dense cells: ids in cell order without sorting.
        used = np.zeros(int(np.prod(dims)), bool)
        used[flat] = True
        ids = np.cumsum(used) - 1
        inverse = ids[flat]
        n = int(used.sum())
    else:
        _, inverse = np.unique(flat, return_inverse=True)
        n = int(inverse.max()) + 1
    count = np.bincount(inverse, minlength=n).astype(float)
    merged = np.stack([np.bincount(inverse, weights=v[:, k], minlength=n) for k in range(3)], 1)
    merged /= count[:, None]
    g = inverse[np.asarray(faces)]
    keep = (g[:, 0] != g[:, 1]) & (g[:, 1] != g[:, 2]) & (g[:, 0] != g[:, 2])
    return merged, np.ascontiguousarray(g[keep], dtype=np.int64)
