"""The curves of the parallelism term (docs/method/lilium.md): skull-curve detection, facial curves.

Curves are pixel polylines ``(N, 2)`` in ``uv`` (u = column, v = row), ordered along the curve
and 8-connected after refinement. Orientation, written once: chin-jaw curves (frontal views)
run left to right in the image (increasing u), forehead curves (lateral views) top to bottom
(increasing v), so the two curves of a pair start at the same end.

Skull curves, for a population of projected regions at once (:func:`detect_curves_batch`; a
single camera is a batch of one, the result a :class:`CurveBatch`): rasterise the region (the
union of its triangles at the photo's resolution, :mod:`lilium.imaging.raster`), drop isolated
pixels (no 8-neighbour), then take its outer boundary on the side that faces the skin: the
lowest pixel of every column for the chin-jaw in frontal views; the most anterior pixel of
every row for the forehead in lateral views (smallest u for ``lateral_left``, where the face
points to -u; largest u for ``lateral_right``), keeping only the rows inside the
glabella-metopion span. Gaps between consecutive boundary pixels (steep stretches, fragments)
are joined by straight pixel segments (:func:`join_fragments_batch`). Boundary pixels come out
in increasing u (frontal) or v (lateral), so detected curves need no reorientation.

Facial curves, once per SFO: :func:`face_curve_from_mask` (from the face mask and landmarks) or
:func:`refine_curve` (a given contour: pixels, order, direction, joined gaps).

``tests/pll_oracle.py`` spells the same detection out for one curve at a time; the tests check
this module against it.
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..constants import VIEWS
from ..imaging.raster import scan_crossings, winding_intervals
from ._curve_kernels import (
    VIEW_CODES,
    boundary_kernel,
    edge_face_table,
    span_join_kernel,
    windows_kernel,
)

#: Largest side (pixels) of the window a region is rasterised in; beyond, it is clipped.
MAX_WINDOW_PX = 8192

#: Cells (members x rows x columns) of the stacked rasters of :func:`detect_curves_batch`.
BATCH_CELL_BUDGET = 2_000_000


def check_view(view):
    """Return ``view`` if it is one of :data:`lilium.constants.VIEWS`, else raise ValueError."""
    if view not in VIEWS:
        raise ValueError(f"view must be one of {VIEWS}, got {view!r}")
    return view


@dataclass(frozen=True)
class CurveBatch:
    """Curves of a population, concatenated.

    Attributes
    ----------
    points : ndarray of shape (N, 2)
        ``uv`` of all curves, member after member, each in curve order.
    offset : ndarray of shape (S + 1,) of int64
        Member ``m``'s curve is ``points[offset[m] : offset[m + 1]]``.
    """

    points: np.ndarray
    offset: np.ndarray

    @classmethod
    def from_curves(cls, curves):
        """Concatenate a sequence of curves, each an array_like of shape (N_m, 2)."""
        curves = [np.asarray(c, dtype=float).reshape(-1, 2) for c in curves]
        points = np.concatenate(curves) if curves else np.zeros((0, 2))
        offset = np.concatenate([[0], np.cumsum([len(c) for c in curves], dtype=np.int64)])
        return cls(points, offset.astype(np.int64))

    def __len__(self):
        return len(self.offset) - 1

    @property
    def lengths(self):
        """Points per curve, ndarray of shape (S,)."""
        return np.diff(self.offset)

    def curve(self, m):
        """Member ``m``'s curve, ndarray of shape (N_m, 2)."""
        return self.points[self.offset[m] : self.offset[m + 1]]


# --- facial curves (once per SFO) ------------------------------------------------------------


def join_fragments(points):
    """:func:`join_fragments_batch` of one curve ``(N, 2)``: the joined curve ``(M, 2)``."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return join_fragments_batch(p, [0, len(p)]).points


def orient_curve(curve, view):
    """Reverse a curve ``(N, 2)`` when needed so that it runs as the module docstring says."""
    curve = np.asarray(curve, dtype=float)
    if len(curve) < 2:
        return curve
    axis = 0 if check_view(view) == "frontal" else 1
    return curve[::-1] if curve[-1, axis] < curve[0, axis] else curve


def order_points(points):
    """Order an unordered point set along its curve (greedy nearest neighbour).

    Starts from the point farthest out along the set's principal axis. Fine for the few
    hundred points of a contour, once per SFO; not meant for a hot path.
    """
    from scipy.spatial import cKDTree

    p = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(p) < 3:
        return p.copy()
    centred = p - p.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    current = int(np.argmin(centred @ axis))
    tree = cKDTree(p)
    visited = np.zeros(len(p), bool)
    order = [current]
    visited[current] = True
    for _ in range(len(p) - 1):
        k = 8
        while True:
            _, idx = tree.query(p[current], k=min(k, len(p)))
            free = [i for i in np.atleast_1d(idx) if not visited[i]]
            if free or k >= len(p):
                break
            k *= 4
        if not free:
            free = list(np.flatnonzero(~visited))
            free = [free[int(np.argmin(np.linalg.norm(p[free] - p[current], axis=1)))]]
        current = int(free[0])
        visited[current] = True
        order.append(current)
    return p[order]


def refine_curve(points, view, ordered=True):
    """Refine a given curve (a facial contour, say): pixels, order, direction, joined gaps.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        ``uv`` positions (sub-pixel allowed; non-finite rows are dropped).
    view : {"frontal", "lateral_left", "lateral_right"}
    ordered : bool
        Whether ``points`` are already in curve order; if not, :func:`order_points` orders them.

    Returns
    -------
    curve : ndarray of shape (M, 2)
        Ordered, oriented, 8-connected pixel curve.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    p = p[np.all(np.isfinite(p), axis=1)]
    p = np.rint(p)
    if not ordered:
        p = order_points(np.unique(p, axis=0))
    return orient_curve(join_fragments(p), view)


def face_curve_bounds(view):
    """The two facial landmarks that bound a view's facial curve taken from the mask.

    ``("cheilion_l", "cheilion_r")`` for the chin-jaw (frontal), ``("glabella", "metopion")``
    for the forehead (lateral).
    """
    return (
        ("cheilion_l", "cheilion_r") if check_view(view) == "frontal" else ("glabella", "metopion")
    )


def missing_curve_bounds(view, landmarks_uv):
    """Which of :func:`face_curve_bounds` are absent (or not finite) in ``landmarks_uv``."""
    return [
        n
        for n in face_curve_bounds(view)
        if n not in landmarks_uv or not np.all(np.isfinite(np.asarray(landmarks_uv[n], float)))
    ]


def face_curve_from_mask(face_mask, view, landmarks_uv):
    """The facial contour of a photo from its face mask (docs/method/lilium.md).

    Chin-jaw (frontal): for every column between the two cheilion u's, going down from the
    mouth level (mean v of the cheilions), the last face pixel before the background. Forehead
    (lateral): for every row between the glabella and metopion v's, the most anterior face
    pixel (smallest u for ``lateral_left``, largest for ``lateral_right``). The mask must end at
    the chin (no neck) for the chin-jaw contour to be meaningful; otherwise give
    ``face_curve.json``.

    Parameters
    ----------
    face_mask : array_like of shape (height, width)
        Non-zero = face pixel, indexed ``[row, column]``.
    view : {"frontal", "lateral_left", "lateral_right"}
    landmarks_uv : dict of str -> (u, v)
        ``cheilion_l``/``cheilion_r`` (frontal) or ``glabella``/``metopion`` (lateral).

    Returns
    -------
    curve : ndarray of shape (N, 2)
        Ordered, 8-connected pixel curve.

    Raises
    ------
    ValueError
        A bounding landmark is missing (:func:`missing_curve_bounds`). An SFO does not get
        here: it switches P_pll off instead (:class:`lilium.methods.lilium_terms.PllTerm`).
    """
    check_view(view)
    mask = np.asarray(face_mask) != 0
    if mask.ndim != 2:
        raise ValueError(f"face_mask must be 2D (rows, columns), got shape {mask.shape}")
    height, width = mask.shape
    names = face_curve_bounds(view)
    missing = missing_curve_bounds(view, landmarks_uv)
    if missing:
        region = "chin-jaw" if view == "frontal" else "forehead"
        raise ValueError(
            f"the {region} curve of a {view} photo is taken from the face mask between "
            f"{names[0]} and {names[1]}, and {' and '.join(missing)} is not marked; mark it in "
            "the photo's landmarks or give face_curve.json"
        )
    a, b = (np.asarray(landmarks_uv[n], dtype=float) for n in names)
    if view == "frontal":
        cols = np.arange(
            max(0, int(np.ceil(min(a[0], b[0])))), min(width, int(max(a[0], b[0])) + 1)
        )
        start = int(np.clip(np.rint((a[1] + b[1]) / 2), 0, height - 1))
        below = mask[start:, cols]
        has_start = below[0] if len(below) else np.zeros(len(cols), bool)
        background = ~below
        first_bg = np.where(background.any(axis=0), np.argmax(background, axis=0), len(below))
        keep = has_start & (first_bg > 0)
        points = np.column_stack([cols[keep], start + first_bg[keep] - 1])
    else:
        rows = np.arange(
            max(0, int(np.ceil(min(a[1], b[1])))), min(height, int(max(a[1], b[1])) + 1)
        )
        sub = mask[rows]
        any_ = sub.any(axis=1)
        if view == "lateral_left":
            cols = np.argmax(sub, axis=1)
        else:
            cols = width - 1 - np.argmax(sub[:, ::-1], axis=1)
        points = np.column_stack([cols[any_], rows[any_]])
    return orient_curve(join_fragments(points.astype(float)), view)


# --- skull curves (a population at once) -----------------------------------------------------


def _windows(uv, image_shape):
    """Per-member raster windows (the bounding box of the finite vertices) and which are clipped.

    Parameters
    ----------
    uv : ndarray of shape (S, K, 2)
    image_shape : (int, int) or None

    Returns
    -------
    lo, hi : ndarray of shape (S, 2) of int64
        ``(u, v)`` of the window's first pixel and one past its last; clipped to the image
        grown by one image size on every side (when ``image_shape`` is given) and to
        :data:`MAX_WINDOW_PX` per side.
    empty : ndarray of shape (S,) of bool
        No finite vertex, or a window clipped to nothing.
    clipped : ndarray of shape (S,) of bool
        The window was clipped: its raster is scanned on its own (crossings outside it).
    """
    u, v = uv[..., 0], uv[..., 1]
    if jit.compiled():
        height, width = (-1, -1) if image_shape is None else image_shape
        u, v = np.ascontiguousarray(u), np.ascontiguousarray(v)
        return windows_kernel(u, v, int(height), int(width), MAX_WINDOW_PX)
    finite = np.isfinite(u) & np.isfinite(v)
    empty = ~finite.any(axis=1)
    lo = np.stack([np.where(finite, x, np.inf).min(axis=1) for x in (u, v)], axis=1)
    hi = np.stack([np.where(finite, x, -np.inf).max(axis=1) for x in (u, v)], axis=1)
    lo = np.where(empty[:, None], 0.0, np.floor(lo)).astype(np.int64)
    hi = np.where(empty[:, None], 1.0, np.ceil(hi) + 1).astype(np.int64)
    box_lo, box_hi = lo, hi
    if image_shape is not None:
        height, width = image_shape
        lo = np.maximum(lo, [-width, -height])
        hi = np.minimum(hi, [2 * width, 2 * height])
    hi = np.minimum(hi, lo + MAX_WINDOW_PX)
    clipped = np.any(lo != box_lo, axis=1) | np.any(hi != box_hi, axis=1)
    empty |= np.any(hi <= lo, axis=1)
    return lo, hi, empty, clipped & ~empty


def _stacked_rasters(uv, topology, lo, hi):
    """Union rasters ``(S, h, w)`` of several members, each in its window ``lo``, ``hi`` (S, 2).

    The windows share one size (the largest); the scan covers their union, so every member's
    crossings must lie inside its own window (true unless the window was clipped).
    """
    h, w = (hi - lo).max(axis=0)[::-1]
    c = scan_crossings(
        uv,
        topology,
        (int(lo[:, 1].min()), int(hi[:, 1].max())),
        (int(lo[:, 0].min()), int(hi[:, 0].max())),
    )
    member, row, start, stop = winding_intervals(c)
    n = len(uv) * h * (w + 1)
    base = (member * h + row - lo[member, 1]) * (w + 1) - lo[member, 0]
    diff = np.bincount(base + start, minlength=n) - np.bincount(base + stop, minlength=n)
    return np.cumsum(diff.reshape(len(uv), h, w + 1), axis=2)[:, :, :w] > 0


def _drop_isolated_stack(grid):
    """Pixels of every raster of a stack ``(S, h, w)`` that have at least one 8-neighbour."""
    g = grid.view(np.uint8)
    pad = np.pad(g, ((0, 0), (1, 1), (1, 1)))
    h, w = g.shape[1:]
    n = np.zeros(g.shape, np.uint8)
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            if dr != 1 or dc != 1:
                n += pad[:, dr : dr + h, dc : dc + w]
    return grid & (n > 0)


def _boundary_stack(grid, lo, view):
    """Skin-side boundary pixels of a stack of rasters ``(S, h, w)`` with origins ``lo (S, 2)``.

    One pixel per covered column (frontal: the lowest) or row (lateral: the most anterior).
    Returns ``member (N,)`` and ``points (N, 2)`` (``uv``), in member order, then curve order.
    """
    S, h, w = grid.shape
    if view == "frontal":
        member, cols = np.nonzero(grid.any(axis=1))
        last = h - 1 - np.argmax(grid[:, ::-1, :], axis=1)
        rows = last[member, cols]
    else:
        member, rows = np.nonzero(grid.any(axis=2))
        if view == "lateral_left":
            first = np.argmax(grid, axis=2)
        else:
            first = w - 1 - np.argmax(grid[:, :, ::-1], axis=2)
        cols = first[member, rows]
    points = np.column_stack([cols + lo[member, 0], rows + lo[member, 1]]).astype(float)
    return member, points


def _runs_boundary(member, row, start, stop, view):
    """Lateral :func:`_boundary_stack` straight from covered runs (no raster), isolated dropped.

    Runs come sorted by (member, row, start), non-overlapping within a row. A pixel is isolated
    when it is a one-pixel run and no other run of its row or of the rows above and below
    reaches columns ``c - 1 .. c + 1``. Returns ``member (N,)``, ``points (N, 2)``.
    """
    if len(row) == 0:
        return np.zeros(0, np.int64), np.zeros((0, 2))
    r0, c0 = int(row.min()) - 1, int(start.min()) - 2
    n_rows, n_cols = int(row.max()) - r0 + 2, int(stop.max()) - c0 + 3
    key_row = member * n_rows + (row - r0)
    key_start = key_row * n_cols + (start - c0)
    key_stop = key_row * n_cols + (stop - c0)
    single = np.flatnonzero(stop - start == 1)
    if len(single):
        c = start[single] - c0
        count = np.zeros(len(single), np.int64)
        for dr in (-1, 0, 1):
            q = (key_row[single] + dr) * n_cols
            i0 = np.searchsorted(key_stop, q + c - 1, side="right")
            i1 = np.searchsorted(key_start, q + c + 2, side="left")
            count += np.maximum(i1 - i0, 0)
        keep = np.ones(len(row), bool)
        keep[single[count == 1]] = False
        key_row, member, row, start, stop = (x[keep] for x in (key_row, member, row, start, stop))
    new_group = np.flatnonzero(np.diff(key_row)) + 1
    if view == "lateral_left":
        pick = np.concatenate([[0], new_group])
        cols = start[pick]
    else:
        pick = np.concatenate([new_group - 1, [len(row) - 1]])
        cols = stop[pick] - 1
    return member[pick], np.column_stack([cols, row[pick]]).astype(float)


def join_fragments_batch(points, offset):
    """Join the consecutive points of every curve by straight 8-connected pixel segments.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        Integer-valued pixel positions of all curves, concatenated, each in curve order.
    offset : array_like of shape (S + 1,)
        Curve ``m`` is ``points[offset[m] : offset[m + 1]]`` (as in :class:`CurveBatch`).

    Returns
    -------
    CurveBatch
        The same points with the pixels of the joining segments inserted (a step of ``n``
        pixels gets ``n - 1``); consecutive duplicates removed; curves never joined to each
        other.

    Examples
    --------
    >>> join_fragments_batch([[0, 0], [3, 0], [3, 0], [5, 2]], [0, 4]).points.tolist()
    [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [4.0, 1.0], [5.0, 2.0]]
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    offset = np.asarray(offset, dtype=np.int64)
    if len(p) == 0:
        return CurveBatch(p.copy(), np.zeros_like(offset))
    d = np.diff(p, axis=0)
    steps = np.maximum(np.abs(d[:, 0]), np.abs(d[:, 1])).astype(np.int64)
    # The step from a member's last point to the next member's first emits that last point only.
    last = offset[1:-1] - 1
    last = last[(last >= 0) & (last < len(d))]
    d[last] = 0.0
    steps[last] = 1
    total = int(steps.sum())
    seg = np.repeat(np.arange(len(d)), steps)
    k = np.arange(total) - np.repeat(np.cumsum(steps) - steps, steps)
    t = (k / np.repeat(steps, steps))[:, None]
    filled = np.rint(p[seg] + t * d[seg])
    out = np.vstack([filled, p[-1:]])
    # Output position of every input point = its segment's first emitted point.
    first = np.concatenate([[0], np.cumsum(steps)])
    new_offset = np.where(offset < len(p), first[np.minimum(offset, len(p) - 1)], len(out))
    return CurveBatch(out, new_offset)


def detect_curves_batch(uv, view, *, topology, span_v=None, image_shape=None, edge_faces=None):
    """The skin-side contours of a projected region (chin-jaw or forehead), for a population.

    The rasters of the members are scanned together and stacked in windows of a common size
    (in chunks of at most :data:`BATCH_CELL_BUDGET` cells; lateral views take the anterior pixel
    of every row straight from the covered runs, without a raster); boundary, span filter and
    the joining of fragments run on the concatenated points. A member whose window is clipped
    (a region far off the image, or wider than :data:`MAX_WINDOW_PX`) is scanned on its own.

    Parameters
    ----------
    uv : array_like of shape (S, K, 2)
        Projected vertices of the region (:class:`lilium.fitness.regions.Region`), one row per
        member; NaN for vertices behind the camera.
    view : {"frontal", "lateral_left", "lateral_right"}
    topology : EdgeTopology
        ``mesh_edge_topology(region.faces)``, computed once.
    span_v : array_like of shape (S, 2), optional
        For the forehead: the v of the projected glabella and metopion of every member;
        boundary pixels outside that span are dropped.
    image_shape : (int, int), optional
        ``(height, width)``: windows are clipped to the image grown by one image size on every
        side.
    edge_faces : tuple, optional
        ``edge_face_table(topology)`` (:mod:`lilium.fitness._curve_kernels`), for the compiled
        path; computed here when not given.

    Returns
    -------
    CurveBatch
        ``S`` ordered, 8-connected pixel curves (some may be empty).
    """
    check_view(view)
    uv = np.asarray(uv, dtype=float)
    if uv.ndim != 3 or uv.shape[-1] != 2:
        raise ValueError(f"uv must have shape (S, K, 2), got {uv.shape}")
    S = len(uv)
    lo, hi = np.zeros((S, 2), np.int64), np.ones((S, 2), np.int64)
    empty, clipped = np.ones(S, bool), np.zeros(S, bool)
    if topology.n_faces and S:
        lo, hi, empty, clipped = _windows(uv, image_shape)
    if jit.compiled():
        u = np.ascontiguousarray(uv[..., 0])
        v = np.ascontiguousarray(uv[..., 1])
        member, points = boundary_kernel(
            u,
            v,
            topology.corners,
            *(edge_face_table(topology) if edge_faces is None else edge_faces),
            topology.edges_a,
            topology.edges_b,
            np.ascontiguousarray(lo),
            np.ascontiguousarray(hi),
            ~empty,
            VIEW_CODES[view],
        )
        return _span_and_join(member, points, span_v, S)
    members, points = [], []
    together = np.flatnonzero(~empty & ~clipped)
    if view != "frontal" and len(together):
        c = scan_crossings(
            uv[together],
            topology,
            (int(lo[together, 1].min()), int(hi[together, 1].max())),
            (int(lo[together, 0].min()), int(hi[together, 0].max())),
        )
        m, pts = _runs_boundary(*winding_intervals(c), view)
        members.append(together[m])
        points.append(pts)
        together = together[:0]
    # Chunks of members whose stacked rasters stay within the cell budget; clipped windows alone.
    cells = np.prod(hi - lo, axis=1)[together]
    chunks = []
    first = 0
    while first < len(together):
        stop = first + 1
        while stop < len(together) and (stop - first + 1) * cells[first : stop + 1].max() <= (
            BATCH_CELL_BUDGET
        ):
            stop += 1
        chunks.append(together[first:stop])
        first = stop
    chunks += [np.array([m]) for m in np.flatnonzero(clipped)]
    for sel in chunks:
        grid = _drop_isolated_stack(_stacked_rasters(uv[sel], topology, lo[sel], hi[sel]))
        m, pts = _boundary_stack(grid, lo[sel], view)
        members.append(sel[m])
        points.append(pts)
    member = np.concatenate(members) if members else np.zeros(0, np.int64)
    points = np.concatenate(points) if points else np.zeros((0, 2))
    if clipped.any():
        order = np.argsort(member, kind="stable")
        member, points = member[order], points[order]
    return _span_and_join(member, points, span_v, S)


def _span_and_join(member, points, span_v, S):
    """Boundary pixels ``(N, 2)`` of members ``(N,)``: span filter, then joined fragments."""
    if jit.compiled():
        has_span = span_v is not None
        span = (
            np.ascontiguousarray(np.reshape(span_v, (S, 2)), float)
            if has_span
            else np.zeros((S, 2))
        )
        member = np.ascontiguousarray(member, np.int64)
        points = np.ascontiguousarray(points, dtype=float).reshape(-1, 2)
        return CurveBatch(*span_join_kernel(member, points, span, has_span, S))
    if span_v is not None and len(points):
        span_v = np.asarray(span_v, dtype=float).reshape(S, 2)
        a, b = span_v[member, 0], span_v[member, 1]
        v = points[:, 1]
        keep = (v >= np.minimum(a, b)) & (v <= np.maximum(a, b))
        member, points = member[keep], points[keep]
    offset = np.searchsorted(member, np.arange(S + 1))
    return join_fragments_batch(points, offset)
