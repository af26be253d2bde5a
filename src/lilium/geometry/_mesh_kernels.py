"""Compiled vertex clustering (:func:`lilium.geometry.mesh.cluster_vertices`); numba, see
:mod:`lilium.jit`.

The same steps with the same arithmetic as the numpy code, the reference: the cell of each
vertex from ``floor((v - min) / cell)``, the cells numbered in the order of their flat index
(what ``np.unique``'s inverse and the dense ``cumsum`` numbering both give), each cell's mean
summed in vertex order (as ``np.bincount`` with weights sums), then the faces whose three
corners fall in three different cells. Bit for bit the numpy result
(``tests/test_kernels_mesh.py``).
"""

import numpy as np

from ..jit import njit


@njit
def cluster_kernel(v, faces, cell_mm, dense_limit):
    """Merged vertices ``(V', 3)`` and kept faces ``(F', 3)`` of int64.

    ``dense_limit``: the cells are numbered through a table of every cell of the bounding box
    when it has at most that many, else by sorting the flat indices.
    """
    V = v.shape[0]
    lo = np.empty(3)
    for k in range(3):
        m = np.inf
        for i in range(V):
            m = min(m, v[i, k])
        lo[k] = m
    key = np.empty((V, 3), np.int64)
    dims = np.zeros(3, np.int64)
    for i in range(V):
        for k in range(3):
            key[i, k] = np.int64(np.floor((v[i, k] - lo[k]) / cell_mm))
            dims[k] = max(dims[k], key[i, k] + 1)
    flat = np.empty(V, np.int64)
    for i in range(V):
        flat[i] = (key[i, 0] * dims[1] + key[i, 1]) * dims[2] + key[i, 2]
    inverse = np.empty(V, np.int64)
    if float(dims[0]) * float(dims[1]) * float(dims[2]) <= dense_limit:
        ids = np.full(dims[0] * dims[1] * dims[2], -1, np.int64)
        for i in range(V):
            ids[flat[i]] = 0
        n = 0
        for c in range(ids.shape[0]):
            if ids[c] == 0:
                ids[c] = n
                n += 1
        for i in range(V):
            inverse[i] = ids[flat[i]]
    else:
        order = np.argsort(flat, kind="mergesort")
        n = 0
        for j in range(V):
            if j > 0 and flat[order[j]] != flat[order[j - 1]]:
                n += 1
            inverse[order[j]] = n
        n = n + 1 if V else 0
    count = np.zeros(n)
    merged = np.zeros((n, 3))
    for i in range(V):
        count[inverse[i]] += 1.0
    for k in range(3):
        for i in range(V):
            merged[inverse[i], k] += v[i, k]
    for c in range(n):
        for k in range(3):
            merged[c, k] /= count[c]
    F = faces.shape[0]
    kept = np.empty((F, 3), np.int64)
    n_kept = 0
    for f in range(F):
        a, b, c = inverse[faces[f, 0]], inverse[faces[f, 1]], inverse[faces[f, 2]]
        if a != b and b != c and a != c:
            kept[n_kept, 0], kept[n_kept, 1], kept[n_kept, 2] = a, b, c
            n_kept += 1
    return merged, kept[:n_kept].copy()


@njit
def _root(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]  # path halving
        i = parent[i]
    return i


@njit
def component_kernel(faces, n_vertices):
    """Each face's connected component as the smallest vertex index of that component, (F,)
    int64: union-find over the faces' corners (faces sharing a vertex are connected)."""
    parent = np.arange(n_vertices)
    for f in range(faces.shape[0]):
        a = _root(parent, faces[f, 0])
        for k in range(1, 3):
            b = _root(parent, faces[f, k])
            if a < b:
                parent[b] = a
            elif b < a:
                parent[a] = b
                a = b
    out = np.empty(faces.shape[0], np.int64)
    for f in range(faces.shape[0]):
        out[f] = _root(parent, faces[f, 0])
    return out
