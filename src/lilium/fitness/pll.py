"""P_pll, the parallelism term of SPEC section 5: ``Delta_d + P_conv + P_int``.

Given the skull curve and the facial curve of one region (pixel polylines in ``uv``, ordered as
in :mod:`lilium.fitness.curves`):

1. Trimming (:func:`trim_curves`): at each end of each curve, the mean tangent of its terminal
   20 % (at least two points) defines the end's normal line (through the end point,
   perpendicular to that tangent); the other curve's points beyond that line, counted from its
   corresponding end until the first point on the near side, are cut off. All four cuts are
   computed on the untrimmed curves. A cut that would remove a whole curve is not applied.
2. Pairing (:func:`pair_curves`): every skull point to its nearest face point, then every face
   point that no skull point chose to its nearest skull point; equal distances (common on
   pixel curves) go to the lowest index (:func:`nearest_index`; a k-d tree would break them by
   its own layout: on 1440 cameras of ``benchmarks/bench_terms.py`` cases the cKDTree pairing
   changed 97 totals, i.e. the old result depended on the tree). The
   pairs are listed along the curves: sorted by the skull point's index, then by the face
   point's index, so the first and last pairs are the ends (an unpaired face stretch beyond a
   skull end comes out in face order, its outermost point first at the start and last at the
   end).
3. Terms (:func:`pll_terms`): ``Delta_d = max d - min d``; ``P_conv`` from the end deviations
   ``delta_e = |d_e - mean d|`` (an end converges when ``delta_e > 0.25 mean d``; both ends:
   ``2 (delta_1 + delta_N)``, one end: ``4 delta_e``, none: 0); ``P_int = 1000 *`` the number
   of pairs with the skull on the wrong side (frontal: ``s.v >= p.v``; lateral_left:
   ``s.u <= p.u``; lateral_right: ``s.u >= p.u``).

Populations: :meth:`PllContext.evaluate_batch` runs detection and the three steps for all
members at once (:func:`lilium.fitness.curves.detect_curves_batch`, :func:`pll_totals_batch`,
with a precomputed nearest-face-point table) and gives the same totals bit for bit: every sum
the terms depend on (end tangents, mean distance) is a sequential ``cumsum`` in both paths.
About 4-6x faster than the per-member loop (0.14-0.38 ms against 0.8-1.2 ms per member,
populations of 30, ``benchmarks/bench_terms.py``).

When a curve is empty (a region projected off the image, say) no pair exists:
:data:`PLL_NO_CURVE` is returned as the total.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import C_INF
from ..imaging.raster import mesh_edge_topology
from .curves import check_view, detect_curve, detect_curves_batch, refine_curve

#: Fraction of a curve's length whose mean tangent defines its end normal (SPEC: 20 %).
END_FRACTION = 0.2

#: An end converges when its deviation from the mean distance exceeds this fraction of it.
CONVERGENCE_RATIO = 0.25

#: Penalty per pair with the skull on the wrong side of the face (SPEC: 1000).
INTERSECTION_WEIGHT = 1000.0

#: P_pll when either curve is empty: as bad as an impossible camera.
PLL_NO_CURVE = C_INF

#: Query x point pairs per chunk of the brute-force nearest-point search.
NEAREST_CHUNK = 250_000

#: Margin (pixels) around the facial curve of the nearest-face-point table of PllContext.
NEAREST_TABLE_MARGIN_PX = 64


@dataclass(frozen=True)
class PllTerms:
    """The parts of P_pll (pixels for ``delta_d`` and ``p_conv``).

    ``n_pairs`` = 0 marks a failure (an empty curve): the parts are NaN and ``total`` is
    :data:`PLL_NO_CURVE`.
    """

    delta_d: float
    p_conv: float
    p_int: float
    total: float
    n_pairs: int = 0

    def __bool__(self):
        return self.n_pairs > 0


def _failed():
    return PllTerms(np.nan, np.nan, np.nan, PLL_NO_CURVE, 0)


def _end_tangents(curve):
    """Unit mean tangents at the start (pointing outwards, i.e. backwards) and at the end."""
    n = len(curve)
    k = min(n - 1, max(2, int(np.ceil(END_FRACTION * n))))
    du, dv = np.diff(curve[:, 0]), np.diff(curve[:, 1])
    length = np.maximum(np.hypot(du, dv), 1e-12)
    du, dv = du / length, dv / length
    # Sequential sums (cumsum), which the batched path reproduces bit for bit.
    head = -np.array([np.cumsum(du[:k])[-1] / k, np.cumsum(dv[:k])[-1] / k])
    tail = np.array([np.cumsum(du[-k:])[-1] / k, np.cumsum(dv[-k:])[-1] / k])
    return [t / n_ if (n_ := np.hypot(*t)) > 1e-12 else t for t in (head, tail)]


def _beyond_run(side):
    """Length of the leading run of True in a bool array."""
    if side.all():
        return len(side)
    return int(np.argmin(side))


def trim_curves(skull_curve, face_curve):
    """Trim both curves at their counterparts' end normals (see the module docstring).

    Parameters
    ----------
    skull_curve : array_like of shape (K, 2)
    face_curve : array_like of shape (M, 2)
        Both ordered in the same direction.

    Returns
    -------
    skull_curve, face_curve : ndarray
        Trimmed copies.
    """
    curves = [np.asarray(skull_curve, dtype=float), np.asarray(face_curve, dtype=float)]
    if min(len(c) for c in curves) < 3:
        return curves[0].copy(), curves[1].copy()
    cut = [[0, 0], [0, 0]]  # cut[curve][end]: points removed at the start / end
    for i in (0, 1):
        this, other = curves[i], curves[1 - i]
        for end, tangent in enumerate(_end_tangents(this)):
            anchor = this[0] if end == 0 else this[-1]
            beyond = (other[:, 0] - anchor[0]) * tangent[0] + (other[:, 1] - anchor[1]) * tangent[
                1
            ] > 0
            run = _beyond_run(beyond if end == 0 else beyond[::-1])
            cut[1 - i][end] = run
    out = []
    for curve, (head, tail) in zip(curves, cut, strict=True):
        if head + tail >= len(curve):
            out.append(curve.copy())
        else:
            out.append(curve[head : len(curve) - tail].copy())
    return out[0], out[1]


def pair_curves(skull_curve, face_curve):
    """Pairs of SPEC 5, in curve order (see the module docstring).

    Returns
    -------
    s, p : ndarray of shape (N, 2)
        Paired skull and face points.
    d : ndarray of shape (N,)
        Their distances (pixels).
    """
    s = np.asarray(skull_curve, dtype=float)
    p = np.asarray(face_curve, dtype=float)
    nearest_p = nearest_index(s, p)
    chosen = np.zeros(len(p), bool)
    chosen[nearest_p] = True
    unpaired = np.flatnonzero(~chosen)
    if len(unpaired):
        nearest_s = nearest_index(p[unpaired], s)
        si = np.concatenate([np.arange(len(s)), nearest_s])
        pi = np.concatenate([nearest_p, unpaired])
    else:
        si, pi = np.arange(len(s)), nearest_p
    order = np.lexsort((pi, si))
    si, pi = si[order], pi[order]
    sp, pp = s[si], p[pi]
    return sp, pp, _distance(sp, pp)


def _distance(a, b):
    du, dv = a[:, 0] - b[:, 0], a[:, 1] - b[:, 1]
    return np.sqrt(du * du + dv * dv)


def nearest_index(queries, points):
    """Index of the nearest of ``points`` (M, 2) to each of ``queries`` (Q, 2); ties: lowest.

    Brute force in chunks (curves hold hundreds of points): the tie rule makes the pairing
    well defined for pixel curves, where equal distances are common (a k-d tree breaks them
    by its own layout).
    """
    q = np.asarray(queries, dtype=float).reshape(-1, 2)
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    out = np.empty(len(q), np.int64)
    chunk = max(1, NEAREST_CHUNK // max(1, len(p)))
    for first in range(0, len(q), chunk):
        du = q[first : first + chunk, 0, None] - p[None, :, 0]
        dv = q[first : first + chunk, 1, None] - p[None, :, 1]
        out[first : first + chunk] = np.argmin(du * du + dv * dv, axis=1)
    return out


def convergence_penalty(d):
    """P_conv of SPEC 5 from the ordered pair distances ``d`` (N,)."""
    d = np.asarray(d, dtype=float)
    dbar = np.cumsum(d)[-1] / len(d)  # a sequential sum, as in the batched path
    deltas = np.abs(d[[0, -1]] - dbar)
    converging = deltas > CONVERGENCE_RATIO * dbar
    if converging.all():
        return float(2.0 * deltas.sum())
    if converging.any():
        return float(4.0 * deltas[converging][0])
    return 0.0


def intersection_count(s, p, view):
    """Number of pairs with the skull point on the wrong side of its face point."""
    check_view(view)
    s, p = np.asarray(s, dtype=float), np.asarray(p, dtype=float)
    if view == "frontal":
        bad = s[:, 1] >= p[:, 1]
    elif view == "lateral_left":
        bad = s[:, 0] <= p[:, 0]
    else:
        bad = s[:, 0] >= p[:, 0]
    return int(np.count_nonzero(bad))


def pll_terms(s, p, d, view):
    """``PllTerms`` from paired points (no trimming, no pairing)."""
    d = np.asarray(d, dtype=float)
    if len(d) == 0:
        return _failed()
    delta_d = float(d.max() - d.min())
    p_conv = convergence_penalty(d)
    p_int = INTERSECTION_WEIGHT * intersection_count(s, p, view)
    return PllTerms(delta_d, p_conv, p_int, delta_d + p_conv + p_int, len(d))


def pll_penalty(skull_curve, face_curve, view, trim=True):
    """P_pll of a skull curve against a face curve.

    Parameters
    ----------
    skull_curve : array_like of shape (K, 2)
        From :func:`lilium.fitness.curves.detect_curve`.
    face_curve : array_like of shape (M, 2)
        From :func:`lilium.fitness.curves.face_curve_from_mask` or
        :func:`lilium.fitness.curves.refine_curve`; same direction as the skull curve.
    view : {"frontal", "lateral_left", "lateral_right"}
    trim : bool
        Apply :func:`trim_curves` first (SPEC 5 does).

    Returns
    -------
    PllTerms

    Examples
    --------
    Two horizontal, parallel curves, the skull 5 px above the face (frontal):

    >>> u = np.arange(10.0)
    >>> skull = np.column_stack([u, np.full(10, 100.0)])
    >>> face = np.column_stack([u, np.full(10, 105.0)])
    >>> pll_penalty(skull, face, "frontal").total
    0.0
    """
    check_view(view)
    s = np.asarray(skull_curve, dtype=float).reshape(-1, 2)
    p = np.asarray(face_curve, dtype=float).reshape(-1, 2)
    if len(s) == 0 or len(p) == 0:
        return _failed()
    if trim:
        s, p = trim_curves(s, p)
    return pll_terms(*pair_curves(s, p), view)


@dataclass(frozen=True)
class FaceCurveIndex:
    """What the batched P_pll precomputes about the (fixed) facial curve.

    Attributes
    ----------
    curve : ndarray of shape (M, 2)
    ends : tuple or None
        ``(head_anchor, head_tangent, tail_anchor, tail_tangent)`` of :func:`trim_curves`
        (None when the curve has fewer than 3 points: no trimming).
    table : ndarray of shape (h, w) of int64
        ``table[row - v0, col - u0]``: index of the nearest curve point to pixel ``(col, row)``
        (lowest index on ties), over the curve's bounding box grown by
        :data:`NEAREST_TABLE_MARGIN_PX`.
    origin : (int, int)
        ``(u0, v0)``.
    """

    curve: np.ndarray
    ends: tuple | None
    table: np.ndarray
    origin: tuple


def face_curve_index(face_curve, margin_px=NEAREST_TABLE_MARGIN_PX):
    """Build the :class:`FaceCurveIndex` of a refined (integer-pixel) facial curve."""
    from scipy.spatial import cKDTree

    p = np.asarray(face_curve, dtype=float).reshape(-1, 2)
    ends = None
    if len(p) >= 3:
        head, tail = _end_tangents(p)
        ends = (p[0], head, p[-1], tail)
    lo = np.floor(p.min(axis=0)).astype(np.int64) - margin_px
    hi = np.ceil(p.max(axis=0)).astype(np.int64) + margin_px + 1
    cols, rows = np.arange(lo[0], hi[0]), np.arange(lo[1], hi[1])
    cells = np.column_stack([np.tile(cols, len(rows)), np.repeat(rows, len(cols))]).astype(float)
    k = min(8, len(p))
    _, cand = cKDTree(p).query(cells, k=k)
    cand = cand.reshape(len(cells), k)
    du = cells[:, 0, None] - p[cand, 0]
    dv = cells[:, 1, None] - p[cand, 1]
    d2 = du * du + dv * dv
    best = d2.min(axis=1, keepdims=True)
    nearest = np.where(d2 == best, cand, len(p)).min(axis=1)
    # More ties than the k candidates (or a k-d tree rounding slip): settle by brute force.
    unsure = np.flatnonzero(d2.max(axis=1) <= best[:, 0]) if k < len(p) else np.zeros(0, int)
    if len(unsure):
        nearest[unsure] = nearest_index(cells[unsure], p)
    table = nearest.reshape(len(rows), len(cols))
    return FaceCurveIndex(p, ends, table, (int(lo[0]), int(lo[1])))


def _leading_run(beyond, offset):
    """Per segment ``[offset[m], offset[m + 1])`` of a flat bool array: its leading True run."""
    n = np.diff(offset)
    falses = np.flatnonzero(~beyond)
    first = np.take(np.append(falses, len(beyond)), np.searchsorted(falses, offset[:-1]))
    return np.minimum(first - offset[:-1], n)


def _trailing_run(beyond, offset):
    n = np.diff(offset)
    falses = np.flatnonzero(~beyond)
    i = np.searchsorted(falses, offset[1:]) - 1
    last = np.where(i >= 0, np.take(falses, np.maximum(i, 0)) if len(falses) else -1, -1)
    return np.where(last >= offset[:-1], offset[1:] - 1 - last, n)


def _padded(values, offset, starts, lengths):
    """Rows ``values[offset[m] + starts[m] + j]`` for ``j < lengths[m]``, zero padded."""
    width = int(lengths.max()) if len(lengths) else 0
    j = np.arange(width)
    valid = j < lengths[:, None]
    idx = np.where(valid, (offset + starts)[:, None] + j, 0)
    return np.where(valid, np.take(values, idx), 0.0)


def _row_sums(values, offset, starts, lengths):
    """Sequential (cumsum) sums of segments, bit-identical to ``np.cumsum(segment)[-1]``."""
    rows = _padded(values, offset, starts, lengths)
    if rows.shape[1] == 0:
        return np.zeros(len(lengths))
    return np.cumsum(rows, axis=1)[:, -1]


def pll_totals_batch(curves, face_index, view):
    """P_pll totals of many skull curves against one facial curve (identical to the reference).

    Same steps and arithmetic as :func:`pll_penalty` (trimming, pairing with lowest-index
    ties, terms), run on all curves at once: skull-to-face pairing is a lookup in the face
    curve's nearest-point table (brute force where the table's answer was trimmed away or the
    point lies outside it), face-to-skull pairing a brute-force search over each member's
    curve.

    Parameters
    ----------
    curves : CurveBatch
        From :func:`lilium.fitness.curves.detect_curves_batch`.
    face_index : FaceCurveIndex
    view : str

    Returns
    -------
    total : ndarray of shape (S,)
    """
    check_view(view)
    P = curves.points
    offset = np.asarray(curves.offset, np.int64)
    S = len(offset) - 1
    n = np.diff(offset)
    face = face_index.curve
    M = len(face)
    total = np.full(S, PLL_NO_CURVE)
    if M == 0 or not n.any():
        return total
    member = np.repeat(np.arange(S), n)
    head_s, tail_s = np.zeros(S, np.int64), np.zeros(S, np.int64)
    face_lo, face_hi = np.zeros(S, np.int64), np.full(S, M, np.int64)
    trim = np.flatnonzero(n >= 3) if face_index.ends is not None else np.zeros(0, np.int64)
    if len(trim):
        # Skull end tangents (as _end_tangents): mean unit steps of the terminal 20 %.
        du, dv = np.diff(P[:, 0]), np.diff(P[:, 1])
        length = np.maximum(np.hypot(du, dv), 1e-12)
        du, dv = du / length, dv / length
        nt, ot = n[trim], offset[trim]
        k = np.minimum(nt - 1, np.maximum(2, np.ceil(END_FRACTION * nt).astype(np.int64)))
        zero = np.zeros(len(trim), np.int64)
        tangents = []
        for sign, starts in ((-1.0, zero), (1.0, nt - 1 - k)):
            tu = _row_sums(du, ot, starts, k) / k
            tv = _row_sums(dv, ot, starts, k) / k
            if sign < 0:
                tu, tv = -tu, -tv
            norm = np.hypot(tu, tv)
            big = norm > 1e-12
            tangents.append(
                (
                    np.where(big, tu / np.where(big, norm, 1), tu),
                    np.where(big, tv / np.where(big, norm, 1), tv),
                )
            )
        # The skull's ends cut the face curve.
        cut_face = []
        for end, anchor in ((0, P[ot]), (1, P[ot + nt - 1])):
            tu, tv = tangents[end]
            beyond = (face[None, :, 0] - anchor[:, 0, None]) * tu[:, None] + (
                face[None, :, 1] - anchor[:, 1, None]
            ) * tv[:, None] > 0
            if end == 1:
                beyond = beyond[:, ::-1]
            cut_face.append(np.where(beyond.all(axis=1), M, np.argmin(beyond, axis=1)))
        # The face's ends cut the skull curves.
        a_head, t_head, a_tail, t_tail = face_index.ends
        sub_offset = np.concatenate([[0], np.cumsum(nt)])
        idx = np.repeat(ot - sub_offset[:-1], nt) + np.arange(sub_offset[-1])
        Q = P[idx]
        beyond = (Q[:, 0] - a_head[0]) * t_head[0] + (Q[:, 1] - a_head[1]) * t_head[1] > 0
        hs = _leading_run(beyond, sub_offset)
        beyond = (Q[:, 0] - a_tail[0]) * t_tail[0] + (Q[:, 1] - a_tail[1]) * t_tail[1] > 0
        ts = _trailing_run(beyond, sub_offset)
        ok = hs + ts < nt
        head_s[trim], tail_s[trim] = np.where(ok, hs, 0), np.where(ok, ts, 0)
        hf, tf = cut_face
        ok = hf + tf < M
        face_lo[trim], face_hi[trim] = np.where(ok, hf, 0), np.where(ok, M - tf, M)
    # Trimmed skull curves.
    local = np.arange(len(P)) - np.repeat(offset[:-1], n)
    keep = (local >= head_s[member]) & (local < (n - tail_s)[member])
    sp, s_member, s_local = P[keep], member[keep], local[keep] - head_s[member[keep]]
    n_kept = n - head_s - tail_s
    # Skull -> face: table lookup, brute force where it cannot answer.
    u0, v0 = face_index.origin
    h, w = face_index.table.shape
    col = sp[:, 0].astype(np.int64) - u0
    row = sp[:, 1].astype(np.int64) - v0
    inside = (col >= 0) & (col < w) & (row >= 0) & (row < h)
    nearest_p = np.full(len(sp), -1, np.int64)
    nearest_p[inside] = face_index.table[row[inside], col[inside]]
    lo_m, hi_m = face_lo[s_member], face_hi[s_member]
    redo = np.flatnonzero((nearest_p < lo_m) | (nearest_p >= hi_m))
    if len(redo):
        j = np.arange(M)
        chunk = max(1, NEAREST_CHUNK // M)
        for first in range(0, len(redo), chunk):
            r = redo[first : first + chunk]
            du = sp[r, 0, None] - face[None, :, 0]
            dv = sp[r, 1, None] - face[None, :, 1]
            d2 = du * du + dv * dv
            d2[(j < lo_m[r, None]) | (j >= hi_m[r, None])] = np.inf
            nearest_p[r] = np.argmin(d2, axis=1)
    # Face -> skull for the face points no skull point chose.
    chosen = np.zeros((S, M), bool)
    chosen[s_member, nearest_p] = True
    j = np.arange(M)
    free = ~chosen & (j >= face_lo[:, None]) & (j < face_hi[:, None]) & (n_kept > 0)[:, None]
    f_member, f_index = np.nonzero(free)
    kept_offset = np.concatenate([[0], np.cumsum(n_kept)])
    nearest_s = np.zeros(len(f_member), np.int64)
    if len(f_member):
        width = int(n_kept.max())
        jj = np.arange(width)
        valid = jj < n_kept[:, None]
        idx = np.where(valid, kept_offset[:-1, None] + jj, 0)
        pad_u = np.where(valid, np.take(sp[:, 0], idx), np.inf)
        pad_v = np.where(valid, np.take(sp[:, 1], idx), np.inf)
        chunk = max(1, NEAREST_CHUNK // max(1, width))
        for first in range(0, len(f_member), chunk):
            m = f_member[first : first + chunk]
            q = face[f_index[first : first + chunk]]
            du = q[:, 0, None] - pad_u[m]
            dv = q[:, 1, None] - pad_v[m]
            nearest_s[first : first + chunk] = np.argmin(du * du + dv * dv, axis=1)
    # Pairs in curve order: by member, skull index, face index.
    pm = np.concatenate([s_member, f_member])
    si = np.concatenate([s_local, nearest_s])
    pi = np.concatenate([nearest_p, f_index])
    K = int(n_kept.max()) + 1
    order = np.argsort((pm * K + si) * M + pi)
    pm, si, pi = pm[order], si[order], pi[order]
    s_xy = sp[kept_offset[pm] + si]
    p_xy = face[pi]
    d = _distance(s_xy, p_xy)
    count = np.bincount(pm, minlength=S)
    has = np.flatnonzero(count)
    start = np.concatenate([[0], np.cumsum(count)])[has]
    c = count[has]
    delta_d = np.maximum.reduceat(d, start) - np.minimum.reduceat(d, start)
    dbar = _row_sums(d, start, np.zeros(len(has), np.int64), c) / c
    first, last = d[start], d[start + c - 1]
    d1, dn = np.abs(first - dbar), np.abs(last - dbar)
    c1, cn = d1 > CONVERGENCE_RATIO * dbar, dn > CONVERGENCE_RATIO * dbar
    p_conv = np.where(c1 & cn, 2.0 * (d1 + dn), np.where(c1, 4.0 * d1, np.where(cn, 4.0 * dn, 0.0)))
    if view == "frontal":
        bad = s_xy[:, 1] >= p_xy[:, 1]
    elif view == "lateral_left":
        bad = s_xy[:, 0] <= p_xy[:, 0]
    else:
        bad = s_xy[:, 0] >= p_xy[:, 0]
    p_int = INTERSECTION_WEIGHT * np.add.reduceat(bad.astype(np.int64), start)
    total[has] = delta_d + p_conv + p_int
    return total


@dataclass(frozen=True)
class PllContext:
    """What P_pll needs that is fixed during one SFO: the region and the facial curve.

    Attributes
    ----------
    faces : ndarray of shape (G, 3)
        The region's faces, indexing the region's own vertices.
    topology : EdgeTopology
    face_curve : ndarray of shape (M, 2)
    view : str
    image_shape : (int, int) or None
    """

    faces: np.ndarray
    topology: object
    face_curve: np.ndarray
    view: str
    image_shape: tuple | None = None
    face_index: FaceCurveIndex | None = None

    @classmethod
    def build(cls, region_faces, face_curve, view, image_shape=None, ordered=True):
        """From a region's faces and a facial curve (refined here)."""
        check_view(view)
        curve = refine_curve(face_curve, view, ordered=ordered)
        return cls(
            np.asarray(region_faces),
            mesh_edge_topology(region_faces),
            curve,
            view,
            None if image_shape is None else tuple(image_shape),
            face_curve_index(curve),
        )

    def skull_curve(self, region_uv, span_v=None):
        return detect_curve(
            region_uv,
            view=self.view,
            span_v=span_v,
            topology=self.topology,
            image_shape=self.image_shape,
        )

    def evaluate(self, region_uv, span_v=None):
        """P_pll of one projection of the region.

        Parameters
        ----------
        region_uv : array_like of shape (K, 2)
            The region's projected vertices.
        span_v : (float, float), optional
            Forehead only: the v of the projected cranial glabella and metopion.

        Returns
        -------
        PllTerms
        """
        return pll_penalty(self.skull_curve(region_uv, span_v), self.face_curve, self.view)

    def evaluate_batch(self, region_uv, span_v=None):
        """Totals for a population: ``region_uv`` (S, K, 2), ``span_v`` (S, 2) or None.

        All members at once (:func:`lilium.fitness.curves.detect_curves_batch` and
        :func:`pll_totals_batch`); the totals equal those of :meth:`evaluate` member by member
        (checked by the tests on random cameras).
        """
        region_uv = np.asarray(region_uv, dtype=float)
        if region_uv.ndim != 3 or region_uv.shape[-1] != 2:
            raise ValueError(f"region_uv must have shape (S, K, 2), got {region_uv.shape}")
        if len(self.face_curve) == 0:
            return np.full(len(region_uv), PLL_NO_CURVE)
        curves = detect_curves_batch(
            region_uv,
            self.view,
            span_v=span_v,
            topology=self.topology,
            image_shape=self.image_shape,
        )
        index = (
            self.face_index if self.face_index is not None else face_curve_index(self.face_curve)
        )
        return pll_totals_batch(curves, index, self.view)
