"""Curve detection and refinement of the parallelism term (SPEC section 5).

Curves are pixel polylines ``(N, 2)`` in ``uv`` (u = column, v = row), ordered along the curve
and 8-connected after refinement. Orientation, written once: chin-jaw curves (frontal views)
run left to right in the image (increasing u), forehead curves (lateral views) top to bottom
(increasing v), so the two curves of a pair start at the same end.

Detection of a projected mesh region: rasterise it (union of its triangles at the photo's
resolution, :mod:`lilium.imaging.raster`), drop isolated pixels (no 8-neighbour), then take its
outer boundary on the side that faces the skin: the lowest pixel of every column for the
chin-jaw in frontal views; the most anterior pixel of every row for the forehead in lateral
views (smallest u for ``lateral_left``, where the face points to -u; largest u for
``lateral_right``), keeping only the rows inside the glabella-metopion span. Gaps between
consecutive boundary pixels (steep stretches, fragments) are joined by straight pixel segments.
"""

from dataclasses import dataclass

import numpy as np

from ..constants import VIEWS
from ..imaging.raster import mesh_edge_topology, scan_crossings, winding_intervals

#: Largest side (pixels) of the window a region is rasterised in; beyond, it is clipped.
MAX_WINDOW_PX = 8192


def check_view(view):
    """Return ``view`` if it is one of :data:`lilium.constants.VIEWS`, else raise ValueError."""
    if view not in VIEWS:
        raise ValueError(f"view must be one of {VIEWS}, got {view!r}")
    return view


def join_fragments(points):
    """Join consecutive points by straight 8-connected pixel segments.

    Parameters
    ----------
    points : array_like of shape (N, 2)
        Integer-valued pixel positions, in curve order.

    Returns
    -------
    curve : ndarray of shape (M, 2)
        The same points with the pixels of the joining segments inserted; consecutive
        duplicates removed.
    """
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
    """Reverse a curve when needed so that it runs in the direction of the module docstring."""
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
        ``uv`` positions (sub-pixel allowed).
    view : str
    ordered : bool
        Whether ``points`` are already in curve order; if not, :func:`order_points` orders them.

    Returns
    -------
    curve : ndarray of shape (M, 2)
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    p = p[np.all(np.isfinite(p), axis=1)]
    p = np.rint(p)
    if not ordered:
        p = order_points(np.unique(p, axis=0))
    return orient_curve(join_fragments(p), view)


def _drop_isolated(grid):
    """Pixels with at least one 8-neighbour."""
    g = grid.astype(np.uint8)
    pad = np.pad(g, 1)
    h, w = g.shape
    n = np.zeros((h, w), np.uint8)
    for dr in (0, 1, 2):
        for dc in (0, 1, 2):
            if dr != 1 or dc != 1:
                n += pad[dr : dr + h, dc : dc + w]
    return grid & (n > 0)


def region_raster(uv, faces=None, *, topology=None, image_shape=None):
    """Rasterise a projected region in its own window.

    Parameters
    ----------
    uv : array_like of shape (K, 2)
        Projected region vertices.
    faces : array_like of shape (G, 3), optional if ``topology`` is given
    topology : EdgeTopology, optional
    image_shape : (int, int), optional
        When given, the window is clipped to the image grown by one image size on every side.

    Returns
    -------
    grid : ndarray of shape (h, w) of bool
    origin : (int, int)
        ``(u0, v0)``: the image position of ``grid[0, 0]``.
    """
    uv = np.asarray(uv, dtype=float)
    if topology is None:
        topology = mesh_edge_topology(faces)
    u, v = uv[:, 0], uv[:, 1]
    if np.isnan(u.sum()):  # (a column-wise reduction of an (N, 2) array is slow)
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
    h, w = int(v1 - v0), int(u1 - u0)
    n = h * (w + 1)
    base = (row - v0) * (w + 1)
    diff = np.bincount(base + (start - u0), minlength=n) - np.bincount(
        base + (stop - u0), minlength=n
    )
    grid = np.cumsum(diff.reshape(h, w + 1), axis=1)[:, :w] > 0
    return grid, (int(u0), int(v0))


def boundary_pixels(grid, origin, view):
    """The outer boundary of a raster on the skin side (see the module docstring).

    Returns
    -------
    points : ndarray of shape (N, 2)
        ``uv`` of one pixel per column (frontal) or per row (lateral), in curve order.
    """
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
    """The skin-side contour of a projected region (chin-jaw or forehead).

    Parameters
    ----------
    uv : array_like of shape (K, 2)
        Projected vertices of the region (:class:`lilium.fitness.regions.Region`).
    faces : array_like of shape (G, 3), optional if ``topology`` is given
        The region's faces.
    view : {"frontal", "lateral_left", "lateral_right"}
    span_v : (float, float), optional
        For the forehead: the v of the projected glabella and metopion; boundary pixels outside
        that span are dropped.
    topology : EdgeTopology, optional
        ``mesh_edge_topology(region.faces)``, computed once.
    image_shape : (int, int), optional
        Bounds the raster window (see :func:`region_raster`).

    Returns
    -------
    curve : ndarray of shape (N, 2)
        Ordered, 8-connected pixel curve (may be empty).
    """
    check_view(view)
    grid, origin = region_raster(uv, faces, topology=topology, image_shape=image_shape)
    if grid.size:
        grid = _drop_isolated(grid)
    points = boundary_pixels(grid, origin, view)
    if span_v is not None and len(points):
        lo, hi = sorted(span_v)
        points = points[(points[:, 1] >= lo) & (points[:, 1] <= hi)]
    return orient_curve(join_fragments(points), view)


def face_curve_from_mask(face_mask, view, landmarks_uv):
    """The facial contour of a photo from its face mask (SPEC section 5).

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
    """
    check_view(view)
    mask = np.asarray(face_mask) != 0
    if mask.ndim != 2:
        raise ValueError(f"face_mask must be 2D (rows, columns), got shape {mask.shape}")
    height, width = mask.shape
    names = ("cheilion_l", "cheilion_r") if view == "frontal" else ("glabella", "metopion")
    missing = [n for n in names if n not in landmarks_uv]
    if missing:
        raise ValueError(f"the {view} facial curve from the mask needs the landmarks {missing}")
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


#: Cells (members x rows x columns) of the stacked rasters of :func:`detect_curves_batch`.
BATCH_CELL_BUDGET = 2_000_000


@dataclass(frozen=True)
class CurveBatch:
    """The skull curves of a population, concatenated.

    Attributes
    ----------
    points : ndarray of shape (N, 2)
        ``uv`` of all curves, member after member, each in curve order.
    offset : ndarray of shape (S + 1,) of int64
        Member ``m``'s curve is ``points[offset[m] : offset[m + 1]]``.
    """

    points: np.ndarray
    offset: np.ndarray

    def __len__(self):
        return len(self.offset) - 1

    def curve(self, m):
        return self.points[self.offset[m] : self.offset[m + 1]]


def _windows(uv, image_shape):
    """Per-member raster windows of :func:`region_raster`, and which need the reference path.

    Returns ``lo (S, 2)``, ``hi (S, 2)`` (int64, ``(u, v)``), ``empty (S,)`` (no finite vertex)
    and ``slow (S,)`` (window clipped: left to :func:`detect_curve`).
    """
    u, v = uv[..., 0], uv[..., 1]
    finite = np.isfinite(u) & np.isfinite(v)
    empty = ~finite.any(axis=1)
    lo = np.stack([np.where(finite, x, np.inf).min(axis=1) for x in (u, v)], axis=1)
    hi = np.stack([np.where(finite, x, -np.inf).max(axis=1) for x in (u, v)], axis=1)
    lo = np.where(empty[:, None], 0.0, np.floor(lo))
    hi = np.where(empty[:, None], 1.0, np.ceil(hi) + 1)
    slow = np.any(hi - lo > MAX_WINDOW_PX, axis=1)
    if image_shape is not None:
        height, width = image_shape
        slow |= np.any(lo < [-width, -height], axis=1) | np.any(hi > [2 * width, 2 * height], 1)
    return lo.astype(np.int64), hi.astype(np.int64), empty, slow


def _stacked_rasters(uv, topology, lo, hi):
    """Rasters of several members in windows of a common size, each at its own origin ``lo``."""
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
    """:func:`_drop_isolated` of every raster of a stack ``(S, h, w)``."""
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
    """:func:`boundary_pixels` of a stack: ``member (N,)``, ``points (N, 2)`` in member order."""
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
    """Lateral :func:`boundary_pixels` straight from covered runs (no raster), isolated dropped.

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
    """:func:`join_fragments` of many curves concatenated (``offset`` as in :class:`CurveBatch`).

    Returns the joined :class:`CurveBatch`; the arithmetic is that of :func:`join_fragments`, so
    the curves are identical.
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


def detect_curves_batch(uv, view="frontal", *, span_v=None, topology=None, image_shape=None):
    """:func:`detect_curve` for a population, all members at once (identical curves).

    The rasters of the members are scanned together and stacked in windows of a common size;
    boundary, span filter and the joining of fragments run on the concatenated points. Members
    whose window :func:`region_raster` would clip (regions far off the image, or wider than
    :data:`MAX_WINDOW_PX`) go through :func:`detect_curve`.

    Parameters
    ----------
    uv : ndarray of shape (S, K, 2)
    view : {"frontal", "lateral_left", "lateral_right"}
    span_v : ndarray of shape (S, 2), optional
    topology : EdgeTopology
    image_shape : (int, int), optional

    Returns
    -------
    CurveBatch
    """
    check_view(view)
    uv = np.asarray(uv, dtype=float)
    S = len(uv)
    lo, hi = np.zeros((S, 2), np.int64), np.ones((S, 2), np.int64)
    empty = np.ones(S, bool)
    slow = np.zeros(S, bool)
    if topology.n_faces and S:
        lo, hi, empty, slow = _windows(uv, image_shape)
    members, points = [], []
    fast = np.flatnonzero(~empty & ~slow)
    cells = np.prod(hi - lo, axis=1)[fast]
    # Chunks of members whose stacked rasters stay within the cell budget.
    if view != "frontal" and len(fast):
        # Lateral: the anterior pixel of every row comes straight from the covered runs.
        c = scan_crossings(
            uv[fast],
            topology,
            (int(lo[fast, 1].min()), int(hi[fast, 1].max())),
            (int(lo[fast, 0].min()), int(hi[fast, 0].max())),
        )
        m, pts = _runs_boundary(*winding_intervals(c), view)
        members.append(fast[m])
        points.append(pts)
        fast = fast[:0]
    start = 0
    while start < len(fast):
        stop = start + 1
        while stop < len(fast) and (stop - start + 1) * cells[start : stop + 1].max() <= (
            BATCH_CELL_BUDGET
        ):
            stop += 1
        sel = fast[start:stop]
        grid = _drop_isolated_stack(_stacked_rasters(uv[sel], topology, lo[sel], hi[sel]))
        m, pts = _boundary_stack(grid, lo[sel], view)
        members.append(sel[m])
        points.append(pts)
        start = stop
    for m in np.flatnonzero(slow):
        grid, origin = region_raster(uv[m], topology=topology, image_shape=image_shape)
        if grid.size:
            grid = _drop_isolated(grid)
        pts = boundary_pixels(grid, origin, view)
        members.append(np.full(len(pts), m))
        points.append(pts)
    member = np.concatenate(members) if members else np.zeros(0, np.int64)
    points = np.concatenate(points) if points else np.zeros((0, 2))
    if len(slow) and slow.any():
        order = np.argsort(member, kind="stable")
        member, points = member[order], points[order]
    if span_v is not None and len(points):
        span_v = np.asarray(span_v, dtype=float)
        a, b = span_v[member, 0], span_v[member, 1]
        v = points[:, 1]
        keep = (v >= np.minimum(a, b)) & (v <= np.maximum(a, b))
        member, points = member[keep], points[keep]
    offset = np.searchsorted(member, np.arange(S + 1))
    return join_fragments_batch(points, offset)
