"""Which triangle each pixel of a shaded picture shows: a compiled depth buffer (numba, see
:mod:`lilium.jit`).

The pictures' silhouettes are the exact union raster (:mod:`lilium.imaging.raster`); inside
them the shading only needs, per pixel, the triangle nearest the camera. The painter's
algorithm (OpenCV's ``fillConvexPoly`` far to near) paid about 2 us per triangle: seconds for a
600k-face CT skull, three pictures per report. Here each triangle visits only the pixel centres
of its bounding box and keeps those it covers where it is nearer than what is there (a
triangle's depth is the mean of its corners', as the painter sorted them; on a tie the later
triangle wins, as the painter's stable order painted it last). Triangles that hold no pixel
centre paint nothing (the callers give the pixels of the silhouette left unpainted a neighbour's
triangle).

:func:`surface_kernel` then computes each painted pixel's depth and normal: the numpy steps of
:func:`lilium.imaging.shading.render_surface` (its reference path) pixel by pixel, the same
numbers bit for bit on the tests' meshes.
"""

import numpy as np

from ..jit import njit


@njit
def _paint(uv, faces, depth, order, height, width):
    index = np.full((height, width), -1, np.int32)
    nearest = np.full((height, width), np.inf)
    for k in order:
        a, b, c = faces[k, 0], faces[k, 1], faces[k, 2]
        u0, v0, u1, v1, u2, v2 = uv[a, 0], uv[a, 1], uv[b, 0], uv[b, 1], uv[c, 0], uv[c, 1]
        area = (u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0)
        if not (area > 0.0 or area < 0.0):  # degenerate, or NaN (behind the camera)
            continue
        s = 1.0 if area > 0.0 else -1.0
        c0 = max(0, int(np.ceil(min(u0, u1, u2))))
        c1 = min(width - 1, int(np.floor(max(u0, u1, u2))))
        r0 = max(0, int(np.ceil(min(v0, v1, v2))))
        r1 = min(height - 1, int(np.floor(max(v0, v1, v2))))
        z = depth[k]
        for r in range(r0, r1 + 1):
            for col in range(c0, c1 + 1):
                if z > nearest[r, col]:
                    continue
                e0 = s * ((u1 - u0) * (r - v0) - (v1 - v0) * (col - u0))
                e1 = s * ((u2 - u1) * (r - v1) - (v2 - v1) * (col - u1))
                e2 = s * ((u0 - u2) * (r - v2) - (v0 - v2) * (col - u2))
                if e0 >= 0.0 and e1 >= 0.0 and e2 >= 0.0:
                    nearest[r, col] = z
                    index[r, col] = k
    return index


def nearest_face_index(uv, faces, depth_mm, shape, keep=None, covered=None):
    """Per pixel, the index of the nearest triangle covering its centre.

    Parameters
    ----------
    uv : ndarray of shape (V, 2)
        Projected vertices (u = column, v = row; pixel centres at integers), NaN behind the
        camera.
    faces : ndarray of shape (F, 3), int
    depth_mm : ndarray of shape (F,)
        Each triangle's depth key (smaller = nearer), e.g. its corners' mean camera z.
    shape : (int, int)
        ``(height, width)`` of the picture.
    keep : ndarray of shape (F,) of bool, optional
        Triangles to paint (default all).
    covered : ndarray of shape (height, width) of bool, optional
        The exact silhouette: its pixels that no triangle's centre test caught take a
        neighbour's triangle (the largest index around), and pixels outside it get -1.

    Returns
    -------
    index : ndarray of shape (height, width), int32
        -1 where no triangle covers the pixel centre (outside ``covered`` when given).
    """
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    order = np.arange(len(faces)) if keep is None else np.flatnonzero(keep)
    height, width = (int(n) for n in shape)
    index = _paint(
        np.ascontiguousarray(uv, dtype=float),
        faces,
        np.ascontiguousarray(depth_mm, dtype=float),
        order.astype(np.int64),
        height,
        width,
    )
    if covered is not None:
        gaps = covered & (index < 0)
        if gaps.any():
            import cv2  # here: the build of the kernels ahead of time has no OpenCV

            # OpenCV's dilate takes no int32: dilate a float32 copy (indices < 2^24 stay exact).
            grown = cv2.dilate(index.astype(np.float32), np.ones((3, 3), np.uint8))
            index[gaps] = grown.astype(np.int32)[gaps]
        index[~covered] = -1
    return index


@njit
def surface_kernel(rows, cols, face, uv, faces, X, normals_cam, c0, c1, focal, height, width):
    """Per covered pixel, the depth and unit normal of :func:`lilium.imaging.shading.render_surface`
    (its numpy steps, pixel by pixel in the same order: barycentric weights of the pixel centre
    clipped to the triangle, interpolated camera z and vertex normal, the face normal where the
    vertex normals cancel, turned towards the camera).

    Parameters
    ----------
    rows, cols, face : ndarray of shape (P,) of int
        The painted pixels and their triangles.
    uv : ndarray of shape (V, 2)
    faces : ndarray of shape (F, 3)
    X : ndarray of shape (V, 3)
        Vertices in the camera frame (mm).
    normals_cam : ndarray of shape (V, 3)
    c0, c1, focal : float
        Principal point and focal length (pixels).

    Returns
    -------
    depth_mm : ndarray of shape (height, width) of float32 (NaN off the skull)
    normal_cam : ndarray of shape (height, width, 3) of float32
    """
    depth_mm = np.full((height, width), np.nan, np.float32)
    normal_cam = np.zeros((height, width, 3), np.float32)
    w = np.empty(3)
    n = np.empty(3)
    for i in range(rows.shape[0]):
        r, col, k = rows[i], cols[i], face[i]
        ia, ib, ic = faces[k, 0], faces[k, 1], faces[k, 2]
        a0, a1, b0, b1, e0, e1 = uv[ia, 0], uv[ia, 1], uv[ib, 0], uv[ib, 1], uv[ic, 0], uv[ic, 1]
        p0, p1 = float(col), float(r)
        d = (b1 - e1) * (a0 - e0) + (e0 - b0) * (a1 - e1)
        if abs(d) > 1e-9:
            w0 = ((b1 - e1) * (p0 - e0) + (e0 - b0) * (p1 - e1)) / d
            w1 = ((e1 - a1) * (p0 - e0) + (a0 - e0) * (p1 - e1)) / d
            w[0], w[1], w[2] = w0, w1, 1 - w0 - w1
            for j in range(3):
                w[j] = min(max(w[j], 0.0), 1.0)
        else:
            w[0] = w[1] = w[2] = 1 / 3
        total = w[0] + w[1] + w[2]
        for j in range(3):
            w[j] = w[j] / total
        depth = w[0] * X[ia, 2] + w[1] * X[ib, 2] + w[2] * X[ic, 2]
        for j in range(3):
            n[j] = w[0] * normals_cam[ia, j] + w[1] * normals_cam[ib, j] + w[2] * normals_cam[ic, j]
        if np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) < 0.3:  # the face normal instead
            ux, uy, uz = X[ib, 0] - X[ia, 0], X[ib, 1] - X[ia, 1], X[ib, 2] - X[ia, 2]
            vx, vy, vz = X[ic, 0] - X[ia, 0], X[ic, 1] - X[ia, 1], X[ic, 2] - X[ia, 2]
            n[0], n[1], n[2] = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        length = max(np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1e-12)
        for j in range(3):
            n[j] = n[j] / length
        if n[0] * (p0 - c0) + n[1] * (p1 - c1) + n[2] * focal > 0:
            for j in range(3):
                n[j] = -n[j]
        depth_mm[r, col] = depth
        for j in range(3):
            normal_cam[r, col, j] = n[j]
    return depth_mm, normal_cam


@njit
def normals_kernel(vertices_mm, faces):
    """:func:`lilium.imaging.shading.vertex_normals` (its numpy steps in their order: each
    face's cross product, summed per vertex corner by corner in face order, normalised), the
    same numbers bit for bit."""
    V, F = vertices_mm.shape[0], faces.shape[0]
    face_n = np.empty((F, 3))
    for f in range(F):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        e0 = vertices_mm[b, 0] - vertices_mm[a, 0]
        e1 = vertices_mm[b, 1] - vertices_mm[a, 1]
        e2 = vertices_mm[b, 2] - vertices_mm[a, 2]
        g0 = vertices_mm[c, 0] - vertices_mm[a, 0]
        g1 = vertices_mm[c, 1] - vertices_mm[a, 1]
        g2 = vertices_mm[c, 2] - vertices_mm[a, 2]
        face_n[f, 0] = e1 * g2 - e2 * g1
        face_n[f, 1] = e2 * g0 - e0 * g2
        face_n[f, 2] = e0 * g1 - e1 * g0
    normals = np.zeros((V, 3))
    corner = np.empty((V, 3))
    for k in range(3):  # one bincount per corner, added in corner order
        corner[:] = 0.0
        for f in range(F):
            v = faces[f, k]
            for j in range(3):
                corner[v, j] += face_n[f, j]
        for v in range(V):
            for j in range(3):
                normals[v, j] += corner[v, j]
    for v in range(V):
        x, y, z = normals[v, 0], normals[v, 1], normals[v, 2]
        norm = np.sqrt(x * x + y * y + z * z)
        if norm > 1e-12:
            normals[v, 0], normals[v, 1], normals[v, 2] = x / norm, y / norm, z / norm
        else:
            normals[v, 0] = normals[v, 1] = normals[v, 2] = 0.0
    return normals
