"""P_skof's outside-pixel count on the full skull, for a population of cameras: compiled.

``|S \\ F|`` is the union over the triangles ``T`` of ``T \\ F``, so a triangle whose every point
lies inside the face mask can be left out without changing the count. Here whole *clusters* of
triangles are left out before they are even projected: the skull's faces are put in Morton
(Z-curve) order of their centroids and cut into leaves of :data:`LEAF_FACES` consecutive faces,
grouped :data:`GROUP_LEAVES` at a time; each leaf and group carries a bounding sphere (centre
``c``, radius ``r``, skull frame). Under a camera the sphere's image lies within

    ``b = f r |C| / (C_z (C_z - r))``,  ``C = R c + t`` (camera frame, ``C_z > r``)

pixels of the projected centre (the perspective image of a point ``c + d`` moves by
``f |d x C| / (C_z (C_z + d_z))`` at most). When ``b`` is below the face mask's clearance at that
pixel (:class:`lilium.fitness.skof.FaceMaskIndex`: the distance to the nearest non-face pixel
centre, less half a pixel diagonal and a rounding margin) no triangle of the cluster holds a
non-face pixel centre and the cluster is skipped; otherwise its faces are projected (each vertex
once per camera) and go into the exact union raster of :mod:`lilium.imaging._raster_kernels`.
Nothing is approximated: the count equals the full mesh's (``tests/test_kernels_mesh.py`` checks it
against the numpy raster of every face, on rotated, scaled, off-image and behind-camera skulls).

The vertices are projected with the elementwise formula of :func:`project_vertices`, whose numpy
version is the reference path: both paths round identically, so a run gives the same numbers
with or without numba.
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..constants import MIN_DEPTH_MM
from ..geometry._projection_kernels import pinhole
from ..imaging._raster_kernels import accumulate_face, edge_crossings, sort_rows
from ..jit import njit

#: Faces per leaf cluster (consecutive in Morton order).
LEAF_FACES = 8

#: Children per inner node of the cluster tree.
FAN_OUT = 8

#: Relative and absolute (pixels) safety margins on a cluster's image radius.
BOUND_RTOL = 1e-9
BOUND_ATOL_PX = 1e-7


@dataclass(frozen=True)
class FaceClusters:
    """A skull's faces in k-d order, in a tree of clusters with bounding spheres.

    Attributes
    ----------
    order : ndarray of shape (F,)
        ``faces[order]`` is the clustered face list.
    node_sphere : ndarray of shape (N, 4)
        ``(x, y, z, r)`` (skull frame, mm) of every node; the root is node 0.
    node_faces : ndarray of shape (N, 2)
        Clustered faces ``[lo, hi)`` under each node.
    node_children : ndarray of shape (N, 2)
        Child nodes ``[lo, hi)`` of each node; empty for a leaf (at most :data:`LEAF_FACES`
        faces).
    """

    order: np.ndarray
    node_sphere: np.ndarray
    node_faces: np.ndarray
    node_children: np.ndarray


@njit
def _select(key, idx, lo, hi, k):
    """Reorder ``idx[lo:hi]`` so that its first ``k`` entries are the ``k`` smallest by
    ``(key[idx], idx)`` (a quickselect; the order inside each part is unspecified)."""
    while hi - lo > 1:
        mid = (lo + hi) // 2
        # Median of three as the pivot, compared by (key, index): every index is unique.
        a, b, c = idx[lo], idx[mid], idx[hi - 1]
        if (key[b], b) < (key[a], a):
            a, b = b, a
        if (key[c], c) < (key[b], b):
            b, c = c, b
            if (key[b], b) < (key[a], a):
                a, b = b, a
        pk, pi = key[b], b
        i, j = lo, hi - 1
        while i <= j:
            while (key[idx[i]], idx[i]) < (pk, pi):
                i += 1
            while (pk, pi) < (key[idx[j]], idx[j]):
                j -= 1
            if i <= j:
                idx[i], idx[j] = idx[j], idx[i]
                i += 1
                j -= 1
        if lo + k <= j:
            hi = j + 1
        elif lo + k >= i:
            k -= i - lo
            lo = i
        else:
            return


@njit
def _kd_order(points, leaf_size):
    """Order of points ``(N, 3)`` in which every run of ``leaf_size`` is a compact k-d cell.

    Splits along the longest side of each cell's bounding box, the left part the ``half``
    smallest along it (ties by index; ``half`` a multiple of ``leaf_size``, about half), until
    cells hold at most ``leaf_size``; consecutive leaves are neighbours in the tree, so runs of
    leaves are compact too. A selection per cell (no sort): O(N log N) in all.
    """
    n_points = points.shape[0]
    order = np.arange(n_points)
    stack = np.empty((128, 2), np.int64)
    stack[0, 0], stack[0, 1] = 0, n_points
    key = np.empty(n_points)
    depth = 1
    while depth > 0:
        depth -= 1
        lo, hi = stack[depth, 0], stack[depth, 1]
        n = hi - lo
        if n <= leaf_size:
            continue
        best_axis, best_extent = 0, -1.0
        for axis in range(3):
            a_min, a_max = np.inf, -np.inf
            for i in range(lo, hi):
                x = points[order[i], axis]
                a_min = min(a_min, x)
                a_max = max(a_max, x)
            if a_max - a_min > best_extent:
                best_axis, best_extent = axis, a_max - a_min
        for i in range(lo, hi):
            key[order[i]] = points[order[i], best_axis]
        half = max(leaf_size, (n // 2 + leaf_size - 1) // leaf_size * leaf_size)
        if half >= n:
            half = n - leaf_size
        _select(key, order, lo, hi, half)
        stack[depth, 0], stack[depth, 1] = lo + half, hi
        stack[depth + 1, 0], stack[depth + 1, 1] = lo, lo + half
        depth += 2
    return order


@njit
def squared_distance_to_background(mask):
    """Exact squared distance (square pixels) from every pixel centre of ``mask``
    ``(height, width)`` (True = face) to the nearest False pixel centre; ``inf`` without one.

    Felzenszwalb and Huttenlocher's two passes (columns, then the lower envelope of parabolas
    along the rows). Integers below 2**53: exact, the square of
    ``scipy.ndimage.distance_transform_edt``'s distance.
    """
    height, width = mask.shape
    big = np.inf
    g = np.empty((height, width))  # squared distance along the column
    last = np.full(width, -1, np.int64)  # row of the last background pixel seen per column
    for r in range(height):
        for c in range(width):
            if not mask[r, c]:
                last[c] = r
            g[r, c] = big if last[c] < 0 else float((r - last[c]) * (r - last[c]))
    last[:] = -1
    for r in range(height - 1, -1, -1):
        for c in range(width):
            if not mask[r, c]:
                last[c] = r
            if last[c] >= 0:
                d = float((last[c] - r) * (last[c] - r))
                if d < g[r, c]:
                    g[r, c] = d
    out = np.empty((height, width))
    v = np.empty(width, np.int64)
    z = np.empty(width + 1)
    for r in range(height):
        f = g[r]
        k = -1
        s = 0.0
        for q in range(width):
            if f[q] == big:
                continue
            while k >= 0:
                s = ((f[q] + q * q) - (f[v[k]] + v[k] * v[k])) / (2.0 * (q - v[k]))
                if s <= z[k]:
                    k -= 1
                else:
                    break
            k += 1
            v[k] = q
            z[k] = -big if k == 0 else s
            z[k + 1] = big
        if k < 0:
            out[r, :] = big
            continue
        j = 0
        for q in range(width):
            while z[j + 1] < q:
                j += 1
            d = q - v[j]
            out[r, q] = d * d + f[v[j]]
    return out


@njit
def _spheres(vertices, faces, ranges):
    """Bounding sphere ``(x, y, z, r)`` of the corners of each face range ``[lo, hi)`` (K, 2):
    centre at the middle of their bounding box, radius the largest distance (padded)."""
    out = np.zeros((ranges.shape[0], 4))
    for k in range(ranges.shape[0]):
        lo, hi = ranges[k, 0], ranges[k, 1]
        if hi <= lo:
            continue
        box_lo = np.full(3, np.inf)
        box_hi = np.full(3, -np.inf)
        for f in range(lo, hi):
            for j in range(3):
                for a in range(3):
                    x = vertices[faces[f, j], a]
                    box_lo[a] = min(box_lo[a], x)
                    box_hi[a] = max(box_hi[a], x)
        centre = 0.5 * (box_lo + box_hi)
        r2 = 0.0
        for f in range(lo, hi):
            for j in range(3):
                d2 = 0.0
                for a in range(3):
                    d = vertices[faces[f, j], a] - centre[a]
                    d2 += d * d
                r2 = max(r2, d2)
        out[k, :3] = centre
        out[k, 3] = np.sqrt(r2) * (1.0 + 1e-12) + 1e-9
    return out


class SkofScratch:
    """The outside count's per-vertex and per-edge scratch arrays, kept between calls.

    Allocating them at every call (3.6 MB for a 600k-face skull's working mesh) cost more than
    counting did: fresh pages fault in on every call. One SFO's term owns one; not for
    concurrent use.
    """

    def __init__(self, n_vertices, n_edges):
        self.vstamp = np.full(n_vertices, -1, np.int64)
        self.mark = np.full(n_edges, -1, np.int64)
        self.mult = np.zeros(n_edges)
        self.touched = np.empty(n_edges, np.int64)
        self.u = np.empty(n_vertices)
        self.v = np.empty(n_vertices)
        self.next_stamp = 0

    def stamps(self, n_cameras):
        """The first stamp for ``n_cameras`` cameras (each takes the next one)."""
        first = self.next_stamp
        self.next_stamp += n_cameras
        return first


@njit
def _centroids(vertices_mm, faces):
    """Face centroids ``(F, 3)``: ``vertices_mm[faces].mean(axis=1)``, the same sums."""
    out = np.empty((faces.shape[0], 3))
    for f in range(faces.shape[0]):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        for k in range(3):
            out[f, k] = (vertices_mm[a, k] + vertices_mm[b, k] + vertices_mm[c, k]) / 3.0
    return out


def face_clusters(vertices_mm, faces, leaf_faces=LEAF_FACES, fan_out=FAN_OUT):
    """Build the :class:`FaceClusters` of a mesh (once per skull).

    Leaves are runs of ``leaf_faces`` faces in k-d order; each level above joins ``fan_out``
    consecutive nodes, up to one root.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3) of int64
    leaf_faces, fan_out : int
    """
    vertices_mm = np.asarray(vertices_mm, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    n = len(faces)
    if not n:
        centroids = np.zeros((0, 3))
    elif jit.compiled():
        centroids = _centroids(vertices_mm, faces)
    else:
        centroids = vertices_mm[faces].mean(axis=1)
    order = (
        _kd_order(np.ascontiguousarray(centroids), int(leaf_faces)) if n else np.zeros(0, np.int64)
    )
    clustered = faces[order]
    # Levels, leaves first: the face range [lo, hi) of each node.
    lo = np.arange(0, max(n, 1), leaf_faces, dtype=np.int64)
    levels = [np.column_stack([lo, np.minimum(lo + leaf_faces, n)])]
    while len(levels[-1]) > 1:
        below = levels[-1]
        last = np.minimum(np.arange(0, len(below), fan_out) + fan_out, len(below)) - 1
        levels.append(np.column_stack([below[::fan_out, 0], below[last, 1]]))
    levels = levels[::-1]  # root first
    first = np.cumsum([0] + [len(level) for level in levels])
    children = np.zeros((first[-1], 2), np.int64)
    for d in range(len(levels) - 1):
        j = np.arange(len(levels[d]))
        size = len(levels[d + 1])
        children[first[d] : first[d + 1], 0] = first[d + 1] + np.minimum(j * fan_out, size)
        children[first[d] : first[d + 1], 1] = first[d + 1] + np.minimum((j + 1) * fan_out, size)
    node_faces = np.concatenate(levels)
    return FaceClusters(
        order=order,
        node_sphere=_spheres(vertices_mm, np.ascontiguousarray(clustered), node_faces),
        node_faces=node_faces,
        node_children=children,
    )


def project_vertices(vertices_mm, R, t, focal_px, principal_point_px):
    """Projected vertices ``(S, V, 2)``: the reference of the compiled projection.

    The pinhole of :func:`lilium.geometry.camera.project_points` written out element by element
    (``X = R[0, 0] x + R[0, 1] y + R[0, 2] z + t[0]``, ...) so that numpy and the compiled
    kernel round identically; NaN for points at depth <= ``MIN_DEPTH_MM``.
    """
    P = np.asarray(vertices_mm, dtype=float)
    x, y, z = P[:, 0], P[:, 1], P[:, 2]
    R, t = np.asarray(R, dtype=float), np.asarray(t, dtype=float)
    f = np.asarray(focal_px, dtype=float)[:, None]
    X = [
        R[:, i, 0, None] * x + R[:, i, 1, None] * y + R[:, i, 2, None] * z + t[:, i, None]
        for i in range(3)
    ]
    behind = X[2] <= MIN_DEPTH_MM
    scale = f / np.where(behind, 1.0, X[2])
    scale[behind] = np.nan
    uv = np.empty(X[0].shape + (2,))
    uv[..., 0] = X[0] * scale + principal_point_px[0]
    uv[..., 1] = X[1] * scale + principal_point_px[1]
    return uv


@njit
def _sphere_inside(sphere, R, t, f, c0, c1, clearance2, width, height):
    """Whether every point of a bounding sphere projects well inside the face mask."""
    x, y, z, r = sphere[0], sphere[1], sphere[2], sphere[3]
    cx = R[0, 0] * x + R[0, 1] * y + R[0, 2] * z + t[0]
    cy = R[1, 0] * x + R[1, 1] * y + R[1, 2] * z + t[1]
    cz = R[2, 0] * x + R[2, 1] * y + R[2, 2] * z + t[2]
    if not cz - r > 1e-3:
        return False
    pu = cx * (f / cz) + c0
    pv = cy * (f / cz) + c1
    if not (np.isfinite(pu) and np.isfinite(pv)):
        return False
    bound = f * r * np.sqrt(cx * cx + cy * cy + cz * cz) / (cz * (cz - r))
    bound = bound * (1.0 + BOUND_RTOL) + BOUND_ATOL_PX
    col = min(max(np.rint(pu), -1.0), float(width)) + 1.0
    row = min(max(np.rint(pv), -1.0), float(height)) + 1.0
    return bound * bound < clearance2[np.int64(row) * (width + 2) + np.int64(col)]


@njit
def _project(i, vertices, R, t, f, c0, c1, u, v):
    u[i], v[i] = pinhole(vertices[i, 0], vertices[i, 1], vertices[i, 2], R, t, f, c0, c1)


@njit
def outside_pixels_kernel(
    vertices,
    faces,
    face_edges,
    face_dirs,
    edges_a,
    edges_b,
    node_sphere,
    node_faces,
    node_children,
    R,
    t,
    focal,
    c0,
    c1,
    clearance2,
    prefix,
    vstamp,
    mark,
    mult,
    touched,
    u,
    v,
    stamp0,
):
    """``|S \\ F|`` of the clustered mesh under S cameras (see the module docstring).

    ``vstamp``, ``u``, ``v`` (V,), ``mark``, ``mult``, ``touched`` (E,) are scratch arrays kept
    between calls (:class:`SkofScratch`): camera ``m`` stamps vertices and edges with
    ``stamp0 + m``, so the stamps must be larger than every earlier call's.

    Returns
    -------
    count : ndarray of shape (S,) of int64
    faces_done : ndarray of shape (S,) of int64
        Faces rasterised per camera (the rest were skipped as inside the mask).
    """
    S = R.shape[0]
    height = prefix.shape[0]
    width = prefix.shape[1] - 1
    buf = np.empty((1024, 3), np.int64)
    keys = np.empty(1024, np.int64)
    rows = np.empty(1024, np.int64)
    count = np.zeros(S, np.int64)
    faces_done = np.zeros(S, np.int64)
    stack = np.empty(64 * (FAN_OUT + 1), np.int64)
    for m in range(S):
        Rm, tm, f = R[m], t[m], focal[m]
        stamp = stamp0 + m
        n_touched = 0
        depth = 0
        if node_faces.shape[0] and node_faces[0, 1] > node_faces[0, 0]:
            stack[0] = 0
            depth = 1
        while depth > 0:
            depth -= 1
            node = stack[depth]
            if _sphere_inside(node_sphere[node], Rm, tm, f, c0, c1, clearance2, width, height):
                continue
            if node_children[node, 1] > node_children[node, 0]:
                for child in range(node_children[node, 1] - 1, node_children[node, 0] - 1, -1):
                    stack[depth] = child
                    depth += 1
                continue
            for k in range(node_faces[node, 0], node_faces[node, 1]):
                i0, i1, i2 = faces[k, 0], faces[k, 1], faces[k, 2]
                for i in (i0, i1, i2):
                    if vstamp[i] != stamp:
                        vstamp[i] = stamp
                        _project(i, vertices, Rm, tm, f, c0, c1, u, v)
                du1, dv1 = u[i1] - u[i0], v[i1] - v[i0]
                du2, dv2 = u[i2] - u[i0], v[i2] - v[i0]
                # The face test of lilium.fitness.skof._signs_outside_interior.
                reach2 = max(du1 * du1 + dv1 * dv1, du2 * du2 + dv2 * dv2)
                col = min(max(np.rint(u[i0]), -1.0), float(width)) + 1.0
                row = min(max(np.rint(v[i0]), -1.0), float(height)) + 1.0
                if np.isfinite(col) and np.isfinite(row):
                    pixel = np.int64(row) * (width + 2) + np.int64(col)
                    if not clearance2[pixel] <= reach2:
                        continue
                faces_done[m] += 1
                area = du1 * dv2 - du2 * dv1
                if area > 0.0:
                    s = 1.0
                elif area < 0.0:
                    s = -1.0
                else:
                    continue  # degenerate or NaN (behind the camera): covers nothing
                n_touched = accumulate_face(
                    k, s, face_edges, face_dirs, mult, mark, stamp, touched, n_touched
                )
        buf, n = edge_crossings(
            u,
            v,
            touched,
            n_touched,
            mult,
            edges_a,
            edges_b,
            0.0,
            float(height),
            0.0,
            float(width),
            buf,
        )
        keys, rows = sort_rows(buf, n, keys, rows)
        winding = 0
        total = 0
        for i in range(n - 1):
            winding += buf[i, 2]
            start, stop = buf[i, 1], buf[i + 1, 1]
            if winding != 0 and stop > start:
                r = buf[i, 0]
                total += prefix[r, stop] - prefix[r, start]
        count[m] = total
    return count, faces_done
