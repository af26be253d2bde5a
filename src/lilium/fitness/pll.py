"""P_pll, the parallelism term of SPEC section 5: ``Delta_d + P_conv + P_int``.

Given the skull curve and the facial curve of one region (pixel polylines in ``uv``, ordered as
in :mod:`lilium.fitness.curves`):

1. Trimming (:func:`trim_curves`): at each end of each curve, the mean tangent of its terminal
   20 % (at least two points) defines the end's normal line (through the end point,
   perpendicular to that tangent); the other curve's points beyond that line, counted from its
   corresponding end until the first point on the near side, are cut off. All four cuts are
   computed on the untrimmed curves. A cut that would remove a whole curve is not applied.
2. Pairing (:func:`pair_curves`): every skull point to its nearest face point, then every face
   point that no skull point chose to its nearest skull point (``scipy.spatial.cKDTree``). The
   pairs are listed along the curves: sorted by the skull point's index, then by the face
   point's index, so the first and last pairs are the ends (an unpaired face stretch beyond a
   skull end comes out in face order, its outermost point first at the start and last at the
   end).
3. Terms (:func:`pll_terms`): ``Delta_d = max d - min d``; ``P_conv`` from the end deviations
   ``delta_e = |d_e - mean d|`` (an end converges when ``delta_e > 0.25 mean d``; both ends:
   ``2 (delta_1 + delta_N)``, one end: ``4 delta_e``, none: 0); ``P_int = 1000 *`` the number
   of pairs with the skull on the wrong side (frontal: ``s.v >= p.v``; lateral_left:
   ``s.u <= p.u``; lateral_right: ``s.u >= p.u``).

When a curve is empty (a region projected off the image, say) no pair exists:
:data:`PLL_NO_CURVE` is returned as the total.
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..constants import C_INF
from .curves import check_view, detect_curve, refine_curve
from .raster import mesh_edge_topology

#: Fraction of a curve's length whose mean tangent defines its end normal (SPEC: 20 %).
END_FRACTION = 0.2

#: An end converges when its deviation from the mean distance exceeds this fraction of it.
CONVERGENCE_RATIO = 0.25

#: Penalty per pair with the skull on the wrong side of the face (SPEC: 1000).
INTERSECTION_WEIGHT = 1000.0

#: P_pll when either curve is empty: as bad as an impossible camera.
PLL_NO_CURVE = C_INF


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
    head = -np.array([du[:k].mean(), dv[:k].mean()])
    tail = np.array([du[-k:].mean(), dv[-k:].mean()])
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
            beyond = (other - anchor) @ tangent > 0
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
    nearest_p = cKDTree(p).query(s)[1]
    chosen = np.zeros(len(p), bool)
    chosen[nearest_p] = True
    unpaired = np.flatnonzero(~chosen)
    if len(unpaired):
        nearest_s = cKDTree(s).query(p[unpaired])[1]
        si = np.concatenate([np.arange(len(s)), nearest_s])
        pi = np.concatenate([nearest_p, unpaired])
    else:
        si, pi = np.arange(len(s)), nearest_p
    order = np.lexsort((pi, si))
    si, pi = si[order], pi[order]
    sp, pp = s[si], p[pi]
    return sp, pp, np.linalg.norm(sp - pp, axis=1)


def convergence_penalty(d):
    """P_conv of SPEC 5 from the ordered pair distances ``d`` (N,)."""
    d = np.asarray(d, dtype=float)
    dbar = d.mean()
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
        """Totals for a population: ``region_uv`` (S, K, 2), ``span_v`` (S, 2) or None."""
        region_uv = np.asarray(region_uv, dtype=float)
        return np.array(
            [
                self.evaluate(uv, None if span_v is None else span_v[i]).total
                for i, uv in enumerate(region_uv)
            ]
        )
