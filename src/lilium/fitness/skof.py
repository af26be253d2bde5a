"""P_skof, the skull-outside-face term of docs/method/lilium.md: ``100 * |S \\ F|``.

``S`` is the union of the projected skull triangles rasterised at the photo's resolution (pixel
centres, see :mod:`lilium.imaging.raster` for the rule), clipped to the photo: pixels beyond the
image border are not pixels of the photo, so a vault cut off by the frame costs nothing (the face
mask of such a photo reaches the border too). ``F`` is the face mask.

Method and measured cost. No per-triangle loop: the union is the non-zero-winding region of
the mesh's *contour edges* (silhouettes and open borders, found by one sparse product from the
per-face orientation signs), scanned row by row; the pixels outside ``F`` inside each covered
run are read from a per-row prefix count of the non-face pixels, computed once per photo, so
the cost does not depend on the covered area. Triangles that the mask's distance transform
proves to lie inside ``F`` are dropped first (``S \\ F`` is the union of the ``T \\ F``, so this
changes nothing). The count is exact: ``benchmarks/bench_raster.py`` (closed bumpy ellipsoids
of 3k, 20k and 50k faces projected to about 600 x 800 px in a 1600 x 2400 image, 30-36 % of
the skull outside an elliptical mask, three poses each) finds 0 pixels of difference against
the per-triangle closed-triangle union in all nine cases. CPU time per call, measured on a
shared 2-core machine under load (where OpenCV's per-triangle ``fillConvexPoly`` loop took
7-29 ms at 3k faces and 36-83 ms at 20k-50k): 0.65-0.69 ms at 3k, 1.3-2.5 ms at 20k,
2.6-3.4 ms at 50k faces; with the skull inside the mask 0.2, 0.8 and 1.7 ms. That loop's own
union differs by its fill rule (it also paints pixels the edges merely graze: about +0.26 % of
``S`` here). Lilium counts on the full skull with :func:`skull_outside_pixels_cameras`, which
skips whole clusters of faces the same way before projecting them (compiled).
"""

from dataclasses import dataclass

import numpy as np

from .. import jit
from ..imaging.raster import (
    EdgeTopology,
    check_faces,
    check_topology,
    face_orientations,
    mesh_edge_topology,
    scan_crossings,
    skull_raster,  # noqa: F401 - the raster S itself, re-exported next to the count
    winding_intervals,
)
from ._skof_kernels import (
    FaceClusters,
    SkofScratch,
    face_clusters,
    outside_pixels_kernel,
    project_vertices,
    squared_distance_to_background,
)

#: Weight of the outside-pixel count in P_skof (docs/method/lilium.md).
SKOF_WEIGHT = 100.0

#: Members x faces processed at once by :func:`skull_outside_pixels_batch` (cache-sized).
BATCH_FACE_BUDGET = 60_000


@dataclass(frozen=True)
class FaceMaskIndex:
    """Per-row prefix counts of the non-face pixels of a photo (once per photo).

    Attributes
    ----------
    shape : (int, int)
        ``(height, width)`` of the photo.
    outside_prefix : ndarray of shape (height, width + 1)
        ``outside_prefix[r, c]`` = number of pixels of row ``r`` with column ``< c`` that are
        not in the face mask.
    clearance2 : ndarray of shape ((height + 2) * (width + 2),)
        Flattened, with a ring of zeros around the image: ``max(D - sqrt(1/2) - 1e-6, 0) ** 2``
        with ``D`` the Euclidean distance from the pixel centre to the nearest non-face pixel
        centre (pixels beyond the image border do not count): a triangle whose vertex rounds to
        this pixel and that reaches less than ``sqrt(clearance2)`` from that vertex holds no
        non-face pixel centre.
    """

    shape: tuple
    outside_prefix: np.ndarray
    clearance2: np.ndarray


def check_face_mask(face_mask):
    """Validate a face mask and return it as a 2D bool array (non-zero = face)."""
    mask = np.asarray(face_mask)
    if mask.ndim != 2:
        raise ValueError(
            f"face_mask must be a 2D (rows, columns) array, got shape {mask.shape}; "
            "convert a colour mask to one channel first"
        )
    return mask != 0


def face_mask_index(face_mask):
    """Precompute the :class:`FaceMaskIndex` of a face mask.

    Parameters
    ----------
    face_mask : array_like of shape (height, width)
        Non-zero = face/head pixel, indexed ``[row, column]``.
    """
    if isinstance(face_mask, FaceMaskIndex):
        return face_mask
    mask = check_face_mask(face_mask)
    height, width = mask.shape
    prefix = np.zeros((height, width + 1), np.int32)
    np.cumsum(~mask, axis=1, out=prefix[:, 1:])
    if mask.all():
        clearance = np.full(mask.shape, np.inf)
    else:
        if jit.compiled():
            distance = np.sqrt(squared_distance_to_background(mask))
        else:
            from scipy import ndimage  # the numpy reference path only

            distance = ndimage.distance_transform_edt(mask)
        clearance = np.maximum(distance - np.sqrt(0.5) - 1e-6, 0.0) ** 2
    return FaceMaskIndex(
        shape=(height, width), outside_prefix=prefix, clearance2=np.pad(clearance, 1).reshape(-1)
    )


@dataclass(frozen=True)
class SkofContext:
    """Everything P_skof needs that is fixed during one SFO.

    Attributes
    ----------
    topology : EdgeTopology
        Of the skull's faces (in cluster order when ``clusters`` is set).
    mask_index : FaceMaskIndex
    vertices_mm : ndarray of shape (V, 3) or None
        The skull's vertices, for :func:`skull_outside_pixels_cameras`.
    clusters : FaceClusters or None
        The faces' Morton clusters (:mod:`lilium.fitness._skof_kernels`).
    scratch : SkofScratch or None
        The compiled count's scratch arrays (with the clusters; one context per SFO, not for
        concurrent use).
    """

    topology: EdgeTopology
    mask_index: FaceMaskIndex
    vertices_mm: np.ndarray | None = None
    clusters: FaceClusters | None = None
    scratch: SkofScratch | None = None


def prepare_skof(faces, face_mask, vertices_mm=None):
    """Build the :class:`SkofContext` of a skull mesh and a face mask (once per SFO).

    With ``vertices_mm`` the faces are also clustered (:func:`face_clusters`) for
    :func:`skull_outside_pixels_cameras`.
    """
    faces = check_faces(faces, None if vertices_mm is None else len(vertices_mm))
    if vertices_mm is None:
        return SkofContext(mesh_edge_topology(faces), face_mask_index(face_mask))
    vertices_mm = np.ascontiguousarray(vertices_mm, dtype=float)
    clusters = face_clusters(vertices_mm, faces)
    topology = mesh_edge_topology(faces[clusters.order])
    scratch = SkofScratch(len(vertices_mm), len(topology.edges_a))
    return SkofContext(topology, face_mask_index(face_mask), vertices_mm, clusters, scratch)


def skull_outside_pixels_cameras(context, R, t, focal_px, principal_point_px):
    """``|S \\ F|`` of the full skull under S cameras (exact; P_skof's count).

    Compiled: only the clusters of faces that can reach a non-face pixel are projected and
    rasterised (:mod:`lilium.fitness._skof_kernels`). Numpy path: every vertex projected
    (:func:`~lilium.fitness._skof_kernels.project_vertices`, the same rounding) and
    :func:`skull_outside_pixels_batch`. Both give the same counts.

    Parameters
    ----------
    context : SkofContext
        From :func:`prepare_skof` with the skull's vertices.
    R : array_like of shape (S, 3, 3)
    t : array_like of shape (S, 3)
        Skull-to-camera rotation and translation (mm).
    focal_px : array_like of shape (S,)
    principal_point_px : array_like of shape (2,)

    Returns
    -------
    count : ndarray of shape (S,) of int64
    """
    if context.clusters is None:
        raise ValueError("build the SkofContext with the skull's vertices (prepare_skof)")
    R = np.ascontiguousarray(R, dtype=float).reshape(-1, 3, 3)
    t = np.ascontiguousarray(t, dtype=float).reshape(-1, 3)
    f = np.ascontiguousarray(focal_px, dtype=float).reshape(-1)
    c = np.asarray(principal_point_px, dtype=float)
    if not jit.compiled():
        uv = project_vertices(context.vertices_mm, R, t, f, c)
        return skull_outside_pixels_batch(
            uv, topology=context.topology, mask_index=context.mask_index
        )
    topo, cl, index = context.topology, context.clusters, context.mask_index
    scratch = context.scratch
    if scratch is None:  # a context made by hand: scratch for this call only
        scratch = SkofScratch(len(context.vertices_mm), len(topo.edges_a))
    count, _ = outside_pixels_kernel(
        context.vertices_mm,
        topo.faces,
        topo.face_edges,
        topo.face_dirs,
        topo.edges_a,
        topo.edges_b,
        cl.node_sphere,
        cl.node_faces,
        cl.node_children,
        R,
        t,
        f,
        float(c[0]),
        float(c[1]),
        index.clearance2,
        index.outside_prefix,
        scratch.vstamp,
        scratch.mark,
        scratch.mult,
        scratch.touched,
        scratch.u,
        scratch.v,
        scratch.stamps(len(R)),
    )
    return count


def _check_uv(uv, batched):
    uv = np.asarray(uv, dtype=float)
    want = 3 if batched else 2
    if uv.ndim != want or uv.shape[-1] != 2:
        raise ValueError(
            f"uv must have shape {'(S, V, 2)' if batched else '(V, 2)'}, got {uv.shape}"
        )
    return uv


def _signs_outside_interior(uv, topology, mask_index):
    """Face signs with the faces that certainly hold no non-face pixel set to 0.

    ``S \\ F`` is the union of ``T \\ F`` over the triangles ``T``, so dropping triangles
    that lie inside ``F`` leaves it unchanged (exact, not an approximation).
    """
    height, width = mask_index.shape
    u = np.ascontiguousarray(uv[..., 0])
    v = np.ascontiguousarray(uv[..., 1])
    sign, reach2 = face_orientations(u, v, topology.corners, with_reach=True)
    # Vertices off the image (and NaN ones: fmax/fmin drop NaN) land on the ring of zeros.
    col = np.fmin(np.fmax(np.rint(u), -1.0), width) + 1.0
    row = np.fmin(np.fmax(np.rint(v), -1.0), height) + 1.0
    pixel = (row * (width + 2) + col).astype(np.int64)
    clearance2 = np.take(mask_index.clearance2, pixel)
    sign *= np.take(clearance2, topology.corners[0], axis=1) <= reach2
    return sign


def skull_outside_pixels_batch(
    uv, faces=None, face_mask=None, *, topology=None, mask_index=None, cull=True
):
    """``|S \\ F|`` for many projections of one mesh at once.

    Parameters
    ----------
    uv : array_like of shape (S, V, 2)
        Projected skull vertices (u = column, v = row), NaN behind the camera (such faces
        are dropped).
    faces : array_like of shape (F, 3), optional if ``topology`` is given
    face_mask : array_like of shape (height, width), optional if ``mask_index`` is given
    topology : EdgeTopology, optional
        From :func:`mesh_edge_topology`, to skip recomputing it.
    mask_index : FaceMaskIndex, optional
        From :func:`face_mask_index`, to skip recomputing it.
    cull : bool
        Skip the triangles that the mask's distance transform proves to lie inside the face
        (exact; faster when most of the skull is inside).

    Returns
    -------
    count : ndarray of shape (S,) of int64
        Pixels of the photo covered by the projected skull and not in the face mask.
    """
    uv = _check_uv(uv, batched=True)
    topology = check_topology(faces, topology)
    if mask_index is None:
        if face_mask is None:
            raise ValueError("give face_mask or mask_index")
        mask_index = face_mask_index(face_mask)
    height, width = mask_index.shape
    flat = mask_index.outside_prefix.reshape(-1)
    count = np.zeros(len(uv), np.int64)
    # Chunks keep the (members x faces) temporaries in cache.
    chunk = max(1, BATCH_FACE_BUDGET // max(1, topology.n_faces))
    for first in range(0, len(uv), chunk):
        part = uv[first : first + chunk]
        sign = _signs_outside_interior(part, topology, mask_index) if cull else None
        c = scan_crossings(part, topology, (0, height), (0, width), sign=sign)
        member, row, start, stop = winding_intervals(c)
        base = row * (width + 1)
        outside = np.take(flat, base + stop).astype(np.int64) - np.take(flat, base + start)
        count[first : first + chunk] = np.bincount(member, weights=outside, minlength=len(part))
    return count


def skull_outside_pixels(
    uv, faces=None, face_mask=None, *, topology=None, mask_index=None, cull=True
):
    """``|S \\ F|``: pixels covered by the projected skull that are not face pixels.

    Parameters
    ----------
    uv : array_like of shape (V, 2)
        Projected skull vertices (u = column, v = row).
    faces : array_like of shape (F, 3), optional if ``topology`` is given
    face_mask : array_like of shape (height, width), optional if ``mask_index`` is given
    topology, mask_index : optional precomputations (see :func:`prepare_skof`).
    cull : bool
        See :func:`skull_outside_pixels_batch`.

    Returns
    -------
    count : int

    Examples
    --------
    >>> uv = np.array([[10.5, 10.5], [20.5, 10.5], [20.5, 20.5], [10.5, 20.5]])
    >>> square = np.array([[0, 1, 2], [0, 2, 3]])
    >>> mask = np.zeros((40, 40), bool); mask[:, :16] = True
    >>> skull_outside_pixels(uv, square, mask)  # columns 16..20 of rows 11..20
    50
    """
    uv = _check_uv(uv, batched=False)
    return int(
        skull_outside_pixels_batch(
            uv[None], faces, face_mask, topology=topology, mask_index=mask_index, cull=cull
        )[0]
    )


def skof_penalty(outside_pixels):
    """P_skof = ``100 * |S \\ F|`` (works on scalars and arrays)."""
    return SKOF_WEIGHT * np.asarray(outside_pixels, dtype=float)
