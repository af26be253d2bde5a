"""A detailed skull render for the eye: smooth normals, cavity shading and crease lines.

The report's pictures must let a forensic expert judge the orbits, the nasal aperture, the
dentition and the chin against a face that may be only a couple of hundred pixels wide. A flat
Lambert shade per triangle shows a marching-cubes mesh's facets and little of its cavities, so
this module renders per pixel:

- **surface buffers** (:func:`render_surface`): the exact silhouette (the one mesh raster,
  :func:`lilium.imaging.raster.skull_raster`), and inside it each pixel's nearest triangle
  (a compiled depth buffer, :mod:`lilium.imaging._paint_kernels`), its depth (mm, camera
  frame) and its normal, interpolated from area-weighted vertex normals with the pixel
  centre's barycentric coordinates;
- **shade** (:func:`shade_surface`): a key light from the upper left and a fill light from the
  camera (two-sided, a mesh may be wound either way), darkened where the surface lies deeper
  than its neighbourhood (unsharp masking of the depth buffer, Luft, Colditz & Deussen 2006: a
  cheap ambient occlusion at two scales, :data:`CAVITY_SCALES`; orbits, nasal aperture, gaps
  between teeth) and drawn with dark lines where the depth jumps (orbital rims, aperture edge,
  teeth outlines: :data:`CREASE_SLOPE`).

Scales are set in millimetres on the skull and converted to pixels with the camera's focal
length and the median depth, so the picture reads the same at any resolution. Arrays are
indexed ``[row, column]``; ``uv`` = (column, row), pixel centres at integers.
"""

from dataclasses import dataclass

import cv2
import numpy as np

from .. import jit
from ._paint_kernels import nearest_face_index, normals_kernel, surface_kernel
from .raster import content_key, skull_raster

#: Direction towards the key light in the camera frame (x right, y down, z forward): upper
#: left, in front of the face.
KEY_LIGHT_CAM = np.array([-0.45, -0.55, -1.0]) / np.linalg.norm([-0.45, -0.55, -1.0])

#: Ambient, key and fill (camera headlight) weights of the shade (they sum to 1).
AMBIENT, KEY, FILL = 0.12, 0.58, 0.30

#: Cavity shading: (Gaussian sigma in mm on the skull, depth in mm for full darkening,
#: strength in [0, 1]) per scale; coarse for orbits and aperture, fine for teeth and sutures.
CAVITY_SCALES = ((9.0, 14.0, 0.62), (1.6, 2.5, 0.45))

#: Depth slope (mm of depth per mm across) above which a crease line is drawn, the slope of
#: full line strength, and the line's darkening.
CREASE_SLOPE, CREASE_FULL_SLOPE, CREASE_STRENGTH = 2.5, 7.0, 0.75

#: Largest Gaussian sigma (pixels) blurred at full resolution (wider: on a shrunk picture).
_BLUR_SIGMA_PX = 6.0


@dataclass(frozen=True)
class SurfaceRender:
    """Per-pixel buffers of a mesh seen by a camera.

    Attributes
    ----------
    covered : ndarray of shape (H, W), bool
        The exact union of the projected triangles.
    face_index : ndarray of shape (H, W), int32
        The nearest triangle under each pixel centre (depth buffer), -1 where none.
    depth_mm : ndarray of shape (H, W), float32
        Camera-frame depth of the surface (mm), NaN off the mesh.
    normal_cam : ndarray of shape (H, W, 3), float32
        Unit surface normal in the camera frame, turned towards the camera; 0 off the mesh.
    focal_px : float
        The camera's focal length (pixels), to convert millimetres to pixels.
    """

    covered: np.ndarray
    face_index: np.ndarray
    depth_mm: np.ndarray
    normal_cam: np.ndarray
    focal_px: float

    def mm_to_px(self, length_mm):
        """Pixels spanned by ``length_mm`` at the surface's median depth."""
        depth = np.nanmedian(self.depth_mm) if np.any(self.covered) else np.nan
        if not np.isfinite(depth) or depth <= 0:
            return 1.0
        return float(length_mm * self.focal_px / depth)


_normals = {}


def cached_vertex_normals(vertices_mm, faces):
    """:func:`vertex_normals`, kept for the last mesh (a report shades one skull three times)."""
    key = content_key(vertices_mm, faces)
    if key not in _normals:
        _normals.clear()
        _normals[key] = vertex_normals(vertices_mm, faces)
    return _normals[key]


def vertex_normals(vertices_mm, faces):
    """Area-weighted unit vertex normals ``(V, 3)`` (0 for an unused vertex)."""
    if jit.compiled():  # the same steps, compiled (imaging/_paint_kernels.py)
        return normals_kernel(
            np.ascontiguousarray(vertices_mm, dtype=float), np.ascontiguousarray(faces, np.int64)
        )
    tri = vertices_mm[faces]
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # length = 2 x area
    n = len(vertices_mm)
    normals = np.stack(
        [
            sum(np.bincount(faces[:, k], weights=face_n[:, j], minlength=n) for k in range(3))
            for j in range(3)
        ],
        axis=1,
    )
    norm = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, norm, out=np.zeros_like(normals), where=norm > 1e-12)


def render_surface(vertices_mm, faces, camera, image_size_wh, *, topology=None):
    """Per-pixel triangle, depth and normal of a mesh (see :class:`SurfaceRender`).

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    camera : Camera
    image_size_wh : tuple (width, height), int
    topology : EdgeTopology, optional
        ``mesh_edge_topology(faces)``, to skip recomputing it.

    Returns
    -------
    SurfaceRender
    """
    width, height = (int(s) for s in image_size_wh)
    vertices_mm = np.asarray(vertices_mm, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    uv = camera.project(vertices_mm)
    covered = skull_raster(uv, faces, (height, width), topology=topology)
    X = camera.to_camera_frame(vertices_mm)
    normals_cam = cached_vertex_normals(vertices_mm, faces) @ camera.R.T
    # The nearest triangle at each pixel centre (a compiled depth buffer).
    depth_key = X[:, 2][faces].mean(axis=1)
    face_index = nearest_face_index(uv, faces, depth_key, (height, width), covered=covered)
    rows, cols = np.nonzero(face_index >= 0)
    f = face_index[rows, cols]
    if jit.compiled():  # the same steps per pixel, compiled (imaging/_paint_kernels.py)
        c0, c1 = (float(x) for x in camera.principal_point_px)
        depth_mm, normal_cam = surface_kernel(
            rows, cols, f, np.ascontiguousarray(uv), faces, np.ascontiguousarray(X),
            np.ascontiguousarray(normals_cam), c0, c1, float(camera.focal_px), height, width,
        )  # fmt: skip
        return SurfaceRender(covered, face_index, depth_mm, normal_cam, float(camera.focal_px))
    a, b, c = (uv[faces[f, k]] for k in range(3))
    p = np.stack([cols, rows], axis=1).astype(float)
    # Barycentric coordinates of the pixel centre (clipped: a gap pixel shows a neighbour).
    d = (b[:, 1] - c[:, 1]) * (a[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (a[:, 1] - c[:, 1])
    ok = np.abs(d) > 1e-9
    d = np.where(ok, d, 1.0)
    w0 = ((b[:, 1] - c[:, 1]) * (p[:, 0] - c[:, 0]) + (c[:, 0] - b[:, 0]) * (p[:, 1] - c[:, 1])) / d
    w1 = ((c[:, 1] - a[:, 1]) * (p[:, 0] - c[:, 0]) + (a[:, 0] - c[:, 0]) * (p[:, 1] - c[:, 1])) / d
    w = np.clip(np.stack([w0, w1, 1 - w0 - w1], axis=1), 0, 1)
    w = np.where(ok[:, None], w, 1 / 3)
    w /= w.sum(axis=1, keepdims=True)
    corners = faces[f]
    depth = np.einsum("nk,nk->n", w, X[corners, 2])
    normal = np.einsum("nk,nkd->nd", w, normals_cam[corners])
    tri = X[corners]
    flat = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    weak = np.linalg.norm(normal, axis=1) < 0.3  # inconsistent winding: use the face normal
    normal[weak] = flat[weak]
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    ray = np.stack([p[:, 0] - camera.principal_point_px[0], p[:, 1], np.zeros(len(p))], axis=1)
    ray[:, 1] -= camera.principal_point_px[1]
    ray[:, 2] = camera.focal_px
    normal *= np.where(np.einsum("nd,nd->n", normal, ray) > 0, -1.0, 1.0)[:, None]
    depth_mm = np.full((height, width), np.nan, dtype=np.float32)
    depth_mm[rows, cols] = depth
    normal_cam = np.zeros((height, width, 3), dtype=np.float32)
    normal_cam[rows, cols] = normal
    return SurfaceRender(covered, face_index, depth_mm, normal_cam, float(camera.focal_px))


def _masked_blur(values, weight, sigma_px):
    """Normalised Gaussian blur of ``values`` where ``weight`` (float) is non-zero.

    Wide blurs run on a picture shrunk so that sigma is :data:`_BLUR_SIGMA_PX` there (area
    average down, bilinear up): the result is smooth at that scale anyway, and a 200 px sigma
    on a 1,400 px picture would cost seconds.
    """
    sigma_px = max(float(sigma_px), 0.5)
    h, w = values.shape
    factor = max(1.0, sigma_px / _BLUR_SIGMA_PX)
    small_wh = (max(1, round(w / factor)), max(1, round(h / factor)))
    num, den = values * weight, weight
    if factor > 1:
        num = cv2.resize(num, small_wh, interpolation=cv2.INTER_AREA)
        den = cv2.resize(den, small_wh, interpolation=cv2.INTER_AREA)
    sigma = sigma_px / factor
    size = 2 * int(np.ceil(3 * sigma)) + 1
    num = cv2.GaussianBlur(num, (size, size), sigma)
    den = cv2.GaussianBlur(den, (size, size), sigma)
    out = num / np.maximum(den, 1e-6)
    if factor > 1:
        out = cv2.resize(out, (w, h), interpolation=cv2.INTER_LINEAR)
    return out


def cavity(surface):
    """How much each pixel lies deeper than its neighbourhood, in [0, 1] per scale, combined.

    Returns
    -------
    ndarray of shape (H, W), float32
        Darkening factor in (0, 1]: 1 = open surface, smaller = cavity.
    """
    weight = surface.covered.astype(np.float32)
    depth = np.where(surface.covered, surface.depth_mm, 0).astype(np.float32)
    factor = np.ones(depth.shape, dtype=np.float32)
    for sigma_mm, full_mm, strength in CAVITY_SCALES:
        around = _masked_blur(depth, weight, surface.mm_to_px(sigma_mm))
        deeper = np.clip((depth - around) / full_mm, 0, 1)
        factor *= 1 - strength * deeper
    return factor


def creases(surface):
    """Line strength in [0, 1] where the depth jumps (steep slopes, occlusion edges).

    Returns
    -------
    ndarray of shape (H, W), float32
    """
    depth = np.where(surface.covered, surface.depth_mm, np.nan).astype(np.float32)
    fill = np.where(np.isfinite(depth), depth, np.nanmax(depth) if np.any(surface.covered) else 0)
    dv, du = np.gradient(fill)
    mm_per_px = np.where(np.isfinite(depth), depth, 1) / surface.focal_px
    slope = np.hypot(du, dv) / np.maximum(mm_per_px, 1e-9)
    line = np.clip((slope - CREASE_SLOPE) / (CREASE_FULL_SLOPE - CREASE_SLOPE), 0, 1)
    line[~surface.covered] = 0
    # The silhouette is outlined by the caller: only interior creases here.
    inner = cv2.erode(surface.covered.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    return np.where(inner, line, 0).astype(np.float32)


def shade_surface(surface):
    """The shade in [0, 1] of a :class:`SurfaceRender`: lights, cavities and crease lines.

    Returns
    -------
    ndarray of shape (H, W), float32
        0 off the mesh.
    """
    n = surface.normal_cam
    key = np.clip(n @ KEY_LIGHT_CAM, 0, 1)
    fill = np.clip(-n[..., 2], 0, 1)  # headlight: towards the camera
    shade = AMBIENT + KEY * key + FILL * fill
    shade = shade * cavity(surface) * (1 - CREASE_STRENGTH * creases(surface))
    shade[~surface.covered] = 0
    return np.clip(shade, 0, 1).astype(np.float32)


def render_skull_detailed(vertices_mm, faces, camera, image_size_wh, *, topology=None):
    """Shade and silhouette of a skull for the eye (see the module docstring).

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    camera : Camera
    image_size_wh : tuple (width, height), int
    topology : EdgeTopology, optional

    Returns
    -------
    shade : ndarray of shape (H, W), float32
        In [0, 1] on the skull, 0 elsewhere.
    surface : SurfaceRender
        The buffers (``covered`` is the exact silhouette, ``depth_mm`` the depth).
    """
    surface = render_surface(vertices_mm, faces, camera, image_size_wh, topology=topology)
    return shade_surface(surface), surface
