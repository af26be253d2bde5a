"""Exact union rasterisation of projected triangle meshes, without a per-triangle loop.

This is the one rasteriser of every mesh mask in Lilium (P_skof, P_pll curves, the implausible
SFO metric, overlays, synthetic photos). It lives in :mod:`lilium.imaging`, the pixels layer,
rather than in :mod:`lilium.fitness`, because fitness, evaluation, imaging and synthetic data all
need it and only fitness is about the objective: the others should not depend on the fitness
layer for their pixels.

- :func:`skull_raster` the raster ``S`` of projected vertices ``uv`` (any mesh, skull or skin);
- :func:`mesh_mask` the raster of a mesh seen by a :class:`~lilium.geometry.camera.Camera`;
- :func:`mesh_edge_topology`, :func:`scan_crossings`, :func:`winding_intervals` the pieces, for
  callers that count pixels without building a mask (:mod:`lilium.fitness.skof`).

Rule, written once: pixel ``(row, column)`` belongs to the raster of a set of triangles when its
centre ``(u, v) = (column, row)`` lies inside at least one triangle (the *union*, so overlapping
triangles count once, whatever their orientation). A centre exactly on an edge is decided by a
half-open rule (rows: ``v0 <= v < v1``; columns: ``u >= u_edge``), so two triangles sharing an
edge never leave a gap nor double a pixel; for vertices at generic (non-integer) positions this
is the closed-triangle test.

How, without visiting every triangle's pixels: flip every projected triangle to the same
orientation; the coverage count of a point (how many triangles hold it) is then the winding
number of the sum of the triangles' boundaries. Every edge shared by two triangles of the same
projected orientation cancels in that sum, so only the *contour edges* survive: the silhouette
edges (front/back-facing neighbours) and the mesh's open borders. A scanline over those few
edges gives, per row, the column intervals of non-zero winding: the union, exactly. The edge
incidence is fixed by the mesh, so it is computed once (:func:`mesh_edge_topology`); per call
the cost is one signed area per face, one sparse product, and work proportional to the number
of contour-edge/row crossings (a few thousand for a skull), not to the covered area.
"""

import hashlib
from dataclasses import dataclass

import numpy as np

from .. import jit
from ._raster_kernels import edge_table_kernel, incidence_kernel, scan_kernel

__all__ = [
    "Crossings",
    "EdgeIncidence",
    "EdgeTopology",
    "check_faces",
    "check_topology",
    "contour_edges",
    "covered_box",
    "edge_incidence",
    "face_orientations",
    "mesh_edge_topology",
    "mesh_mask",
    "rasterise_union",
    "scan_crossings",
    "skull_raster",
    "winding_intervals",
]


@dataclass(frozen=True)
class EdgeTopology:
    """Undirected edges of a triangle mesh and their incidence to faces.

    Attributes
    ----------
    faces : ndarray of shape (F, 3)
        The faces it was built from (int64).
    edges : ndarray of shape (E, 2)
        Vertex indices ``(a, b)`` with ``a < b``.
    incidence : EdgeIncidence of shape (E, F)
        +1 where face f runs along edge e as ``a -> b``, -1 as ``b -> a``.
    corners : ndarray of shape (3, F)
        ``faces.T``, C-contiguous (fast gathers).
    edges_a, edges_b : ndarray of shape (E,)
        ``edges[:, 0]`` and ``edges[:, 1]``, contiguous.
    face_edges : ndarray of shape (F, 3) of int64
        The edge under each side ``faces[f, k] -> faces[f, (k + 1) % 3]`` (the compiled scan).
    face_dirs : ndarray of shape (F, 3) of float64
        +1 where that side runs along its edge ``a -> b``, -1 where it runs ``b -> a``.
    """

    faces: np.ndarray
    edges: np.ndarray
    incidence: "EdgeIncidence"
    corners: np.ndarray
    edges_a: np.ndarray
    edges_b: np.ndarray
    face_edges: np.ndarray
    face_dirs: np.ndarray

    @property
    def n_faces(self):
        return len(self.faces)


@dataclass(frozen=True)
class EdgeIncidence:
    """A sparse (E, F) edge-face incidence in compressed rows (scipy's CSR layout, without
    scipy.sparse, whose import cost every ``lilium sfo`` 0.1 s).

    Attributes
    ----------
    indptr : ndarray of shape (E + 1,) of int64
        Edge ``e``'s entries are ``indptr[e]:indptr[e + 1]``.
    indices : ndarray of shape (K,) of int64
        Their faces, ascending within an edge.
    data : ndarray of shape (K,) of float64
        Their values: the sum of the face's sides along the edge (+1 / -1; 0 or +-2 only on
        degenerate faces).
    shape : tuple of int
    """

    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray
    shape: tuple

    def __matmul__(self, dense):
        """``incidence @ dense`` for a dense ``dense`` (F, S): (E, S) of float64."""
        out = np.zeros((self.shape[0], dense.shape[1]))
        rows = np.flatnonzero(self.indptr[1:] > self.indptr[:-1])  # rows with entries
        if len(rows):
            products = self.data[:, None] * dense[self.indices]
            out[rows] = np.add.reduceat(products, self.indptr[rows], axis=0)
        return out


def edge_incidence(edge_of, direction, n_edges):
    """The :class:`EdgeIncidence` of half-edges ``i`` (a side of face ``i // 3``) on their edges.

    Parameters
    ----------
    edge_of : ndarray of shape (3F,) of int64
    direction : ndarray of shape (3F,) of float64
        +1 / -1: the side runs along / against its edge.
    n_edges : int

    Returns
    -------
    EdgeIncidence
    """
    edge_of = np.asarray(edge_of, np.int64)
    direction = np.asarray(direction, np.float64)
    if edge_of.ndim != 1 or len(edge_of) % 3 or direction.shape != edge_of.shape:
        raise ValueError("edge_of and direction must be (3F,) arrays, three sides per face")
    n_faces = len(edge_of) // 3
    if jit.compiled() and len(edge_of):  # the same rows, compiled (imaging/_raster_kernels.py)
        indptr, indices, data = incidence_kernel(
            np.ascontiguousarray(edge_of, np.int64), np.ascontiguousarray(direction), int(n_edges)
        )
        return EdgeIncidence(indptr, indices, data, (int(n_edges), n_faces))
    order = np.argsort(edge_of, kind="stable")  # faces ascend within an edge
    edge, face = edge_of[order], order // 3
    first = np.ones(len(order), bool)
    first[1:] = (edge[1:] != edge[:-1]) | (face[1:] != face[:-1])
    starts = np.flatnonzero(first)
    data = np.add.reduceat(direction[order], starts) if len(starts) else np.zeros(0)
    indptr = np.searchsorted(edge[starts], np.arange(n_edges + 1)).astype(np.int64)
    return EdgeIncidence(indptr, face[starts].astype(np.int64), data, (int(n_edges), n_faces))


def covered_box(covered):
    """``(rows, cols)`` slices of the smallest box holding every True pixel of ``covered``
    (H, W); None when there is none."""
    rows = np.flatnonzero(covered.any(axis=1))
    if not rows.size:
        return None
    cols = np.flatnonzero(covered[rows[0] : rows[-1] + 1].any(axis=0))
    return slice(int(rows[0]), int(rows[-1]) + 1), slice(int(cols[0]), int(cols[-1]) + 1)


def check_faces(faces, n_vertices=None):
    """Validate a triangle index array and return it as int64 of shape (F, 3)."""
    faces = np.asarray(faces)
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"faces must have shape (F, 3), got {faces.shape}")
    if faces.size and not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"faces must hold integer vertex indices, got dtype {faces.dtype}")
    faces = faces.astype(np.int64, copy=False)
    if faces.size and faces.min() < 0:
        raise ValueError("faces hold a negative vertex index")
    if n_vertices is not None and faces.size and faces.max() >= n_vertices:
        raise ValueError(
            f"faces refer to vertex {faces.max()} but only {n_vertices} vertices were given"
        )
    return faces


def mesh_edge_topology(faces):
    """Edge-face incidence of a triangle mesh (once per mesh).

    Parameters
    ----------
    faces : array_like of shape (F, 3)
        Vertex indices. Any mesh: open, non-manifold or inconsistently oriented ones are fine
        (such edges simply do not cancel, which costs time, not exactness).

    Returns
    -------
    EdgeTopology
    """
    faces = check_faces(faces)
    n_faces = len(faces)
    a = faces.reshape(-1)
    b = faces[:, [1, 2, 0]].reshape(-1)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    direction = np.where(a < b, 1, -1).astype(np.int8)
    if len(lo) and jit.compiled():  # the same table, compiled (imaging/_raster_kernels.py)
        edges_lo, edges_hi, edge_of = edge_table_kernel(
            np.ascontiguousarray(lo, np.int64),
            np.ascontiguousarray(hi, np.int64),
            int(hi.max()) + 1,
        )
        edges = np.column_stack([edges_lo, edges_hi])
    elif len(lo):
        # One int64 key per edge sorts like the (lo, hi) rows, and far faster.
        n_vertices = int(hi.max()) + 1
        keys, edge_of = np.unique(lo * n_vertices + hi, return_inverse=True)
        edges = np.column_stack([keys // n_vertices, keys % n_vertices])
    else:
        edges, edge_of = np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    return EdgeTopology(
        faces=faces,
        edges=edges,
        incidence=edge_incidence(edge_of.reshape(-1), direction.astype(np.float64), len(edges)),
        corners=np.ascontiguousarray(faces.T),
        edges_a=np.ascontiguousarray(edges[:, 0]),
        edges_b=np.ascontiguousarray(edges[:, 1]),
        face_edges=np.ascontiguousarray(edge_of.reshape(n_faces, 3), dtype=np.int64),
        face_dirs=direction.astype(np.float64).reshape(n_faces, 3),
    )


def face_orientations(u, v, corners, with_reach=False):
    """Sign of each projected triangle's area.

    Parameters
    ----------
    u, v : ndarray of shape (S, V)
        Projected vertex coordinates (C-contiguous for speed).
    corners : ndarray of shape (3, F)
        The faces, transposed (``faces.T``, C-contiguous for speed).
    with_reach : bool
        Also return each triangle's squared reach from its first vertex.

    Returns
    -------
    sign : ndarray of shape (S, F)
        +1, -1, or 0 for a degenerate triangle or one with a NaN vertex (behind the camera);
        a zero face covers nothing.
    reach2 : ndarray of shape (S, F), only with ``with_reach``
        ``max(|p1 - p0|, |p2 - p0|) ** 2``: every point of the triangle lies within this
        distance of its first vertex ``p0``.
    """
    f0, f1, f2 = corners
    u0, v0 = np.take(u, f0, axis=1), np.take(v, f0, axis=1)
    du1, dv1 = np.take(u, f1, axis=1) - u0, np.take(v, f1, axis=1) - v0
    du2, dv2 = np.take(u, f2, axis=1) - u0, np.take(v, f2, axis=1) - v0
    sign = np.sign(du1 * dv2 - du2 * dv1)
    sign[np.isnan(sign)] = 0.0
    if not with_reach:
        return sign
    reach2 = np.maximum(du1 * du1 + dv1 * dv1, du2 * du2 + dv2 * dv2)
    return sign, reach2


def contour_edges(sign, topology):
    """Directed contour edges (silhouettes and open borders) of projected meshes.

    Parameters
    ----------
    sign : ndarray of shape (S, F)
        Face orientation signs (:func:`face_orientations`); a 0 drops the face.
    topology : EdgeTopology

    Returns
    -------
    member : ndarray of shape (K,)
        Which of the S projections each edge belongs to.
    start, end : ndarray of shape (K,)
        Vertex indices; the edge runs ``start -> end`` with the winding weight ``weight``.
    weight : ndarray of shape (K,) of int64
        Net multiplicity (non-zero).
    """
    mult = topology.incidence @ sign.T  # (E, S)
    flat = np.flatnonzero(mult != 0)  # (a bool array is several times faster to scan)
    if mult.shape[1] == 1:
        edge, member = flat, np.zeros(len(flat), np.int64)
    else:
        edge, member = np.divmod(flat, mult.shape[1])
    weight = np.take(mult, flat).astype(np.int64)
    return member, np.take(topology.edges_a, edge), np.take(topology.edges_b, edge), weight


@dataclass(frozen=True)
class Crossings:
    """Scanline crossings of contour edges, sorted by (member, row, column).

    Attributes
    ----------
    member, row, column : ndarray of shape (N,) of int64
        ``column`` is the first pixel column whose centre lies right of the crossing, clipped to
        ``col_range``.
    winding : ndarray of shape (N,)
        Winding number of the pixels from ``column[k]`` (inclusive) to ``column[k + 1]``
        (exclusive), on row ``row[k]``; 0 after the last crossing of a row.
    """

    member: np.ndarray
    row: np.ndarray
    column: np.ndarray
    winding: np.ndarray


def _empty_crossings():
    empty = np.zeros(0, np.int64)
    return Crossings(empty, empty, empty, empty)


def _bits(n):
    return max(1, int(n - 1).bit_length())


def scan_crossings(uv, topology, row_range, col_range, sign=None):
    """Per-row winding intervals of the union of projected triangles.

    Parameters
    ----------
    uv : ndarray of shape (S, V, 2)
        Projected vertices (u = column, v = row); NaN rows are vertices behind the camera.
    topology : EdgeTopology
    row_range : (int, int)
        Only rows ``lo <= row < hi`` are scanned (the image, say).
    col_range : (int, int)
        Columns are clipped to ``[lo, hi]``.
    sign : ndarray of shape (S, F), optional
        Face orientation signs, if already computed; zeros drop faces.

    Returns
    -------
    Crossings
    """
    u = np.ascontiguousarray(uv[..., 0])
    v = np.ascontiguousarray(uv[..., 1])
    if sign is None:
        sign = face_orientations(u, v, topology.corners)
    bits = _bits(row_range[1] - row_range[0]) + _bits(col_range[1] - col_range[0] + 1)
    if bits + _bits(uv.shape[0]) + 2 > 62:
        raise ValueError("scan window too large; clip row_range/col_range to the image")
    if jit.compiled():
        member, row, column, winding = scan_kernel(
            u,
            v,
            np.ascontiguousarray(sign, dtype=np.float64),
            topology.face_edges,
            topology.face_dirs,
            topology.edges_a,
            topology.edges_b,
            int(row_range[0]),
            int(row_range[1]),
            int(col_range[0]),
            int(col_range[1]),
        )
        return Crossings(member, row, column, winding)
    return _scan_crossings_numpy(u, v, sign, topology, row_range, col_range)


def _scan_crossings_numpy(u, v, sign, topology, row_range, col_range):
    """:func:`scan_crossings` in numpy (the reference of the compiled kernel)."""
    n_members, n_vertices = u.shape
    member, a, b, weight = contour_edges(sign, topology)
    ia, ib = member * n_vertices + a, member * n_vertices + b
    u, v = u.reshape(-1), v.reshape(-1)
    ua, va, ub, vb = np.take(u, ia), np.take(v, ia), np.take(u, ib), np.take(v, ib)
    down = vb > va
    r0 = np.maximum(np.ceil(np.minimum(va, vb)), row_range[0])
    r1 = np.minimum(np.ceil(np.maximum(va, vb)), row_range[1])  # vmin <= row < vmax
    count = (r1 - r0).astype(np.int64)
    keep = np.flatnonzero(count > 0)
    count = np.take(count, keep)
    total = int(count.sum())
    if total == 0:
        return _empty_crossings()
    ua, va, ub, vb, r0 = (np.take(x, keep) for x in (ua, va, ub, vb, r0))
    slope = (ub - ua) / (vb - va)
    local = np.repeat(np.arange(len(keep)), count)
    step = np.arange(total) - np.take(np.cumsum(count) - count, local)
    row = np.take(r0, local) + step
    u_cross = np.take(ua, local) + (row - np.take(va, local)) * np.take(slope, local)
    column = np.ceil(np.clip(u_cross, col_range[0], col_range[1])).astype(np.int64)
    column -= col_range[0]
    row = row.astype(np.int64) - row_range[0]
    weight = np.take(weight, keep)
    delta = np.where(np.take(down, keep), weight, -weight)
    # One sort key (member, row, column, delta) in bit fields; the small delta rides in the low
    # bits so a plain (SIMD) sort replaces an argsort.
    half = int(np.abs(delta).max())
    d_bits = _bits(2 * half + 1)
    c_bits = _bits(col_range[1] - col_range[0] + 1)
    r_bits = _bits(row_range[1] - row_range[0])
    if d_bits + c_bits + r_bits + _bits(n_members) > 62:
        raise ValueError("scan window too large; clip row_range/col_range to the image")
    edge_key = (np.take(member, keep) << (r_bits + c_bits + d_bits)) | (delta + half)
    key = np.take(edge_key, local) | (((row << c_bits) | column) << d_bits)
    key.sort()
    winding = np.cumsum((key & ((1 << d_bits) - 1)) - half)
    key >>= d_bits
    column = (key & ((1 << c_bits) - 1)) + col_range[0]
    key >>= c_bits
    row = (key & ((1 << r_bits) - 1)) + row_range[0]
    # Every row of every member sums to zero, so one running sum is the per-row winding.
    return Crossings(key >> r_bits, row, column, winding)


def winding_intervals(crossings):
    """Covered runs ``[start, stop)`` on each row: the union's pixels, run-length encoded.

    Returns
    -------
    member, row, start, stop : ndarray of shape (R,)
        Adjacent runs of one row may touch; runs have positive length.
    """
    c = crossings
    if len(c.row) < 2:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty, empty
    start, stop = c.column[:-1], c.column[1:]
    sel = np.flatnonzero((c.winding[:-1] != 0) & (stop > start))
    return np.take(c.member, sel), np.take(c.row, sel), np.take(start, sel), np.take(stop, sel)


#: Pixels per block of rows when a union raster is accumulated (bounds its temporaries).
RASTER_BLOCK_PIXELS = 1 << 20


def rasterise_union(uv, topology, shape):
    """Boolean raster of the union of projected triangles.

    Parameters
    ----------
    uv : ndarray of shape (V, 2)
    topology : EdgeTopology
    shape : (int, int)
        ``(height, width)`` of the image; pixels outside it are not represented.

    Returns
    -------
    mask : ndarray of shape (height, width), bool
    """
    height, width = int(shape[0]), int(shape[1])
    uv = np.asarray(uv, dtype=float)[None]
    c = scan_crossings(uv, topology, row_range=(0, height), col_range=(0, width))
    _, row, start, stop = winding_intervals(c)
    mask = np.zeros((height, width), bool)
    if len(row) == 0:
        return mask
    # Interval ends counted per row and summed along it, over blocks of rows: the int64
    # temporaries stay at RASTER_BLOCK_PIXELS whatever the image's size.
    step = max(1, RASTER_BLOCK_PIXELS // (width + 1))
    for r0 in range(int(row.min()), int(row.max()) + 1, step):
        r1 = min(r0 + step, height)
        sel = (row >= r0) & (row < r1)
        n = (r1 - r0) * (width + 1)
        base = (row[sel] - r0) * (width + 1)
        diff = np.bincount(base + start[sel], minlength=n) - np.bincount(
            base + stop[sel], minlength=n
        )
        mask[r0:r1] = np.cumsum(diff.reshape(r1 - r0, width + 1), axis=1)[:, :width] > 0
    return mask


def _check_uv(uv):
    uv = np.asarray(uv, dtype=float)
    if uv.ndim != 2 or uv.shape[-1] != 2:
        raise ValueError(f"uv must have shape (V, 2), got {uv.shape}")
    return uv


def check_topology(faces, topology):
    """The :class:`EdgeTopology` of ``faces``: ``topology`` when given (checked), else built."""
    if topology is not None:
        if faces is not None and len(faces) != topology.n_faces:
            raise ValueError(
                f"topology was built for {topology.n_faces} faces but {len(faces)} were given"
            )
        return topology
    if faces is None:
        raise ValueError("give the mesh faces or its topology")
    return cached_topology(faces)


def content_key(*arrays):
    """A key that identifies arrays by their dtype, shape and content (SHA-256 digests: with
    the CPU's SHA instructions about twice as fast as BLAKE2, 10 against 19 ms for the faces of
    a 600k-face mesh; a case looks its skull up about ten times)."""
    key = []
    for a in arrays:
        a = np.ascontiguousarray(a)
        key += [a.dtype.str, a.shape, hashlib.sha256(a.data).digest()]
    return tuple(key)


#: Meshes whose :class:`EdgeTopology` :func:`cached_topology` keeps (the most recent ones).
TOPOLOGY_CACHE_SIZE = 4

_topologies = {}


def cached_topology(faces):
    """:func:`mesh_edge_topology` of ``faces``, kept for the last :data:`TOPOLOGY_CACHE_SIZE`
    meshes, keyed by the faces' content (a SHA-256 digest: about 10 ms for a 600k-face mesh,
    against about a second to build the topology).

    After an SFO a case rasterises the same skull under the same camera for the outside count,
    the identification terms and the report: the topology is built once for them.
    """
    faces = check_faces(faces)
    key = content_key(faces)
    topology = _topologies.pop(key, None)
    if topology is None:
        topology = mesh_edge_topology(faces)
    _topologies[key] = topology  # most recent last
    while len(_topologies) > TOPOLOGY_CACHE_SIZE:
        del _topologies[next(iter(_topologies))]
    return topology


def skull_raster(uv, faces=None, shape=None, *, topology=None):
    """The exact union raster ``S`` of a projected mesh (the one raster of every mesh mask).

    Parameters
    ----------
    uv : array_like of shape (V, 2)
        Projected vertices (u = column, v = row); NaN rows (behind the camera) drop their faces.
    faces : array_like of shape (F, 3), optional if ``topology`` is given
    shape : (int, int)
        ``(height, width)`` of the photo.
    topology : EdgeTopology, optional
        From :func:`mesh_edge_topology`, to skip recomputing it.

    Returns
    -------
    mask : ndarray of shape (height, width), bool
        Indexed ``[row, column]``.

    Examples
    --------
    >>> uv = np.array([[10.5, 10.5], [20.5, 10.5], [20.5, 20.5], [10.5, 20.5]])
    >>> int(skull_raster(uv, [[0, 1, 2], [0, 2, 3]], (40, 40)).sum())  # pixel centres 11..20
    100
    """
    if shape is None:
        raise ValueError("give the image shape (height, width)")
    uv = _check_uv(uv)
    return rasterise_union(uv, check_topology(faces, topology), shape)


def mesh_mask(vertices_mm, faces, camera, image_size_wh, *, topology=None):
    """Pixels covered by a mesh seen by a camera: :func:`skull_raster` of its projection.

    Parameters
    ----------
    vertices_mm : array_like of shape (V, 3)
        Skull-frame vertices (mm).
    faces : array_like of shape (F, 3), or None if ``topology`` is given
    camera : Camera
        Projects the vertices (NaN behind the camera: those faces cover nothing).
    image_size_wh : (int, int)
        ``(width, height)`` of the image in pixels.
    topology : EdgeTopology, optional
        From :func:`mesh_edge_topology`, to skip recomputing it.

    Returns
    -------
    mask : ndarray of shape (height, width), bool
        Indexed ``[row, column]``.
    """
    width, height = (int(s) for s in image_size_wh)
    uv = camera.project(np.asarray(vertices_mm, dtype=float))
    return skull_raster(uv, faces, (height, width), topology=topology)
