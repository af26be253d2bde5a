"""The working level of Lilium's image terms: a coarser photo and skull for the DE (issue 26).

Inside differential evolution P_skof and P_pll are evaluated tens of thousands of times; their
cost grows with the photo's pixels and the skull's faces, and a real case (a 600k-face CT skull,
a 12-48 MP phone photo) carries far more detail than a pixel of the face needs. So the DE
scores its populations at a *working level*, one rule for both:

- **resolution**: the photo is resampled by ``scale = min(1, face_px / extent_px)``, with
  ``extent_px`` the largest distance between two of the photo's landmarks in the SFO (the face
  about :data:`WORKING_FACE_PX` pixels across). The working camera of a camera ``(f, c)`` is
  ``(scale f, (c + 1/2) scale - 1/2)`` (pixel centres at integer coordinates), and so are the
  landmarks, the facial curve and the mask (area-resampled, a working pixel is face when at least
  half of it is);
- **mesh**: for P_skof the skull's vertices are clustered in cubic cells of
  :data:`WORKING_CELL_PX` working pixels (converted to millimetres by the landmarks' own image
  scale, :func:`px_per_mm`); each cell's vertices merge into their mean and the faces that
  collapse are dropped (not done when the cells would be smaller than the mesh's median edge).
  P_pll's region is cut from the full mesh and quadric-decimated to a median edge of about
  :data:`WORKING_PLL_EDGE_PX` working pixels (not when its edges are longer already).

The terms come back in full-resolution units: P_skof's count divided by ``scale^2``, P_pll's
distances (``Delta_d``, ``P_conv``) by ``scale``, ``P_int``'s count unchanged. The result of an
SFO is not taken from the working level: its terms, the outside count and the implausible flag
are recomputed on the full mesh at the photo's resolution
(:func:`lilium.methods.lilium_outcome.photo_outcome`).
"""

from dataclasses import dataclass, replace

import cv2
import numpy as np

from ..geometry.camera import Cameras
from ..geometry.mesh import cluster_vertices

#: The face (the largest distance between two landmarks of the SFO) is about this many pixels
#: across at the working resolution; photos where it is smaller are not resampled.
WORKING_FACE_PX = 400.0

#: Vertex-clustering cell of the working mesh P_skof counts on, in working pixels.
WORKING_CELL_PX = 8.0

#: P_pll's region (cut from the full mesh) is quadric-decimated to a median edge of about this
#: many working pixels (its curve is the region's outline: a shape-keeping decimation).
WORKING_PLL_EDGE_PX = 8.0


@dataclass(frozen=True)
class WorkingLevel:
    """A skull and photo at the working level, and how to get there from the full one.

    Attributes
    ----------
    scale : float
        Working pixels per photo pixel (<= 1).
    skull : Skull
        The working mesh of P_skof (the same landmarks).
    photo : Photo
        Resampled: ``image_size_wh``, landmarks, mask and facial curve in working pixels;
        the pixels of the picture itself dropped.
    cell_mm : float
        Vertex-clustering cell (0: the full mesh).
    pll_fraction : float
        The fraction of P_pll's region faces kept (:data:`WORKING_PLL_EDGE_PX`; 1 = all).
    """

    scale: float
    skull: object
    photo: object
    cell_mm: float = 0.0
    pll_fraction: float = 1.0

    @property
    def is_full(self):
        """True when the working level is the full one (no resampling, the full mesh)."""
        return self.scale == 1.0 and self.cell_mm == 0.0 and self.pll_fraction == 1.0

    def centre(self, centre_px):
        """The working principal point ``(2,)`` of a full-resolution one."""
        return (np.asarray(centre_px, float) + 0.5) * self.scale - 0.5

    def cameras(self, cameras):
        """The working :class:`Cameras` of full-resolution ``cameras``."""
        return Cameras(
            cameras.R,
            cameras.t,
            np.asarray(cameras.focal_px) * self.scale,
            self.centre(cameras.principal_point_px),
        )


def face_extent_px(uv_px):
    """Largest distance (pixels) between two of the points ``uv_px`` (N, 2)."""
    uv = np.asarray(uv_px, float)
    d = np.linalg.norm(uv[:, None] - uv[None], axis=-1)
    return float(d.max()) if d.size else 0.0


def px_per_mm(uv_px, points_mm):
    """The photo's scale at the face (pixels per mm): the largest ratio of a landmark pair's
    image distance to its 3D distance (the pair the least foreshortened).

    Parameters
    ----------
    uv_px : ndarray of shape (N, 2)
    points_mm : ndarray of shape (N, 3)
        The same landmarks in 3D (the cranial ones do: soft tissue shifts them a few mm).
    """
    uv, x = np.asarray(uv_px, float), np.asarray(points_mm, float)
    d2 = np.linalg.norm(uv[:, None] - uv[None], axis=-1)
    d3 = np.linalg.norm(x[:, None] - x[None], axis=-1)
    far = d3 > 10.0
    return float((d2[far] / d3[far]).max()) if far.any() else 0.0


def median_edge_mm(vertices_mm, faces):
    """Median edge length (mm) of a mesh (its first edges; at most 100k faces sampled)."""
    f = np.asarray(faces)[:: max(1, len(faces) // 100_000)]
    v = np.asarray(vertices_mm, float)
    return float(np.median(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1))) if len(f) else 0.0


def _scale_uv(uv, scale):
    return (np.asarray(uv, float) + 0.5) * scale - 0.5


def resample_photo(photo, scale):
    """``photo`` at ``scale`` working pixels per pixel (see the module's rule).

    The mask is area-resampled (a working pixel is face when at least half of it is); the
    picture itself is dropped (the terms never read it).
    """
    width, height = photo.image_size_wh
    size_wh = (max(1, round(width * scale)), max(1, round(height * scale)))
    mask = photo.face_mask
    if mask is not None:
        area = cv2.resize(np.asarray(mask != 0, np.float32), size_wh, interpolation=cv2.INTER_AREA)
        mask = area >= 0.5
    curve = photo.face_curve_uv
    if curve is not None:
        curve = np.rint(_scale_uv(curve, scale))
        keep = np.ones(len(curve), bool)
        keep[1:] = np.any(curve[1:] != curve[:-1], axis=1)
        curve = curve[keep]
    return replace(
        photo,
        image_size_wh=size_wh,
        landmarks_uv={k: _scale_uv(uv, scale) for k, uv in photo.landmarks_uv.items()},
        face_mask=mask,
        face_curve_uv=curve,
        image=None,
    )


def working_level(skull, photo, corr, face_px=WORKING_FACE_PX, cell_px=WORKING_CELL_PX):
    """The :class:`WorkingLevel` of an SFO by the module's rule.

    Parameters
    ----------
    skull : Skull
    photo : Photo
    corr : Correspondences
        The SFO's landmark pairs (their image extent and scale set the level).
    face_px : float or None
        :data:`WORKING_FACE_PX`; None = the full level (the photo's resolution, the full mesh).
    cell_px : float
        :data:`WORKING_CELL_PX`.
    """
    if face_px is None:
        return WorkingLevel(1.0, skull, photo)
    extent = face_extent_px(corr.uv_px)
    scale = min(1.0, face_px / extent) if extent > 0 else 1.0
    work_photo = photo if scale == 1.0 else resample_photo(photo, scale)
    density = px_per_mm(corr.uv_px, corr.cranial_mm) * scale
    edge_mm = median_edge_mm(skull.vertices_mm, skull.faces)

    def clustered(cell):
        cell_mm = cell / density if density > 0 else 0.0
        if cell_mm <= edge_mm:
            return skull, 0.0
        vertices, faces = cluster_vertices(skull.vertices_mm, skull.faces, cell_mm)
        return replace(skull, vertices_mm=vertices, faces=faces), cell_mm

    work_skull, cell_mm = clustered(cell_px)
    pll_fraction = min(1.0, (edge_mm * density / WORKING_PLL_EDGE_PX) ** 2)
    return WorkingLevel(scale, work_skull, work_photo, cell_mm, pll_fraction)


class WorkingSkof:
    """P_skof of full-resolution cameras evaluated at a working level (full-resolution units).

    Parameters
    ----------
    term : SkofTerm
        Built on ``level.skull`` and ``level.photo``.
    level : WorkingLevel
    """

    def __init__(self, term, level):
        self.term, self.level = term, level

    def __call__(self, cameras):
        """``(S,)`` P_skof: the working count divided by ``scale^2``, times the weight."""
        return self.term(self.level.cameras(cameras)) / self.level.scale**2


class WorkingPll:
    """P_pll of full-resolution cameras evaluated at a working level (full-resolution units).

    Parameters
    ----------
    term : PllTerm
        Built on ``level.skull`` and ``level.photo``.
    level : WorkingLevel
    """

    def __init__(self, term, level):
        self.term, self.level = term, level

    def __call__(self, cameras):
        """``(S,)`` P_pll: ``(Delta_d + P_conv) / scale + P_int``; a failure keeps its total."""
        parts = self.term.parts(self.level.cameras(cameras))
        ok = np.asarray(parts.n_pairs) > 0
        with np.errstate(invalid="ignore"):
            scaled = (parts.delta_d + parts.p_conv) / self.level.scale + parts.p_int
        return np.where(ok, scaled, parts.total)
