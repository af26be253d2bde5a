"""The typed inputs (:class:`~lilium.inputs.Skull`, :class:`~lilium.inputs.Photo`) built and
checked from what :mod:`lilium.io` parses, in one pass per skull and per photo.

:mod:`lilium.io` turns each file into plain arrays and dicts (a mesh's vertices and faces, a
landmark file's points); here they are cleaned and checked against each other (landmarks on the
mesh and spread, landmarks inside the image, the mesh's parts apart from the skull) and put
together. Every problem found is a ``ValueError`` whose message names the file, the field and
the fix.
"""

from pathlib import Path

import numpy as np

from ..constants import MIN_CRANIAL_EXTENT_FRACTION, PART_APART_MM
from ..geometry.mesh import clean_mesh, compact, parts_apart, point_surface_distance
from ..inputs import CaseWarning, Skull
from ..io.case import (
    check_axes_file,
    check_folder,
    check_landmark_layout,
    parse_axes,
    parse_cranial_landmarks,
    subject_files,
)
from ..io.mesh import parse_mesh
from ..io.paths import path_id, safe_id
from ..softtissue.landmarks import CRANIAL_TO_FACIAL
from ..softtissue.normals import landmark_normals

__all__ = ["read_skull", "skull_from_files"]


def read_skull(folder, axes_path=None, landmarks_path=None):
    """Read a subject (skull) folder.

    Parameters
    ----------
    folder : str or Path
        Holds ``skull.ply`` (or ``.obj``/``.stl``), ``cranial_landmarks.json`` and optionally
        ``soft_tissue_axes.json``.
    axes_path : str or Path, optional
        Soft-tissue axes file to use instead of the folder's own (e.g. a perturbed set); it
        must exist (a missing file is an error, never a silent fall-back to the normals).
    landmarks_path : str or Path, optional
        Cranial landmark file to use instead of the folder's own (any supported format).

    Returns
    -------
    Skull
        Axes missing from the file default to the outward skull-surface normal. Its id is the
        folder's name (:func:`lilium.io.paths.path_id`).
    """
    folder = check_folder(folder, "subject")
    mesh_path, lm_path = subject_files(folder)
    if landmarks_path is not None:
        lm_path = Path(landmarks_path)
    if axes_path is not None:
        check_axes_file(axes_path)
    else:
        axes_path = folder / "soft_tissue_axes.json"
    return skull_from_files(mesh_path, lm_path, axes_path, skull_id=path_id(folder, "skull"))


def skull_from_files(mesh_path, landmarks_path, axes_path=None, skull_id=None):
    """A :class:`Skull` from a mesh file and a landmark file of any supported format.

    Parameters
    ----------
    mesh_path : str or Path
        PLY, OBJ or STL (millimetres).
    landmarks_path : str or Path
        ``cranial_landmarks.json`` (docs/contract.md), or any file
        :func:`lilium.io.formats.read_landmarks` reads (3D Slicer, MeshLab, CSV, JSON; aliases).
    axes_path : str or Path, optional
        ``soft_tissue_axes.json``; absent axes default to the outward skull-surface normal.
    skull_id : str, optional
        Defaults to the mesh's folder name for ``skull.*`` and to the mesh's stem otherwise;
        made a safe folder name either way (:func:`lilium.io.paths.safe_id`).
    """
    mesh_path, lm_path = Path(mesh_path), Path(landmarks_path)
    if skull_id is None:
        skull_id = (
            path_id(mesh_path.parent, "skull") if mesh_path.stem == "skull" else mesh_path.stem
        )
    skull_id = safe_id(skull_id, "skull")
    vertices, faces = clean_mesh(*parse_mesh(mesh_path), source=str(mesh_path))
    landmarks = parse_cranial_landmarks(lm_path)
    vertices, faces, warnings = _skull_part(mesh_path, vertices, faces, landmarks)
    extent = np.ptp(vertices, axis=0).max()
    _check_on_mesh(lm_path, landmarks, vertices, faces, 0.1 * extent)
    check_landmark_layout(lm_path, landmarks, extent * MIN_CRANIAL_EXTENT_FRACTION, "mm")
    axes = {}
    for name, a in parse_axes(axes_path).items():
        norm = np.linalg.norm(a)
        if norm == 0:
            raise ValueError(f"{Path(axes_path)}: axes.{name} is the zero vector; give a direction")
        axes[name] = a / norm
    missing = [n for n in landmarks if n not in axes and n in CRANIAL_TO_FACIAL]
    if missing:
        axes.update(landmark_normals(vertices, faces, {n: landmarks[n] for n in missing}))
    return Skull(skull_id, vertices, faces, landmarks, axes, warnings=tuple(warnings))


def _skull_part(mesh_path, vertices, faces, landmarks):
    """The mesh without the parts apart from its cranial landmarks' part (:data:`PART_APART_MM`)
    and without unreferenced vertices; and the warning that names what was left out."""
    apart, parts = parts_apart(vertices, faces, np.array(list(landmarks.values())), PART_APART_MM)
    warnings = []
    if parts:
        faces = faces[~apart]
        sizes = "; ".join(f"{n} faces, {gap:.0f} mm away" for n, gap in parts[:3])
        more = f"; and {len(parts) - 3} more" if len(parts) > 3 else ""
        warnings.append(
            CaseWarning(
                "mesh_part_left_out",
                f"{mesh_path}: {len(parts)} fragment(s) of the mesh lie apart from the skull (the "
                f"part holding its cranial landmarks) and are left out ({sizes}{more}); delete "
                "them from the mesh if they are not this skull's bone",
            )
        )
    vertices, faces = compact(vertices, faces)
    return vertices, faces, warnings


def _check_on_mesh(lm_path, landmarks, vertices, faces, tolerance_mm):
    """Raise when a cranial landmark lies farther than ``tolerance_mm`` from the skull's surface
    (its triangles, not only its vertices: a coarse mesh has vertices far apart)."""
    sample = vertices[:: max(1, len(vertices) // 20_000)]  # a CT skull's: a sample first
    for name, p in landmarks.items():
        gap = np.min(np.linalg.norm(sample - p, axis=1))  # >= the whole mesh's gap
        if gap > tolerance_mm:
            gap = np.min(np.linalg.norm(vertices - p, axis=1))
        if gap > tolerance_mm:
            gap = point_surface_distance(p[None], vertices, faces)[0]
        if gap > tolerance_mm:
            raise ValueError(
                f"{lm_path}: landmarks.{name} lies {gap:.0f} mm from the skull mesh; landmarks "
                "must be in the mesh's frame and units"
            )
