"""``review.html`` of a skull: its cranial landmarks in 3D, draggable along the bone, one
self-contained page (no network, no server).

The skull is drawn with WebGL (the shared ``web/meshgl.js``) through an orbit camera, the
project's pinhole (:mod:`lilium.geometry.camera`) turned about the skull's centre: drag to turn,
shift-drag to move, the wheel to zoom, buttons for the frontal, left, right and top views
(skull frame: x = subject's left, y = up, z = anterior, mm). Every cranial landmark is a marker
with its name, coloured by its quality (located, template, reviewed), hidden when the bone is in
front of it; dragging a marker moves the landmark along the surface (the first surface point
under the pointer). A checkbox per landmark switches it on or off; template points start off,
so saving without looking confirms none of them (as the photo's review page,
:mod:`lilium.photo.review`).

A page opened from ``file://`` cannot write to disk, so **Save** offers the landmarks as a
download, ``cranial_landmarks.json`` (a ``data:`` link): ``{"landmarks": {name: [x, y, z]},
"landmark_sources": {name: {"source": "reviewed", "quality": <the original quality>,
"confirmed": true}}}``, the points switched on only; a point never moved keeps its coordinates
exactly. It is the contract's cranial landmark file: put it in the subject folder, or pass it to
:func:`lilium.casework.build.read_skull` as ``landmarks_path``.

Nothing is fetched: the scripts (``lilium/report/web/*.js``) and styles are inline, the mesh is
base64 (float32 vertices relative to the skull's centre, uint32 faces, little-endian). A mesh
above ``max_faces`` is decimated (:func:`lilium.geometry.mesh.decimate`, quadric).

Opened as ``review.html?test[&view=left][&tick=NAME,...]``, the page draws, writes
``<pre id="first-draw-ms">``, ticks the named landmarks, drags the first switched-on landmark in
sight by (+15, +8) CSS pixels with pointer events (``<pre id="dragged">``), lists the landmarks
in sight (``<pre id="visible">``) and presses Save, which then fills the download link and
``<pre id="saved">`` without saving a file (for the headless-browser tests). ``?view=left``
(``right``, ``top``, ``front``) also works without ``test``.
"""

import html

import numpy as np

from ..geometry.mesh import decimate
from ..io.results import write_page
from ..photo.review import script_json
from .web_pages import base64_array, web_page
from .workbench import DEFAULT_MAX_FACES, skull_centre

__all__ = ["DEFAULT_MAX_FACES", "skull_review_page", "write_skull_review"]

def _check_mesh(vertices_mm, faces):
    vertices = np.asarray(vertices_mm, dtype=float)
    faces = np.asarray(faces)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or not len(vertices):
        raise ValueError(f"vertices_mm must have shape (V, 3), got {vertices.shape}")
    if not np.isfinite(vertices).all():
        raise ValueError("vertices_mm holds NaN or infinite coordinates; clean the mesh first")
    if faces.ndim != 2 or faces.shape[1] != 3 or not len(faces):
        raise ValueError(f"faces must have shape (F, 3), got {faces.shape}")
    if not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"faces must be integer vertex indices, got dtype {faces.dtype}")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise ValueError(
            f"faces index vertices 0 to {len(vertices) - 1}, got {faces.min()} to {faces.max()}"
        )
    return vertices, faces.astype(np.int64)


def _check_landmarks(landmarks_mm):
    out = {}
    for name, p in landmarks_mm.items():
        p = np.asarray(p, dtype=float)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ValueError(f"landmarks_mm[{name!r}] must be 3 finite numbers (mm), got {p}")
        out[str(name)] = [float(x) for x in p]
    return out


def _parts_line(parts):
    if not parts:
        return ""
    found = [html.escape(str(k)) for k, v in parts.items() if v]
    missing = [html.escape(str(k)) for k, v in parts.items() if not v]
    text = "found: " + (", ".join(found) or "none")
    return text + ("; not found: <b>" + ", ".join(missing) + "</b>" if missing else "")


def skull_review_page(
    vertices_mm,
    faces,
    landmarks_mm,
    sources,
    *,
    title="",
    parts=None,
    max_faces=DEFAULT_MAX_FACES,
    message="",
    skull_axes=None,
):
    """The review page of a skull's cranial landmarks, as HTML text.

    Parameters
    ----------
    vertices_mm : array_like of shape (V, 3)
        The skull mesh, skull frame (x = subject's left, y = up, z = anterior), mm.
    faces : array_like of shape (F, 3), int
    landmarks_mm : dict of str -> array_like of shape (3,)
        Cranial landmarks, skull frame, mm; listed in this order (the test hook drags the
        first one switched on and in sight).
    sources : dict of str -> dict
        ``landmark_sources`` of ``cranial_landmarks.json``: ``{"source", "quality"[, "flag"]}``
        per name; ``quality`` ``"located"`` or ``"template"`` colours the marker, and template
        points start switched off; ``"flag": "orientation_dependent"`` rings the marker and
        marks its row "check" until it is reviewed. A name without one is ``"manual"``
        (switched on).
    title : str
        Shown on top (escaped).
    parts : dict of str -> bool, optional
        Which parts of the skull were found, e.g. ``{"cranium": True, "mandible": False}``.
    max_faces : int
        Faces drawn; a larger mesh is decimated to about this many (about 7 MB of base64 at
        300,000).
    message : str
        A line shown above the skull, e.g. what was not found (escaped).
    skull_axes : array_like of shape (3, 3), optional
        Rows: the skull's left, up and anterior directions in the mesh's frame (the rotation
        of ``lilium skull``'s ``mesh2skull``), for the named views of a mesh in any pose;
        default the identity (a mesh in the skull frame: x = left, y = up, z = anterior).

    Returns
    -------
    str

    Raises
    ------
    ValueError
        A mesh that is not (V, 3) finite vertices and (F, 3) indices into them, or a landmark
        that is not 3 finite numbers.
    """
    vertices, faces = _check_mesh(vertices_mm, faces)
    landmarks = _check_landmarks(landmarks_mm)
    axes = np.eye(3) if skull_axes is None else np.asarray(skull_axes, dtype=float)
    axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    drawn_v, drawn_f = decimate(vertices, faces, max_faces)
    origin = skull_centre(drawn_v)
    data = {
        "mesh_origin_mm": [float(x) for x in origin],
        "extent_mm": [float(x) for x in np.ptp(drawn_v, axis=0)],
        "landmarks_mm": landmarks,
        "sources": {
            name: {str(k): v for k, v in (sources or {}).get(name, {}).items()}
            for name in landmarks
        },
        "parts": {str(k): bool(v) for k, v in (parts or {}).items()},
        "faces": {"drawn": len(drawn_f), "of": len(faces)},
        "axes": dict(zip(("left", "up", "anterior"), axes.tolist(), strict=True)),
    }
    faces_line = f"{len(drawn_f):,} faces drawn" + (
        f" (of {len(faces):,})" if len(drawn_f) < len(faces) else ""
    )
    values = {
        "__TITLE__": html.escape(title or "cranial landmarks"),
        "__PARTS__": _parts_line(parts),
        "__FACES__": faces_line,
        "__MESSAGE__": html.escape(message),
        "__DATA__": script_json(data),
        "__POSITIONS__": base64_array(np.asarray(drawn_v, dtype=float) - origin, "<f4"),
        "__INDICES__": base64_array(drawn_f, "<u4"),
    }
    return web_page("skull_review.html", "skull_review.js", values)


def write_skull_review(path, vertices_mm, faces, landmarks_mm, sources, **kwargs):
    """Write :func:`skull_review_page` to ``path`` (e.g. ``SUBJECT_DIR/review.html``).

    Keywords go to :func:`skull_review_page`. Returns the path.
    """
    page = skull_review_page(vertices_mm, faces, landmarks_mm, sources, **kwargs)
    return write_page(path, page)
