"""Compiled skull-curve detection of P_pll (:func:`lilium.fitness.curves.detect_curves_batch`);
numba, see :mod:`lilium.jit`.

Per member: the region's union raster in the member's own window (the contour-edge scan of
:mod:`lilium.imaging._raster_kernels`, the same crossings), isolated pixels dropped (no
8-neighbour), and the skin-side boundary: the lowest pixel of every column (frontal) or the
first (``lateral_left``) or last (``lateral_right``) pixel of every row. Integer pixels, so the
result equals the numpy path's exactly.
"""

import numpy as np

from ..imaging._raster_kernels import accumulate_face, edge_crossings, sort_rows
from ..jit import njit

#: View codes of :func:`boundary_kernel`.
VIEW_CODES = {"frontal": 0, "lateral_left": 1, "lateral_right": 2}


@njit
def boundary_kernel(u, v, corners, face_edges, face_dirs, edges_a, edges_b, lo, hi, todo, view):
    """Skin-side boundary pixels of S projected regions.

    Parameters
    ----------
    u, v : ndarray of shape (S, K)
        Projected region vertices (NaN behind the camera).
    corners : ndarray of shape (3, F)
    face_edges, face_dirs, edges_a, edges_b : the region's edge topology
        (:class:`lilium.imaging.raster.EdgeTopology`).
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
    mult = np.zeros(E)
    mark = np.full(E, -1, np.int64)
    touched = np.empty(E, np.int64)
    buf = np.empty((1024, 3), np.int64)
    keys = np.empty(1024, np.int64)
    rows = np.empty(1024, np.int64)
    cells = 0
    for m in range(S):
        if todo[m]:
            cells = max(cells, (hi[m, 0] - lo[m, 0]) * (hi[m, 1] - lo[m, 1]))
    grid = np.zeros(cells, np.uint8)
    out_member = np.empty(1024, np.int64)
    out = np.empty((1024, 2))
    total = 0
    for m in range(S):
        if not todo[m]:
            continue
        um, vm = u[m], v[m]
        n_touched = 0
        for f in range(F):
            i0, i1, i2 = corners[0, f], corners[1, f], corners[2, f]
            du1, dv1 = um[i1] - um[i0], vm[i1] - vm[i0]
            du2, dv2 = um[i2] - um[i0], vm[i2] - vm[i0]
            area = du1 * dv2 - du2 * dv1
            if area > 0.0:
                s = 1.0
            elif area < 0.0:
                s = -1.0
            else:
                continue
            n_touched = accumulate_face(
                f, s, face_edges, face_dirs, mult, mark, m, touched, n_touched
            )
        u0, v0 = lo[m, 0], lo[m, 1]
        w, h = hi[m, 0] - u0, hi[m, 1] - v0
        buf, n = edge_crossings(
            um, vm, touched, n_touched, mult, edges_a, edges_b,
            float(v0), float(hi[m, 1]), float(u0), float(hi[m, 0]), buf,
        )  # fmt: skip
        keys, rows = sort_rows(buf, n, keys, rows)
        g = grid[: w * h].reshape(h, w)
        g[:, :] = 0
        winding = 0
        for i in range(n - 1):
            winding += buf[i, 2]
            start, stop = buf[i, 1], buf[i + 1, 1]
            if winding != 0 and stop > start:
                r = buf[i, 0] - v0
                for c in range(start - u0, stop - u0):
                    g[r, c] = 1
        # Drop isolated pixels (no 8-neighbour): mark kept pixels with 2.
        for r in range(h):
            for c in range(w):
                if g[r, c] == 0:
                    continue
                found = False
                for dr in range(-1, 2):
                    rr = r + dr
                    if rr < 0 or rr >= h:
                        continue
                    for dc in range(-1, 2):
                        cc = c + dc
                        if (dr != 0 or dc != 0) and 0 <= cc < w and g[rr, cc] != 0:
                            found = True
                if found:
                    g[r, c] = 2
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
            for c in range(w):
                for r in range(h - 1, -1, -1):
                    if g[r, c] == 2:
                        out[total, 0] = c + u0
                        out[total, 1] = r + v0
                        out_member[total] = m
                        total += 1
                        break
        else:
            for r in range(h):
                for k in range(w):
                    c = k if view == 1 else w - 1 - k
                    if g[r, c] == 2:
                        out[total, 0] = c + u0
                        out[total, 1] = r + v0
                        out_member[total] = m
                        total += 1
                        break
    return out_member[:total].copy(), out[:total].copy()
