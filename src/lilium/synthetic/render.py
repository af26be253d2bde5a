"""A small software rasteriser for synthetic photographs (painter's algorithm on OpenCV).

Triangles are sorted far to near by the camera depth of their centroid and filled one by one with
``cv2.fillConvexPoly`` (sub-pixel vertex positions, pixel centres at integer ``uv``) into a
*face-index buffer*: pixel (row v, column u) holds the index of the triangle seen there, or -1.
Everything else is derived from that buffer: the flat Lambert shading of the photo, the head
mask, and the depth of the visible surface at any pixel (ray-plane intersection with the
triangle there), which decides whether a landmark is hidden by the head itself.

Painter's order by centroid depth is exact for a closed, non-self-intersecting surface except
along silhouettes, where a few pixels may show a triangle a few mm behind the front one; the
visibility tolerance (:data:`VISIBILITY_TOLERANCE_MM`) absorbs that.

A Python loop over ``fillConvexPoly`` costs about 2 us per triangle whatever its size.

This is a depth buffer (which triangle is seen where), not the mask rasteriser: a mesh's
silhouette mask *as a set of pixels* (the skull's ``S``) is :func:`lilium.imaging.raster.mesh_mask`,
the one exact union raster. The head mask of a synthetic photo is this buffer's coverage, because
the photo's pixels are the ones this buffer shades.

Camera convention (:mod:`lilium.geometry.camera`): ``X_cam = R X + t`` with ``skull2cam``,
x right, y down, z forward; ``uv = c + f X_cam[:2] / X_cam[2]``.
"""

from dataclasses import dataclass

import cv2
import numpy as np

from ..geometry.camera import Camera, principal_point_of

#: Fixed-point bits of the sub-pixel vertex positions given to OpenCV's polygon fill.
_SHIFT_BITS = 4
_SHIFT_SCALE = float(1 << _SHIFT_BITS)

#: A landmark is visible when it is at most this far (mm, along its ray) behind the surface
#: seen at its pixel (or at one of the 8 neighbouring pixels).
VISIBILITY_TOLERANCE_MM = 4.0

#: Skin albedo (RGB, 0-255) and lighting of the shaded render.
SKIN_RGB = np.array([222.0, 176.0, 146.0])
AMBIENT = 0.28
#: Direction towards the key light in the camera frame (up-left of the camera, towards it).
LIGHT_DIRECTION_CAM = np.array([-0.35, -0.45, -1.0]) / np.linalg.norm([-0.35, -0.45, -1.0])
#: Background gradient (RGB, top and bottom rows).
BACKGROUND_TOP_RGB = np.array([96.0, 108.0, 124.0])
BACKGROUND_BOTTOM_RGB = np.array([46.0, 50.0, 60.0])


@dataclass(frozen=True)
class MeshRender:
    """The face-index buffer of one mesh seen by one camera.

    Attributes
    ----------
    face_index : ndarray of shape (H, W), int32
        Index of the triangle seen at pixel (row v, column u); -1 for background.
    vertices_cam_mm : ndarray of shape (V, 3)
        Mesh vertices in the camera frame.
    faces : ndarray of shape (F, 3), int
    camera : Camera
    """

    face_index: np.ndarray
    vertices_cam_mm: np.ndarray
    faces: np.ndarray
    camera: Camera

    @property
    def image_size_wh(self):
        return (self.face_index.shape[1], self.face_index.shape[0])

    @property
    def mask(self):
        """Pixels covered by the mesh, ndarray of shape (H, W), bool."""
        return self.face_index >= 0


def _fixed_point_triangles(vertices_cam_mm, faces, focal_px, principal_point_px):
    z = vertices_cam_mm[:, 2]
    uv = principal_point_px + focal_px * vertices_cam_mm[:, :2] / np.maximum(z, 1e-6)[:, None]
    tri = uv[faces]
    in_front = np.all(z[faces] > 1.0, axis=1)
    # Far outside the image, fixed-point coordinates would overflow int32: such triangles are
    # clipped away by dropping them (only ever near the camera plane).
    sane = np.all(np.abs(tri) < 1e6, axis=(1, 2))
    keep = in_front & sane
    pts = np.round(tri * _SHIFT_SCALE).astype(np.int32)
    return pts, keep, z[faces].mean(axis=1)


def front_facing(vertices_cam_mm, faces):
    """Triangles whose (counter-clockwise, outward) normal points towards the camera centre."""
    tri = vertices_cam_mm[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return np.einsum("ij,ij->i", n, tri.mean(axis=1)) < 0


def rasterize_face_index(
    vertices_cam_mm,
    faces,
    focal_px,
    image_size_wh,
    principal_point_px=None,
    cull_back_faces=False,
):
    """Face-index buffer of a mesh in the camera frame (painter's algorithm, far to near).

    Parameters
    ----------
    vertices_cam_mm : array_like of shape (V, 3)
    faces : array_like of shape (F, 3), int
    focal_px : float
    image_size_wh : (int, int)
        ``(width, height)`` in pixels.
    principal_point_px : array_like of shape (2,), optional
        Image centre when omitted.
    cull_back_faces : bool
        Skip triangles facing away from the camera (about half of them, so twice as fast). Only
        for consistently wound meshes with outward normals; a hole (e.g. the neck cut) then shows
        the background instead of the inside.

    Returns
    -------
    face_index : ndarray of shape (H, W), int32
        Triangle index per pixel, -1 where no triangle covers the pixel centre.
    """
    width, height = (int(s) for s in image_size_wh)
    if principal_point_px is None:
        principal_point_px = principal_point_of((width, height))
    vertices_cam_mm = np.asarray(vertices_cam_mm, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    pts, keep, depth = _fixed_point_triangles(
        vertices_cam_mm, faces, focal_px, np.asarray(principal_point_px, dtype=float)
    )
    if cull_back_faces:
        keep &= front_facing(vertices_cam_mm, faces)
    buffer = np.full((height, width), -1, dtype=np.int32)
    order = np.flatnonzero(keep)
    order = order[np.argsort(-depth[order], kind="stable")]
    fill = cv2.fillConvexPoly
    for i in order.tolist():
        fill(buffer, pts[i], i, cv2.LINE_8, _SHIFT_BITS)
    return buffer


def render_mesh(vertices_mm, faces, camera, image_size_wh, cull_back_faces=False):
    """Rasterise a mesh seen by a camera; see :class:`MeshRender`.

    Parameters
    ----------
    vertices_mm : array_like of shape (V, 3)
        Skull-frame vertices (mm).
    faces : array_like of shape (F, 3), int
    camera : Camera
    image_size_wh : (int, int)
    cull_back_faces : bool
        See :func:`rasterize_face_index`.

    Returns
    -------
    MeshRender
    """
    vertices_cam = camera.to_camera_frame(vertices_mm)
    faces = np.asarray(faces, dtype=np.int64)
    face_index = rasterize_face_index(
        vertices_cam,
        faces,
        camera.focal_px,
        image_size_wh,
        camera.principal_point_px,
        cull_back_faces,
    )
    return MeshRender(face_index, vertices_cam, faces, camera)


def face_normals(vertices, faces):
    """Unit triangle normals ``(F, 3)`` (zero for degenerate triangles)."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(norm > 0, norm, 1.0)


def shade(render, albedo_rgb=SKIN_RGB, light_direction_cam=LIGHT_DIRECTION_CAM, smooth_px=1.5):
    """A Lambert-shaded RGB picture of the render over a gradient background.

    Shading is flat per triangle and two-sided (mesh winding is not trusted), then softened by a
    small Gaussian blur inside the mesh silhouette.

    Returns
    -------
    image : ndarray of shape (H, W, 3), uint8, RGB
    """
    n = face_normals(render.vertices_cam_mm, render.faces)
    intensity = AMBIENT + (1.0 - AMBIENT) * np.abs(n @ light_direction_cam)
    lut = np.append(intensity, 0.0).astype(np.float32)  # index -1 -> 0
    height, width = render.face_index.shape
    ramp = np.linspace(0.0, 1.0, height, dtype=np.float32)[:, None]
    background = (1 - ramp) * BACKGROUND_TOP_RGB + ramp * BACKGROUND_BOTTOM_RGB
    image = np.repeat(background.astype(np.uint8)[:, None, :], width, axis=1)
    mask = render.mask
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return image
    # Work on the silhouette's bounding box (plus the blur's reach) only.
    pad = int(np.ceil(3 * smooth_px)) + 1
    r0, r1 = max(0, rows[0] - pad), min(height, rows[-1] + pad + 1)
    c0, c1 = max(0, cols[0] - pad), min(width, cols[-1] + pad + 1)
    box_mask = mask[r0:r1, c0:c1]
    shading = lut[render.face_index[r0:r1, c0:c1]]
    if smooth_px > 0:
        ksize = int(2 * np.ceil(2 * smooth_px) + 1)
        num = cv2.GaussianBlur(shading, (ksize, ksize), smooth_px)
        den = cv2.GaussianBlur(box_mask.astype(np.float32), (ksize, ksize), smooth_px)
        shading = num / np.maximum(den, 1e-6)
    skin = np.clip(shading[..., None] * albedo_rgb.astype(np.float32), 0, 255).astype(np.uint8)
    box = image[r0:r1, c0:c1]
    box[box_mask] = skin[box_mask]
    return image


def surface_depth_along_rays(render, uv):
    """Camera depth (z, mm) of the visible surface on the rays through pixel points ``uv``.

    For each point the triangle stored at its pixel and at the 8 neighbouring pixels is
    intersected with the point's ray; the farthest of those depths is returned (lenient at
    silhouettes). NaN where no triangle covers any of those pixels or ``uv`` is NaN/outside.

    Parameters
    ----------
    render : MeshRender
    uv : array_like of shape (N, 2)

    Returns
    -------
    depth_mm : ndarray of shape (N,)
    """
    uv = np.asarray(uv, dtype=float)
    width, height = render.image_size_wh
    out = np.full(len(uv), np.nan)
    ok = np.all(np.isfinite(uv), axis=1)
    if not np.any(ok):
        return out
    pixel = np.zeros((len(uv), 2), dtype=np.int64)
    pixel[ok] = np.rint(uv[ok]).astype(np.int64)
    cols, rows = pixel[:, 0], pixel[:, 1]
    rays = np.column_stack(
        [(uv - render.camera.principal_point_px) / render.camera.focal_px, np.ones(len(uv))]
    )  # X = s * ray, s = depth
    n = face_normals(render.vertices_cam_mm, render.faces)
    v0 = render.vertices_cam_mm[render.faces[:, 0]]
    best = np.full(len(uv), -np.inf)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            r, c = rows + dr, cols + dc
            inside = ok & (r >= 0) & (r < height) & (c >= 0) & (c < width)
            idx = np.full(len(uv), -1)
            idx[inside] = render.face_index[r[inside], c[inside]]
            hit = idx >= 0
            if not np.any(hit):
                continue
            f = idx[hit]
            denom = np.einsum("ij,ij->i", n[f], rays[hit])
            num = np.einsum("ij,ij->i", n[f], v0[f])
            with np.errstate(divide="ignore", invalid="ignore"):
                s = np.where(np.abs(denom) > 1e-9, num / denom, np.nan)
            # A ray grazing its triangle: fall back to the triangle's centroid depth.
            centroid_z = render.vertices_cam_mm[render.faces[f]][:, :, 2].mean(axis=1)
            s = np.where(np.isfinite(s) & (s > 0), s, centroid_z)
            best[hit] = np.maximum(best[hit], s)
    out[np.isfinite(best)] = best[np.isfinite(best)]
    return out


def visible_points(render, points_mm, camera, tolerance_mm=VISIBILITY_TOLERANCE_MM):
    """Which skull-frame points are seen by the camera (not hidden by the mesh itself).

    Parameters
    ----------
    render : MeshRender
    points_mm : array_like of shape (N, 3)
    camera : Camera
    tolerance_mm : float
        Largest depth (mm) a point may lie behind the visible surface.

    Returns
    -------
    visible : ndarray of shape (N,), bool
    uv : ndarray of shape (N, 2)
        The projections (NaN behind the camera).
    """
    z = camera.to_camera_frame(points_mm)[:, 2]
    uv = camera.project(points_mm)
    width, height = render.image_size_wh
    inside = (
        np.all(np.isfinite(uv), axis=1)
        & (uv[:, 0] >= -0.5)
        & (uv[:, 0] <= width - 0.5)
        & (uv[:, 1] >= -0.5)
        & (uv[:, 1] <= height - 0.5)
    )
    surface = surface_depth_along_rays(render, uv)
    visible = inside & np.isfinite(surface) & (z <= surface + tolerance_mm)
    return visible, uv
