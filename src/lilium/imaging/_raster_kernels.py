"""Compiled kernels of the skull raster (:mod:`lilium.imaging.raster`); numba, see
:mod:`lilium.jit`.

They compute what the numpy code of :mod:`lilium.imaging.raster` computes, with the same
floating-point operations in the same order (no fastmath), so the crossings, and every pixel
count made from them, are identical:

- :func:`scan_kernel` = :func:`~lilium.imaging.raster.contour_edges` followed by
  :func:`~lilium.imaging.raster.scan_crossings`: contour edges from the per-face signs (a
  face-by-face accumulation of each edge's multiplicity instead of the sparse product), their
  scanline crossings, sorted by (member, row, column, winding step) by a per-row bucket sort
  instead of one global sort, and the running winding number.
- :func:`member_crossings` the same for one member and an explicit list of faces, the building
  block of the culled P_skof count (:mod:`lilium.fitness._skof_kernels`).
- :func:`edge_table_kernel` the edges of :func:`~lilium.imaging.raster.mesh_edge_topology` by
  a counting sort instead of ``np.unique`` (the same edges in the same order), and
  :func:`incidence_kernel` their incidence to the faces by a counting sort instead of a stable
  argsort.
"""

import numpy as np

from ..jit import njit

#: Offset that makes a winding step non-negative inside a (column, step) sort key.
_STEP_OFFSET = 1 << 20


@njit
def _grow(buf, need):
    """``buf`` (K, 3) int64, enlarged (doubled) to hold at least ``need`` rows."""
    if need <= buf.shape[0]:
        return buf
    size = max(need, 2 * buf.shape[0])
    out = np.empty((size, buf.shape[1]), np.int64)
    out[: buf.shape[0]] = buf
    return out


@njit
def accumulate_face(f, s, face_edges, face_dirs, mult, mark, stamp, touched, n_touched):
    """Add face ``f`` with sign ``s`` to the edge multiplicities; return the new touched count."""
    for k in range(3):
        e = face_edges[f, k]
        if mark[e] != stamp:
            mark[e] = stamp
            mult[e] = 0.0
            touched[n_touched] = e
            n_touched += 1
        mult[e] += s * face_dirs[f, k]
    return n_touched


@njit
def edge_crossings(u, v, touched, n_touched, mult, edges_a, edges_b, r_lo, r_hi, c_lo, c_hi, buf):
    """Crossings ``(row, column, step)`` of the contour edges among the touched ones.

    ``u``, ``v`` (V,) are one member's projected vertices. Returns the buffer (grown as needed)
    and the number of rows written. The arithmetic is that of
    :func:`lilium.imaging.raster.scan_crossings`.
    """
    n = 0
    for i in range(n_touched):
        e = touched[i]
        w = mult[e]
        if w == 0.0:
            continue
        weight = np.int64(w)
        a, b = edges_a[e], edges_b[e]
        ua, va, ub, vb = u[a], v[a], u[b], v[b]
        r0 = max(np.ceil(min(va, vb)), r_lo)
        r1 = min(np.ceil(max(va, vb)), r_hi)
        count = np.int64(r1 - r0)
        if count <= 0:
            continue
        slope = (ub - ua) / (vb - va)
        step = weight if vb > va else -weight
        buf = _grow(buf, n + count)
        for j in range(count):
            row = r0 + j
            u_cross = ua + (row - va) * slope
            col = np.ceil(min(max(u_cross, c_lo), c_hi))
            buf[n, 0] = np.int64(row)
            buf[n, 1] = np.int64(col)
            buf[n, 2] = step
            n += 1
    return buf, n


@njit
def sort_rows(buf, n, keys, order_rows):
    """Sort the first ``n`` crossings of ``buf`` by (row, column, step), in place.

    Bucket sort by row, then each row by its (column, step) key: insertion sort for the few
    crossings of a typical row, ``np.sort`` for long rows. ``keys`` and ``order_rows`` are
    scratch buffers of at least ``n`` entries (returned, grown if needed).
    """
    if n == 0:
        return keys, order_rows
    if keys.shape[0] < n:
        keys = np.empty(max(n, 2 * keys.shape[0]), np.int64)
        order_rows = np.empty(max(n, 2 * order_rows.shape[0]), np.int64)
    r_min, r_max = buf[0, 0], buf[0, 0]
    for i in range(n):
        r = buf[i, 0]
        r_min = min(r_min, r)
        r_max = max(r_max, r)
    n_rows = r_max - r_min + 1
    start = np.zeros(n_rows + 1, np.int64)
    for i in range(n):
        start[buf[i, 0] - r_min + 1] += 1
    for r in range(n_rows):
        start[r + 1] += start[r]
    fill = start[:-1].copy()
    for i in range(n):
        r = buf[i, 0] - r_min
        k = fill[r]
        fill[r] += 1
        keys[k] = buf[i, 1] * (2 * _STEP_OFFSET) + (buf[i, 2] + _STEP_OFFSET)
        order_rows[k] = buf[i, 0]
    for r in range(n_rows):
        lo, hi = start[r], start[r + 1]
        if hi - lo > 32:
            keys[lo:hi] = np.sort(keys[lo:hi])
        else:
            for i in range(lo + 1, hi):
                key = keys[i]
                j = i - 1
                while j >= lo and keys[j] > key:
                    keys[j + 1] = keys[j]
                    j -= 1
                keys[j + 1] = key
    for i in range(n):
        key = keys[i]
        # floor division keeps negative columns right (c_lo may be negative).
        col = key // (2 * _STEP_OFFSET)
        buf[i, 0] = order_rows[i]
        buf[i, 1] = col
        buf[i, 2] = key - col * (2 * _STEP_OFFSET) - _STEP_OFFSET
    return keys, order_rows


@njit
def scan_kernel(u, v, sign, face_edges, face_dirs, edges_a, edges_b, r_lo, r_hi, c_lo, c_hi):
    """Sorted crossings of S projected meshes: ``(member, row, column, winding)`` arrays.

    Parameters
    ----------
    u, v : ndarray of shape (S, V)
    sign : ndarray of shape (S, F)
        Face orientation signs (0 drops a face).
    face_edges : ndarray of shape (F, 3) of int64
        Edge of each face side (``k -> k + 1``).
    face_dirs : ndarray of shape (F, 3) of float64
        +1 when the side runs along its edge ``a -> b``, -1 otherwise.
    edges_a, edges_b : ndarray of shape (E,)
    r_lo, r_hi, c_lo, c_hi : int
        Rows ``r_lo <= row < r_hi`` are scanned; columns are clipped to ``[c_lo, c_hi]``.
    """
    S, F = sign.shape
    E = edges_a.shape[0]
    mult = np.zeros(E)
    mark = np.full(E, -1, np.int64)
    touched = np.empty(E, np.int64)
    buf = np.empty((1024, 3), np.int64)
    keys = np.empty(1024, np.int64)
    rows = np.empty(1024, np.int64)
    out_member = np.empty(0, np.int64)
    out = np.empty((0, 3), np.int64)
    total = 0
    flo, fhi = float(r_lo), float(r_hi)
    clo, chi = float(c_lo), float(c_hi)
    for m in range(S):
        n_touched = 0
        for f in range(F):
            s = sign[m, f]
            if s != 0.0:
                n_touched = accumulate_face(
                    f, s, face_edges, face_dirs, mult, mark, m, touched, n_touched
                )
        buf, n = edge_crossings(
            u[m], v[m], touched, n_touched, mult, edges_a, edges_b, flo, fhi, clo, chi, buf
        )
        keys, rows = sort_rows(buf, n, keys, rows)
        if total + n > out.shape[0]:
            size = max(total + n, 2 * out.shape[0])
            grown = np.empty((size, 3), np.int64)
            grown[:total] = out[:total]
            out = grown
            grown_m = np.empty(size, np.int64)
            grown_m[:total] = out_member[:total]
            out_member = grown_m
        out[total : total + n] = buf[:n]
        out_member[total : total + n] = m
        total += n
    winding = np.empty(total, np.int64)
    acc = 0
    for i in range(total):
        acc += out[i, 2]
        winding[i] = acc
    return out_member[:total], out[:total, 0].copy(), out[:total, 1].copy(), winding


@njit
def _counting_order(keys, n_keys):
    """The stable order of ``keys`` (H,) of int64 in ``[0, n_keys)`` by a counting sort, and
    where each key's run starts in it, ``start`` (n_keys + 1,)."""
    start = np.zeros(n_keys + 1, np.int64)
    for i in range(keys.shape[0]):
        start[keys[i] + 1] += 1
    for k in range(n_keys):
        start[k + 1] += start[k]
    order = np.empty(keys.shape[0], np.int64)
    fill = start[:-1].copy()
    for i in range(keys.shape[0]):
        order[fill[keys[i]]] = i
        fill[keys[i]] += 1
    return order, start


@njit
def edge_table_kernel(lo, hi, n_vertices):
    """The distinct edges of a mesh's half-edges and each half-edge's edge, as
    ``np.unique(lo * n_vertices + hi, return_inverse=True)`` gives them (edges sorted by
    ``(lo, hi)``), by a counting sort on ``lo`` and a sort of each vertex's few ``hi``.

    Parameters
    ----------
    lo, hi : ndarray of shape (H,) of int64
        Each half-edge's smaller and larger vertex index.
    n_vertices : int

    Returns
    -------
    edges_lo, edges_hi : ndarray of shape (E,) of int64
    edge_of : ndarray of shape (H,) of int64
    """
    H = lo.shape[0]
    order, start = _counting_order(lo, n_vertices)
    edges_lo = np.empty(H, np.int64)
    edges_hi = np.empty(H, np.int64)
    edge_of = np.empty(H, np.int64)
    n_edges = 0
    for v in range(n_vertices):
        a, b = start[v], start[v + 1]
        if b - a > 32:
            run = order[a:b]
            order[a:b] = run[np.argsort(hi[run], kind="mergesort")]
        else:  # insertion sort of a vertex's few half-edges by their other vertex
            for j in range(a + 1, b):
                i = order[j]
                k = j - 1
                while k >= a and hi[order[k]] > hi[i]:
                    order[k + 1] = order[k]
                    k -= 1
                order[k + 1] = i
        for j in range(a, b):
            i = order[j]
            if j == a or hi[i] != hi[order[j - 1]]:
                edges_lo[n_edges] = v
                edges_hi[n_edges] = hi[i]
                n_edges += 1
            edge_of[i] = n_edges - 1
    return edges_lo[:n_edges].copy(), edges_hi[:n_edges].copy(), edge_of


@njit
def incidence_kernel(edge_of, direction, n_edges):
    """``(indptr, indices, data)`` of :func:`~lilium.imaging.raster.edge_incidence` (its
    arguments and rows) by a counting sort on the edge: half-edge ``i`` is a side of face
    ``i // 3``, so faces ascend within an edge, and a face's sides along one edge are summed."""
    order, start = _counting_order(edge_of, n_edges)
    indptr = np.zeros(n_edges + 1, np.int64)
    indices = np.empty(edge_of.shape[0], np.int64)
    data = np.empty(edge_of.shape[0])
    k = 0
    for e in range(n_edges):
        for j in range(start[e], start[e + 1]):
            i = order[j]
            if j > start[e] and indices[k - 1] == i // 3:
                data[k - 1] += direction[i]
            else:
                indices[k] = i // 3
                data[k] = direction[i]
                k += 1
        indptr[e + 1] = k
    return indptr, indices[:k].copy(), data[:k].copy()
