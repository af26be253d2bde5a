"""Mesh files (PLY, OBJ, STL): parsed into arrays here, welded and checked by
:func:`lilium.geometry.mesh.clean_mesh`."""

import signal
import sys
import threading
from pathlib import Path

import numpy as np

from ..geometry.mesh import PLAUSIBLE_EXTENT_MM, check_mesh, clean_mesh
from .paths import naming_errors

__all__ = [
    "MESH_SUFFIXES",
    "PLAUSIBLE_EXTENT_MM",
    "check_mesh",
    "import_trimesh",
    "parse_mesh",
    "read_binary_ply",
    "read_mesh",
    "write_mesh",
]

MESH_SUFFIXES = (".ply", ".obj", ".stl")


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
    """Read a triangle mesh and check it: :func:`parse_mesh`, then
    :func:`~lilium.geometry.mesh.clean_mesh`.

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
    return clean_mesh(*parse_mesh(path), source=str(path))


def parse_mesh(path):
    """Parse a triangle mesh file into arrays, as stored: no welding, no checks.

    Parameters
    ----------
    path : str or Path
        ``.ply``, ``.obj`` or ``.stl``.

    Returns
    -------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3), int
    shared : bool
        True for a binary PLY read as stored (its vertices shared by its faces as written);
        False for the formats read through trimesh (an STL's loose triangles, an OBJ's seams).

    Raises
    ------
    ValueError
        Missing, unsupported or unreadable file.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: file not found")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise ValueError(f"{path}: unsupported mesh format; use PLY, OBJ or STL")
    if path.suffix.lower() == ".ply":
        fast = read_binary_ply(path)
        if fast is not None:
            return (*fast, True)
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
    return vertices, faces, False


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


def write_mesh(path, vertices_mm, faces):
    """Write a triangle mesh (format from the suffix)."""
    trimesh = import_trimesh()

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with naming_errors(path):
        trimesh.Trimesh(vertices_mm, faces, process=False).export(path)
