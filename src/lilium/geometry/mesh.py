"""Triangle-mesh operations: connected components, compaction, quadric decimation, the distance
of points to a surface.

Pure functions over ``vertices (V, 3)`` and ``faces (F, 3)``, used by the CT importer, the
synthetic generator and the fitness terms alike.
"""

import numpy as np

from .. import jit
from ..constants import PART_APART_MM
from ._mesh_kernels import cluster_kernel, component_kernel

#: A skull in millimetres spans roughly 100-300 mm (an adult's length 170-210 mm, a mandible
#: alone about 100 mm); outside this range the unit is wrong. The lower bound refuses a skull in
#: centimetres (13-22 units), which the landmark checks cannot catch when its landmarks are in
#: centimetres too: the depth table in mm then makes the soft tissue ten times too thick, and the
#: true person was excluded.
PLAUSIBLE_EXTENT_MM = (30.0, 1000.0)


def face_components(faces, n_vertices):
    """The connected component of each face (faces sharing a vertex are connected).

    Parameters
    ----------
    faces : ndarray of shape (F, 3), int
    n_vertices : int

    Returns
    -------
    ndarray of shape (F,), int64
        Components numbered 0, 1, ... in the order of their smallest vertex index.
    """
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    if len(faces) == 0:
        return np.zeros(0, np.int64)
    if jit.compiled():  # union-find (geometry/_mesh_kernels.py); the same partition
        roots = component_kernel(faces, int(n_vertices))
    else:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        rows = np.concatenate([faces[:, 0], faces[:, 1], faces[:, 2]])
        cols = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
        graph = coo_matrix(
            (np.ones(len(rows), dtype=np.int8), (rows, cols)), shape=(n_vertices, n_vertices)
        )
        _, labels = connected_components(graph, directed=False)
        vertex_root = np.full(int(labels.max()) + 1, n_vertices)
        np.minimum.at(vertex_root, labels, np.arange(n_vertices))
        roots = vertex_root[labels[faces[:, 0]]]
    if np.all(roots == roots[0]):
        return np.zeros(len(faces), np.int64)  # one piece (most meshes): no sort
    return np.unique(roots, return_inverse=True)[1].reshape(-1).astype(np.int64)


def largest_component(faces, n_vertices):
    """The faces of the connected component with the most faces, and the face counts of the
    others.

    Parameters
    ----------
    faces : ndarray of shape (F, 3), int (F >= 1)
    n_vertices : int

    Returns
    -------
    largest : ndarray of shape (F,), bool
    others : tuple of int
        Largest first.
    """
    labels = face_components(faces, n_vertices)
    counts = np.bincount(labels)
    keep_label = int(np.argmax(counts))
    others = sorted((int(n) for k, n in enumerate(counts) if k != keep_label), reverse=True)
    return labels == keep_label, tuple(others)


def keep_largest_component(vertices, faces):
    """Keep the connected component with the most faces (vertices re-indexed).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int

    Returns
    -------
    vertices : ndarray of shape (V', 3)
    faces : ndarray of shape (F', 3)
    """
    if len(faces) == 0:
        return vertices, faces
    return compact(vertices, faces[largest_component(faces, len(vertices))[0]])


def parts_apart(vertices, faces, anchors, gap_mm):
    """The connected parts of a mesh that lie apart from the part holding ``anchors``.

    The skull grows from the parts holding the vertex nearest to each anchor: any part whose
    bounding box comes within ``gap_mm`` of the grown bounding box joins it, until none does.
    So a mesh split into pieces that touch (an STL's loose triangles, an OBJ cut along its
    texture seams, a separate mandible) stays whole, and only what lies beyond ``gap_mm`` of
    everything else is apart.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    anchors : ndarray of shape (A, 3) or None
        Points on the part to keep (a skull's cranial landmarks), A >= 1; None: the part
        with the most faces.
    gap_mm : float

    Returns
    -------
    apart : ndarray of shape (F,), bool
        The faces of the parts apart (all False for a mesh of one piece).
    parts : list of (int, float)
        Each part apart: its face count and the gap between its bounding box and the kept
        one's, largest gap first.
    """
    labels = face_components(faces, len(vertices))
    n = int(labels.max()) + 1 if len(labels) else 0
    if n <= 1:
        return np.zeros(len(faces), bool), []
    corner_label = np.repeat(labels, 3)
    corners = np.asarray(faces).reshape(-1)
    lo = np.full((n, 3), np.inf)
    hi = np.full((n, 3), -np.inf)
    np.minimum.at(lo, corner_label, vertices[corners])
    np.maximum.at(hi, corner_label, vertices[corners])
    counts = np.bincount(labels, minlength=n)
    kept = np.zeros(n, bool)
    if anchors is None:
        kept[np.argmax(counts)] = True
    else:
        vertex_label = np.full(len(vertices), -1)
        vertex_label[corners] = corner_label
        used = np.flatnonzero(vertex_label >= 0)
        for point in np.asarray(anchors, float):
            nearest = used[np.argmin(np.sum((vertices[used] - point) ** 2, axis=1))]
            kept[vertex_label[nearest]] = True
    while True:
        box_lo, box_hi = lo[kept].min(axis=0), hi[kept].max(axis=0)
        gap = np.linalg.norm(np.maximum(0.0, np.maximum(lo - box_hi, box_lo - hi)), axis=1)
        joining = ~kept & (gap <= gap_mm)
        if not joining.any():
            break
        kept |= joining
    parts = sorted(
        ((int(counts[c]), float(gap[c])) for c in np.flatnonzero(~kept)), key=lambda p: -p[1]
    )
    return ~kept[labels], parts


def weld(vertices, faces):
    """Merge the vertices at exactly one position into one (the first's place in the order).

    An STL holds every triangle with vertices of its own, and an OBJ is often split along its
    texture seams: welded, the mesh is connected again (its silhouettes, contours and parts are
    the surface's, not each triangle's). A mesh without duplicates comes back unchanged.

    Returns
    -------
    vertices : ndarray of shape (V', 3)
    faces : ndarray of shape (F, 3), int64
    """
    v = np.ascontiguousarray(vertices, dtype=float)
    key = v.view(np.dtype((np.void, v.dtype.itemsize * 3))).reshape(-1)
    _, first, inverse = np.unique(key, return_index=True, return_inverse=True)
    if len(first) == len(v):
        return vertices, faces
    order = np.argsort(first)
    rank = np.empty(len(first), np.int64)
    rank[order] = np.arange(len(first))
    return v[first[order]], rank[inverse.reshape(-1)][np.asarray(faces, dtype=np.int64)]


def compact(vertices, faces):
    """Drop unreferenced vertices and re-index the faces (the vertices keep their order); a
    mesh whose every vertex is referenced comes back as it is (its faces int64, contiguous)."""
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    used = np.zeros(len(vertices), bool)
    used[faces.reshape(-1)] = True
    if used.all():
        return vertices, faces
    index = np.cumsum(used) - 1
    return vertices[used], index[faces]


def open_edge_points(vertices, faces, min_length_mm):
    """The vertices on the mesh's open edges (edges of one face) that run at least
    ``min_length_mm`` in one piece: a cut or a missing region, not a pinhole's rim.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    min_length_mm : float
        Total length of a connected run of open edges, below which it is left out.

    Returns
    -------
    ndarray of shape (K, 3)
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(vertices)
    edges = np.sort(np.asarray(faces, np.int64)[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    key, count = np.unique(edges[:, 0] * n + edges[:, 1], return_counts=True)  # one int per edge
    open_ = np.column_stack(np.divmod(key[count == 1], n))
    if not len(open_):
        return np.empty((0, 3))
    graph = coo_matrix((np.ones(len(open_)), (open_[:, 0], open_[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    run = label[open_[:, 0]]
    length = np.linalg.norm(vertices[open_[:, 0]] - vertices[open_[:, 1]], axis=1)
    long_run = np.bincount(run, weights=length, minlength=n)[run] >= min_length_mm
    return vertices[np.unique(open_[long_run].reshape(-1))]


def gaps_beyond(points, vertices, faces, tolerance_mm):
    """The points farther than ``tolerance_mm`` from a triangle surface, with their distance.

    Cheap first: a point within ``tolerance_mm`` of a sample of the vertices (a CT skull's mesh
    has hundreds of thousands), or of some vertex, is near enough; the rest are measured to the
    triangles themselves (:func:`point_surface_distance`: a coarse mesh has vertices far apart).

    Parameters
    ----------
    points : dict of str -> ndarray of shape (3,)
        Named points, in the mesh's frame and units.
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    tolerance_mm : float

    Returns
    -------
    dict of str -> float
        The points farther than ``tolerance_mm`` and their distance to the surface, in the
        order of ``points``.
    """
    sample = vertices[:: max(1, len(vertices) // 20_000)]
    far = {}
    for name, p in points.items():
        gap = np.min(np.linalg.norm(sample - p, axis=1))  # >= the whole mesh's gap
        if gap > tolerance_mm:
            gap = np.min(np.linalg.norm(vertices - p, axis=1))
        if gap > tolerance_mm:
            gap = point_surface_distance(p[None], vertices, faces)[0]
        if gap > tolerance_mm:
            far[name] = gap
    return far


#: A landmark farther than this share of the mesh's largest extent from its surface is not on
#: it: another frame or unit (:func:`check_landmarks_on_mesh`).
OFF_MESH_FRACTION = 0.1


def check_landmarks_on_mesh(landmarks, vertices, faces, source):
    """Raise a ``ValueError`` naming ``source`` (the landmarks' file) and the first landmark
    farther than :data:`OFF_MESH_FRACTION` of the mesh's extent from its surface."""
    extent = np.ptp(vertices, axis=0).max()
    off_mesh = gaps_beyond(landmarks, vertices, faces, OFF_MESH_FRACTION * extent)
    if off_mesh:  # the first, in the file's order
        name, gap = next(iter(off_mesh.items()))
        raise ValueError(
            f"{source}: landmarks.{name} lies {gap:.0f} mm from the skull mesh; landmarks "
            "must be in the mesh's frame and units"
        )


def point_surface_distance(points, vertices, faces):
    """Distance of each point to the nearest point of a triangle surface (not only its vertices).

    Brute force over every face (about 50 ms per point for 600k faces): for the few points
    whose nearest vertex is not close enough to settle it.

    Parameters
    ----------
    points : ndarray of shape (P, 3)
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int

    Returns
    -------
    ndarray of shape (P,)
    """
    a, b, c = (np.asarray(vertices, float)[faces[:, k]] for k in range(3))
    ab, ac = b - a, c - a
    out = np.empty(len(points))
    for i, p in enumerate(np.asarray(points, float)):
        out[i] = np.sqrt(np.min(_squared_distance_to_triangles(p, a, ab, ac)))
    return out


def _squared_distance_to_triangles(p, a, ab, ac):
    """Squared distance from ``p`` (3,) to triangles ``a + s ab + t ac`` (each (F, 3)): the
    nearest of the triangle's interior (where the plane's foot falls inside) and its three
    edges."""

    def segment(q0, d):
        dd = np.einsum("ij,ij->i", d, d)
        s = np.clip(np.einsum("ij,ij->i", p - q0, d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
        r = p - (q0 + s[:, None] * d)
        return np.einsum("ij,ij->i", r, r)

    best = np.minimum(np.minimum(segment(a, ab), segment(a, ac)), segment(a + ab, ac - ab))
    ap = p - a
    d00, d01, d11 = (np.einsum("ij,ij->i", x, y) for x, y in ((ab, ab), (ab, ac), (ac, ac)))
    d20, d21 = np.einsum("ij,ij->i", ap, ab), np.einsum("ij,ij->i", ap, ac)
    det = d00 * d11 - d01 * d01
    ok = det > 1e-12 * np.maximum(d00 * d11, 1e-300)
    det = np.where(ok, det, 1.0)
    s, t = (d11 * d20 - d01 * d21) / det, (d00 * d21 - d01 * d20) / det
    inside = ok & (s >= 0) & (t >= 0) & (s + t <= 1)
    r = ap - s[:, None] * ab - t[:, None] * ac
    return np.where(inside, np.minimum(best, np.einsum("ij,ij->i", r, r)), best)


def decimate(vertices, faces, target_faces):
    """Quadric decimation to about ``target_faces`` faces (needs ``fast-simplification``).

    Returns the input unchanged when it already has at most ``target_faces`` faces.
    """
    target_faces = int(target_faces)
    if target_faces < 4:
        raise ValueError(f"target_faces must be at least 4, got {target_faces}")
    if len(faces) <= target_faces:
        return vertices, faces
    try:
        import fast_simplification
    except ImportError as exc:
        raise ValueError(
            "decimation (target_faces) needs the optional package fast-simplification: "
            "pip install fast-simplification, or leave target_faces unset"
        ) from exc
    reduction = 1.0 - target_faces / len(faces)
    v, f = fast_simplification.simplify(
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64),
        target_reduction=reduction,
    )
    return compact(np.asarray(v, dtype=float), np.asarray(f, dtype=np.int64))


def cluster_vertices(vertices_mm, faces, cell_mm):
    """Vertex clustering: merge the vertices of each cubic cell into their mean.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    cell_mm : float

    Returns
    -------
    vertices_mm : ndarray of shape (V', 3)
    faces : ndarray of shape (F', 3), int64
        The faces whose corners stay in three different cells (orientation kept).
    """
    v = np.asarray(vertices_mm, float)
    dense_limit = 4 * len(v) + 1e6  # cells of the bounding box numbered through a table
    if jit.compiled() and len(v):  # the same steps, compiled (geometry/_mesh_kernels.py)
        faces = np.ascontiguousarray(faces, dtype=np.int64)
        return cluster_kernel(np.ascontiguousarray(v), faces, float(cell_mm), dense_limit)
    key = np.floor((v - v.min(axis=0)) / cell_mm).astype(np.int64)
    dims = key.max(axis=0) + 1
    flat = (key[:, 0] * dims[1] + key[:, 1]) * dims[2] + key[:, 2]
    if np.prod(dims.astype(float)) <= dense_limit:
        # Dense cells: ids in cell order without sorting.
        used = np.zeros(int(np.prod(dims)), bool)
        used[flat] = True
        ids = np.cumsum(used) - 1
        inverse = ids[flat]
        n = int(used.sum())
    else:
        _, inverse = np.unique(flat, return_inverse=True)
        n = int(inverse.max()) + 1
    count = np.bincount(inverse, minlength=n).astype(float)
    merged = np.stack([np.bincount(inverse, weights=v[:, k], minlength=n) for k in range(3)], 1)
    merged /= count[:, None]
    g = inverse[np.asarray(faces)]
    keep = (g[:, 0] != g[:, 1]) & (g[:, 1] != g[:, 2]) & (g[:, 0] != g[:, 2])
    return merged, np.ascontiguousarray(g[keep], dtype=np.int64)


def clean_mesh(vertices, faces, shared=False, source="mesh"):
    """A parsed mesh welded where its vertices are not shared, then checked
    (:func:`check_mesh`).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    shared : bool
        The vertices are shared as the file stored them (a binary PLY): welded only when there
        are more of them than faces (loose triangles; a closed mesh has about F / 2). Otherwise
        always welded (an STL's loose triangles, an OBJ's seams).
    source : str
        Names the mesh in the messages.

    Returns
    -------
    vertices_mm : ndarray of shape (V', 3)
    faces : ndarray of shape (F, 3), int
    """
    if (not shared or len(vertices) > len(faces)) and _indexed(vertices, faces):
        vertices, faces = weld(vertices, faces)
    check_mesh(vertices, faces, source)
    return vertices, faces


def _indexed(vertices, faces):
    """Whether the faces index existing, finite vertices (else check_mesh names the fault)."""
    valid = len(faces) and faces.min() >= 0 and faces.max() < len(vertices)
    return bool(valid) and bool(np.all(np.isfinite(vertices)))


def check_mesh(vertices_mm, faces, source="mesh"):
    """Raise a ``ValueError`` saying what is wrong if a mesh cannot be a skull in mm."""
    if len(faces) == 0 or len(vertices_mm) < 3:
        raise ValueError(f"{source}: the mesh has no triangles; export the surface, not points")
    if not np.all(np.isfinite(vertices_mm)):
        raise ValueError(f"{source}: vertex coordinates contain NaN or infinity; repair the mesh")
    if faces.min() < 0 or faces.max() >= len(vertices_mm):
        raise ValueError(f"{source}: faces index missing vertices; repair the mesh")

    def area_sum(f):
        tri = vertices_mm[f]
        return np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()

    # Areas are >= 0: a sample with area settles it (a CT skull has hundreds of thousands).
    if area_sum(faces[:: max(1, len(faces) // 20_000)]) <= 0 and area_sum(faces) <= 0:
        raise ValueError(f"{source}: degenerate mesh (all triangles have zero area)")
    used = np.zeros(len(vertices_mm), bool)
    used[faces.reshape(-1)] = True
    extent = np.ptp(vertices_mm[used], axis=0)
    if extent.min() <= 1e-3 * extent.max():
        raise ValueError(f"{source}: degenerate mesh (flat or a line, extent {extent.tolist()})")
    lo, hi = PLAUSIBLE_EXTENT_MM
    if extent.max() > hi and _largest_part_extent_mm(vertices_mm, faces) <= hi:
        return  # a skull with a part far from it: the skull reader leaves that out and says so
    if not lo <= extent.max() <= hi:
        raise ValueError(
            f"{source}: the mesh spans {extent.max():.3g} units; a skull in millimetres spans "
            f"{lo:.0f}-{hi:.0f}; rescale it to millimetres"
        )


def _largest_part_extent_mm(vertices_mm, faces):
    """Largest side of the bounding box of the mesh without its parts apart from the part with
    the most faces (:func:`~lilium.geometry.mesh.parts_apart`)."""
    apart, _ = parts_apart(vertices_mm, faces, None, PART_APART_MM)
    corners = faces[~apart].reshape(-1)
    return float(np.ptp(vertices_mm[corners], axis=0).max())
