"""Mesh files (PLY, OBJ, STL) through trimesh, with checks for degenerate meshes."""

from pathlib import Path

import numpy as np

MESH_SUFFIXES = (".ply", ".obj", ".stl")

#: A skull in millimetres spans roughly 100-300 mm; outside this the unit is probably wrong.
PLAUSIBLE_EXTENT_MM = (20.0, 1000.0)


def read_mesh(path):
    """Read a triangle mesh and check it.

    Parameters
    ----------
    path : str or Path
        ``.ply``, ``.obj`` or ``.stl``.

    Returns
    -------
    vertices_mm : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int

    Raises
    ------
    ValueError
        Missing or unreadable file, no triangles, non-finite coordinates, a flat or
        point-like mesh, or one whose size suggests metres or centimetres.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"{path}: unsupported mesh format; use PLY, OBJ or STL")
    try:
        mesh = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:  # trimesh raises many kinds for a corrupt file
        detail = " ".join(str(exc).split())[:120]
        kind = path.suffix[1:].upper()
        raise ValueError(
            f"{path}: not a readable {kind} triangle mesh (its header or data are damaged or "
            f"of another format: {type(exc).__name__}{f' {detail}' if detail else ''}); open it "
            "in a mesh program (MeshLab, 3D Slicer) and export the skull surface again as PLY"
        ) from exc
    vertices = np.asarray(getattr(mesh, "vertices", np.empty((0, 3))), dtype=float)
    faces = np.asarray(getattr(mesh, "faces", np.empty((0, 3))), dtype=np.int64)
    check_mesh(vertices, faces, str(path))
    return vertices, faces


def check_mesh(vertices_mm, faces, source="mesh"):
    """Raise a ``ValueError`` saying what is wrong if a mesh cannot be a skull in mm."""
    if len(faces) == 0 or len(vertices_mm) < 3:
        raise ValueError(f"{source}: the mesh has no triangles; export the surface, not points")
    if not np.all(np.isfinite(vertices_mm)):
        raise ValueError(f"{source}: vertex coordinates contain NaN or infinity; repair the mesh")
    if faces.min() < 0 or faces.max() >= len(vertices_mm):
        raise ValueError(f"{source}: faces index missing vertices; repair the mesh")
    tri = vertices_mm[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    if area.sum() <= 0:
        raise ValueError(f"{source}: degenerate mesh (all triangles have zero area)")
    extent = np.ptp(vertices_mm[np.unique(faces)], axis=0)
    if extent.min() <= 1e-3 * extent.max():
        raise ValueError(f"{source}: degenerate mesh (flat or a line, extent {extent.tolist()})")
    lo, hi = PLAUSIBLE_EXTENT_MM
    if not lo <= extent.max() <= hi:
        raise ValueError(
            f"{source}: the mesh spans {extent.max():.3g} units; a skull in millimetres spans "
            f"{lo:.0f}-{hi:.0f}; rescale it to millimetres"
        )


def write_mesh(path, vertices_mm, faces):
    """Write a triangle mesh (format from the suffix)."""
    import trimesh

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.Trimesh(vertices_mm, faces, process=False).export(path)
