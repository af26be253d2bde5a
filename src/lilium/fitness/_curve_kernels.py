"""Compiled skull-curve detection of P_pll (:func:`lilium.fitness.curves.detect_curves_batch`);
numba, see :mod:`lilium.jit`.

Per member: the covered runs of the region's union raster in the member's own window (the
contour-edge scan of :mod:`lilium.imaging._raster_kernels`, the same crossings), and from them,
without building the raster, the skin-side boundary with isolated pixels (no 8-neighbour)
dropped: the lowest pixel of every column (frontal: rows bottom-up, a union-find skipping the
columns already done, so the cost follows the number of runs, not the covered area) or the first
(``lateral_left``) or last (``lateral_right``) pixel of every row. Integer pixels, so the result
equals the numpy path's exactly.
"""

import numpy as np

from ..imaging._raster_kernels import edge_crossings, sort_rows
from ..jit import njit

#: View codes of :func:`boundary_kernel`.
VIEW_CODES = {"frontal": 0, "lateral_left": 1, "lateral_right": 2}


@njit
def _find(nxt, c):
    """First column >= c still without a boundary pixel (path-halving union-find)."""
    while nxt[c] != c:
        nxt[c] = nxt[nxt[c]]
        c = nxt[c]
    return c


@njit
def _isolated(runs, row_start, k, h):
    """Whether the one-pixel run ``k`` has no 8-neighbour among the runs of its row and the
    rows above and below."""
    r, c = runs[k, 0], runs[k, 1]
    for rr in range(max(r - 1, 0), min(r + 2, h)):
        for j in range(row_start[rr], row_start[rr + 1]):
            if j != k and runs[j, 1] < c + 2 and runs[j, 2] > c - 1:
                return False
    return True


def edge_face_table(topology):
    """The faces of every edge, padded: ``edge_face`` (E, D) of int64 (``F`` = no face) and
    ``edge_dir`` (E, D) (+1 / -1, the face's side along / against the edge; 0 for padding);
    ``D`` the largest number of faces of an edge (2 on a manifold mesh), at least 1.

    From ``topology.incidence`` (:class:`lilium.imaging.raster.EdgeTopology`), once per region.
    """
    incidence = topology.incidence
    E, F = incidence.shape
    degree = np.diff(incidence.indptr)
    D = max(1, int(degree.max()) if E else 1)
    edge_face = np.full((E, D), F, np.int64)
    edge_dir = np.zeros((E, D))
    rows = np.repeat(np.arange(E), degree)
    slot = np.arange(len(rows)) - np.repeat(incidence.indptr[:-1], degree)
    edge_face[rows, slot] = incidence.indices
    edge_dir[rows, slot] = incidence.data
    return edge_face, edge_dir


@njit
def _contour_edges(um, vm, corners, edge_face, edge_dir, sign, mult, touched):
    """One member's contour edges: the face signs ``sign`` (F + 1,) of the projected faces,
    then each edge's multiplicity ``mult[e]`` (the sum of ``sign[f] * dir`` over its faces) and
    the edges where it is not 0 in ``touched``; returns their count."""
    for f in range(corners.shape[1]):
        i0, i1, i2 = corners[0, f], corners[1, f], corners[2, f]
        du1, dv1 = um[i1] - um[i0], vm[i1] - vm[i0]
        du2, dv2 = um[i2] - um[i0], vm[i2] - vm[i0]
        area = du1 * dv2 - du2 * dv1
        sign[f] = 1.0 if area > 0.0 else (-1.0 if area < 0.0 else 0.0)
    E, D = edge_face.shape
    n_touched = 0
    for e in range(E):
        if D == 2:  # a manifold region: no inner loop
            w = sign[edge_face[e, 0]] * edge_dir[e, 0] + sign[edge_face[e, 1]] * edge_dir[e, 1]
        else:
            w = 0.0
            for k in range(D):
                w += sign[edge_face[e, k]] * edge_dir[e, k]
        if w != 0.0:
            mult[e] = w
            touched[n_touched] = e
            n_touched += 1
    return n_touched


@njit
def boundary_kernel(u, v, corners, edge_face, edge_dir, edges_a, edges_b, lo, hi, todo, view):
    """Skin-side boundary pixels of S projected regions.

    The contour edges of a member come edge by edge from the face signs (``mult[e]``, the sum
    of ``sign[f] * dir`` over the faces of edge ``e``): integers, so the same multiplicities as
    the face-by-face accumulation of the numpy path.

    Parameters
    ----------
    u, v : ndarray of shape (S, K)
        Projected region vertices (NaN behind the camera).
    corners : ndarray of shape (3, F)
    edge_face, edge_dir : ndarray of shape (E, D) of int64, float64
        :func:`edge_face_table` of the region's edge topology.
    edges_a, edges_b : ndarray of shape (E,)
        The edges' vertices (:class:`lilium.imaging.raster.EdgeTopology`).
    lo, hi : ndarray of shape (S, 2) of int64
        ``(u, v)`` of each member's window: first pixel and one past the last.
    todo : ndarray of shape (S,) of bool
        Members to detect (the others get no points).
    view : int
        :data:`VIEW_CODES`.

    Returns
    -------
    member : ndarray of shape (N,) of int64
    points : ndarray of shape (N, 2)
        ``uv`` of the boundary pixels, member after member, in curve order.
    """
    S = u.shape[0]
    F = corners.shape[1]
    E = edges_a.shape[0]
    sign = np.zeros(F + 1)  # sign[F] = 0: the padding face of edge_face
    mult = np.zeros(E)
    touched = np.empty(E, np.int64)
    buf = np.empty((1024, 3), np.int64)
    keys = np.empty(1024, np.int64)
    rows = np.empty(1024, np.int64)
    runs = np.empty((1024, 3), np.int64)
    out_member = np.empty(1024, np.int64)
    out = np.empty((1024, 2))
    # Per-member scratch, allocated once for the largest window.
    size = 0
    for m in range(S):
        if todo[m]:
            size = max(size, hi[m, 0] - lo[m, 0] + 1, hi[m, 1] - lo[m, 1] + 2)
    row_start = np.empty(size + 1, np.int64)
    lowest = np.empty(size, np.int64)
    nxt = np.empty(size + 1, np.int64)
    total = 0
    for m in range(S):
        if not todo[m]:
            continue
        um, vm = u[m], v[m]
        n_touched = _contour_edges(um, vm, corners, edge_face, edge_dir, sign, mult, touched)
        u0, v0 = lo[m, 0], lo[m, 1]
        w, h = hi[m, 0] - u0, hi[m, 1] - v0
        buf, n = edge_crossings(
            um, vm, touched, n_touched, mult, edges_a, edges_b,
            float(v0), float(hi[m, 1]), float(u0), float(hi[m, 0]), buf,
        )  # fmt: skip
        keys, rows = sort_rows(buf, n, keys, rows)
        # Covered runs (row, start, stop), sorted by row then start; no raster.
        n_runs = 0
        winding = 0
        for i in range(n - 1):
            winding += buf[i, 2]
            start, stop = buf[i, 1], buf[i + 1, 1]
            if winding != 0 and stop > start:
                if n_runs == runs.shape[0]:
                    grown_runs = np.empty((2 * n_runs, 3), np.int64)
                    grown_runs[:n_runs] = runs[:n_runs]
                    runs = grown_runs
                runs[n_runs, 0] = buf[i, 0] - v0
                runs[n_runs, 1] = start - u0
                runs[n_runs, 2] = stop - u0
                n_runs += 1
        row_start[: h + 2] = 0  # runs of window row r: row_start[r]..[r + 1]
        for k in range(n_runs):
            row_start[runs[k, 0] + 1] += 1
        for r in range(h + 1):
            row_start[r + 1] += row_start[r]
        need = total + (w if view == 0 else h)
        if need > out.shape[0]:
            size = max(need, 2 * out.shape[0])
            grown = np.empty((size, 2))
            grown[:total] = out[:total]
            out = grown
            grown_m = np.empty(size, np.int64)
            grown_m[:total] = out_member[:total]
            out_member = grown_m
        if view == 0:
            # Rows bottom-up; nxt[c] leads to the first column >= c without a boundary pixel.
            lowest[:w] = -1
            for c in range(w + 1):
                nxt[c] = c
            for r in range(h - 1, -1, -1):
                for k in range(row_start[r], row_start[r + 1]):
                    c = _find(nxt, runs[k, 1])
                    while c < runs[k, 2]:
                        if runs[k, 2] - runs[k, 1] == 1 and _isolated(runs, row_start, k, h):
                            break
                        lowest[c] = r
                        nxt[c] = c + 1
                        c = _find(nxt, c + 1)
            for c in range(w):
                if lowest[c] >= 0:
                    out[total, 0] = c + u0
                    out[total, 1] = lowest[c] + v0
                    out_member[total] = m
                    total += 1
        else:
            for r in range(h):
                lo_k, hi_k = row_start[r], row_start[r + 1]
                for j in range(hi_k - lo_k):
                    k = lo_k + j if view == 1 else hi_k - 1 - j
                    if runs[k, 2] - runs[k, 1] == 1 and _isolated(runs, row_start, k, h):
                        continue
                    c = runs[k, 1] if view == 1 else runs[k, 2] - 1
                    out[total, 0] = c + u0
                    out[total, 1] = r + v0
                    out_member[total] = m
                    total += 1
                    break
    return out_member[:total].copy(), out[:total].copy()


@njit
def windows_kernel(u, v, height, width, max_window):
    """:func:`lilium.fitness.curves._windows` (``height`` < 0: no image to clip to).

    Returns ``lo``, ``hi`` (S, 2) of int64, ``empty`` and ``clipped`` (S,) of bool.
    """
    S, K = u.shape
    lo = np.zeros((S, 2), np.int64)
    hi = np.ones((S, 2), np.int64)
    empty = np.ones(S, np.bool_)
    clipped = np.zeros(S, np.bool_)
    for m in range(S):
        u_lo, v_lo, u_hi, v_hi = np.inf, np.inf, -np.inf, -np.inf
        for k in range(K):
            x, y = u[m, k], v[m, k]
            if np.isfinite(x) and np.isfinite(y):
                empty[m] = False
                u_lo, u_hi = min(u_lo, x), max(u_hi, x)
                v_lo, v_hi = min(v_lo, y), max(v_hi, y)
        if empty[m]:
            continue
        box0, box1 = np.int64(np.floor(u_lo)), np.int64(np.floor(v_lo))
        box2, box3 = np.int64(np.ceil(u_hi) + 1), np.int64(np.ceil(v_hi) + 1)
        a0, a1, b0, b1 = box0, box1, box2, box3
        if height >= 0:
            a0, a1 = max(a0, -width), max(a1, -height)
            b0, b1 = min(b0, 2 * width), min(b1, 2 * height)
        b0, b1 = min(b0, a0 + max_window), min(b1, a1 + max_window)
        lo[m, 0], lo[m, 1], hi[m, 0], hi[m, 1] = a0, a1, b0, b1
        empty[m] = b0 <= a0 or b1 <= a1
        changed = a0 != box0 or a1 != box1 or b0 != box2 or b1 != box3
        clipped[m] = changed and not empty[m]
    return lo, hi, empty, clipped


@njit
def span_join_kernel(member, points, span_v, has_span, S):
    """:func:`lilium.fitness.curves._span_and_join` of the boundary pixels ``points`` (N, 2)
    (integer-valued) of members ``member`` (N,), sorted: the span filter (``span_v`` (S, 2),
    when ``has_span``), then :func:`~lilium.fitness.curves.join_fragments_batch`.

    Returns the joined points ``(N', 2)`` and their offsets ``(S + 1,)``.
    """
    N = points.shape[0]
    keep = np.ones(N, np.bool_)
    if has_span:
        for i in range(N):
            a, b = span_v[member[i], 0], span_v[member[i], 1]
            y = points[i, 1]
            keep[i] = y >= np.minimum(a, b) and y <= np.maximum(a, b)
    idx = np.flatnonzero(keep)
    p = points[idx]
    mem = member[idx]
    n = p.shape[0]
    offset = np.searchsorted(mem, np.arange(S + 1))
    if n == 0:
        return np.zeros((0, 2)), np.zeros_like(offset)
    # Steps between consecutive points: the last point of a member emits itself alone.
    is_last = np.zeros(n, np.bool_)
    for m in range(1, S):
        if 0 < offset[m] <= n - 1:
            is_last[offset[m] - 1] = True
    first = np.zeros(n, np.int64)  # output position of every input point
    total = 0
    for i in range(n - 1):
        first[i] = total
        if is_last[i]:
            total += 1
        else:
            total += np.int64(max(abs(p[i + 1, 0] - p[i, 0]), abs(p[i + 1, 1] - p[i, 1])))
    first[n - 1] = total
    out = np.empty((total + 1, 2))
    for i in range(n - 1):
        if is_last[i]:
            out[first[i], 0], out[first[i], 1] = np.rint(p[i, 0]), np.rint(p[i, 1])
            continue
        du, dv = p[i + 1, 0] - p[i, 0], p[i + 1, 1] - p[i, 1]
        steps = first[i + 1] - first[i]
        for k in range(steps):
            t = k / steps
            out[first[i] + k, 0] = np.rint(p[i, 0] + t * du)
            out[first[i] + k, 1] = np.rint(p[i, 1] + t * dv)
    out[total, 0], out[total, 1] = p[n - 1, 0], p[n - 1, 1]
    new_offset = np.empty(S + 1, np.int64)
    for m in range(S + 1):
        new_offset[m] = first[offset[m]] if offset[m] < n else total + 1
    return out, new_offset
