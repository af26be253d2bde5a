"""The readable P_pll of docs/method/lilium.md, one skull curve at a time: the tests' oracle.

Production has one implementation, batched over a population of cameras
(:func:`lilium.fitness.curves.detect_curves_batch`, :func:`lilium.fitness.pll.pll_terms_batch`);
a single camera is a batch of one. This module says the same thing plainly, a loop-free step per
function, so a test can check the batched code against it member by member (bit for bit: every
sum the terms depend on is a sequential ``cumsum`` here as there).

- detection: :func:`region_raster` (the region's union raster in its own window),
  :func:`drop_isolated`, :func:`boundary_pixels` (skin side), :func:`join_fragments`,
  :func:`orient_curve`, all in :func:`detect_curve`;
- terms: :func:`trim_curves` (end normals), :func:`pair_curves` (nearest points, lowest index
  on ties), :func:`convergence_penalty`, :func:`intersection_count`, :func:`pll_terms`, all in
  :func:`pll_penalty`.

Conventions (curve orientation, the meaning of each step) are those written in the docstrings
of :mod:`lilium.fitness.curves` and :mod:`lilium.fitness.pll`.
"""

import numpy as np

from lilium.fitness.curves import MAX_WINDOW_PX, check_view
from lilium.fitness.pll import (
    CONVERGENCE_RATIO,
    END_FRACTION,
    INTERSECTION_WEIGHT,
    PLL_NO_CURVE,
    PllTerms,
)
from lilium.imaging.raster import mesh_edge_topology, scan_crossings, winding_intervals

# --- detection -------------------------------------------------------------------------------


def join_fragments(points):
    """Join consecutive points ``(N, 2)`` by straight 8-connected pixel segments ``(M, 2)``."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(p) < 2:
        return p.copy()
    d = np.diff(p, axis=0)
    steps = np.maximum(np.abs(d[:, 0]), np.abs(d[:, 1])).astype(np.int64)  # 0: a duplicate
    total = int(steps.sum())
    seg = np.repeat(np.arange(len(d)), steps)
    k = np.arange(total) - np.repeat(np.cumsum(steps) - steps, steps)
    t = (k / np.repeat(steps, steps))[:, None]
    filled = np.rint(p[seg] + t * d[seg])
    return np.vstack([filled, p[-1:]])


def orient_curve(curve, view):
    """Reverse a curve so that it runs left to right (frontal) or top to bottom (lateral)."""
    curve = np.asarray(curve, dtype=float)
    if len(curve) < 2:
        return curve
    axis = 0 if check_view(view) == "frontal" else 1
    return curve[::-1] if curve[-1, axis] < curve[0, axis] else curve


def drop_isolated(grid):
    """Pixels of a raster ``(h, w)`` with at least one 8-neighbour."""
    g = grid.astype(np.uint8)
    pad = np.pad(g, 1)
    h, w = g.shape
    n = np.zeros((h, w), np.uint8)
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            if dr != 1 or dc != 1:
                n += pad[dr : dr + h, dc : dc + w]
    return grid & (n > 0)


def region_raster(uv, topology, image_shape=None):
    """The union raster ``(h, w)`` of a projected region ``(K, 2)`` and its origin ``(u0, v0)``.

    The window is the region's bounding box, clipped to the image grown by one image size on
    every side (when ``image_shape`` is given) and to :data:`MAX_WINDOW_PX` per side.
    """
    uv = np.asarray(uv, dtype=float)
    u, v = uv[:, 0], uv[:, 1]
    ok = np.isfinite(u) & np.isfinite(v)
    u, v = u[ok], v[ok]
    if len(u) == 0 or topology.n_faces == 0:
        return np.zeros((0, 0), bool), (0, 0)
    lo = np.array([np.floor(u.min()), np.floor(v.min())], dtype=np.int64)
    hi = np.array([np.ceil(u.max()), np.ceil(v.max())], dtype=np.int64) + 1
    if image_shape is not None:
        height, width = image_shape
        lo = np.maximum(lo, [-width, -height])
        hi = np.minimum(hi, [2 * width, 2 * height])
    hi = np.minimum(hi, lo + MAX_WINDOW_PX)
    if np.any(hi <= lo):
        return np.zeros((0, 0), bool), (0, 0)
    (u0, v0), (u1, v1) = lo, hi
    c = scan_crossings(uv[None], topology, (int(v0), int(v1)), (int(u0), int(u1)))
    _, row, start, stop = winding_intervals(c)
    grid = np.zeros((int(v1 - v0), int(u1 - u0)), bool)
    for r, a, b in zip(row - v0, start - u0, stop - u0, strict=True):
        grid[r, a:b] = True
    return grid, (int(u0), int(v0))


def boundary_pixels(grid, origin, view):
    """``uv`` ``(N, 2)`` of the skin-side pixel of every column (frontal) or row (lateral)."""
    check_view(view)
    u0, v0 = origin
    if grid.size == 0:
        return np.zeros((0, 2))
    h, w = grid.shape
    if view == "frontal":
        cols = np.flatnonzero(grid.any(axis=0))
        rows = h - 1 - np.argmax(grid[::-1, cols], axis=0)
    else:
        rows = np.flatnonzero(grid.any(axis=1))
        if view == "lateral_left":
            cols = np.argmax(grid[rows], axis=1)
        else:
            cols = w - 1 - np.argmax(grid[rows, ::-1], axis=1)
    return np.column_stack([cols + u0, rows + v0]).astype(float)


def detect_curve(uv, faces=None, view="frontal", *, span_v=None, topology=None, image_shape=None):
    """The skull curve ``(N, 2)`` of one projected region ``(K, 2)`` (docs/method/lilium.md
    detection)."""
    check_view(view)
    if topology is None:
        topology = mesh_edge_topology(faces)
    grid, origin = region_raster(uv, topology, image_shape)
    if grid.size:
        grid = drop_isolated(grid)
    points = boundary_pixels(grid, origin, view)
    if span_v is not None and len(points):
        lo, hi = sorted(span_v)
        points = points[(points[:, 1] >= lo) & (points[:, 1] <= hi)]
    return orient_curve(join_fragments(points), view)


# --- terms -----------------------------------------------------------------------------------


def end_tangents(curve):
    """Unit mean tangents of a curve ``(N, 2)`` at its start (pointing backwards) and end."""
    n = len(curve)
    k = min(n - 1, max(2, int(np.ceil(END_FRACTION * n))))
    du, dv = np.diff(curve[:, 0]), np.diff(curve[:, 1])
    length = np.maximum(np.hypot(du, dv), 1e-12)
    du, dv = du / length, dv / length
    head = -np.array([np.cumsum(du[:k])[-1] / k, np.cumsum(dv[:k])[-1] / k])
    tail = np.array([np.cumsum(du[-k:])[-1] / k, np.cumsum(dv[-k:])[-1] / k])
    return [t / n_ if (n_ := np.hypot(*t)) > 1e-12 else t for t in (head, tail)]


def trim_curves(skull_curve, face_curve):
    """Both curves cut where they pass the other curve's end normals (four cuts at once)."""
    curves = [np.asarray(skull_curve, dtype=float), np.asarray(face_curve, dtype=float)]
    if min(len(c) for c in curves) < 3:
        return curves[0].copy(), curves[1].copy()
    cut = [[0, 0], [0, 0]]  # cut[curve][end]: points removed at the start / end
    for i in (0, 1):
        this, other = curves[i], curves[1 - i]
        for end, tangent in enumerate(end_tangents(this)):
            anchor = this[0] if end == 0 else this[-1]
            offset = other - anchor
            beyond = offset[:, 0] * tangent[0] + offset[:, 1] * tangent[1] > 0
            if end == 1:
                beyond = beyond[::-1]
            cut[1 - i][end] = len(beyond) if beyond.all() else int(np.argmin(beyond))
    out = []
    for curve, (head, tail) in zip(curves, cut, strict=True):
        keep = curve if head + tail >= len(curve) else curve[head : len(curve) - tail]
        out.append(keep.copy())
    return out[0], out[1]


def nearest_index(queries, points):
    """Index of the nearest of ``points`` (M, 2) to each of ``queries`` (Q, 2); ties: lowest."""
    q = np.asarray(queries, dtype=float).reshape(-1, 2)
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    du = q[:, 0, None] - p[None, :, 0]
    dv = q[:, 1, None] - p[None, :, 1]
    return np.argmin(du * du + dv * dv, axis=1)


def pair_curves(skull_curve, face_curve):
    """Pairs in curve order: skull points ``(N, 2)``, face points ``(N, 2)``, distances ``(N,)``."""
    s = np.asarray(skull_curve, dtype=float)
    p = np.asarray(face_curve, dtype=float)
    nearest_p = nearest_index(s, p)
    chosen = np.zeros(len(p), bool)
    chosen[nearest_p] = True
    unpaired = np.flatnonzero(~chosen)
    si = np.concatenate([np.arange(len(s)), nearest_index(p[unpaired], s)])
    pi = np.concatenate([nearest_p, unpaired])
    order = np.lexsort((pi, si))
    sp, pp = s[si[order]], p[pi[order]]
    du, dv = sp[:, 0] - pp[:, 0], sp[:, 1] - pp[:, 1]
    return sp, pp, np.sqrt(du * du + dv * dv)


def convergence_penalty(d):
    """P_conv from the ordered pair distances ``d`` (N,)."""
    d = np.asarray(d, dtype=float)
    dbar = np.cumsum(d)[-1] / len(d)
    deltas = np.abs(d[[0, -1]] - dbar)
    converging = deltas > CONVERGENCE_RATIO * dbar
    if converging.all():
        return float(2.0 * deltas.sum())
    if converging.any():
        return float(4.0 * deltas[converging][0])
    return 0.0


def intersection_count(s, p, view):
    """Number of pairs ``(N, 2)``, ``(N, 2)`` with the skull on the wrong side of the face."""
    check_view(view)
    if view == "frontal":
        bad = s[:, 1] >= p[:, 1]
    elif view == "lateral_left":
        bad = s[:, 0] <= p[:, 0]
    else:
        bad = s[:, 0] >= p[:, 0]
    return int(np.count_nonzero(bad))


def pll_terms(s, p, d, view):
    """:class:`PllTerms` from paired points (no trimming, no pairing)."""
    d = np.asarray(d, dtype=float)
    if len(d) == 0:
        return PllTerms(np.nan, np.nan, np.nan, PLL_NO_CURVE, 0)
    delta_d = float(d.max() - d.min())
    p_conv = convergence_penalty(d)
    p_int = INTERSECTION_WEIGHT * intersection_count(s, p, view)
    return PllTerms(delta_d, p_conv, p_int, delta_d + p_conv + p_int, len(d))


def pll_penalty(skull_curve, face_curve, view, trim=True):
    """:class:`PllTerms` of a skull curve ``(K, 2)`` against a face curve ``(M, 2)``."""
    check_view(view)
    s = np.asarray(skull_curve, dtype=float).reshape(-1, 2)
    p = np.asarray(face_curve, dtype=float).reshape(-1, 2)
    if len(s) == 0 or len(p) == 0:
        return PllTerms(np.nan, np.nan, np.nan, PLL_NO_CURVE, 0)
    if trim:
        s, p = trim_curves(s, p)
    return pll_terms(*pair_curves(s, p), view)
