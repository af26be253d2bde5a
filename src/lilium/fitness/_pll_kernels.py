"""Compiled steps of P_pll (:mod:`lilium.fitness.pll`): trimming, pairing, terms; numba, see
:mod:`lilium.jit`.

One loop over the members of a population, in the order and with the arithmetic of the numpy
path (the reference, :func:`lilium.fitness.pll.trim_curves_batch`,
:func:`~lilium.fitness.pll.pair_curves_batch`, :func:`~lilium.fitness.pll.terms_from_pairs`):
the same end tangents (unit steps summed left to right, as ``cumsum`` does), the same
``(a - b) * t + (c - d) * s > 0`` side tests, the same nearest-point rules (the face curve's
table, then a search whose ties go to the lowest index, as ``argmin``'s), the pairs in curve
order, and the sums of the terms in pair order. Integers (cuts, pair indices, counts) are
equal and floats bit for bit equal on finite curves (``tests/test_kernels_mesh.py``).
"""

import math

import numpy as np

from ..geometry._projection_kernels import pinhole
from ..jit import njit
from ._curve_kernels import boundary_kernel, span_join_kernel, windows_kernel

#: Fraction of a curve's length whose mean tangent defines its end normal (pll.END_FRACTION).
END_FRACTION = 0.2

#: pll.CONVERGENCE_RATIO and pll.INTERSECTION_WEIGHT.
CONVERGENCE_RATIO = 0.25
INTERSECTION_WEIGHT = 1000.0

#: Wrong-side codes of :func:`terms_kernel`: frontal, lateral_left, lateral_right.
SIDE_CODES = {"frontal": 0, "lateral_left": 1, "lateral_right": 2}


@njit
def end_tangent(P, first, n, head):
    """Unit mean tangent of the first (``head``: pointing outwards) or last steps of the curve
    ``P[first : first + n]`` (``n >= 2``); :func:`lilium.fitness.pll.end_tangents` of one end."""
    k = min(n - 1, max(2, math.ceil(END_FRACTION * n)))
    j0 = first if head else first + n - 1 - k
    su = sv = 0.0
    for j in range(j0, j0 + k):
        du, dv = P[j + 1, 0] - P[j, 0], P[j + 1, 1] - P[j, 1]
        length = max(math.hypot(du, dv), 1e-12)
        if j == j0:
            su, sv = du / length, dv / length
        else:
            su += du / length
            sv += dv / length
    tu, tv = su / k, sv / k
    if head:
        tu, tv = -tu, -tv
    norm = math.hypot(tu, tv)
    if norm > 1e-12:
        return tu / norm, tv / norm
    return tu, tv


@njit
def _beyond(x, y, a, t):
    """Whether ``(x, y)`` lies beyond the normal line through ``a`` (2,) along ``t`` (2,)."""
    return (x - a[0]) * t[0] + (y - a[1]) * t[1] > 0


@njit
def trim_kernel(P, offset, face, ends, has_ends):
    """Step 1 (:func:`lilium.fitness.pll.trim_curves_batch`) of ``S`` curves.

    Parameters
    ----------
    P : ndarray of shape (N, 2)
    offset : ndarray of shape (S + 1,) of int64
    face : ndarray of shape (M, 2)
    ends : ndarray of shape (4, 2)
        The facial curve's head anchor, head tangent, tail anchor, tail tangent.
    has_ends : bool
        False: nothing is trimmed (a facial curve of fewer than 3 points).

    Returns
    -------
    points : ndarray of shape (N', 2)
    kept : ndarray of shape (S + 1,) of int64
        Offsets of the trimmed curves.
    face_lo, face_hi : ndarray of shape (S,) of int64
    """
    S = offset.shape[0] - 1
    M = face.shape[0]
    head_s = np.zeros(S, np.int64)
    tail_s = np.zeros(S, np.int64)
    face_lo = np.zeros(S, np.int64)
    face_hi = np.full(S, M, np.int64)
    anchor = np.empty(2)
    tangent = np.empty(2)
    for m in range(S):
        o, n = offset[m], offset[m + 1] - offset[m]
        if not has_ends or n < 3:
            continue
        # The skull's ends cut the face curve.
        anchor[0], anchor[1] = P[o, 0], P[o, 1]
        tangent[0], tangent[1] = end_tangent(P, o, n, True)
        hf = M
        for j in range(M):
            if not _beyond(face[j, 0], face[j, 1], anchor, tangent):
                hf = j
                break
        anchor[0], anchor[1] = P[o + n - 1, 0], P[o + n - 1, 1]
        tangent[0], tangent[1] = end_tangent(P, o, n, False)
        tf = M
        for jj in range(M):
            j = M - 1 - jj
            if not _beyond(face[j, 0], face[j, 1], anchor, tangent):
                tf = jj
                break
        # The face's ends cut the skull curve.
        hs = n
        for i in range(n):
            if not _beyond(P[o + i, 0], P[o + i, 1], ends[0], ends[1]):
                hs = i
                break
        ts = n
        for ii in range(n):
            i = o + n - 1 - ii
            if not _beyond(P[i, 0], P[i, 1], ends[2], ends[3]):
                ts = ii
                break
        if hs + ts < n:
            head_s[m], tail_s[m] = hs, ts
        if hf + tf < M:
            face_lo[m], face_hi[m] = hf, M - tf
    kept = np.zeros(S + 1, np.int64)
    for m in range(S):
        kept[m + 1] = kept[m] + (offset[m + 1] - offset[m]) - head_s[m] - tail_s[m]
    points = np.empty((kept[S], 2))
    for m in range(S):
        first = offset[m] + head_s[m]
        for i in range(kept[m + 1] - kept[m]):
            points[kept[m] + i, 0] = P[first + i, 0]
            points[kept[m] + i, 1] = P[first + i, 1]
    return points, kept, face_lo, face_hi


@njit
def _table_lookup(x, y, table, u0, v0):
    """The face curve's nearest-point table at pixel ``(x, y)``; -1 off the grid or table."""
    if not (abs(x) < 4e18 and abs(y) < 4e18):  # also NaN
        return -1
    col, row = np.int64(x), np.int64(y)
    if col != x or row != y:
        return -1
    col -= u0
    row -= v0
    if col < 0 or row < 0 or row >= table.shape[0] or col >= table.shape[1]:
        return -1
    return table[row, col]


@njit
def _argmin_d2(x, y, pts, lo, hi):
    """``argmin`` of the squared distances from ``(x, y)`` to ``pts[lo:hi]`` (index into
    ``pts``), ``argmin``'s ties and NaN rule; 0 when every distance is infinite."""
    best, at = np.inf, 0
    for j in range(lo, hi):
        du, dv = x - pts[j, 0], y - pts[j, 1]
        d2 = du * du + dv * dv
        if d2 != d2:
            return j
        if d2 < best:
            best, at = d2, j
    return at


@njit
def pair_kernel(P, offset, face, face_lo, face_hi, table, u0, v0):
    """Step 2 (:func:`lilium.fitness.pll.pair_curves_batch`) of ``S`` (trimmed) curves.

    Parameters
    ----------
    P : ndarray of shape (N, 2)
    offset : ndarray of shape (S + 1,) of int64
    face : ndarray of shape (M, 2)
    face_lo, face_hi : ndarray of shape (S,) of int64
    table : ndarray of shape (h, w) of int64
    u0, v0 : int
        The table's origin.

    Returns
    -------
    skull, face_xy : ndarray of shape (Q, 2)
    distance : ndarray of shape (Q,)
    pair_offset : ndarray of shape (S + 1,) of int64
    """
    S = offset.shape[0] - 1
    M = face.shape[0]
    N = P.shape[0]
    pair_offset = np.zeros(S + 1, np.int64)
    if M == 0 or N == 0:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), pair_offset
    size = N
    for m in range(S):
        if offset[m + 1] > offset[m]:
            size += face_hi[m] - face_lo[m]
    s_idx = np.empty(size, np.int64)  # global skull point of each pair
    f_idx = np.empty(size, np.int64)
    nearest_p = np.empty(N, np.int64)
    chosen = np.full(M, -1, np.int64)  # member that chose face point j
    nearest_s = np.empty(M, np.int64)
    count = np.empty(N + 1, np.int64)
    bucket = np.empty(M, np.int64)
    total = 0
    for m in range(S):
        o, n = offset[m], offset[m + 1] - offset[m]
        pair_offset[m] = total
        if n == 0:
            continue
        lo, hi = face_lo[m], face_hi[m]
        # Skull -> face: table lookup, a search where it cannot answer.
        for i in range(o, o + n):
            k = _table_lookup(P[i, 0], P[i, 1], table, u0, v0)
            if k < lo or k >= hi:
                k = _argmin_d2(P[i, 0], P[i, 1], face, lo, hi)
            nearest_p[i] = k
            chosen[k] = m
        # Face -> skull for the face points no skull point chose; bucketed by skull point.
        for i in range(n + 1):
            count[i] = 0
        for j in range(lo, hi):
            if chosen[j] != m:
                nearest_s[j] = _argmin_d2(face[j, 0], face[j, 1], P[o : o + n], 0, n)
                count[nearest_s[j] + 1] += 1
        for i in range(n):
            count[i + 1] += count[i]
        for j in range(lo, hi):
            if chosen[j] != m:
                bucket[count[nearest_s[j]]] = j
                count[nearest_s[j]] += 1
        # Pairs in curve order: skull index, then face index (the bucket is in face order).
        b = 0
        for i in range(n):
            own = nearest_p[o + i]
            placed = False
            while b < count[i]:
                if not placed and own < bucket[b]:
                    s_idx[total], f_idx[total] = o + i, own
                    total += 1
                    placed = True
                s_idx[total], f_idx[total] = o + i, bucket[b]
                total += 1
                b += 1
            if not placed:
                s_idx[total], f_idx[total] = o + i, own
                total += 1
    pair_offset[S] = total
    skull = np.empty((total, 2))
    face_xy = np.empty((total, 2))
    distance = np.empty(total)
    for q in range(total):
        su, sv = P[s_idx[q], 0], P[s_idx[q], 1]
        fu, fv = face[f_idx[q], 0], face[f_idx[q], 1]
        skull[q, 0], skull[q, 1] = su, sv
        face_xy[q, 0], face_xy[q, 1] = fu, fv
        du, dv = su - fu, sv - fv
        distance[q] = math.sqrt(du * du + dv * dv)
    return skull, face_xy, distance, pair_offset


@njit
def terms_kernel(skull, face, distance, offset, side, no_curve):
    """Step 3 (:func:`lilium.fitness.pll.terms_from_pairs`): ``delta_d``, ``p_conv``,
    ``p_int``, ``total`` and ``n_pairs``, each of shape (S,), from the pairs (``offset``
    (S + 1,)); a member without pairs gets NaN parts and ``no_curve`` as its total. ``side`` is
    a :data:`SIDE_CODES` value."""
    S = offset.shape[0] - 1
    delta_d = np.full(S, np.nan)
    p_conv = np.full(S, np.nan)
    p_int = np.full(S, np.nan)
    total = np.full(S, no_curve)
    n_pairs = np.zeros(S, np.int64)
    for m in range(S):
        a, c = offset[m], offset[m + 1] - offset[m]
        n_pairs[m] = c
        if c == 0:
            continue
        lo = hi = distance[a]
        s = distance[a]
        bad = 0
        for q in range(a, a + c):
            d = distance[q]
            if q > a:
                s += d
                lo = min(lo, d)
                hi = max(hi, d)
            if side == 0:
                bad += skull[q, 1] >= face[q, 1]
            elif side == 1:
                bad += skull[q, 0] <= face[q, 0]
            else:
                bad += skull[q, 0] >= face[q, 0]
        dbar = s / c
        d1, dn = abs(distance[a] - dbar), abs(distance[a + c - 1] - dbar)
        c1, cn = d1 > CONVERGENCE_RATIO * dbar, dn > CONVERGENCE_RATIO * dbar
        if c1 and cn:
            conv = 2.0 * (d1 + dn)
        elif c1:
            conv = 4.0 * d1
        elif cn:
            conv = 4.0 * dn
        else:
            conv = 0.0
        delta_d[m] = hi - lo
        p_conv[m] = conv
        p_int[m] = INTERSECTION_WEIGHT * bad
        total[m] = delta_d[m] + conv + p_int[m]
    return delta_d, p_conv, p_int, total, n_pairs


@njit
def population_kernel(
    vertices, span_mm, has_span, R, t, f, c0, c1, height, width, max_window,
    corners, edge_face, edge_dir, edges_a, edges_b, view,
    face, ends, has_ends, table, u0, v0, side, no_curve,
):  # fmt: skip
    """P_pll of a region under ``S`` cameras in one call: the projection, the skull curves
    (:func:`~lilium.fitness._curve_kernels.windows_kernel`, ``boundary_kernel``,
    ``span_join_kernel``) and the three steps (:func:`trim_kernel`, :func:`pair_kernel`,
    :func:`terms_kernel`), the kernels :meth:`lilium.fitness.pll_context.PllContext.terms_batch`
    calls one by one, in the same order on the same arrays (so the same numbers).

    Parameters
    ----------
    vertices : ndarray of shape (K, 3)
        The region's vertices (skull frame, mm).
    span_mm : ndarray of shape (2, 3)
        Glabella and metopion (the forehead's span, when ``has_span``).
    R, t, f : ndarray of shape (S, 3, 3), (S, 3), (S,)
    c0, c1 : float
        Principal point.
    height, width : int
        The image (``height`` < 0: no image to clip the windows to).
    max_window : int
    corners, edge_face, edge_dir, edges_a, edges_b, view
        As :func:`~lilium.fitness._curve_kernels.boundary_kernel`.
    face, ends, has_ends, table, u0, v0, side, no_curve
        As :func:`trim_kernel`, :func:`pair_kernel` and :func:`terms_kernel`.

    Returns
    -------
    delta_d, p_conv, p_int, total, n_pairs : ndarray of shape (S,)
    """
    S, K = R.shape[0], vertices.shape[0]
    u = np.empty((S, K))
    v = np.empty((S, K))
    span_v = np.zeros((S, 2))
    for s in range(S):
        for k in range(K):
            x, y, z = vertices[k, 0], vertices[k, 1], vertices[k, 2]
            u[s, k], v[s, k] = pinhole(x, y, z, R[s], t[s], f[s], c0, c1)
        if has_span:
            for j in range(2):
                x, y, z = span_mm[j, 0], span_mm[j, 1], span_mm[j, 2]
                span_v[s, j] = pinhole(x, y, z, R[s], t[s], f[s], c0, c1)[1]
    lo, hi, empty, _ = windows_kernel(u, v, height, width, max_window)
    member, points = boundary_kernel(
        u, v, corners, edge_face, edge_dir, edges_a, edges_b, lo, hi, ~empty, view
    )
    points, offset = span_join_kernel(member, points, span_v, has_span, S)
    points, offset, face_lo, face_hi = trim_kernel(points, offset, face, ends, has_ends)
    skull, face_xy, distance, pair_offset = pair_kernel(
        points, offset, face, face_lo, face_hi, table, u0, v0
    )
    return terms_kernel(skull, face_xy, distance, pair_offset, side, no_curve)


#: Side (pixels) of the buckets of :func:`nearest_table_kernel`.
NEAREST_BUCKET_PX = 16


@njit
def nearest_table_kernel(points, u0, v0, height, width):
    """The nearest-point table of :func:`lilium.fitness.pll.face_curve_index`: for every pixel
    ``(u0 + c, v0 + r)`` of a ``height`` x ``width`` box, the index of the nearest of ``points``
    (M, 2) (lowest index on ties), the same squared distances as the numpy path's.

    The points go into square buckets of :data:`NEAREST_BUCKET_PX`; each pixel searches rings
    of buckets outwards and stops once every point left is farther than its best (a point in
    ring ``r + 1`` lies more than ``r`` bucket sides away), so the answer is exact.
    """
    B = NEAREST_BUCKET_PX
    M = points.shape[0]
    gw, gh = (width + B - 1) // B, (height + B - 1) // B
    bx = np.empty(M, np.int64)
    by = np.empty(M, np.int64)
    start = np.zeros(gw * gh + 1, np.int64)
    for j in range(M):
        bx[j] = min(max(np.int64(np.floor((points[j, 0] - u0) / B)), 0), gw - 1)
        by[j] = min(max(np.int64(np.floor((points[j, 1] - v0) / B)), 0), gh - 1)
        start[by[j] * gw + bx[j] + 1] += 1
    for b in range(gw * gh):
        start[b + 1] += start[b]
    fill = start[:-1].copy()
    members = np.empty(M, np.int64)  # each bucket's points in index order
    for j in range(M):
        b = by[j] * gw + bx[j]
        members[fill[b]] = j
        fill[b] += 1
    table = np.empty((height, width), np.int64)
    rings = max(gw, gh)
    for r in range(height):
        y = float(v0 + r)
        cy = r // B
        for c in range(width):
            x = float(u0 + c)
            cx = c // B
            best, at = np.inf, -1
            for ring in range(rings):
                if ring > 0 and best < float((ring - 1) * B) ** 2:
                    break  # every point not seen is farther than the best
                for qy in range(cy - ring, cy + ring + 1):
                    if qy < 0 or qy >= gh:
                        continue
                    edge_row = qy == cy - ring or qy == cy + ring
                    step = 1 if edge_row else 2 * ring
                    qx = cx - ring
                    while qx <= cx + ring:
                        if 0 <= qx < gw:
                            b = qy * gw + qx
                            for k in range(start[b], start[b + 1]):
                                j = members[k]
                                du, dv = x - points[j, 0], y - points[j, 1]
                                d2 = du * du + dv * dv
                                if d2 < best or (d2 == best and j < at):
                                    best, at = d2, j
                        qx += step
            table[r, c] = at
    return table
