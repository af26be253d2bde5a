"""Mesh regions of the parallelism term (docs/method/lilium.md): forehead and chin-jaw.

Computed once per SFO (skull) or once per face mesh, from 3D landmarks in the mesh frame.

Anatomical frame (:func:`anatomical_frame`): ``up`` is the normal of the Frankfurt plane through
``porion_l``, ``porion_r`` and ``orbitale_l`` (``orbitale_r`` when the left one is missing),
``left`` lies in that plane from ``porion_r`` to ``porion_l``, ``anterior = left x up``, signs
checked against the landmarks (up towards glabella/metopion/bregma/nasion; anterior from the
mean midpoint of the bilateral pairs towards nasion/glabella/prosthion/subspinale/metopion).

Documented fallback when the Frankfurt landmarks are missing:
``left`` = the midsagittal normal of :func:`lilium.softtissue.cones.midsagittal_plane` (mean
left-minus-right direction of the bilateral pairs, mesh ``+x`` without pairs), ``up`` = the
facial height axis, from the mean of the lower midline landmarks (prosthion, subspinale,
infradentale, pogonion, gnathion) to the mean of the upper ones (nasion, glabella, metopion,
bregma), made perpendicular to ``left``. The facial height axis is not exactly the Frankfurt normal,
so the cutting planes of the fallback tilt a little (by the angle between the two).

Regions:

- forehead: vertices whose height lies between the heights of glabella and metopion (planes
  parallel to the Frankfurt plane), and, to keep only the frontal bone, not more than
  ``depth_mm`` (default 80 mm) behind the more anterior of the two landmarks. The anterior
  boundary seen in a lateral photo is untouched by that second cut.
- chin-jaw: vertices below the height of ``infradentale`` (skull) and whose left-right
  coordinate lies between those of the two lateral landmarks (``mental_foramen_l/_r`` on the
  skull, ``cheilion_l/_r`` on a face mesh): below a plane parallel to the Frankfurt plane,
  between two sagittal (vertical) planes.

A face belongs to a region when its three vertices do.
"""

from dataclasses import dataclass

import numpy as np

from ..imaging.raster import check_faces
from ..softtissue.cones import midsagittal_plane
from ..softtissue.landmarks import side, twin

UPPER_MIDLINE = ("nasion", "glabella", "metopion", "bregma")
LOWER_MIDLINE = ("prosthion", "subspinale", "infradentale", "pogonion", "gnathion")
ANTERIOR_MIDLINE = ("nasion", "glabella", "prosthion", "subspinale", "metopion")

#: How far behind glabella/metopion (mm) the forehead region reaches.
FOREHEAD_DEPTH_MM = 80.0

#: Vertices this close (mm) to a cutting plane count as inside (rounding-proof cuts).
CUT_TOLERANCE_MM = 1e-6


@dataclass(frozen=True)
class AnatomicalFrame:
    """Orthonormal head frame in mesh coordinates.

    Attributes
    ----------
    origin : ndarray of shape (3,)
    left, up, anterior : ndarray of shape (3,)
        Unit vectors; ``anterior = left x up`` (its negative for a mirrored mesh).
    source : str
        ``"frankfurt"`` or ``"fallback"``.
    """

    origin: np.ndarray
    left: np.ndarray
    up: np.ndarray
    anterior: np.ndarray
    source: str

    def coordinates(self, points_mm):
        """(left, up, anterior) coordinates (mm) of points of shape (..., 3)."""
        d = np.asarray(points_mm, dtype=float) - self.origin
        return np.stack([d @ self.left, d @ self.up, d @ self.anterior], axis=-1)


def _get(landmarks, names):
    return [np.asarray(landmarks[n], dtype=float) for n in names if n in landmarks]


def _unit(x):
    n = np.linalg.norm(x)
    if not np.isfinite(n) or n < 1e-12:
        raise ValueError("degenerate landmark configuration (coincident or collinear points)")
    return x / n


def anatomical_frame(landmarks_mm):
    """The head frame of a skull (or face) from its 3D landmarks.

    Parameters
    ----------
    landmarks_mm : dict of str -> array_like of shape (3,)

    Returns
    -------
    AnatomicalFrame

    Raises
    ------
    ValueError
        When neither the Frankfurt landmarks nor an upper and a lower midline landmark are
        given.
    """
    lm = {k: np.asarray(v, dtype=float) for k, v in landmarks_mm.items()}
    orbitale = lm.get("orbitale_l", lm.get("orbitale_r"))
    upper, lower = _get(lm, UPPER_MIDLINE), _get(lm, LOWER_MIDLINE)
    if "porion_l" in lm and "porion_r" in lm and orbitale is not None:
        pl, pr = lm["porion_l"], lm["porion_r"]
        up = _unit(np.cross(pl - pr, orbitale - pr))
        above = upper or _get(lm, ("frontotemporale_l", "frontotemporale_r"))
        if above and np.mean([(p - pr) @ up for p in above]) < 0:
            up = -up
        elif not above and lower and np.mean([(p - pr) @ up for p in lower]) > 0:
            up = -up
        left = _unit((pl - pr) - ((pl - pr) @ up) * up)
        origin, source = (pl + pr) / 2, "frankfurt"
    else:
        if not upper or not lower:
            raise ValueError(
                "cannot orient the head: give porion_l, porion_r and orbitale_l/_r (Frankfurt "
                f"plane), or at least one of {UPPER_MIDLINE} and one of {LOWER_MIDLINE}"
            )
        _, left = midsagittal_plane(lm)
        height = np.mean(upper, axis=0) - np.mean(lower, axis=0)
        up = _unit(height - (height @ left) * left)
        origin, source = np.mean(upper + lower, axis=0), "fallback"
    anterior = np.cross(left, up)
    front = _get(lm, ANTERIOR_MIDLINE)
    back = [(lm[n] + lm[twin(n)]) / 2 for n in lm if side(n) == "l" and twin(n) in lm]
    if front and back and (np.mean(front, axis=0) - np.mean(back, axis=0)) @ anterior < 0:
        # A mirrored (left-handed) mesh: keep anterior pointing to the face.
        anterior = -anterior
    return AnatomicalFrame(origin, left, up, anterior, source)


@dataclass(frozen=True)
class Region:
    """A sub-mesh.

    Attributes
    ----------
    vertex_index : ndarray of shape (K,)
        Indices of the region's vertices in the full mesh.
    faces : ndarray of shape (G, 3)
        The region's faces, indexing ``vertex_index`` (0..K-1).
    face_index : ndarray of shape (G,)
        Indices of those faces in the full mesh.
    vertex_mask : ndarray of shape (V,) of bool
        Which full-mesh vertices satisfy the region's cuts (a superset of ``vertex_index``:
        vertices in no region face are not kept).
    """

    vertex_index: np.ndarray
    faces: np.ndarray
    face_index: np.ndarray
    vertex_mask: np.ndarray

    def vertices_of(self, vertices_mm):
        """The region's vertices (or any per-vertex array) taken from the full mesh's."""
        return np.asarray(vertices_mm)[self.vertex_index]


def submesh(vertex_mask, faces):
    """The faces whose three vertices are in ``vertex_mask``, re-indexed compactly."""
    faces = check_faces(faces, len(vertex_mask))
    vertex_mask = np.asarray(vertex_mask, dtype=bool)
    face_index = np.flatnonzero(np.all(vertex_mask[faces], axis=1))
    kept = faces[face_index]
    vertex_index = np.unique(kept)
    remap = np.full(len(vertex_mask), -1, np.int64)
    remap[vertex_index] = np.arange(len(vertex_index))
    return Region(vertex_index, remap[kept].reshape(-1, 3), face_index, vertex_mask)


def _need(landmarks, names, region):
    missing = [n for n in names if n not in landmarks]
    if missing:
        raise ValueError(f"the {region} region needs the landmarks {missing}")
    return [np.asarray(landmarks[n], dtype=float) for n in names]


def forehead_region(vertices_mm, faces, landmarks_mm, frame=None, depth_mm=FOREHEAD_DEPTH_MM):
    """Forehead: between the planes parallel to the Frankfurt plane through glabella and metopion.

    Parameters
    ----------
    vertices_mm : array_like of shape (V, 3)
    faces : array_like of shape (F, 3)
    landmarks_mm : dict of str -> array_like of shape (3,)
        Needs ``glabella`` and ``metopion`` (the skull's, or the face mesh's own).
    frame : AnatomicalFrame, optional
        Default: :func:`anatomical_frame` of ``landmarks_mm``.
    depth_mm : float or None
        Keep only vertices at most this far behind the more anterior landmark; None keeps the
        whole slice (back of the head included).

    Returns
    -------
    Region
    """
    glabella, metopion = _need(landmarks_mm, ("glabella", "metopion"), "forehead")
    frame = anatomical_frame(landmarks_mm) if frame is None else frame
    coords = frame.coordinates(vertices_mm)
    g, m = frame.coordinates(glabella), frame.coordinates(metopion)
    tol = CUT_TOLERANCE_MM
    lo, hi = sorted((g[1], m[1]))
    keep = (coords[:, 1] >= lo - tol) & (coords[:, 1] <= hi + tol)
    if depth_mm is not None:
        keep &= coords[:, 2] >= max(g[2], m[2]) - depth_mm - tol
    return submesh(keep, faces)


def chin_jaw_region(
    vertices_mm,
    faces,
    landmarks_mm,
    frame=None,
    upper="infradentale",
    lateral=("mental_foramen_l", "mental_foramen_r"),
):
    """Chin-jaw: below the horizontal plane through ``upper``, between sagittal planes.

    Parameters
    ----------
    vertices_mm : array_like of shape (V, 3)
    faces : array_like of shape (F, 3)
    landmarks_mm : dict of str -> array_like of shape (3,)
    frame : AnatomicalFrame, optional
    upper : str
        Landmark of the horizontal cut (``infradentale`` on the skull).
    lateral : (str, str)
        Landmarks of the two vertical cuts: ``mental_foramen_l/_r`` on the skull,
        ``cheilion_l/_r`` on a face mesh (see :func:`face_chin_jaw_region`).

    Returns
    -------
    Region
    """
    top, a, b = _need(landmarks_mm, (upper, *lateral), "chin-jaw")
    frame = anatomical_frame(landmarks_mm) if frame is None else frame
    coords = frame.coordinates(vertices_mm)
    t, ca, cb = (frame.coordinates(p) for p in (top, a, b))
    tol = CUT_TOLERANCE_MM
    lo, hi = sorted((ca[0], cb[0]))
    keep = (coords[:, 1] <= t[1] + tol) & (coords[:, 0] >= lo - tol) & (coords[:, 0] <= hi + tol)
    return submesh(keep, faces)


def face_chin_jaw_region(vertices_mm, faces, landmarks_mm, frame, upper="infradentale"):
    """Chin-jaw of a face mesh: the same cut with ``cheilion_l/_r`` as the vertical planes.

    ``frame`` should be the skull's (face meshes carry no porion/orbitale); ``upper`` names the
    landmark of the horizontal cut among ``landmarks_mm`` (the skull's infradentale by
    default, which the caller may merge in).
    """
    return chin_jaw_region(
        vertices_mm, faces, landmarks_mm, frame, upper=upper, lateral=("cheilion_l", "cheilion_r")
    )
