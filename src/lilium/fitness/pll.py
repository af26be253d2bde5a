"""P_pll, the parallelism term of docs/method/lilium.md: ``Delta_d + P_conv + P_int``.

One implementation, over a population: the skull curves of ``S`` cameras
(:class:`lilium.fitness.curves.CurveBatch`, pixel polylines in ``uv`` ordered as in
:mod:`lilium.fitness.curves`) against the one facial curve of the photo, whose end normals and
nearest-point table are computed once (:class:`FaceCurveIndex`). A single camera is a batch of
one (:func:`pll_penalty`; :class:`lilium.fitness.pll_context.PllContext` holds what one SFO
fixes). ``tests/pll_oracle.py`` spells the same steps out for one pair of curves; the tests
check this module against it bit for bit.

1. Trimming (:func:`trim_curves_batch`): at each end of each curve, the mean tangent of its
   terminal 20 % (at least two points) defines the end's normal line (through the end point,
   perpendicular to that tangent); the other curve's points beyond that line, counted from its
   corresponding end until the first point on the near side, are cut off. All four cuts are
   computed on the untrimmed curves. A cut that would remove a whole curve is not applied.
   Curves of fewer than 3 points are not trimmed.
2. Pairing (:func:`pair_curves_batch`): every skull point to its nearest face point, then every
   face point that no skull point chose to its nearest skull point; equal distances (common on
   pixel curves) go to the lowest index (a k-d tree would break them by its own layout: on 1440
   cameras of ``benchmarks/bench_terms.py`` cases the cKDTree pairing changed 97 totals). The
   pairs are listed along the curves: sorted by the skull point's index, then by the face
   point's index, so the first and last pairs are the ends (an unpaired face stretch beyond a
   skull end comes out in face order, its outermost point first at the start and last at the
   end).
3. Terms (:func:`terms_from_pairs`): ``Delta_d = max d - min d``; ``P_conv`` from the end
   deviations ``delta_e = |d_e - mean d|`` (an end converges when ``delta_e > 0.25 mean d``;
   both ends: ``2 (delta_1 + delta_N)``, one end: ``4 delta_e``, none: 0;
   :func:`convergence_penalties`); ``P_int = 1000 *`` the number of pairs with the skull on the
   wrong side (frontal: ``s.v >= p.v``; lateral_left: ``s.u <= p.u``; lateral_right:
   ``s.u >= p.u``; :func:`wrong_side`).

Every sum the terms depend on (end tangents, mean distance) is a sequential ``cumsum``, so a
member's result does not depend on the population it is evaluated in. Skull-to-face pairing is
a lookup in the face curve's nearest-point table (brute force where the table's answer was
trimmed away or the point lies off the table or off the pixel grid); face-to-skull pairing a
brute-force search over each member's curve (0.06-0.3 ms per member in populations of 30,
``benchmarks/bench_terms.py``; 2-6x faster than the oracle's per-member loop). The three steps
are compiled (:mod:`lilium.fitness._pll_kernels`, one loop over the members, the same numbers);
the numpy code here is their reference and the fallback (:mod:`lilium.jit`).

When a curve is empty (a region projected off the image, say) no pair exists:
:data:`PLL_NO_CURVE` is the total and the parts are NaN.
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..constants import C_INF
from ._pll_kernels import (
    SIDE_CODES,
    nearest_table_kernel,
    pair_kernel,
    terms_kernel,
    trim_kernel,
)
from .curves import CurveBatch, check_view

#: Fraction of a curve's length whose mean tangent defines its end normal (docs/method/lilium.md: 20
#: %).
END_FRACTION = 0.2

#: An end converges when its deviation from the mean distance exceeds this fraction of it.
CONVERGENCE_RATIO = 0.25

#: Penalty per pair with the skull on the wrong side of the face (docs/method/lilium.md: 1000).
INTERSECTION_WEIGHT = 1000.0

#: P_pll when either curve is empty: as bad as an impossible camera.
PLL_NO_CURVE = C_INF

#: Query x point pairs per chunk of the brute-force nearest-point searches.
NEAREST_CHUNK = 250_000

#: Margin (pixels) around the facial curve of the nearest-face-point table of
#: :class:`~lilium.fitness.pll_context.PllContext`.
NEAREST_TABLE_MARGIN_PX = 64


@dataclass(frozen=True)
class PllTerms:
    """The parts of P_pll (pixels for ``delta_d`` and ``p_conv``), of one camera or of ``S``.

    Fields are scalars for one camera (:func:`pll_penalty`, ``PllContext.evaluate``) and
    ndarrays of shape (S,) for a population (:func:`pll_terms_batch`; :meth:`member` picks one).
    ``n_pairs`` = 0 marks a failure (an empty curve): the parts are NaN and ``total`` is
    :data:`PLL_NO_CURVE`.
    """

    delta_d: float
    p_conv: float
    p_int: float
    total: float
    n_pairs: int = 0

    def __bool__(self):
        return bool(np.all(np.asarray(self.n_pairs) > 0))

    def member(self, m):
        """The scalar :class:`PllTerms` of member ``m`` of a population's terms."""
        parts = (self.delta_d, self.p_conv, self.p_int, self.total)
        return PllTerms(*(float(x[m]) for x in parts), int(self.n_pairs[m]))


def _failed(S):
    nan = np.full(S, np.nan)
    return PllTerms(nan, nan.copy(), nan.copy(), np.full(S, PLL_NO_CURVE), np.zeros(S, np.int64))


# --- segment helpers (curves concatenated, member m at offset[m]) -----------------------------


def _leading_run(beyond, offset):
    """Per segment ``[offset[m], offset[m + 1])`` of a flat bool array: its leading True run."""
    n = np.diff(offset)
    falses = np.flatnonzero(~beyond)
    first = np.take(np.append(falses, len(beyond)), np.searchsorted(falses, offset[:-1]))
    return np.minimum(first - offset[:-1], n)


def _trailing_run(beyond, offset):
    """Per segment of a flat bool array: its trailing True run."""
    n = np.diff(offset)
    falses = np.flatnonzero(~beyond)
    i = np.searchsorted(falses, offset[1:]) - 1
    last = np.where(i >= 0, np.take(falses, np.maximum(i, 0)) if len(falses) else -1, -1)
    return np.where(last >= offset[:-1], offset[1:] - 1 - last, n)


def _padded(values, offset, starts, lengths, fill=0.0):
    """Rows ``values[offset[m] + starts[m] + j]`` for ``j < lengths[m]``, padded with ``fill``."""
    width = int(lengths.max()) if len(lengths) else 0
    j = np.arange(width)
    valid = j < lengths[:, None]
    idx = np.where(valid, (offset + starts)[:, None] + j, 0)
    return np.where(valid, np.take(values, idx), fill)


def _row_sums(values, offset, starts, lengths):
    """Sequential (cumsum) sums of segments, bit-identical to ``np.cumsum(segment)[-1]``."""
    rows = _padded(values, offset, starts, lengths)
    if rows.shape[1] == 0:
        return np.zeros(len(lengths))
    return np.cumsum(rows, axis=1)[:, -1]


def _distance(a, b):
    du, dv = a[:, 0] - b[:, 0], a[:, 1] - b[:, 1]
    return np.sqrt(du * du + dv * dv)


def _nearest_index(queries, points):
    """Index of the nearest of ``points`` (M, 2) to each of ``queries`` (Q, 2); ties: lowest."""
    out = np.empty(len(queries), np.int64)
    chunk = max(1, NEAREST_CHUNK // max(1, len(points)))
    for first in range(0, len(queries), chunk):
        du = queries[first : first + chunk, 0, None] - points[None, :, 0]
        dv = queries[first : first + chunk, 1, None] - points[None, :, 1]
        out[first : first + chunk] = np.argmin(du * du + dv * dv, axis=1)
    return out


# --- the facial curve, indexed once ----------------------------------------------------------


def end_tangents(points, offset, n):
    """Unit mean tangents at both ends of curves of at least 2 points.

    Parameters
    ----------
    points : ndarray of shape (N, 2)
        Concatenated curves.
    offset, n : ndarray of shape (T,) of int64
        First point and number of points of each curve.

    Returns
    -------
    head, tail : ndarray of shape (T, 2)
        Mean of the unit steps of the first / last ``k = min(n - 1, max(2, ceil(0.2 n)))``
        steps, normalised; ``head`` points outwards (backwards along the curve).
    """
    du, dv = np.diff(points[:, 0]), np.diff(points[:, 1])
    length = np.maximum(np.hypot(du, dv), 1e-12)
    du, dv = du / length, dv / length
    k = np.minimum(n - 1, np.maximum(2, np.ceil(END_FRACTION * n).astype(np.int64)))
    out = []
    for sign, starts in ((-1.0, np.zeros(len(n), np.int64)), (1.0, n - 1 - k)):
        tu = _row_sums(du, offset, starts, k) / k
        tv = _row_sums(dv, offset, starts, k) / k
        if sign < 0:
            tu, tv = -tu, -tv
        norm = np.hypot(tu, tv)
        big = norm > 1e-12
        scale = np.where(big, norm, 1)
        out.append(np.column_stack([np.where(big, tu / scale, tu), np.where(big, tv / scale, tv)]))
    return out[0], out[1]


@dataclass(frozen=True)
class FaceCurveIndex:
    """What P_pll precomputes about the (fixed) facial curve.

    Attributes
    ----------
    curve : ndarray of shape (M, 2)
    ends : tuple or None
        ``(head_anchor, head_tangent, tail_anchor, tail_tangent)``, each of shape (2,), of the
        trimming step (None when the curve has fewer than 3 points: no trimming).
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
    """Build the :class:`FaceCurveIndex` of a facial curve ``(M, 2)`` (refined: integer pixels).

    The table: compiled, a bucket search (:func:`~lilium.fitness._pll_kernels.nearest_table_kernel`,
    no k-d tree to import: scipy.spatial took about 0.1 s of a command's start); numpy path, a
    k-d tree's candidates settled by brute force where they tie. The same table.
    """
    p = np.asarray(face_curve, dtype=float).reshape(-1, 2)
    if len(p) == 0:
        return FaceCurveIndex(p, None, np.zeros((0, 0), np.int64), (0, 0))
    ends = None
    if len(p) >= 3:
        head, tail = end_tangents(p, np.array([0]), np.array([len(p)]))
        ends = (p[0], head[0], p[-1], tail[0])
    lo = np.floor(p.min(axis=0)).astype(np.int64) - margin_px
    hi = np.ceil(p.max(axis=0)).astype(np.int64) + margin_px + 1
    if jit.compiled():
        table = nearest_table_kernel(
            np.ascontiguousarray(p), int(lo[0]), int(lo[1]), int(hi[1] - lo[1]), int(hi[0] - lo[0])
        )
        return FaceCurveIndex(p, ends, table, (int(lo[0]), int(lo[1])))
    from scipy.spatial import cKDTree

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
        nearest[unsure] = _nearest_index(cells[unsure], p)
    table = nearest.reshape(len(rows), len(cols))
    return FaceCurveIndex(p, ends, table, (int(lo[0]), int(lo[1])))


# --- the three steps -------------------------------------------------------------------------


def trim_curves_batch(curves, face_index):
    """Trim every skull curve and the facial curve at each other's end normals (step 1).

    Parameters
    ----------
    curves : CurveBatch
        ``S`` skull curves.
    face_index : FaceCurveIndex

    Returns
    -------
    skull : CurveBatch
        The trimmed skull curves.
    face_lo, face_hi : ndarray of shape (S,) of int64
        Member ``m``'s trimmed facial curve is ``face_index.curve[face_lo[m] : face_hi[m]]``.
    """
    P = np.ascontiguousarray(curves.points, dtype=float)
    offset = np.ascontiguousarray(curves.offset, np.int64)
    face = np.ascontiguousarray(face_index.curve, dtype=float)
    if jit.compiled():
        ends = np.zeros((4, 2)) if face_index.ends is None else np.array(face_index.ends, float)
        points, kept, lo, hi = trim_kernel(P, offset, face, ends, face_index.ends is not None)
        return CurveBatch(points, kept), lo, hi
    S = len(offset) - 1
    n = np.diff(offset)
    M = len(face)
    head_s, tail_s = np.zeros(S, np.int64), np.zeros(S, np.int64)
    face_lo, face_hi = np.zeros(S, np.int64), np.full(S, M, np.int64)
    trim = np.flatnonzero(n >= 3) if face_index.ends is not None else np.zeros(0, np.int64)
    if len(trim):
        nt, ot = n[trim], offset[trim]
        # The skull's ends cut the face curve.
        cut_face = []
        for anchor, tangent in zip((P[ot], P[ot + nt - 1]), end_tangents(P, ot, nt), strict=True):
            beyond = (face[None, :, 0] - anchor[:, 0, None]) * tangent[:, 0, None] + (
                face[None, :, 1] - anchor[:, 1, None]
            ) * tangent[:, 1, None] > 0
            if len(cut_face) == 1:
                beyond = beyond[:, ::-1]
            cut_face.append(np.where(beyond.all(axis=1), M, np.argmin(beyond, axis=1)))
        # The face's ends cut the skull curves.
        a_head, t_head, a_tail, t_tail = face_index.ends
        sub_offset = np.concatenate([[0], np.cumsum(nt)])
        Q = P[np.repeat(ot - sub_offset[:-1], nt) + np.arange(sub_offset[-1])]
        beyond = (Q[:, 0] - a_head[0]) * t_head[0] + (Q[:, 1] - a_head[1]) * t_head[1] > 0
        hs = _leading_run(beyond, sub_offset)
        beyond = (Q[:, 0] - a_tail[0]) * t_tail[0] + (Q[:, 1] - a_tail[1]) * t_tail[1] > 0
        ts = _trailing_run(beyond, sub_offset)
        ok = hs + ts < nt
        head_s[trim], tail_s[trim] = np.where(ok, hs, 0), np.where(ok, ts, 0)
        hf, tf = cut_face
        ok = hf + tf < M
        face_lo[trim], face_hi[trim] = np.where(ok, hf, 0), np.where(ok, M - tf, M)
    member = np.repeat(np.arange(S), n)
    local = np.arange(len(P)) - np.repeat(offset[:-1], n)
    keep = (local >= head_s[member]) & (local < (n - tail_s)[member])
    kept = np.concatenate([[0], np.cumsum(n - head_s - tail_s)]).astype(np.int64)
    return CurveBatch(P[keep], kept), face_lo, face_hi


@dataclass(frozen=True)
class PairBatch:
    """The pairs of every member, concatenated, each member's in curve order.

    Attributes
    ----------
    skull, face : ndarray of shape (N, 2)
        Paired skull and face points.
    distance : ndarray of shape (N,)
        Their distances (pixels).
    offset : ndarray of shape (S + 1,) of int64
        Member ``m``'s pairs are ``[offset[m], offset[m + 1])``.
    """

    skull: np.ndarray
    face: np.ndarray
    distance: np.ndarray
    offset: np.ndarray


def pair_curves_batch(skull, face_index, face_lo=None, face_hi=None):
    """Pair every skull curve with (its stretch of) the facial curve (step 2).

    Parameters
    ----------
    skull : CurveBatch
        ``S`` skull curves (trimmed).
    face_index : FaceCurveIndex
    face_lo, face_hi : ndarray of shape (S,), optional
        Member ``m`` pairs with ``face_index.curve[face_lo[m] : face_hi[m]]``; default: all.

    Returns
    -------
    PairBatch
    """
    P = np.ascontiguousarray(skull.points, dtype=float)
    offset = np.ascontiguousarray(skull.offset, np.int64)
    S = len(offset) - 1
    n = np.diff(offset)
    face = np.ascontiguousarray(face_index.curve, dtype=float)
    M = len(face)
    face_lo = np.zeros(S, np.int64) if face_lo is None else np.asarray(face_lo, np.int64)
    face_hi = np.full(S, M, np.int64) if face_hi is None else np.asarray(face_hi, np.int64)
    if jit.compiled():
        u0, v0 = face_index.origin
        table = np.ascontiguousarray(face_index.table, np.int64)
        lo, hi = np.ascontiguousarray(face_lo), np.ascontiguousarray(face_hi)
        return PairBatch(*pair_kernel(P, offset, face, lo, hi, table, int(u0), int(v0)))
    if M == 0 or not n.any():
        return PairBatch(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(S + 1, np.int64))
    member = np.repeat(np.arange(S), n)
    local = np.arange(len(P)) - np.repeat(offset[:-1], n)
    # Skull -> face: table lookup, brute force where it cannot answer.
    u0, v0 = face_index.origin
    h, w = face_index.table.shape
    col = P[:, 0].astype(np.int64)
    row = P[:, 1].astype(np.int64)
    on_grid = (col == P[:, 0]) & (row == P[:, 1])
    col, row = col - u0, row - v0
    inside = on_grid & (col >= 0) & (col < w) & (row >= 0) & (row < h)
    nearest_p = np.full(len(P), -1, np.int64)
    nearest_p[inside] = face_index.table[row[inside], col[inside]]
    lo_m, hi_m = face_lo[member], face_hi[member]
    redo = np.flatnonzero((nearest_p < lo_m) | (nearest_p >= hi_m))
    j = np.arange(M)
    chunk = max(1, NEAREST_CHUNK // M)
    for first in range(0, len(redo), chunk):
        r = redo[first : first + chunk]
        du = P[r, 0, None] - face[None, :, 0]
        dv = P[r, 1, None] - face[None, :, 1]
        d2 = du * du + dv * dv
        d2[(j < lo_m[r, None]) | (j >= hi_m[r, None])] = np.inf
        nearest_p[r] = np.argmin(d2, axis=1)
    # Face -> skull for the face points no skull point chose.
    chosen = np.zeros((S, M), bool)
    chosen[member, nearest_p] = True
    free = ~chosen & (j >= face_lo[:, None]) & (j < face_hi[:, None]) & (n > 0)[:, None]
    f_member, f_index = np.nonzero(free)
    nearest_s = np.zeros(len(f_member), np.int64)
    if len(f_member):
        zero = np.zeros(S, np.int64)
        pad_u = _padded(P[:, 0], offset[:-1], zero, n, fill=np.inf)
        pad_v = _padded(P[:, 1], offset[:-1], zero, n, fill=np.inf)
        chunk = max(1, NEAREST_CHUNK // max(1, pad_u.shape[1]))
        for first in range(0, len(f_member), chunk):
            m = f_member[first : first + chunk]
            q = face[f_index[first : first + chunk]]
            du = q[:, 0, None] - pad_u[m]
            dv = q[:, 1, None] - pad_v[m]
            nearest_s[first : first + chunk] = np.argmin(du * du + dv * dv, axis=1)
    # Pairs in curve order: by member, skull index, face index (the keys are unique).
    pm = np.concatenate([member, f_member])
    si = np.concatenate([local, nearest_s])
    pi = np.concatenate([nearest_p, f_index])
    K = int(n.max()) + 1
    order = np.argsort((pm * K + si) * M + pi)
    pm, si, pi = pm[order], si[order], pi[order]
    s_xy = P[offset[pm] + si]
    p_xy = face[pi]
    pair_offset = np.concatenate([[0], np.cumsum(np.bincount(pm, minlength=S))])
    return PairBatch(s_xy, p_xy, _distance(s_xy, p_xy), pair_offset.astype(np.int64))


def convergence_penalties(distance, offset):
    """P_conv of every member from its ordered pair distances.

    Parameters
    ----------
    distance : array_like of shape (N,)
        Pair distances, member after member, each in curve order.
    offset : array_like of shape (S + 1,)
        Member ``m``'s distances are ``distance[offset[m] : offset[m + 1]]``.

    Returns
    -------
    p_conv : ndarray of shape (S,)
        NaN for a member without pairs.

    Examples
    --------
    Three members: parallel; none; one converging end (mean 7, ``4 |2 - 7|``):

    >>> d = [5.0, 5, 5, 2, 8, 8, 8, 8, 8, 8, 6]
    >>> convergence_penalties(d, [0, 3, 3, 11]).tolist()
    [0.0, nan, 20.0]
    """
    d = np.asarray(distance, dtype=float)
    offset = np.asarray(offset, np.int64)
    count = np.diff(offset)
    has = np.flatnonzero(count)
    start, c = offset[:-1][has], count[has]
    dbar = _row_sums(d, start, np.zeros(len(has), np.int64), c) / c
    d1, dn = np.abs(d[start] - dbar), np.abs(d[start + c - 1] - dbar)
    c1, cn = d1 > CONVERGENCE_RATIO * dbar, dn > CONVERGENCE_RATIO * dbar
    out = np.full(len(count), np.nan)
    out[has] = np.where(
        c1 & cn, 2.0 * (d1 + dn), np.where(c1, 4.0 * d1, np.where(cn, 4.0 * dn, 0.0))
    )
    return out


def wrong_side(skull, face, view):
    """Whether each skull point ``(N, 2)`` lies on the wrong side of its face point ``(N, 2)``."""
    check_view(view)
    if view == "frontal":
        return skull[:, 1] >= face[:, 1]
    if view == "lateral_left":
        return skull[:, 0] <= face[:, 0]
    return skull[:, 0] >= face[:, 0]


def terms_from_pairs(pairs, view):
    """:class:`PllTerms` of every member, fields of shape (S,), from its pairs (step 3)."""
    offset = np.ascontiguousarray(pairs.offset, np.int64)
    if jit.compiled():
        skull, face = (np.ascontiguousarray(x, dtype=float) for x in (pairs.skull, pairs.face))
        distance = np.ascontiguousarray(pairs.distance, dtype=float)
        side = SIDE_CODES[check_view(view)]
        return PllTerms(*terms_kernel(skull, face, distance, offset, side, PLL_NO_CURVE))
    S = len(offset) - 1
    terms = _failed(S)
    count = np.diff(offset)
    has = np.flatnonzero(count)
    if len(has) == 0:
        return terms
    d, start = pairs.distance, offset[:-1][has]
    delta_d = np.maximum.reduceat(d, start) - np.minimum.reduceat(d, start)
    p_conv = convergence_penalties(d, offset)[has]
    bad = wrong_side(pairs.skull, pairs.face, view).astype(np.int64)
    p_int = INTERSECTION_WEIGHT * np.add.reduceat(bad, start)
    terms.delta_d[has], terms.p_conv[has], terms.p_int[has] = delta_d, p_conv, p_int
    terms.total[has] = delta_d + p_conv + p_int
    terms.n_pairs[:] = count
    return terms


def pll_terms_batch(curves, face_index, view, trim=True):
    """P_pll of many skull curves against one facial curve: trim, pair, terms.

    Parameters
    ----------
    curves : CurveBatch
        ``S`` skull curves, from :func:`lilium.fitness.curves.detect_curves_batch`.
    face_index : FaceCurveIndex
    view : {"frontal", "lateral_left", "lateral_right"}
    trim : bool
        Trim first (step 1; docs/method/lilium.md does).

    Returns
    -------
    PllTerms
        Fields of shape (S,).
    """
    check_view(view)
    if trim:
        skull, face_lo, face_hi = trim_curves_batch(curves, face_index)
    else:
        skull, face_lo, face_hi = curves, None, None
    return terms_from_pairs(pair_curves_batch(skull, face_index, face_lo, face_hi), view)


def pll_penalty(skull_curve, face_curve, view, trim=True):
    """P_pll of one skull curve against a facial curve (a batch of one).

    Parameters
    ----------
    skull_curve : array_like of shape (K, 2)
        From :meth:`~lilium.fitness.pll_context.PllContext.skull_curve`.
    face_curve : array_like of shape (M, 2)
        Refined (:func:`lilium.fitness.curves.refine_curve`), same direction as the skull curve.
    view : {"frontal", "lateral_left", "lateral_right"}
    trim : bool
        Trim first (docs/method/lilium.md does).

    Returns
    -------
    PllTerms
        Scalars.

    Examples
    --------
    Two horizontal, parallel curves, the skull 5 px above the face (frontal):

    >>> u = np.arange(10.0)
    >>> skull = np.column_stack([u, np.full(10, 100.0)])
    >>> face = np.column_stack([u, np.full(10, 105.0)])
    >>> pll_penalty(skull, face, "frontal").total
    0.0
    """
    curves = CurveBatch.from_curves([skull_curve])
    return pll_terms_batch(curves, face_curve_index(face_curve), view, trim).member(0)
