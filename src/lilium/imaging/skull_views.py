"""The skull alone, seen from the front or the side, with its cranial landmarks projected.

A misplaced or mislabelled cranial landmark (a point off the bone, ``_l`` and ``_r`` swapped)
is invisible in an overlay on a small face; beside every SFO the report shows the skull in a
frontal and a lateral view with each landmark marked (:mod:`lilium.report.svg` draws the marks
and labels). This module makes the pictures: pure functions, arrays in, arrays out.

Views, from the skull's anatomical directions (mesh frame; the caller gets them from the
landmarks, :func:`lilium.fitness.regions.anatomical_frame`):

- ``frontal``: the camera looks at the face along ``-anterior``; image up = ``up``, so the
  subject's left (``up x anterior``, computed from the mesh, not from the labels) is at the
  image's right, as in a frontal photo;
- ``lateral_left``: the camera on the subject's left, the face towards the image's left edge
  (docs/contract.md's ``lateral_left``); ``lateral_right`` the mirror set-up.

Because the image's left-right comes from the mesh and its anatomical directions, labels that
were swapped between the sides show on the wrong side of the picture.
"""

from dataclasses import dataclass

import numpy as np

from ..geometry.camera import Camera, rigid
from .overlay import SKULL_RGB
from .shading import render_skull_detailed

#: Views a skull is shown in.
SKULL_VIEWS = ("frontal", "lateral_left", "lateral_right")

#: Camera distance (mm) from the skull's centre for the views: nearly orthographic.
VIEW_DISTANCE_MM = 1500.0

#: Margin around the skull in its view (fraction of the picture's side).
VIEW_MARGIN = 0.04

#: Background of the skull views (RGB).
VIEW_BACKGROUND_RGB = (34, 38, 44)

#: A landmark counts as visible when the surface in front of it lies at most this far (mm)
#: nearer to the camera, within :data:`VISIBILITY_RADIUS_PX` pixels.
VISIBILITY_TOLERANCE_MM = 4.0
VISIBILITY_RADIUS_PX = 2


@dataclass(frozen=True)
class SkullView:
    """One picture of the skull alone and its projected landmarks.

    Attributes
    ----------
    view : str
        One of :data:`SKULL_VIEWS`.
    image : ndarray of shape (H, W, 3), uint8
        The shaded skull on :data:`VIEW_BACKGROUND_RGB`.
    names : tuple of str
        Cranial landmarks, in the order given.
    uv : ndarray of shape (N, 2)
        Their pixel positions in ``image`` (NaN when behind the camera).
    visible : ndarray of shape (N,), bool
        Whether each lies on the surface seen (not hidden behind bone).
    camera : Camera
        The view's camera.
    """

    view: str
    image: np.ndarray
    names: tuple
    uv: np.ndarray
    visible: np.ndarray
    camera: Camera


def _unit(x):
    x = np.asarray(x, dtype=float)
    n = np.linalg.norm(x)
    if not np.isfinite(n) or n < 1e-12:
        raise ValueError("the skull's anatomical directions are degenerate (zero vector)")
    return x / n


def view_rotation(anterior, up, view):
    """The rotation skull -> camera of a view (rows: camera x right, y down, z forward).

    Parameters
    ----------
    anterior, up : array_like of shape (3,)
        The skull's anterior and superior directions (mesh frame); ``up`` is made orthogonal
        to ``anterior``.
    view : {"frontal", "lateral_left", "lateral_right"}

    Returns
    -------
    R : ndarray of shape (3, 3)
        A proper rotation (det +1).
    """
    if view not in SKULL_VIEWS:
        raise ValueError(f"unknown skull view {view!r}; use one of {', '.join(SKULL_VIEWS)}")
    anterior = _unit(anterior)
    up = _unit(np.asarray(up, dtype=float) - (np.dot(up, anterior)) * anterior)
    left = np.cross(up, anterior)  # the subject's left, from the geometry
    forward = {"frontal": -anterior, "lateral_left": -left, "lateral_right": left}[view]
    down = -up
    right = np.cross(down, forward)
    return np.stack([right, down, forward])


def _column_bounds(a):
    """``(min, max)`` of each column of ``a`` (N, k): ``a.min(axis=0)``, ``a.max(axis=0)``,
    column by column (numpy reduces a few wide columns about twenty times slower along
    axis 0: 11 against 0.5 ms for 300k vertices)."""
    lo = np.array([a[:, k].min() for k in range(a.shape[1])])
    hi = np.array([a[:, k].max() for k in range(a.shape[1])])
    return lo, hi


def fit_camera(vertices_mm, R, size_wh, margin=VIEW_MARGIN, distance_mm=VIEW_DISTANCE_MM):
    """A camera with rotation ``R`` that frames the whole mesh in a picture of ``size_wh``.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    R : ndarray of shape (3, 3)
    size_wh : tuple (width, height), int
    margin : float
        Free border, fraction of each side.
    distance_mm : float
        From the camera to the mesh's bounding-box centre.

    Returns
    -------
    Camera
    """
    vertices_mm = np.asarray(vertices_mm, dtype=float)
    lo, hi = _column_bounds(vertices_mm)
    centre = (lo + hi) / 2
    t = np.array([0.0, 0.0, distance_mm]) - R @ centre
    X = vertices_mm @ R.T + t
    lo, hi = _column_bounds(X[:, :2] / X[:, 2:3])
    w, h = size_wh
    span = np.maximum(hi - lo, 1e-9)
    focal = min(w * (1 - 2 * margin) / span[0], h * (1 - 2 * margin) / span[1])
    pp = np.array([(w - 1) / 2, (h - 1) / 2]) - focal * (lo + hi) / 2
    return Camera(rigid(R, t), float(focal), pp)


def landmark_visibility(points_mm, uv, camera, depth_mm):
    """Whether each landmark is seen, not hidden behind the surface (see the constants)."""
    h, w = depth_mm.shape
    z = camera.to_camera_frame(points_mm)[:, 2]
    r = VISIBILITY_RADIUS_PX
    visible = np.zeros(len(uv), dtype=bool)
    for k, (u, v) in enumerate(uv):
        if not (np.isfinite(u) and np.isfinite(v)):
            continue
        c, row = int(round(u)), int(round(v))
        patch = depth_mm[max(0, row - r) : row + r + 1, max(0, c - r) : c + r + 1]
        if patch.size == 0:  # outside the picture: nothing hides it
            visible[k] = True
            continue
        seen = patch[np.isfinite(patch)]
        # On or off the silhouette (a profile point, a landmark a little off the mesh): seen.
        on_edge = seen.size < patch.size
        visible[k] = on_edge or seen.max() >= z[k] - VISIBILITY_TOLERANCE_MM
    return visible


def skull_view(vertices_mm, faces, landmarks_mm, anterior, up, view, size_wh, *, topology=None):
    """Render the skull alone in one view and project its landmarks.

    Parameters
    ----------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    landmarks_mm : dict of str -> array_like of shape (3,)
        Cranial landmarks (mesh frame).
    anterior, up : array_like of shape (3,)
        The skull's anatomical directions (mesh frame).
    view : {"frontal", "lateral_left", "lateral_right"}
    size_wh : tuple (width, height), int
    topology : EdgeTopology, optional

    Returns
    -------
    SkullView
    """
    R = view_rotation(anterior, up, view)
    camera = fit_camera(vertices_mm, R, size_wh)
    shade, surface = render_skull_detailed(vertices_mm, faces, camera, size_wh, topology=topology)
    image = np.empty(shade.shape + (3,), dtype=np.float32)
    image[:] = VIEW_BACKGROUND_RGB
    skull = shade[..., None] * SKULL_RGB
    image = np.where(surface.covered[..., None], skull, image)
    names = tuple(landmarks_mm)
    points = np.array([landmarks_mm[n] for n in names], dtype=float).reshape(-1, 3)
    uv = camera.project(points) if len(points) else np.zeros((0, 2))
    visible = landmark_visibility(points, uv, camera, surface.depth_mm)
    rgb = np.clip(image, 0, 255).astype(np.uint8)
    return SkullView(view, rgb, names, uv, visible, camera)
