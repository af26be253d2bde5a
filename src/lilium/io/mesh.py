"""Mesh files (PLY, OBJ, STL) through trimesh, with checks for degenerate meshes."""

import signal
import sys
import threading
from pathlib import Path

import numpy as np

from ..constants import PART_APART_MM
from ..geometry.mesh import parts_apart, weld
from .paths import naming_errors

MESH_SUFFIXES = (".ply", ".obj", ".stl")

#: A skull in millimetres spans roughly 100-300 mm (an adult's length 170-210 mm, a mandible
#: alone about 100 mm); outside this range the unit is wrong. The lower bound refuses a skull in
#: centimetres (13-22 units), which the landmark checks cannot catch when its landmarks are in
#: centimetres too: the depth table in mm then makes the soft tissue ten times too thick, and the
#: true person was excluded.
PLAUSIBLE_EXTENT_MM = (30.0, 1000.0)


def import_trimesh():
    """The ``trimesh`` module, imported on first use with Ctrl-C held back until it is in.

    trimesh imports its optional dependencies under ``except BaseException``, which swallows a
    ``KeyboardInterrupt`` that arrives meanwhile: a Ctrl-C in that 0.15 s was lost and the
    command ran on. During the import a Ctrl-C is only noted (the main thread's handler is
    swapped); once the import is over, it is passed to the handler from before (Python's:
    ``KeyboardInterrupt`` in Lilium's code).
    """
    if "trimesh" in sys.modules:
        return sys.modules["trimesh"]
    if threading.current_thread() is not threading.main_thread():
        import trimesh  # handlers belong to the main thread

        return trimesh
    noted = []
    before = signal.signal(signal.SIGINT, lambda signum, frame: noted.append(signum))
    try:
        import trimesh
    finally:
        signal.signal(signal.SIGINT, before)
    if noted and callable(before):
        before(signal.SIGINT, None)
    elif noted and before == signal.SIG_DFL:
        raise KeyboardInterrupt
    return trimesh


def read_mesh(path):
    """Read a triangle mesh and check it.

    Parameters
    ----------
    path : str or Path
        ``.ply``, ``.obj`` or ``.stl``.

    Returns
    -------
    vertices_mm : ndarray of shape (V, 3)
        Vertices at one position merged (:func:`~lilium.geometry.mesh.weld`) for the formats
        read through trimesh (STL, OBJ, text PLY) and for a binary PLY of more vertices than
        faces (loose triangles); any other binary PLY comes back as stored.
    faces : ndarray of shape (F, 3), int

    Raises
    ------
    ValueError
        Missing or unreadable file, no triangles, non-finite coordinates, a flat or
        point-like mesh, or one whose size suggests metres or centimetres.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"{path}: unsupported mesh format; use PLY, OBJ or STL")
    if path.suffix.lower() == ".ply":
        fast = read_binary_ply(path)
        if fast is not None:
            vertices, faces = fast
            if len(vertices) > len(faces) and _indexed(vertices, faces):
                # More vertices than faces: loose triangles (a closed mesh has about F / 2)
                vertices, faces = weld(vertices, faces)
            check_mesh(vertices, faces, str(path))
            return vertices, faces
    trimesh = import_trimesh()  # 0.15 s: only for the layouts read_binary_ply does not read
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
    if _indexed(vertices, faces):
        vertices, faces = weld(vertices, faces)  # an STL's loose triangles, an OBJ's seams
    check_mesh(vertices, faces, str(path))
    return vertices, faces


def _indexed(vertices, faces):
    """Whether the faces index existing, finite vertices (else check_mesh names the fault)."""
    valid = len(faces) and faces.min() >= 0 and faces.max() < len(vertices)
    return bool(valid) and bool(np.all(np.isfinite(vertices)))


#: PLY scalar types and their numpy dtypes (little endian).
_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "<i2", "int16": "<i2",
    "ushort": "<u2", "uint16": "<u2", "int": "<i4", "int32": "<i4", "uint": "<u4",
    "uint32": "<u4", "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
}  # fmt: skip


def read_binary_ply(path):
    """The common binary PLY (what ``lilium import-ct`` and most mesh programs write) read with
    numpy: ``(vertices (V, 3), faces (F, 3))``, or None for any other layout (then trimesh reads
    it). About 20 times faster than trimesh's import and reader on a 600k-face skull.

    Handled: ``binary_little_endian``; a ``vertex`` element of scalar properties with ``x``,
    ``y``, ``z``; then a ``face`` element whose only property is a list of vertex indices, every
    face a triangle; nothing after it.
    """
    with open(path, "rb") as file:
        if file.read(4) != b"ply\n":
            return None
        lines = []
        while True:
            line = file.readline()
            if not line or len(lines) > 200:
                return None
            line = line.decode("ascii", "replace").strip()
            if line == "end_header":
                break
            lines.append(line.split())
        data = file.read()
    elements = []
    for words in lines:
        if words[0] == "format" and words[1:2] != ["binary_little_endian"]:
            return None
        if words[0] == "element" and len(words) == 3:
            elements.append([words[1], int(words[2]), []])
        elif words[0] == "property" and elements:
            elements[-1][2].append(words[1:])
    if [e[0] for e in elements] != ["vertex", "face"]:
        return None
    (_, n_vertices, vertex_props), (_, n_faces, face_props) = elements
    if any(len(p) != 2 or p[0] not in _PLY_TYPES for p in vertex_props):
        return None
    names = [p[1] for p in vertex_props]
    if not {"x", "y", "z"} <= set(names) or len(face_props) != 1:
        return None
    kind = face_props[0]
    if (
        len(kind) != 4
        or kind[0] != "list"
        or kind[1] not in _PLY_TYPES
        or kind[2] not in _PLY_TYPES
    ):
        return None
    vertex_dtype = np.dtype([(p[1], _PLY_TYPES[p[0]]) for p in vertex_props])
    face_dtype = np.dtype([("n", _PLY_TYPES[kind[1]]), ("i", _PLY_TYPES[kind[2]], 3)])
    size = n_vertices * vertex_dtype.itemsize + n_faces * face_dtype.itemsize
    if len(data) != size:
        return None  # not all triangles, or trailing data: let trimesh decide
    vertex = np.frombuffer(data, vertex_dtype, n_vertices)
    face = np.frombuffer(data, face_dtype, n_faces, offset=n_vertices * vertex_dtype.itemsize)
    if n_faces and not np.all(face["n"] == 3):
        return None
    vertices = np.column_stack([vertex["x"], vertex["y"], vertex["z"]]).astype(float)
    return vertices, face["i"].astype(np.int64)


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


def write_mesh(path, vertices_mm, faces):
    """Write a triangle mesh (format from the suffix)."""
    trimesh = import_trimesh()

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with naming_errors(path):
        trimesh.Trimesh(vertices_mm, faces, process=False).export(path)
